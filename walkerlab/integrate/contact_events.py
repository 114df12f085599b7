"""What every contact run shares, the passive one (:mod:`walkerlab.integrate.contact`) and
the powered one (:mod:`walkerlab.integrate.contact_powered`): its limits
(:class:`ContactLimits`), its sample grid and absolute tolerance, and the location of the
events that end it (a trip, a fall, a flight: :func:`first_event`, on the cubic Hermite
interpolant of the samples; a solver failure at a patch's side: :func:`trip_or_failure`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from walkerlab.models.contact.energy import side_entry

from .ends import RunEnd

__all__ = ["ContactLimits", "first_event", "hermite_root", "hermite_state", "run_atol",
           "sample_grid", "trip_or_failure", "work_limit_message"]


@dataclass(frozen=True)
class ContactLimits:
    """How far a contact integration goes and what ends it (besides its end time).

    Attributes
    ----------
    sample_rate_hz : float
        Output sample rate [Hz] (events are located between samples).
    pin_stance_until : {"none", "first_touchdown", "time"}
        Hold leg2's foot fixed (constraint, reduced coordinates) until leg1 first touches
        ground, or until ``t0 + pin_time_s``.
    pin_time_s : float
        [s].
    fall_hip_height_m : float
        Fall when the hip height above the ground line drops below this [m].
    airborne_hip_height_m : float
        The walker flew off when its hip rises above this [m] (inf: never).
    wall_time_limit_s : float or None
        Stop with ``time_limit`` once this much wall time is used [s] (None: no clock; a
        run it ends depends on the machine's speed).
    max_rhs_evaluations : int or None
        Stop with ``work_limit`` once the run has evaluated its right-hand side this many
        times (checked at each evaluation of a Python right-hand side, between chunks of a
        compiled one and between segments of a powered run): the same end on any machine
        (None: no bound).
    chunk_s : float
        Longest chunk of simulated time [s]; trips, falls, flights, the wall-time limit, the work
        bound and the ``stop`` predicate are checked between chunks.
    use_jacobian : bool
        Pass the analytic Jacobian to odeint / solve_ivp (the compiled backends take none).
    """

    sample_rate_hz: float = 1000.0
    pin_stance_until: str = "none"
    pin_time_s: float = 0.0
    fall_hip_height_m: float = 0.5
    airborne_hip_height_m: float = np.inf
    wall_time_limit_s: float | None = None
    max_rhs_evaluations: int | None = None
    chunk_s: float = 1.0
    use_jacobian: bool = True


def work_limit_message(limits: ContactLimits) -> str:
    """The message of a run the work bound ended (``limits.max_rhs_evaluations``): the
    bound and the scene field that raises it."""
    return (f"work bound reached: {limits.max_rhs_evaluations:,} right-hand-side "
            "evaluations (raise contact_sim.max_rhs_evaluations for a longer run)")


def sample_grid(t0: float, t1: float, rate: float) -> np.ndarray:
    """Sample times from ``t0`` to ``t1`` [s] at ``rate`` [Hz], ``t1`` always included.

    Returns
    -------
    ndarray, shape (k,)
        Increasing times [s].
    """
    n = int(np.floor((t1 - t0) * rate + 1e-9))
    t = t0 + np.arange(n + 1) / rate
    if t1 - t[-1] > 1e-9:
        t = np.append(t, t1)
    return t


def hermite_root(ta, tb, ya, yb, da, db, rising=None):
    """First root in [ta, tb] of the cubic Hermite interpolant (values y, slopes d), or None.

    ``rising``: True keeps only upward crossings, False downward, None either."""
    h = tb - ta
    if h <= 0:
        return None
    # y(u) on u in [0, 1]: Hermite basis in power form
    c3 = 2 * ya - 2 * yb + h * da + h * db
    c2 = -3 * ya + 3 * yb - 2 * h * da - h * db
    c1 = h * da
    c0 = ya
    r = np.roots([c3, c2, c1, c0]) if abs(c3) > 0 or abs(c2) > 0 else np.roots([c1, c0])
    r = np.sort(r[(np.abs(r.imag) < 1e-9) & (r.real >= -1e-12) & (r.real <= 1 + 1e-12)].real)
    for u in r:
        slope = 3 * c3 * u * u + 2 * c2 * u + c1
        if rising is None or (slope > 0) == rising:
            return float(ta + min(max(u, 0.0), 1.0) * h)
    return None


def hermite_state(walker, ta, tb, xa, xb, tc):
    """State at ``tc`` in [ta, tb] on the cubic Hermite interpolant of two samples."""
    fa, fb = walker.rhs(ta, xa), walker.rhs(tb, xb)
    h = tb - ta
    u = (tc - ta) / h
    h00, h10 = 2 * u**3 - 3 * u**2 + 1, u**3 - 2 * u**2 + u
    h01, h11 = -2 * u**3 + 3 * u**2, u**3 - u**2
    return h00 * xa + h10 * h * fa + h01 * xb + h11 * h * fb


def _hip_crossing(walker, tt, X, hh, level, k0, down):
    """First crossing of the hip height ``hh`` through ``level`` (downward if ``down``):
    (sample, time) on the Hermite interpolant, or None."""
    hit = np.flatnonzero(hh < level) if down else np.flatnonzero(hh > level)
    if not hit.size:
        return None
    k = int(hit[0])
    if k == 0:
        return k0 - 1, float(tt[0])
    v = walker.hip_height_rate(X[k0 - 1 + k - 1:k0 - 1 + k + 1])  # hip velocity . n
    tc = hermite_root(tt[k - 1], tt[k], hh[k - 1] - level, hh[k] - level, float(v[0]),
                      float(v[1]), rising=not down)
    if tc is None:
        pair = [hh[k], hh[k - 1]] if down else [hh[k - 1], hh[k]]
        times = [tt[k], tt[k - 1]] if down else [tt[k - 1], tt[k]]
        tc = float(np.interp(level, pair, times))
    return k0 - 1 + k, tc


def first_event(walker, t, X, limits: ContactLimits, k0=1):
    """First trip, fall or flight in samples ``k0..``: (kind, k, time, foot, edge) or None.

    A trip is a foot crossing the along-slope edge of one of its lane's patches while below
    the patch's top (penetration > 0 at the crossing, on the Hermite interpolant); a fall
    is the hip height crossing ``limits.fall_hip_height_m`` downward, a flight
    (``airborne``) ``limits.airborne_hip_height_m`` upward.

    ``t`` (n,) [s] and ``X`` (n, 2 nq) (``walker.state_names()``) are the samples; the
    returned ``time`` is in [s] and ``edge`` the patch edge's along-slope position [m].
    """
    if len(t) <= k0:
        return None
    sl = slice(k0 - 1, None)
    hh = walker.hip_height(X[sl])
    tt = t[sl]
    best = None
    for kind, level, down in ((RunEnd.FALL.value, limits.fall_hip_height_m, True),
                              (RunEnd.AIRBORNE.value, limits.airborne_hip_height_m, False)):
        c = _hip_crossing(walker, tt, X, hh, level, k0, down)
        if c is not None and (best is None or c[1] < best[2]):
            best = (kind, c[0], c[1], "", np.nan)
    if walker.continuous:
        return best
    cq = walker.contact_quantities(X[sl])
    hw = walker.patch_half_width
    for foot in cq:  # every contact point on its leg's lane
        q, lane = cq[foot], walker.lane(foot)
        on = q["on_ground"] > 0.5
        pen = q["penetration"]
        # entering a patch horizontally (gap -> patch) with the foot below the top at
        # either sample: find the edge crossing and the penetration there
        cand = np.flatnonzero(~on[:-1] & on[1:] & ((pen[:-1] > 0) | (pen[1:] > 0))) + 1
        for k in cand:
            if best is not None and k0 - 1 + k > best[1]:
                break
            sa, sb = q["s"][k - 1], q["s"][k]
            j = int(np.argmin(np.abs(lane - sb)))
            c = lane[j]
            edge = c - hw if sb < c else c + hw
            vs = q["slip_velocity"]
            te = hermite_root(tt[k - 1], tt[k], sa - edge, sb - edge, vs[k - 1], vs[k])
            if te is None:
                te = float(tt[k])
            xe = hermite_state(walker, tt[k - 1], tt[k], X[k0 - 1 + k - 1], X[k0 - 1 + k], te)
            qe = walker.contact_quantities(xe)[foot]
            pe = qe["penetration"][0]
            if qe["on_ground"][0] <= 0.5:  # found on the gap's side of the edge: the depth
                pe += walker.lane_heights(foot)[j]  # below that patch's top (stairs' lower)
            if pe > 0 and (best is None or te < best[2]):
                best = (RunEnd.TRIP.value, k0 - 1 + k, float(te), foot, float(edge))
                break
    return best


def run_atol(walker, atol: float, method: str):
    """The absolute tolerance a contact run hands its integrator: ``atol`` times the
    walker's per-state :meth:`~walkerlab.models.contact.model.ContactWalker.atol_scale`
    (2 nq,) (a flat foot's rotation rates looser), or the scalar ``atol`` itself where every
    factor is 1 (every walker without flat feet: the same call as ever) and for numbalsoda
    (a scalar atol only).  Units: those of each state [m, rad, m/s, rad/s]."""
    scale = getattr(walker, "atol_scale", None)
    if scale is None or method == "numbalsoda":
        return atol
    f = np.asarray(scale(), dtype=float)
    return atol if np.all(f == 1.0) else atol * f


def trip_or_failure(walker, t_last: float, x_last, message: str, k_last: int,
                    ahead_s: float) -> tuple[RunEnd, str, tuple | None]:
    """How a run ends when its solver fails at the sample ``k_last`` (time ``t_last`` [s],
    state ``x_last``): a trip when a foot below the patch tops in a gap reaches a patch's
    side within ``ahead_s`` [s] (:func:`~walkerlab.models.contact.energy.side_entry`: the
    force jump no step can cross, a walker whose footfalls drifted off the patches), else a
    solver failure with ``message``.  Returns ``(termination, message, event or None)``."""
    hit = side_entry(walker, x_last, ahead_s)
    if hit is None:
        return RunEnd.SOLVER_FAILURE, message, None
    foot, edge, ahead, depth = hit
    return (RunEnd.TRIP, f"trip: {foot}'s foot, {depth:.3g} m below the patch tops in a gap, "
            f"entered a patch from its side (the solver stopped there: {message})",
            (RunEnd.TRIP.value, k_last, float(t_last) + ahead, foot, edge))
