"""Time integration of the contact walker and gait-event extraction.

Integrators: ``"odeint"`` (scipy.integrate.odeint = LSODA with little overhead, run in chunks
so a fall stops the run) or any stiff ``solve_ivp`` method (``"LSODA"``, ``"Radau"``,
``"BDF"``), all given the analytic Jacobian.  Gait events (touchdown / lift-off) are found
from the samples: a foot is in contact when it penetrates ground of its lane; crossing times
are linearly interpolated between samples (error ~ dt^2 * |d''| / 8, i.e. well below the
sample spacing).
"""

from __future__ import annotations

import time
import warnings
from dataclasses import dataclass, field

import numpy as np
from scipy.integrate import ODEintWarning, odeint, solve_ivp

from . import _kernels as K
from .model import FOOT_NAMES, ContactWalker

__all__ = [
    "ContactResult",
    "FootTrace",
    "StepSummary",
    "initial_state_from_ideal",
    "simulate_contact",
]


@dataclass
class FootTrace:
    """Sampled contact quantities and events of one foot.

    Attributes
    ----------
    normal_force, friction_force : ndarray (n,)
        [N]; friction along the down-slope tangent t.
    penetration : ndarray (n,)
        Signed penetration [m] (negative = height above the ground line).
    slip_velocity : ndarray (n,)
        Down-slope foot velocity [m/s].
    s : ndarray (n,)
        Along-slope foot position [m].
    on_ground : ndarray (n,) of bool
        Whether the foot's lane has ground under it.
    touchdown_times, liftoff_times : ndarray
        Event times [s].
    """

    normal_force: np.ndarray
    friction_force: np.ndarray
    penetration: np.ndarray
    slip_velocity: np.ndarray
    s: np.ndarray
    on_ground: np.ndarray
    touchdown_times: np.ndarray
    liftoff_times: np.ndarray


@dataclass
class StepSummary:
    """One step, from a heel strike (or t0) to the next heel strike.

    Attributes
    ----------
    index : int
    stance_leg : str
        "leg1" or "leg2".
    t_start, t_end : float
        [s]; ``t_end`` is nan if the run ended first.
    period : float
        ``t_end - t_start`` [s] (nan if incomplete).
    stance_slip_mm : float
        Along-slope displacement of the stance foot between its touchdown and its last
        lift-off before its next heel strike (or the run's end) [mm]; positive = downhill.
    bounce_count : int
        Touchdowns within the step other than the heel strike that starts it.
    peak_penetration_m : float
        Largest penetration of either foot within the step [m].
    """

    index: int
    stance_leg: str
    t_start: float
    t_end: float
    period: float
    stance_slip_mm: float
    bounce_count: int
    peak_penetration_m: float


@dataclass
class ContactResult:
    """Output of :func:`simulate_contact` (all SI unless named otherwise).

    Attributes
    ----------
    t : ndarray (n,)
        Sample times [s].
    q, qdot : ndarray (n, 4)
        [hip_x, hip_y, theta1, theta2] [m, m, rad, rad] and their rates.
    feet : dict[str, FootTrace]
        Keys "leg1", "leg2".
    heel_strike_times : ndarray
        [s] (touchdowns of the swing foot ahead of the stance foot).
    heel_strike_legs : list[str]
        Leg that struck.
    steps : list[StepSummary]
    termination : str
        "t_final", "fall" or "solver_failure".
    fall_time : float or None
        [s] time hip height crossed the threshold.
    message : str
        Solver message.
    nfev, njev : int
        Right-hand side / Jacobian evaluations.
    wall_time_s : float
        Wall time of the integration (excluding post-processing) [s].
    method : str
    pin_end_time : float
        End of the pinned phase [s] (= t0 if none).
    fall_reason : str or None
        "hip_height" (hip below the threshold) or "trip" (foot entered a patch from the side).
    """

    t: np.ndarray
    q: np.ndarray
    qdot: np.ndarray
    feet: dict
    heel_strike_times: np.ndarray
    heel_strike_legs: list
    steps: list
    termination: str
    fall_time: float | None
    message: str
    nfev: int
    njev: int
    wall_time_s: float
    method: str
    pin_end_time: float = 0.0
    fall_reason: str | None = None
    extra: dict = field(default_factory=dict)

    @property
    def x(self) -> np.ndarray:
        """States (n, 8)."""
        return np.hstack([self.q, self.qdot])

    @property
    def walked_steps(self) -> int:
        """Number of heel strikes."""
        return len(self.heel_strike_times)


