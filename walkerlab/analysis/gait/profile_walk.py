"""The rigid walker on a piecewise-linear height profile ``y(x)`` (``terrain.kind: profile``):
a walk that carries the stance foot's world place from step to step.

The profile's points ``(x_i, y_i)`` [m] are world coordinates (x forward, y up); the first
stance foot stands on the profile at its first point's x.  Each step lands on one segment
``[x_j, x_{j+1}]`` of the profile: its ground is the segment's line, of slope ``gamma_j =
-atan((y_{j+1} - y_j) / (x_{j+1} - x_j))`` (downhill positive, as the scene's slope) lying
``drop_j`` [m] below the stance foot at the stance foot's x, so the step is the walker on
that slope with the heel strike at that landing (:func:`walkerlab.models.hybrid.ground.
on_landing`: the generated clearance guard plus ``drop_j cos(gamma_j)``).  The segment is
solved: the step is integrated on the segment under the swing foot's expected landing
(the stance foot's x plus the last step's advance), and again on the segment where the foot
did land while that differs (a landing at a vertex belongs to either: both lines meet
there).  A profile that is one straight line of the scene's slope through the first stance
foot is the slope itself: its walk is the slope walk (drops exactly 0 there).

A bump the swing foot passes through before the landing segment (a profile not convex
between two footfalls) is not looked for: the ideal model's foot-through, as at mid-stance.
"""

from __future__ import annotations

import math
import time

import numpy as np

from walkerlab.integrate.rigid import HybridTrajectory, integrate_step, other_leg

__all__ = ["ProfileGround", "profile_points", "simulate_on_profile"]

#: tries of one step's landing segment before the walk is ended as a solver failure
_SEGMENT_TRIES = 8


def profile_points(terrain) -> np.ndarray:
    """The profile's points (k, 2) [m] (``terrain.profile_m``).

    Raises
    ------
    ValueError
        A profile given only as ``profile_csv`` (one line).
    """
    if terrain.profile_m is None:
        raise ValueError("terrain.profile_csv: the rigid walk reads inline profiles "
                         "(terrain.profile_m) only so far")
    return np.asarray(terrain.profile_m, dtype=float)


def _segment_of(P: np.ndarray, x: float) -> int:
    """Index ``j`` of the segment ``[x_j, x_{j+1}]`` holding ``x`` (the first or last one
    beyond the ends)."""
    return int(min(max(np.searchsorted(P[:, 0], x, side="right") - 1, 0), len(P) - 2))


def _line(P: np.ndarray, j: int) -> tuple[float, float]:
    """``(gamma_j [rad], dy/dx)`` of segment ``j``."""
    dydx = (P[j + 1, 1] - P[j, 1]) / (P[j + 1, 0] - P[j, 0])
    return -math.atan(dydx), dydx


