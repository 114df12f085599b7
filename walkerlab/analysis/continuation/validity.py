"""Validity checks along a branch of gaits: where the rigid model stops being valid.

Each check is a function of the corrected point that turns negative there (the branch then
ends, located by ``brentq`` along the branch in
:mod:`walkerlab.analysis.continuation.points`): the swing foot's clearance inside the step
(for walkers whose starting gait clears the ground: a compass gait scuffs at mid-stance by
construction) and the ground's normal force on the stance foot (the rigid model pins the
foot: where the force would pull, the model is not valid).
"""

from __future__ import annotations

import math

import numpy as np

from walkerlab.analysis.continuation.gait_map import BranchSystem, state_from_section, step_map
from walkerlab.models.hybrid.base import HybridWalker

__all__ = ["VALIDITY", "normal_force_ratio"]


def _clearance(sys: BranchSystem, u: np.ndarray, sc: float, n: int = 200) -> float:
    """Lowest height [m] of the swing foot above the slope strictly inside the steps."""
    w = sys.family.walker(u[-1] * sc)
    x = state_from_section(w, u[:-1])
    _xk, _T, _J, segs = step_map(w, x, sys.family.solver, sys.k,
                                 max_step_time=sys.family.max_step_time, segments=True,
                                 steps_per_map=sys.family.steps(w))
    low = math.inf
    phi = w.slope_rad
    for seg in segs:
        span = seg.t_end - seg.t_start
        ts = seg.t_start + span * np.linspace(0.08, 0.92, n)  # the feet touch at both ends
        X = seg.sample(ts)
        foot = w.points(X)["swing_foot"]
        h = foot[1] * math.cos(phi) + foot[0] * math.sin(phi)
        low = min(low, float(np.min(h)))
    return low


def _mass_points(w: HybridWalker) -> dict | None:
    """Masses [kg] of the walker's named points (``hip``: ``M_hip``; ``<role>_<body>``:
    ``m_<body>``), or None when they do not add up to the walker's total mass (a model whose
    points this convention does not cover)."""
    p = w.params
    names = w.points(w.layout().zeros())
    out = {"hip": float(p.get("M_hip", 0.0))}
    for name in names:
        for role in ("stance_", "swing_"):
            key = f"m_{name[len(role):]}"
            if name.startswith(role) and key in p:
                out[name] = float(p[key])
    total = float(w.total_mass_kg)
    return out if total > 0 and abs(sum(out.values()) - total) <= 1e-9 * total else None


def normal_force_ratio(w: HybridWalker, segs, n: int = 200) -> float:
    """Smallest ground normal force on the stance foot over the steps, as a fraction of the
    walker's weight ``M g`` [-].

    The only external forces in a step are gravity and the stance foot's contact force, so
    ``F = M (a_com - g_vec)``; its component along the slope normal ``(sin phi, cos phi)`` is
    ``N = M (a_com . n + g cos phi)`` (points of either dimension: a walker in 3D has its
    lateral axis last, across the normal).  ``a_com`` is the second time derivative of the centre
    of mass (the named mass points, :func:`_mass_points`) on the dense output of each phase
    (central differences on ``n`` points inside the phase, so an intra-step impact such as a
    knee strike is not differentiated across).  A negative value means the stance foot would
    have to be pulled: the rigid model (foot pinned) is not valid there.  NaN when the mass
    points are not known.
    """
    masses = _mass_points(w)
    if masses is None:
        return math.nan
    M = sum(masses.values())
    g = float(w.params["gravity_m_per_s2"])
    phi = float(w.slope_rad)
    low = math.inf
    for seg in segs:
        for _ph, dense, (ta, tb) in seg.pieces:
            if tb - ta <= 1e-6:
                continue
            ts = np.linspace(ta, tb, n)
            X = w.layout().state_rows(np.atleast_2d(dense(ts)))
            pts = w.points(X)
            com = sum(m * np.asarray(pts[k], float) for k, m in masses.items()) / M
            dt = ts[1] - ts[0]
            acc = np.gradient(np.gradient(com, dt, axis=1), dt, axis=1)[:, 2:-2]
            # the slope's normal in the points' world axes (x downhill, y up; a walker in
            # 3D has z across, along which the normal has no component)
            nrm = np.zeros(len(acc))
            nrm[:2] = math.sin(phi), math.cos(phi)
            N = (nrm @ acc + g * math.cos(phi)) / g
            low = min(low, float(np.min(N)))
    return low


def _normal_force(sys: BranchSystem, u: np.ndarray, sc: float) -> float:
    w = sys.family.walker(u[-1] * sc)
    x = state_from_section(w, u[:-1])
    segs = step_map(w, x, sys.family.solver, sys.k, max_step_time=sys.family.max_step_time,
                    segments=True, steps_per_map=sys.family.steps(w))[3]
    return normal_force_ratio(w, segs)


#: validity checks along a branch: name -> (function (system, u, p_scale) -> value that
#: turns negative where the rigid model stops being valid, the branch end's cause)
VALIDITY = {
    "clearance": (lambda sys, u, sc: _clearance(sys, u, sc),
                  "swing foot scuffing (its clearance inside the step reaches 0)"),
    "normal_force": (_normal_force, "stance foot lifting (the ground's normal force on it "
                     "reaches 0: the rigid model is not valid beyond)"),
}