def initial_state_from_ideal(walker: ContactWalker, theta1, theta2, dtheta1, dtheta2,
                             rate_scale=(1.0, 1.0)) -> np.ndarray:
    """Floating-walker state (8,) from an ideal-model state (leg2 = stance).

    The stance foot (leg2) is placed at s = 0 at its static penetration
    ``(M g cos phi / k)^(1/e)`` [m] (along -n); the hip velocity follows from the pinned-foot
    kinematics hip = foot2 + L (-sin th2, cos th2).  ``rate_scale`` multiplies
    (dtheta1, dtheta2) first.

    Parameters
    ----------
    theta1, theta2 : float
        Swing / stance leg angles [rad].
    dtheta1, dtheta2 : float
        Their rates [rad/s].
    rate_scale : (float, float)
        Multipliers [-].

    Returns
    -------
    ndarray (8,)
    """
    w1 = dtheta1 * rate_scale[0]
    w2 = dtheta2 * rate_scale[1]
    foot2 = -walker.static_penetration() * walker.normal
    z = np.array([theta1, theta2, w1, w2], float)
    return walker.pinned_to_full(z, foot2)


# ---------------------------------------------------------------------------- integration
def _grid(t0, t1, rate):
    n = int(np.floor((t1 - t0) * rate + 1e-9))
    t = t0 + np.arange(n + 1) / rate
    if t1 - t[-1] > 1e-9:
        t = np.append(t, t1)
    return t


def _run_pinned(walker, x0, t0, t_end, until_touchdown, rate, rtol, atol, max_step, hth):
    """Integrate with leg2's foot held fixed.  Returns (t, X, nfev, njev, status, msg)."""
    foot2 = walker.foot_positions(x0)[1]
    z0 = x0[[2, 3, 6, 7]]

    def f(t, z):
        return walker.rhs_pinned(t, z, foot2)

    def touch(t, z):
        x = walker.pinned_to_full(z, foot2)
        cq = walker.contact_quantities(x)["leg1"]
        return -cq["penetration"][0] if cq["on_ground"][0] > 0 else 1.0

    touch.terminal = True
    touch.direction = -1

    def fall(t, z):
        return walker.hip_height(walker.pinned_to_full(z, foot2))[0] - hth

    fall.terminal = True
    fall.direction = -1
    events = [fall] + ([touch] if until_touchdown else [])
    sol = solve_ivp(f, (t0, t_end), z0, method="LSODA", rtol=rtol, atol=atol,
                    max_step=max_step, t_eval=_grid(t0, t_end, rate), events=events,
                    dense_output=True)
    t, Z = sol.t, sol.y.T
    if sol.status == 1:  # stopped on an event: append the event point
        te = sol.t_events[1][0] if (until_touchdown and sol.t_events[1].size) else sol.t_events[0][0]
        if t.size == 0 or te > t[-1]:
            t = np.append(t, te)
            Z = np.vstack([Z, sol.sol(te)])
    X = np.array([walker.pinned_to_full(z, foot2) for z in Z])
    fell = sol.status == 1 and sol.t_events[0].size > 0
    return t, X, sol.nfev, sol.njev, ("fall" if fell else ("ok" if sol.status >= 0 else "fail")), \
        sol.message


