"""Adams Solver function expressions evaluated at a dataset's start, for the tests of the
Adams exports: the file read back by walkerlab's reader
(:mod:`walkerlab.export.adams_reader`), each function's semantics written out here from the
Adams Solver function reference (``DX(i, j, k)``, ``AZ``, ``WZ``, ``STEP``, ``IF``, ...),
not from the writer."""

from __future__ import annotations

import math
import re

import numpy as np


def evaluate(model, ids, extra: dict | None = None) -> dict:
    """The dataset's VARIABLEs ``ids`` at its start (Adams Solver function semantics:
    ``DX(i, j, k)`` the displacement of marker i from j along k's x (k default ground),
    ``DM`` its length, ``VX(i)`` i's velocity along ground x, ``WZ(i, j, k)`` i's angular
    velocity less j's (its part's) along k's z, ``AZ(i, j)`` the turn of i's x axis
    about j's z (``ATAN2(x_i . y_j, x_i . x_j)``), ``STEP(x, x0, h0, x1, h1)`` the cubic
    step ``h0 + (h1 - h0) u^2 (3 - 2 u)``, ``IF(e: a, b, c)`` a, b, c for e <, =, > 0;
    ``ABS`` the absolute value, ``CONTACT`` 0: the start's feet touch without penetrating)."""
    fns = {**model.functions("VARIABLE"), **(extra or {})}
    cache: dict = {}

    def varval(n):
        if n not in cache:
            e = re.sub(r"IF\(([^:]*):", r"_if(\1,", fns[int(n)])
            cache[n] = eval(e, {"__builtins__": {}}, env)  # noqa: S307 (the test's own file)
        return cache[n]

    def pose(m):
        return model.marker_pose(m)

    def disp(i, j=None, k=None):
        d = pose(i)[0] - (pose(j)[0] if j is not None else 0.0)
        R = pose(k)[1] if k is not None else np.eye(3)
        return R.T @ d / model.length

    def vel(i):
        part = model.get("MARKER", i).integer("PART")
        v, w = model.part_velocity(part)
        cm = pose(model.get("PART", part).integer("CM"))[0]
        return (v + np.cross(w, pose(i)[0] - cm)) / model.length

    def wz(i, j, k):  # i's angular velocity relative to j's, along k's z
        w = model.part_velocity(model.get("MARKER", i).integer("PART"))[1]
        pj = model.get("MARKER", j).integer("PART")
        if pj != 1:  # not the ground's
            w = w - model.part_velocity(pj)[1]
        return (pose(k)[1].T @ w)[2]

    def az(i, j):
        Ri, Rj = pose(i)[1], pose(j)[1]
        return math.atan2(Ri[:, 0] @ Rj[:, 1], Ri[:, 0] @ Rj[:, 0])

    def step(x, x0, h0, x1, h1):
        if x <= x0:
            return h0
        if x >= x1:
            return h1
        u = (x - x0) / (x1 - x0)
        return h0 + (h1 - h0) * u * u * (3 - 2 * u)

    env = {"VARVAL": varval, "AZ": az, "STEP": step, "ATAN2": math.atan2, "SQRT": math.sqrt,
           "CONTACT": lambda *a: 0.0, "MIN": min, "MAX": max, "ABS": abs,
           "DX": lambda *a: disp(*a)[0], "DY": lambda *a: disp(*a)[1],
           "DZ": lambda *a: disp(*a)[2], "DM": lambda i, j: float(np.linalg.norm(disp(i, j))),
           "VX": lambda i: vel(i)[0], "VY": lambda i: vel(i)[1], "VZ": lambda i: vel(i)[2],
           "WZ": wz, "_if": lambda e, a, b, c: a if e < 0 else (b if e == 0 else c)}
    return {n: varval(n) for n in ids}


def evaluate_expr(model, expr: str) -> float:
    """One expression, as :func:`evaluate` reads it."""
    return evaluate(model, (-1,), {-1: expr})[-1]