class ProfileGround:
    """The steps of a walk on the profile ``P`` (module docstring): each step's walker on
    its landing segment and the choice of that segment, shared by
    :func:`simulate_on_profile` and the Gymnasium environment's rigid view
    (:mod:`walkerlab.gym.rigid_view`).

    Parameters
    ----------
    walker_at : callable ``slope [rad] -> HybridWalker``
        The scene's rigid walker on a slope (absolute coordinates).
    data_at : callable ``slope [rad] -> WalkerData``
    P : ndarray (k, 2)
        Profile points [m], x increasing (:func:`profile_points`).
    """

    def __init__(self, walker_at, data_at, P: np.ndarray):
        self.walker_at, self.data_at, self.P = walker_at, data_at, P
        self._walkers: dict[tuple, object] = {}
        #: the walker on the first segment's slope (the walk's legs, its trajectory's)
        self.base = walker_at(_line(P, 0)[0])
        #: the first stance foot's world place [m]
        self.start = np.array([P[0, 0], P[0, 1]])

    def walker(self, j: int, foot: np.ndarray):
        """The walker of a step from the stance foot ``foot`` (2,) [m] landing on segment
        ``j`` (:func:`walkerlab.models.hybrid.ground.on_landing`, built once per landing)."""
        from walkerlab.models.hybrid.ground import on_landing

        P = self.P
        g, dydx = _line(P, j)
        drop = float(foot[1] - (P[j, 1] + (foot[0] - P[j, 0]) * dydx))
        key = (g, drop)
        if key not in self._walkers:
            self._walkers[key] = on_landing(self.walker_at(g), self.data_at(g), drop)
        return self._walkers[key]

    def first_segment(self, foot: np.ndarray, advance: float) -> int:
        """The segment a step is first tried on: under the stance foot's x plus the last
        step's advance ``advance`` [m] (0 before the first)."""
        return _segment_of(self.P, foot[0] + advance)

    def retry(self, j: int, land: float, tried: set) -> int | None:
        """The segment to walk the step again on, after a heel strike at ``land`` [m]
        (world x) on segment ``j``'s line; None to keep this landing (on the segment, or
        no other segment takes it).  ``tried``: the step's segments so far (updated)."""
        P = self.P
        if P[j, 0] <= land <= P[j + 1, 0] or (j == 0 and land < P[0, 0]):
            return None
        tried.add(j)
        j2 = _segment_of(P, land)
        if j2 in tried or len(tried) >= _SEGMENT_TRIES:
            return None  # beyond the profile's end, or no segment takes the landing
        return j2

    def goes_on(self, j: int, land: float) -> bool:
        """Whether the walk goes on after a heel strike at ``land`` [m] on segment ``j``
        (the landing on that segment and on the profile)."""
        P = self.P
        return bool(P[0, 0] <= land <= P[-1, 0] and P[j, 0] <= land <= P[j + 1, 0])


def simulate_on_profile(walker_at, data_at, P: np.ndarray, x0: np.ndarray, n_steps: int,
                        solver, max_step_time: float = 5.0,
                        first_stance_leg: str = "leg2") -> HybridTrajectory:
    """Walk ``n_steps`` steps on the profile ``P`` from ``x0`` (module docstring); stops
    early on a fall, a solver failure or a landing past the profile's end.

    Parameters
    ----------
    walker_at, data_at, P
        As :class:`ProfileGround`.
    x0 : ndarray (2n,)
        State just after heel strike [rad, rad/s].
    n_steps : int
    solver : walkerlab.integrate.solver.Solver
    max_step_time : float
        [s]
    first_stance_leg : str

    Returns
    -------
    HybridTrajectory
        Its segments carry each step's stance foot's world place (``stance_foot_world``
        [m], the first at ``(x_0, y_0)``).
    """
    t_wall = time.perf_counter()
    ground = ProfileGround(walker_at, data_at, P)
    base = ground.base
    segs = []
    x, t, leg = np.asarray(x0, float), 0.0, first_stance_leg
    foot = ground.start.copy()
    advance = 0.0
    for k in range(n_steps):
        j = ground.first_segment(foot, advance)
        tried: set = set()
        while True:
            w = ground.walker(j, foot)
            seg = integrate_step(w, x, solver, t0=t, max_step_time=max_step_time, index=k,
                                 stance_leg=leg, stance_foot_world=foot.copy())
            if seg.termination != "heel_strike":
                break
            land = foot[0] + float(w.points(seg.x_end)["swing_foot"][0])
            j2 = ground.retry(j, land, tried)
            if j2 is None:
                break
            j = j2
        segs.append(seg)
        if seg.termination != "heel_strike" or not ground.goes_on(j, land):
            break
        step = w.points(seg.x_end)["swing_foot"]
        advance = float(step[0])
        foot = foot + np.asarray(step, float)
        x, t, leg = seg.x_next, seg.t_end, other_leg(base, leg)
    return HybridTrajectory(segs, time.perf_counter() - t_wall, base)