def _run_free(walker, x0, t0, t1, method, rtol, atol, max_step, rate, hth, dtrip, use_jac,
              chunk_s):
    """Integrate the free walker.  Returns (t, X, nfev, njev, status, message)."""
    # contact switched off once fallen / tripped (see _kernels.dead): odeint has no events, and
    # the solve_ivp fall event cannot see a trip.  The samples are cut at the first dead one.
    P, c1, c2 = walker._P, walker.lane1, walker.lane2
    hfreeze = 0.98 * hth

    def frhs(t, x):
        return K.rhs_guarded(x, P, c1, c2, hfreeze, dtrip)

    def fjac(t, x):
        return K.jac_guarded(x, P, c1, c2, hfreeze, dtrip)

    if not use_jac:
        fjac = None
    if method == "odeint":
        ts, Xs, nfev, njev = [np.array([t0])], [x0[None]], 0, 0
        ta, xa = t0, x0
        status, msg = "ok", "Integration successful."
        while ta < t1 - 1e-12:
            tb = min(ta + chunk_s, t1)
            tg = _grid(ta, tb, rate)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", ODEintWarning)
                X, info = odeint(frhs, xa, tg, Dfun=fjac, tfirst=True, rtol=rtol, atol=atol,
                                 hmax=0.0 if not np.isfinite(max_step) else max_step,
                                 full_output=True, mxstep=200000)
            nfev += int(info["nfe"][-1])
            njev += int(info["nje"][-1])
            if info["message"] != "Integration successful.":
                nk = int(np.count_nonzero(info["tcur"] >= tg[1:] - 1e-14)) + 1
                ts.append(tg[1:nk]); Xs.append(X[1:nk])
                return np.concatenate(ts), np.vstack(Xs), nfev, njev, "fail", info["message"]
            ts.append(tg[1:]); Xs.append(X[1:])
            if K.dead(X[-1], P, c1, c2, hfreeze, dtrip) or np.any(walker.hip_height(X) < hth):
                status = "fall"  # the caller finds the time and the cause
                break
            ta, xa = tb, X[-1]
        return np.concatenate(ts), np.vstack(Xs), nfev, njev, status, msg

    def fall(t, x):
        return x[0] * np.sin(walker.phi) + x[1] * np.cos(walker.phi) - hth

    fall.terminal = True
    fall.direction = -1
    kw = {"jac": fjac} if use_jac else {}
    sol = solve_ivp(frhs, (t0, t1), x0, method=method, rtol=rtol, atol=atol,
                    max_step=max_step, t_eval=_grid(t0, t1, rate), events=[fall], **kw)
    status = {0: "ok", 1: "fall", -1: "fail"}[sol.status]
    t, X = sol.t, sol.y.T
    if sol.status == 1:  # append the fall-event state
        t = np.append(t, sol.t_events[0][0])
        X = np.vstack([X, sol.y_events[0][0]])
    return t, X, sol.nfev, sol.njev, status, sol.message


