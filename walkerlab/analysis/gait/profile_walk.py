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

The swing foot's path is checked against the profile along each step
(:func:`swing_clearance`): its depth below the profile is sampled densely and at every
profile vertex it passes (the crossings located with :func:`scipy.optimize.brentq` on the
step's dense output), and a swing foot that enters the ground before its heel strike (a
wall, a bump, the far side of a pit) ends the walk as a ``trip`` at the moment it meets the
profile, named with its time and place.  One foot-through stays ignored, as the ideal model
ignores it (McGeer 1990; Garcia et al. 1998): straight legs' swing foot dipping below the
ground when it passes the stance foot at the legs' alignment, as deep as it dips below the
step's own ground line through the stance foot (the landing segment's slope); its depth is
reported (``midstance_scuff_depth_m``), a profile above that line there is a trip.  The
step lands only on the segment under its landing (the segment solving above): a first
contact earlier on the way, even one the foot comes down onto (a bend up just before the
landing segment), is reported as that trip, not solved as a landing there.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace

import numpy as np
from scipy.optimize import brentq

from walkerlab.integrate.rigid import HybridTrajectory, integrate_step, other_leg
from walkerlab.models.hybrid.ground import on_landing

__all__ = ["CLEARANCE_TOL_M", "Clearance", "ProfileGround", "profile_points",
           "simulate_on_profile", "swing_clearance"]

#: tries of one step's landing segment before the walk is ended as a solver failure
_SEGMENT_TRIES = 8
#: depth [m] below the profile a swing foot must reach to count as in the ground: the heel
#: strike puts it on the landing segment to the event location's rounding (~1e-15 m), so
#: 1e-9 m is rounding's margin, not a tolerance of the model
CLEARANCE_TOL_M = 1e-9
#: samples of each step's swing-foot path (with the profile's vertices it passes): 1/400 of
#: a step between samples, where a profile between two vertices is one straight line
_PATH_SAMPLES = 401


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


def profile_height(P: np.ndarray, x) -> np.ndarray:
    """The profile's height [m] at ``x`` [m] (piecewise linear; beyond its ends its first
    and last segments run on, as the walk's and the contact model's ground does)."""
    x = np.asarray(x, float)
    y = np.interp(x, P[:, 0], P[:, 1])
    for j, side in ((0, x < P[0, 0]), (len(P) - 2, x > P[-1, 0])):
        if np.any(side):
            k = 0 if j == 0 else len(P) - 1
            y = np.where(side, P[k, 1] + (x - P[k, 0]) * _line(P, j)[1], y)
    return y


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


@dataclass(frozen=True)
class Clearance:
    """The swing foot's path of one step against the profile (:func:`swing_clearance`).

    Attributes
    ----------
    trip : tuple of float or None
        ``(t [s], x [m], y [m])``: where and when the swing foot met the profile before its
        heel strike (world frame), or None.
    scuff_depth_m : float
        Deepest point [m] of the ignored mid-stance foot-through (0.0: none).
    """

    trip: tuple[float, float, float] | None
    scuff_depth_m: float


