"""Where a period-1 gait on stairs puts its feet: tread drift, the step a foot would miss a
tread, and the swing foot's clearance over the treads and riser edges.

On stairs (``terrain.kind: stairs``, one step per stair) the rigid gait's fixed point is the
walker's state (:func:`walkerlab.models.hybrid.ground.on_landing`), not its place: with the
step advance ``a`` (horizontal distance from the stance foot to the swing foot at heel
strike) and tread depth ``D``, the foot's place on the tread, ``u`` from the tread's back
(riser) end, moves by ``a - D`` every step, ``u_k = u_0 + k (a - D)``: the ``k``-th footfall
misses its tread when ``u_k`` leaves ``[0, D]`` (``u_k > D``: beyond the nosing, on the next
tread; ``u_k < 0``: the foot would have met the stance tread first).

Clearances (the step from the fixed point, the stance foot at ``u_0``; heights above the
tread under the foot, :meth:`walkerlab.models.ground.Ground.clearance` of the scene's ground,
as the report's :func:`walkerlab.analysis.gait.checks.swing_foot_clearance`): over the tread
behind (the swing foot's start), over the stance tread
(the mid-stance foot-through the ideal model ignores, as on a slope) and at the riser edge
ahead (the foot passing above the nosing going down, above the next tread going up); a
negative riser clearance is a scuff against the riser, which the rigid model reports and
does not model.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np
from scipy.optimize import brentq

from walkerlab.integrate.rigid import integrate_step
from walkerlab.models.ground import scene_ground

__all__ = ["TreadLanding", "steps_until_miss", "tread_landing"]

#: dense-output samples per phase for the clearance minima (the extrema are then refined
#: by nothing: a clearance is reported to ~1e-7 m at a 0.7 s step)
_SAMPLES = 4001


@dataclass(frozen=True)
class TreadLanding:
    """Footholds of a period-1 gait on stairs (module docstring).

    Attributes
    ----------
    riser_m, tread_m : float
        The stairs [m].
    direction : str
        ``down`` or ``up``.
    step_advance_m : float
        Horizontal distance from the stance foot to the swing foot at heel strike [m].
    drift_per_step_m : float
        ``step_advance_m - tread_m`` [m]: how far the foot's place on its tread moves per step.
    first_foothold_m : float
        ``u_0`` [m], from the tread's back end.
    steps_until_miss : int
        The first footfall ``k >= 1`` whose ``u_k`` leaves ``[0, tread_m]``; -1: never
        (no drift).
    back_clearance_m, midstance_clearance_m : float
        Smallest height [m] of the swing foot over the tread behind and over the stance
        tread (negative: the foot goes through; over the stance tread this is the mid-stance
        foot-through of the point-foot model, ignored as on a slope).
    riser_clearance_m : float
        Height [m] of the swing foot above the riser's top edge ahead as it passes it
        (NaN: it does not pass it before heel strike: the landing misses the tread, or the
        foot was ahead of the edge all along - a spoked wheel's next spoke, which lands on
        the tread ahead from above).
    riser_scuff : bool
        ``riser_clearance_m < 0``, or NaN with the foot starting behind the edge: the foot
        hits the riser (reported, not modelled).
    """

    riser_m: float
    tread_m: float
    direction: str
    step_advance_m: float
    drift_per_step_m: float
    first_foothold_m: float
    steps_until_miss: int
    back_clearance_m: float
    midstance_clearance_m: float
    riser_clearance_m: float
    riser_scuff: bool

    def as_dict(self) -> dict:
        """Fields by name (the artifact's ``footholds/`` attributes)."""
        return asdict(self)


def steps_until_miss(first_m: float, drift_m: float, tread_m: float) -> int:
    """The first footfall ``k >= 1`` with ``first_m + k drift_m`` outside ``[0, tread_m]``;
    -1 when ``drift_m == 0`` (never)."""
    if drift_m == 0.0:
        return -1
    room = (tread_m - first_m) if drift_m > 0 else first_m
    return int(np.floor(room / abs(drift_m))) + 1


def tread_landing(walker, x, terrain, solver) -> TreadLanding:
    """The footholds and clearances of the step from ``x`` on ``terrain``'s stairs.

    Parameters
    ----------
    walker : HybridWalker
        On the stairs (:func:`walkerlab.models.hybrid.ground.on_landing`).
    x : ndarray (2n,)
        The gait's fixed point (just after heel strike).
    terrain : walkerlab.config.TerrainSettings
        ``kind: stairs``.
    solver : walkerlab.integrate.solver.Solver

    Returns
    -------
    TreadLanding

    Raises
    ------
    ValueError
        The step from ``x`` does not end in heel strike (one line).
    """
    H, D = float(terrain.riser_m), float(terrain.tread_m)
    up = terrain.direction == "up"
    u0 = D / 2 if terrain.first_foothold_m is None else float(terrain.first_foothold_m)
    seg = integrate_step(walker, np.asarray(x, float), solver)
    if seg.termination != "heel_strike":
        raise ValueError(f"terrain: the step from the gait ends in {seg.termination}, not "
                         "heel strike")
    a = float(walker.points(seg.x_end)["swing_foot"][0])
    drift = a - D
    ahead = H if up else -H
    ground = scene_ground(terrain, 0.0)  # the stance foot at the origin, on tread 0
    back, mid = np.inf, np.inf
    cross = []
    x_start = None  # the swing foot's place at the step's start [m]
    for _phase, sol, (ta, tb) in seg.pieces:
        t = np.linspace(ta, tb, _SAMPLES)
        p = np.asarray(walker.points(sol(t))["swing_foot"])
        xf = p[0]
        if x_start is None:
            x_start = float(xf[0])
        c = ground.clearance(xf, p[1])  # the report's quantity (checks.swing_foot_clearance)
        over_back = xf < -u0
        over_stance = (xf >= -u0) & (xf <= D - u0)
        if over_back.any():
            back = min(back, float(np.min(c[over_back])))
        if over_stance.any():
            mid = min(mid, float(np.min(c[over_stance])))
        s = xf - (D - u0)
        k = np.flatnonzero((s[:-1] < 0) & (s[1:] >= 0))
        if k.size and not cross:
            def foot(tt, _sol=sol):
                return np.asarray(walker.points(np.asarray(_sol(tt)).reshape(-1))
                                  ["swing_foot"], dtype=float).reshape(-1)
            tc = brentq(lambda tt: foot(tt)[0] - (D - u0), t[k[0]], t[k[0] + 1], xtol=1e-14)
            cross.append(float(foot(tc)[1]) - max(0.0, ahead))
    edge = cross[0] if cross else float("nan")
    return TreadLanding(
        riser_m=H, tread_m=D, direction="up" if up else "down", step_advance_m=a,
        drift_per_step_m=drift, first_foothold_m=u0,
        steps_until_miss=steps_until_miss(u0, drift, D),
        back_clearance_m=float(back) if np.isfinite(back) else float("nan"),
        midstance_clearance_m=float(mid) if np.isfinite(mid) else float("nan"),
        riser_clearance_m=edge,
        riser_scuff=edge < 0 or (edge != edge and not x_start >= D - u0))