def simulate_contact(walker: ContactWalker, x0: np.ndarray, t_final: float,
                     method: str = "odeint", rtol: float = 1e-8, atol: float = 1e-10,
                     max_step: float = np.inf, sample_rate_hz: float = 1000.0, *,
                     t0: float = 0.0, pin_stance_until: str = "none", pin_time_s: float = 0.0,
                     fall_hip_height_m: float | None = None, use_jacobian: bool = True,
                     trip_depth_m: float | None = None, chunk_s: float = 1.0,
                     min_step_m: float = 0.05,
                     initial_stance: str = "leg2") -> ContactResult:
    """Simulate the floating walker with compliant feet.

    Parameters
    ----------
    walker : ContactWalker
    x0 : ndarray (8,)
        Initial state [hip_x, hip_y, th1, th2, vhip_x, vhip_y, w1, w2] (SI).
    t_final : float
        End time [s].
    method : {"odeint", "LSODA", "Radau", "BDF"}
        Integrator (odeint = LSODA with lower overhead; stops at a chunk end after a fall).
    rtol, atol : float
        Tolerances; ``atol`` [m, rad, m/s, rad/s] must be well below the penetration depth
        (~6e-5 m for the paper's contact), default 1e-10.
    max_step : float
        Largest step [s].
    sample_rate_hz : float
        Output sample rate [Hz].
    pin_stance_until : {"none", "first_touchdown", "time"}
        Hold leg2's foot fixed (constraint, reduced coordinates) until leg1 first touches
        ground, or until ``t0 + pin_time_s``.
    fall_hip_height_m : float, optional
        Fall threshold of the hip height above ground [m] (default 0.5 L).
    trip_depth_m : float, optional
        A foot found more than this [m] below the surface of a patch (it entered through the
        patch's side after sinking in a gap) ends the run as a fall ("trip").  Default: 20 x
        the static penetration under the full weight (1.2 mm for the paper's contact; heel
        strikes reach ~2 x static).
    use_jacobian : bool
        Pass the analytic Jacobian to the integrator.
    chunk_s : float
        Chunk length [s] of the odeint driver (fall checks between chunks).
    min_step_m : float
        A touchdown of the swing foot counts as a heel strike only if it lands at least this
        far [m] downhill of the stance foot's touchdown point (filters scuffs).
    initial_stance : {"leg2", "leg1"}

    Returns
    -------
    ContactResult
    """
    if method not in ("odeint", "LSODA", "Radau", "BDF"):
        raise ValueError(f"method must be odeint, LSODA, Radau or BDF, not {method!r}")
    x0 = np.asarray(x0, dtype=float)
    hth = 0.5 * walker.L if fall_hip_height_m is None else fall_hip_height_m
    if trip_depth_m is None:
        trip_depth_m = 20.0 * walker.static_penetration()
    wall = time.perf_counter()
    ts, Xs, nfev, njev, status, msg = [], [], 0, 0, "ok", ""
    t_pin = t0
    if pin_stance_until != "none":
        t_end = t_final if pin_stance_until == "first_touchdown" else min(t0 + pin_time_s, t_final)
        tp, Xp, nf, nj, status, msg = _run_pinned(
            walker, x0, t0, t_end, pin_stance_until == "first_touchdown", sample_rate_hz,
            rtol, atol, max_step, hth)
        ts.append(tp); Xs.append(Xp); nfev += nf; njev += nj
        t_pin, x0 = tp[-1], Xp[-1]
    if status == "ok" and t_pin < t_final - 1e-12:
        tf, Xf, nf, nj, status, msg = _run_free(walker, x0, t_pin, t_final, method, rtol, atol,
                                                max_step, sample_rate_hz, hth, trip_depth_m,
                                                use_jacobian, chunk_s)
        if ts:
            tf, Xf = tf[1:], Xf[1:]
        ts.append(tf); Xs.append(Xf); nfev += nf; njev += nj
    wall = time.perf_counter() - wall
    t = np.concatenate(ts)
    X = np.vstack(Xs)
    fall_time = None
    termination = {"ok": "t_final", "fall": "fall", "fail": "solver_failure"}[status]
    fall_reason = None
    hh = walker.hip_height(X)
    below = np.flatnonzero(hh < hth + 1e-12)
    cq = walker.contact_quantities(X)
    deep = np.flatnonzero(np.any([(cq[f]["penetration"] > trip_depth_m) & (cq[f]["on_ground"] > 0)
                                  for f in FOOT_NAMES], axis=0))
    k_fall = below[0] if below.size else len(t)
    k_trip = deep[0] if deep.size else len(t)
    if k_fall < len(t) or k_trip < len(t):
        termination = "fall"
        k = min(k_fall, k_trip)
        if k_trip < k_fall:
            # the deep sample itself (absurd IMPACT force) is dropped
            fall_reason, fall_time = "trip", float(t[k])
            msg = f"trip: a foot entered a patch > {trip_depth_m} m below its surface"
            t, X = t[:max(k, 1)], X[:max(k, 1)]
        else:
            fall_reason = "hip_height"
            fall_time = float(t[k]) if k == 0 else float(
                np.interp(hth, [hh[k], hh[k - 1]], [t[k], t[k - 1]]))
            t, X = t[:k + 1], X[:k + 1]
    res = _postprocess(walker, t, X, min_step_m, initial_stance)
    return ContactResult(t=t, q=X[:, :4], qdot=X[:, 4:], feet=res["feet"],
                         heel_strike_times=res["hs_t"], heel_strike_legs=res["hs_leg"],
                         steps=res["steps"], termination=termination, fall_time=fall_time,
                         message=str(msg), nfev=int(nfev), njev=int(njev), wall_time_s=wall,
                         method=method, pin_end_time=float(t_pin), fall_reason=fall_reason)