def swing_clearance(walker, seg, foot: np.ndarray, P: np.ndarray, j: int) -> Clearance:
    """The swing foot's depth below the profile along one step (module docstring).

    Parameters
    ----------
    walker : walkerlab.models.hybrid.HybridWalker
        The step's walker (:meth:`ProfileGround.walker`; points relative to the stance foot,
        x forward, y up [m]).
    seg : walkerlab.integrate.rigid.Segment
        The step (its dense output).
    foot : ndarray (2,)
        The stance foot's world place [m].
    P : ndarray (k, 2)
        The profile's points [m].
    j : int
        The landing segment (its slope is the step's ground at the stance foot).

    Returns
    -------
    Clearance
    """
    t0, t1 = float(seg.t_start), float(seg.t_end)
    if not t1 > t0:
        return Clearance(None, 0.0)

    def at(t):
        X = seg.sample(np.atleast_1d(np.asarray(t, float)))
        p = np.asarray(walker.points(X)["swing_foot"], float).reshape(2, -1)
        return foot[0] + p[0], foot[1] + p[1]

    ts = np.linspace(t0, t1, _PATH_SAMPLES)
    x, _ = at(ts)
    # the profile's vertices the foot passes, and the legs' alignment (x of the stance foot)
    extra = []
    for xv in (*P[(P[:, 0] > x.min()) & (P[:, 0] < x.max()), 0], foot[0]):
        d = x - xv
        for i in np.flatnonzero(np.sign(d[:-1]) * np.sign(d[1:]) < 0):
            extra.append(brentq(lambda t, v=xv: at(t)[0][0] - v, ts[i], ts[i + 1],
                                xtol=1e-14, rtol=1e-12))
    ts = np.union1d(ts, extra)
    x, y = at(ts)
    depth = profile_height(P, x) - y  # > 0: below the profile
    below = depth > CLEARANCE_TOL_M
    below[[0, -1]] = False  # the lift-off and the landing (on the ground to rounding)
    if not below.any():
        return Clearance(None, 0.0)
    dydx = _line(P, j)[1]
    over_line = profile_height(P, x) - (foot[1] + (x - foot[0]) * dydx)
    # the runs below the profile; the one that reaches the legs' alignment (straight legs:
    # the swing foot on the stance foot, at the end of the dip or its start) is the
    # foot-through
    edges = np.flatnonzero(np.diff(np.concatenate([[0], below.astype(int), [0]])))
    scuff = np.zeros(ts.size, bool)
    for a, b in zip(edges[::2], edges[1::2]):
        near = x[max(a - 1, 0):min(b + 1, ts.size)]
        if near.min() - CLEARANCE_TOL_M <= foot[0] <= near.max() + CLEARANCE_TOL_M:
            scuff[a:b] = over_line[a:b] <= CLEARANCE_TOL_M
    hit = np.flatnonzero(below & ~scuff)
    depth_s = float(depth[scuff].max()) if scuff.any() else 0.0
    if not hit.size:
        return Clearance(None, depth_s)
    i = int(hit[0])
    t = float(ts[i])
    if i > 0 and depth[i - 1] <= 0.0 < depth[i]:  # where it meets the profile
        t = brentq(lambda tt: float(profile_height(P, at(tt)[0][0])
                                    - at(tt)[1][0]), ts[i - 1], ts[i], xtol=1e-14)
    xt, yt = at(t)
    return Clearance((t, float(xt[0]), float(yt[0])), depth_s)


def _tripped(seg, t: float):
    """``seg`` cut at ``t`` [s]: a step that ended as a trip (no reset)."""
    x = seg.sample(np.array([t]))[:, 0]
    return replace(seg, t_end=t, x_end=x, x_next=None, termination="trip",
                   event="swing_foot_in_profile", monodromy=None)


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
        [m], the first at ``(x_0, y_0)``); a swing foot that entered the profile ends it
        with a step of termination ``trip`` cut there (:func:`swing_clearance`).  Two
        attributes more: ``profile_trip`` (``(t [s], x [m], y [m])`` of that trip, or None)
        and ``midstance_scuff_depth_m`` (the ignored mid-stance foot-through's deepest
        point over the walk [m], 0.0 for none).
    """
    t_wall = time.perf_counter()
    ground = ProfileGround(walker_at, data_at, P)
    base = ground.base
    segs = []
    x, t, leg = np.asarray(x0, float), 0.0, first_stance_leg
    foot = ground.start.copy()
    advance = 0.0
    trip, scuff = None, 0.0
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
        c = swing_clearance(w, seg, foot, P, j)
        scuff = max(scuff, c.scuff_depth_m)
        if c.trip is not None:
            trip = c.trip
            segs.append(_tripped(seg, trip[0]))
            break
        segs.append(seg)
        if seg.termination != "heel_strike" or not ground.goes_on(j, land):
            break
        step = w.points(seg.x_end)["swing_foot"]
        advance = float(step[0])
        foot = foot + np.asarray(step, float)
        x, t, leg = seg.x_next, seg.t_end, other_leg(base, leg)
    traj = HybridTrajectory(segs, time.perf_counter() - t_wall, base)
    traj.profile_trip, traj.midstance_scuff_depth_m = trip, scuff
    return traj