# ---------------------------------------------------------------------------- events
def _crossings(t, pen, on):
    """Touchdown / lift-off times from sampled penetration and ground flags."""
    c = (pen > 0) & on
    td, lo = [], []
    if c.size and c[0]:
        td.append(t[0])
    for k in np.flatnonzero(c[1:] != c[:-1]) + 1:
        t_a, t_b, p_a, p_b = t[k - 1], t[k], pen[k - 1], pen[k]
        tc = t_b
        if on[k] and on[k - 1] and p_a != p_b:
            tc = t_a + (0.0 - p_a) / (p_b - p_a) * (t_b - t_a)
        (td if c[k] else lo).append(tc)
    return np.array(td), np.array(lo)


def _postprocess(walker, t, X, min_step_m, initial_stance):
    cq = walker.contact_quantities(X)
    feet = {}
    for name in FOOT_NAMES:
        d = cq[name]
        on = d["on_ground"] > 0.5
        td, lo = _crossings(t, d["penetration"], on)
        feet[name] = FootTrace(d["normal_force"], d["friction_force"], d["penetration"],
                               d["slip_velocity"], d["s"], on, td, lo)
    # heel strikes: touchdown of the non-stance foot clearly ahead of the stance point
    evs = sorted((tt, name) for name in FOOT_NAMES for tt in feet[name].touchdown_times)
    stance = initial_stance
    s_stance = float(np.interp(t[0], t, feet[stance].s))
    hs_t, hs_leg, bounces = [], [], [0]
    for tt, name in evs:
        if tt == t[0]:
            continue
        s_here = float(np.interp(tt, t, feet[name].s))
        if name != stance and s_here > s_stance + min_step_m:
            hs_t.append(tt); hs_leg.append(name); bounces.append(0)
            stance, s_stance = name, s_here
        else:
            bounces[-1] += 1
    starts = [t[0]] + hs_t
    legs = [initial_stance] + hs_leg
    steps = []
    for j, (ta, leg) in enumerate(zip(starts, legs)):
        tb = starts[j + 1] if j + 1 < len(starts) else np.nan
        # stance ends at this foot's last lift-off before its next heel strike
        t_next = starts[j + 2] if j + 2 < len(starts) else t[-1]
        lo = feet[leg].liftoff_times
        mine = lo[(lo > ta) & (lo <= t_next)]
        t_lo = mine[-1] if mine.size else t[-1]
        slip = np.interp(t_lo, t, feet[leg].s) - np.interp(ta, t, feet[leg].s)
        sel = (t >= ta) & (t <= (tb if np.isfinite(tb) else t[-1]))
        peak = max(float(np.max(feet[f].penetration[sel] * feet[f].on_ground[sel]))
                   for f in FOOT_NAMES) if sel.any() else np.nan
        steps.append(StepSummary(j, leg, float(ta), float(tb), float(tb - ta),
                                 float(1e3 * slip), int(bounces[j]), max(peak, 0.0)))
    return {"feet": feet, "hs_t": np.array(hs_t), "hs_leg": hs_leg, "steps": steps}
