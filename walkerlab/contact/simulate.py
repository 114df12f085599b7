"""Time integration of the contact walker, gait events and typed outcomes.

Integrators: ``"odeint"`` (scipy.integrate.odeint = LSODA with little overhead, run in chunks
so a fall, a trip, the wall-time limit or the strides cap stops the run), ``"cyrk_bdf"``
(the same chunks through CyRK's BDF with a compiled RHS, no Python per evaluation; see
:mod:`walkerlab.contact._cyrk`), ``"numbalsoda"`` (the same with numbalsoda's LSODA;
optional extra, see :mod:`walkerlab.contact._lsoda`) or any stiff
``solve_ivp`` method (``"LSODA"``, ``"Radau"``, ``"BDF"``), these given the analytic Jacobian.

Contact is decided by geometry only (:mod:`walkerlab.contact.generated`): a foot gets the
IMPACT force whenever it is below the top of a patch and inside its horizontal extent, in
every state (no "dead" state that switches the force off).  A step that would carry a foot
from above a patch to deep inside it therefore sees the force jump and is rejected by the
integrator's local error test: no step jumps over a touchdown.

Events (touchdown, lift-off, a trip, a fall) are located on the cubic Hermite interpolant of
the samples and their time derivatives (the RHS at each sample): penetration with its rate,
along-slope position with the slip velocity.  A **trip** is a foot crossing the side of a
patch (its along-slope edge) while below the patch's top; a **fall** is the hip crossing
``fall_hip_height_m`` (:meth:`ContactWalker.fall_margin`, the one fall test).  Either ends
the run at the event, whose state is appended as the last sample.
"""

from __future__ import annotations

import time
import warnings
from dataclasses import dataclass, field

import numpy as np
from scipy.integrate import ODEintWarning, odeint, solve_ivp

from . import _cyrk
from .model import FOOT_NAMES, ContactWalker

__all__ = [
    "ContactResult",
    "FootTrace",
    "OUTCOME_KINDS",
    "Outcome",
    "StepSummary",
    "classify_complete",
    "initial_state_from_ideal",
    "simulate_contact",
]


#: Typed outcomes of a contact run (:class:`Outcome`): ``completed`` (ran to the end time or
#: the strides cap), ``trip`` (a foot hit the side of a patch), ``fall`` (hip below the fall
#: height), ``scuff`` (the swing foot touched ground before its heel strike), ``slip`` (a
#: stance phase slid farther than the slip limit), ``solver_failure``, ``time_limit`` (the
#: wall-time limit ran out first).
OUTCOME_KINDS = ("completed", "trip", "fall", "scuff", "slip", "solver_failure", "time_limit")


@dataclass
class Outcome:
    """Why a contact run ended, or what went wrong in it (one of :data:`OUTCOME_KINDS`).

    Attributes
    ----------
    kind : str
    time_s : float
        Event time [s] (trip, fall, scuff, slip: start of the offending stance phase;
        solver failure / time limit: last sample); NaN for ``completed``.
    foot : str
        "leg1" / "leg2" for trip, scuff, slip; "" otherwise.
    patch_edge_m : float
        Along-slope position [m] of the patch side hit (trip), else NaN.
    hip_height_m : float
        Hip height above the ground line at ``time_s`` (or at the end) [m].
    message : str
        One line for people.
    """

    kind: str
    time_s: float = float("nan")
    foot: str = ""
    patch_edge_m: float = float("nan")
    hip_height_m: float = float("nan")
    message: str = ""

    @property
    def ok(self) -> bool:
        """The run completed without a trip, fall, scuff, slip or failure."""
        return self.kind == "completed"


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
        Event times [s], located on the Hermite interpolant of the samples.
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
        Along-slope slide of the stance foot over its stance phase(s) that start in this
        step, each from touchdown to lift-off (flight between bounces excluded) [mm];
        positive = downhill.  NaN when the stance phase does not end before the run does.
    double_support_creep_mm : float
        Along-slope travel of both feet (sum of |displacement|) while both are loaded, within
        the step [mm] (the smoothed-stiction creep; reported apart from the slip).
    bounce_count : int
        Touchdowns of the stance foot within the step after the one that starts it.
    scuff_count : int
        Touchdowns of the swing foot within the step that are not its heel strike.
    peak_penetration_m : float
        Largest penetration of either foot within the step [m].
    liftoff_time : float
        Lift-off of the stance foot ending its stance [s] (nan if none).
    """

    index: int
    stance_leg: str
    t_start: float
    t_end: float
    period: float
    stance_slip_mm: float
    double_support_creep_mm: float
    bounce_count: int
    scuff_count: int
    peak_penetration_m: float
    liftoff_time: float = float("nan")


@dataclass
class ContactResult:
    """Output of :func:`simulate_contact` (all SI unless named otherwise).

    Attributes
    ----------
    t : ndarray (n,)
        Sample times [s] (the last one is the event time if a trip or fall ended the run).
    q, qdot : ndarray (n, nq)
        Floating coordinates (``walker.state_names()[:nq]``: hip_x, hip_y, link angles)
        [m, m, rad...] and their rates.
    feet : dict[str, FootTrace]
        Keys "leg1", "leg2".
    heel_strike_times : ndarray
        [s] (touchdowns of the swing foot ahead of the stance foot).
    heel_strike_legs : list[str]
        Leg that struck.
    steps : list[StepSummary]
    termination : str
        How the integration stopped: "t_final", "stride_cap", "trip", "fall",
        "solver_failure" or "time_limit".
    outcome : Outcome
        Typed outcome (termination, or after a complete run: slip beyond ``slip_limit_mm``,
        scuff, or completed).
    fall_time : float or None
        [s] time of the trip or fall.
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
        "trip" or "hip_height" (kept for old readers; see ``outcome``).
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
    outcome: Outcome = field(default_factory=lambda: Outcome("completed"))
    extra: dict = field(default_factory=dict)

    @property
    def x(self) -> np.ndarray:
        """States (n, 2 nq)."""
        return np.hstack([self.q, self.qdot])

    @property
    def walked_steps(self) -> int:
        """Number of heel strikes."""
        return len(self.heel_strike_times)

    @property
    def max_stance_slip_mm(self) -> float:
        """Largest |stance slip| over the stance phases that ended [mm] (0 if none)."""
        v = [abs(s.stance_slip_mm) for s in self.steps if np.isfinite(s.stance_slip_mm)]
        return float(max(v, default=0.0))


def initial_state_from_ideal(walker: ContactWalker, *x_ideal,
                             rate_scale=(1.0, 1.0)) -> np.ndarray:
    """Floating-walker state (2 nq,) from an ideal-model state (leg1 = swing, leg2 = stance).

    The stance foot (leg2) is placed at s = 0 at its static penetration
    ``(M g cos phi / k)^(1/e)`` [m] (along -n) and held at rest there: the hip follows from
    the stance leg's links (:meth:`ContactWalker.pinned_to_full`).  ``rate_scale``
    multiplies leg1's and leg2's rates first.

    Parameters
    ----------
    *x_ideal : float
        The rigid model's state in its role order, e.g. ``theta1, theta2, dtheta1,
        dtheta2`` (swing / stance leg angles [rad] and rates [rad/s]) for the compass gait
        (:meth:`ContactWalker.link_state_from_ideal`).
    rate_scale : (float, float)
        Multipliers [-] on leg1's (swing) and leg2's (stance) rates.

    Returns
    -------
    ndarray (2 nq,)
    """
    foot2 = -walker.static_penetration() * walker.normal
    z = walker.link_state_from_ideal(np.asarray(x_ideal, float).ravel(), rate_scale)
    return walker.pinned_to_full(z, foot2)


# ---------------------------------------------------------------------------- integration
def _grid(t0, t1, rate):
    n = int(np.floor((t1 - t0) * rate + 1e-9))
    t = t0 + np.arange(n + 1) / rate
    if t1 - t[-1] > 1e-9:
        t = np.append(t, t1)
    return t


class _TimeLimit(Exception):
    """Internal: the wall-time limit ran out inside a solve_ivp right-hand side."""


def _run_pinned(walker, x0, t0, t_end, until_touchdown, rate, rtol, atol, max_step, hth):
    """Integrate with leg2's foot held fixed.  Returns (t, X, nfev, njev, status, msg)."""
    foot2 = walker.foot_positions(x0)[1]
    z0 = walker.pinned_state(x0)

    def f(t, z):
        return walker.rhs_pinned(t, z, foot2)

    def touch(t, z):
        x = walker.pinned_to_full(z, foot2)
        cq = walker.contact_quantities(x)["leg1"]
        return -cq["penetration"][0] if cq["on_ground"][0] > 0 else 1.0

    touch.terminal = True
    touch.direction = -1

    def fall(t, z):
        return walker.fall_margin(walker.pinned_to_full(z, foot2), hth)

    fall.terminal = True
    fall.direction = -1
    events = [fall] + ([touch] if until_touchdown else [])
    sol = solve_ivp(f, (t0, t_end), z0, method="LSODA", rtol=rtol, atol=atol,
                    max_step=max_step, t_eval=_grid(t0, t_end, rate), events=events,
                    dense_output=True)
    t, Z = sol.t, sol.y.T
    if sol.status == 1:  # stopped on an event: append the event point
        te = (sol.t_events[1][0] if (until_touchdown and sol.t_events[1].size)
              else sol.t_events[0][0])
        if t.size == 0 or te > t[-1]:
            t = np.append(t, te)
            Z = np.vstack([Z, sol.sol(te)])
    X = np.array([walker.pinned_to_full(z, foot2) for z in Z])
    fell = sol.status == 1 and sol.t_events[0].size > 0
    return t, X, sol.nfev, sol.njev, ("fall" if fell else ("ok" if sol.status >= 0 else "fail")), \
        sol.message


def _hermite_root(ta, tb, ya, yb, da, db, rising=None):
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


def _hermite_state(walker, ta, tb, xa, xb, tc):
    """State (2 nq,) at ``tc`` in [ta, tb] on the cubic Hermite interpolant of two samples."""
    fa, fb = walker.rhs(ta, xa), walker.rhs(tb, xb)
    h = tb - ta
    u = (tc - ta) / h
    h00, h10 = 2 * u**3 - 3 * u**2 + 1, u**3 - 2 * u**2 + u
    h01, h11 = -2 * u**3 + 3 * u**2, u**3 - u**2
    return h00 * xa + h10 * h * fa + h01 * xb + h11 * h * fb


def _first_event(walker, t, X, hth, k0=1):
    """First trip or fall in samples ``k0..``: (kind, k, time, foot, edge) or None.

    A trip is a foot crossing the along-slope edge of one of its lane's patches while below
    the patch's top (penetration > 0 at the crossing, on the Hermite interpolant); a fall
    is the hip height crossing ``hth`` downward.
    """
    if len(t) <= k0:
        return None
    sl = slice(k0 - 1, None)
    nq = walker.nq
    cq = walker.contact_quantities(X[sl])
    hh = walker.hip_height(X[sl])
    tt = t[sl]
    best = None
    below = np.flatnonzero(hh < hth)
    if below.size:
        k = int(below[0])
        if k == 0:
            best = ("fall", k0 - 1, float(tt[0]), "", np.nan)
        else:  # on the Hermite interpolant of the hip height, slope = hip velocity . n
            xa, xb = X[k0 - 1 + k - 1], X[k0 - 1 + k]
            n = walker.normal
            tc = _hermite_root(tt[k - 1], tt[k], hh[k - 1] - hth, hh[k] - hth,
                               float(xa[nq:nq + 2] @ n), float(xb[nq:nq + 2] @ n),
                               rising=False)
            if tc is None:
                tc = float(np.interp(hth, [hh[k], hh[k - 1]], [tt[k], tt[k - 1]]))
            best = ("fall", k0 - 1 + k, tc, "", np.nan)
    hw = walker.patch_half_width
    if not walker.continuous:
        for i, foot in enumerate(("leg1", "leg2")):
            q = cq[foot]
            lane = walker.lane1 if i == 0 else walker.lane2
            on = q["on_ground"] > 0.5
            pen = q["penetration"]
            # entering a patch horizontally (gap -> patch) with the foot below the top at
            # either sample: find the edge crossing and the penetration there
            cand = np.flatnonzero(~on[:-1] & on[1:] & ((pen[:-1] > 0) | (pen[1:] > 0))) + 1
            for k in cand:
                if best is not None and k0 - 1 + k > best[1]:
                    break
                sa, sb = q["s"][k - 1], q["s"][k]
                c = lane[int(np.argmin(np.abs(lane - sb)))]
                edge = c - hw if sb < c else c + hw
                vs = q["slip_velocity"]
                te = _hermite_root(tt[k - 1], tt[k], sa - edge, sb - edge, vs[k - 1], vs[k])
                if te is None:
                    te = float(tt[k])
                xe = _hermite_state(walker, tt[k - 1], tt[k], X[k0 - 1 + k - 1], X[k0 - 1 + k], te)
                pe = walker.contact_quantities(xe)[foot]["penetration"][0]
                if pe > 0 and (best is None or te < best[2]):
                    best = ("trip", k0 - 1 + k, float(te), foot, float(edge))
                    break
    return best


def _run_free(walker, x0, t0, t1, method, rtol, atol, max_step, rate, hth, use_jac,
              chunk_s, deadline, max_heel_strikes, min_step_m, initial_stance):
    """Integrate the free walker until t1, a trip, a fall, the deadline or the strides cap.

    Returns (t, X, nfev, njev, status, message, event) with status "ok", "cap", "trip",
    "fall", "fail" or "time_limit" and event the :func:`_first_event` tuple (or None).
    """
    kern = walker.kernels
    PC, p, c1, c2 = walker.contact_params, walker.walker_params, walker.lane1, walker.lane2

    def frhs(t, x):
        return kern.rhs(x, PC, p, c1, c2)

    def fjac(t, x):
        return kern.jac(x, PC, p, c1, c2)

    if not use_jac:
        fjac = None
    if method == "numbalsoda":
        from . import _lsoda

        if np.isfinite(max_step):
            raise ValueError("contact_solver.max_step_s is not supported by method numbalsoda")
        if not np.isscalar(atol):
            raise ValueError("method numbalsoda needs a scalar atol")
        data = walker.pack()
    elif method in _cyrk.CYRK_METHODS:
        data = walker.pack()

    def odeint_chunk(xs, tg):
        """odeint from ``xs`` at ``tg[0]``: (t, X) at the samples reached after ``tg[0]``,
        ok, message, nfev, njev."""
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", ODEintWarning)
            X, info = odeint(frhs, xs, tg, Dfun=fjac, tfirst=True, rtol=rtol, atol=atol,
                             hmax=0.0 if not np.isfinite(max_step) else max_step,
                             full_output=True, mxstep=200000)
        ok = info["message"] == "Integration successful."
        # after a failure odeint's info arrays past the last sample reached are not filled in
        # (garbage was seen): use them up to that sample only
        reached = info["tcur"] >= tg[1:] - 1e-14
        nk = len(tg) if ok or reached.all() else int(np.argmin(reached)) + 1
        if nk < 2:
            return tg[1:1], X[1:1], ok, info["message"], 0, 0
        return (tg[1:nk], X[1:nk], ok, info["message"], int(info["nfe"][nk - 2]),
                int(info["nje"][nk - 2]))

    ts, Xs, nfev, njev = [np.array([t0])], [x0[None]], 0, 0
    ta, xa = t0, x0
    status, msg, event = "ok", "Integration successful.", None
    n_checked = 1
    while ta < t1 - 1e-12:
        tb = min(ta + chunk_s, t1)
        tg = _grid(ta, tb, rate)
        if method == "odeint":
            tn, Xn, ok, m, nf, nj = odeint_chunk(xa, tg)
            nfev += nf
            njev += nj
        elif method == "numbalsoda":  # whole chunk in compiled code (FD Jacobian)
            X, ok, nf = _lsoda.solve_chunk(xa, tg, data, rtol, atol, kernels=kern)
            nfev += nf
            nk = len(tg) if ok else 1  # rows after a failure are undefined: drop the chunk
            tn, Xn = tg[1:nk], X[1:nk]
            m = "Integration successful." if ok else "numbalsoda LSODA failed in this chunk"
        elif method in _cyrk.CYRK_METHODS:  # whole chunk in compiled code (CyRK BDF)
            X, ok, nf, m = _cyrk.solve_chunk(method, xa, tg, data, rtol, atol, max_step,
                                             kernels=kern)
            nfev += nf
            tn, Xn = tg[1:len(X)], X[1:]
            if not ok:  # a force jump BDF cannot step over (a foot hitting the side of a
                # patch below its top): odeint, which grinds through it as a plain odeint run
                # does, from the last sample reached to the chunk end
                k = max(len(X) - 1, 0)
                tr, Xr, ok, m, nf, nj = odeint_chunk(X[k] if len(X) else xa, tg[k:])
                nfev += nf
                njev += nj
                tn, Xn = np.concatenate([tn, tr]), np.vstack([Xn, Xr])
        else:
            def grhs(t, x):
                if time.perf_counter() > deadline:
                    raise _TimeLimit
                return frhs(t, x)

            kw = {"jac": fjac} if use_jac else {}
            try:
                sol = solve_ivp(grhs, (ta, tb), xa, method=method, rtol=rtol, atol=atol,
                                max_step=max_step, t_eval=tg, **kw)
            except _TimeLimit:
                status, msg = "time_limit", "wall-time limit reached inside a chunk"
                break
            nfev += sol.nfev
            njev += sol.njev
            ok = sol.status == 0
            tn, Xn, m = sol.t[1:], sol.y.T[1:], sol.message
        ts.append(tn)
        Xs.append(Xn)
        t_all, X_all = np.concatenate(ts), np.vstack(Xs)
        event = _first_event(walker, t_all, X_all, hth, k0=n_checked)
        n_checked = len(t_all)
        if event is not None:
            status = event[0]
            break
        if not ok:
            status, msg = "fail", str(m)
            break
        if time.perf_counter() > deadline and tb < t1 - 1e-12:
            status, msg = "time_limit", "wall-time limit reached"
            break
        if max_heel_strikes is not None:
            pp = _postprocess(walker, t_all, X_all, min_step_m, initial_stance, events_only=True)
            if len(pp["hs_t"]) >= max_heel_strikes:
                status, msg = "cap", f"strides cap: {len(pp['hs_t'])} heel strikes"
                break
        ta, xa = tb, X_all[-1]
    t_all, X_all = np.concatenate(ts), np.vstack(Xs)
    if event is not None:  # cut at the event and append the event state
        _, k, te, _, _ = event
        k = max(k, 1)
        xe = _hermite_state(walker, t_all[k - 1], t_all[k], X_all[k - 1], X_all[k], te) \
            if te > t_all[k - 1] else X_all[k - 1]
        t_all = np.append(t_all[:k], te) if te > t_all[k - 1] else t_all[:k]
        X_all = np.vstack([X_all[:k], xe[None]]) if len(t_all) > k else X_all[:k]
        msg = {"trip": "trip: a foot hit the side of a patch below its top",
               "fall": "fall: hip below the fall height"}[event[0]]
    return t_all, X_all, nfev, njev, status, msg, event


def simulate_contact(walker: ContactWalker, x0: np.ndarray, t_final: float,
                     method: str = "cyrk_bdf", rtol: float = 1e-8, atol: float = 1e-10,
                     max_step: float = np.inf, sample_rate_hz: float = 1000.0, *,
                     t0: float = 0.0, pin_stance_until: str = "none", pin_time_s: float = 0.0,
                     fall_hip_height_m: float | None = None, use_jacobian: bool = True,
                     chunk_s: float = 1.0, min_step_m: float = 0.05,
                     initial_stance: str = "leg2", wall_time_limit_s: float | None = None,
                     max_heel_strikes: int | None = None,
                     slip_limit_mm: float | None = None) -> ContactResult:
    """Simulate the floating walker with compliant feet.

    Parameters
    ----------
    walker : ContactWalker
    x0 : ndarray (2 nq,)
        Initial state in ``walker.state_names()`` order (SI).
    t_final : float
        End time [s].
    method : {"odeint", "cyrk_bdf", "numbalsoda", "LSODA", "Radau", "BDF"}
        Integrator (odeint = LSODA with lower overhead; cyrk_bdf = CyRK's BDF called from
        compiled code, finite-difference Jacobian; numbalsoda = LSODA called from
        compiled code, optional extra, finite-difference Jacobian, no ``max_step``), run in
        chunks of ``chunk_s``.
    rtol, atol : float
        Tolerances; ``atol`` [m, rad, m/s, rad/s] must be well below the penetration depth
        (~6e-5 m for the paper's contact), default 1e-10.
    max_step : float
        Largest step [s].
    sample_rate_hz : float
        Output sample rate [Hz] (events are located between samples, see the module doc).
    pin_stance_until : {"none", "first_touchdown", "time"}
        Hold leg2's foot fixed (constraint, reduced coordinates) until leg1 first touches
        ground, or until ``t0 + pin_time_s``.
    fall_hip_height_m : float, optional
        Fall threshold of the hip height above ground [m] (default 0.5 L).
    use_jacobian : bool
        Pass the analytic Jacobian to the integrator (not to cyrk_bdf or numbalsoda, whose
        compiled interfaces take none).
    chunk_s : float
        Chunk length [s]; trips, falls, the wall-time limit and the strides cap are checked
        between chunks (a trip or fall is then located exactly and the run cut there).
    min_step_m : float
        A touchdown of the swing foot counts as a heel strike only if it lands at least this
        far [m] downhill of the stance foot's touchdown point (else it is a scuff).
    initial_stance : {"leg2", "leg1"}
    wall_time_limit_s : float, optional
        Stop with outcome ``time_limit`` once the integration has used this much wall time [s].
    max_heel_strikes : int, optional
        Strides cap: stop (termination ``stride_cap``, outcome completed) at the end of the
        chunk in which this many heel strikes have happened.
    slip_limit_mm : float, optional
        A stance phase sliding farther than this [mm] makes the outcome ``slip``.

    Returns
    -------
    ContactResult

    Raises
    ------
    ValueError
        Unknown ``method``; ``max_step`` with numbalsoda; ``method="numbalsoda"``
        without the numbalsoda package
        (:class:`walkerlab.contact._lsoda.MissingNumbalsoda`, also an ImportError).
    """
    if method not in ("odeint", "numbalsoda", "LSODA", "Radau", "BDF", "RK45", "DOP853",
                      *_cyrk.CYRK_METHODS):
        raise ValueError(f"method must be odeint, cyrk_bdf, numbalsoda, LSODA, Radau or BDF, "
                         f"not {method!r}")
    x0 = np.asarray(x0, dtype=float)
    hth = 0.5 * walker.L if fall_hip_height_m is None else fall_hip_height_m
    wall = time.perf_counter()
    deadline = wall + (wall_time_limit_s if wall_time_limit_s else np.inf)
    ts, Xs, nfev, njev, status, msg = [], [], 0, 0, "ok", ""
    event = None
    t_pin = t0
    if pin_stance_until != "none":
        t_end = t_final if pin_stance_until == "first_touchdown" else min(t0 + pin_time_s, t_final)
        tp, Xp, nf, nj, status, msg = _run_pinned(
            walker, x0, t0, t_end, pin_stance_until == "first_touchdown", sample_rate_hz,
            rtol, atol, max_step, hth)
        ts.append(tp)
        Xs.append(Xp)
        nfev += nf
        njev += nj
        t_pin, x0 = tp[-1], Xp[-1]
        if status == "fall":
            event = ("fall", len(tp) - 1, float(tp[-1]), "", np.nan)
    if status == "ok" and t_pin < t_final - 1e-12:
        tf, Xf, nf, nj, status, msg, event = _run_free(
            walker, x0, t_pin, t_final, method, rtol, atol, max_step, sample_rate_hz, hth,
            use_jacobian, chunk_s, deadline, max_heel_strikes, min_step_m, initial_stance)
        if ts:
            tf, Xf = tf[1:], Xf[1:]
        ts.append(tf)
        Xs.append(Xf)
        nfev += nf
        njev += nj
    wall = time.perf_counter() - wall
    t = np.concatenate(ts)
    X = np.vstack(Xs)
    termination = {"ok": "t_final", "cap": "stride_cap", "fall": "fall", "trip": "trip",
                   "fail": "solver_failure", "time_limit": "time_limit"}[status]
    res = _postprocess(walker, t, X, min_step_m, initial_stance)
    hh = walker.hip_height(X[-1:])[0]
    fall_time = fall_reason = None
    if termination == "trip":
        _, _, te, foot, edge = event
        fall_time, fall_reason = te, "trip"
        out = Outcome("trip", te, foot, edge, float(hh),
                      f"trip: {foot} hit the side of the patch edge at s = {edge:.4f} m at "
                      f"t = {te:.4g} s after {len(res['hs_t'])} heel strikes")
    elif termination == "fall":
        fall_time, fall_reason = float(t[-1]), "hip_height"
        out = Outcome("fall", float(t[-1]), "", np.nan, float(hh),
                      f"fall: hip {hh:.3f} m above ground (< {hth:g} m) at t = {t[-1]:.4g} s "
                      f"after {len(res['hs_t'])} heel strikes")
    elif termination == "solver_failure":
        out = Outcome("solver_failure", float(t[-1]), "", np.nan, float(hh),
                      f"solver failure at t = {t[-1]:.4g} s: {msg}")
    elif termination == "time_limit":
        out = Outcome("time_limit", float(t[-1]), "", np.nan, float(hh),
                      f"time limit: {wall_time_limit_s:g} s of wall time used by t = "
                      f"{t[-1]:.4g} s ({len(res['hs_t'])} heel strikes)")
    else:
        out = classify_complete(res["steps"], slip_limit_mm, float(hh))
    return ContactResult(t=t, q=X[:, :walker.nq], qdot=X[:, walker.nq:], feet=res["feet"],
                         heel_strike_times=res["hs_t"], heel_strike_legs=res["hs_leg"],
                         steps=res["steps"], termination=termination, fall_time=fall_time,
                         message=str(msg), nfev=int(nfev), njev=int(njev), wall_time_s=wall,
                         method=method, pin_end_time=float(t_pin), fall_reason=fall_reason,
                         outcome=out)


def classify_complete(steps, slip_limit_mm: float | None, hip_height_m: float) -> Outcome:
    """Outcome of a run that reached its end: ``slip`` if a stance phase slid farther than
    ``slip_limit_mm`` [mm], else ``scuff`` if the swing foot touched down before its heel
    strike, else ``completed``."""
    if slip_limit_mm is not None:
        for st in steps:
            if np.isfinite(st.stance_slip_mm) and abs(st.stance_slip_mm) > slip_limit_mm:
                return Outcome("slip", st.t_start, st.stance_leg, np.nan, hip_height_m,
                               f"slip: {st.stance_leg} slid {st.stance_slip_mm:.3g} mm in the "
                               f"stance phase from t = {st.t_start:.4g} s (limit "
                               f"{slip_limit_mm:g} mm)")
    for st in steps:
        if st.scuff_count:
            sw = "leg1" if st.stance_leg == "leg2" else "leg2"
            return Outcome("scuff", st.t_start, sw, np.nan, hip_height_m,
                           f"scuff: {sw} touched ground {st.scuff_count} time(s) before its "
                           f"heel strike in step {st.index}")
    return Outcome("completed", hip_height_m=hip_height_m, message="completed")


# ---------------------------------------------------------------------------- events
def _crossings(t, pen, rate, on):
    """Touchdown / lift-off times from sampled penetration, its rate and ground flags.

    Crossings of zero penetration are located on the cubic Hermite interpolant (values and
    rates at the samples); a change of the ground flag (patch edge) counts at the sample.
    """
    c = (pen > 0) & on
    td, lo = [], []
    if c.size and c[0]:
        td.append(t[0])
    for k in np.flatnonzero(c[1:] != c[:-1]) + 1:
        tc = t[k]
        if on[k] and on[k - 1]:
            r = _hermite_root(t[k - 1], t[k], pen[k - 1], pen[k], rate[k - 1], rate[k],
                              rising=bool(c[k]))
            if r is not None:
                tc = r
        (td if c[k] else lo).append(tc)
    return np.array(td), np.array(lo)


def _phase_slip(t, s, td, lo, ta, tb):
    """Slide [m] of a foot over its contact phases starting in [ta, tb): sum of s(lo) - s(td)
    per phase; NaN if the last such phase has no lift-off."""
    total, any_phase = 0.0, False
    for tdj in td:
        if not (ta - 1e-12 <= tdj < tb):
            continue
        any_phase = True
        nxt = lo[lo > tdj]
        if not nxt.size:
            return np.nan
        total += float(np.interp(nxt[0], t, s) - np.interp(tdj, t, s))
    return total if any_phase else np.nan


def _intervals(td, lo, t_end):
    """Contact intervals [(touchdown, lift-off)] of a foot (lift-off = ``t_end`` if none)."""
    out = []
    for a in td:
        nxt = lo[lo > a]
        out.append((float(a), float(nxt[0]) if nxt.size else t_end))
    return out


def _postprocess(walker, t, X, min_step_m, initial_stance, events_only=False):
    cq = walker.contact_quantities(X)
    feet = {}
    for name in FOOT_NAMES:
        d = cq[name]
        on = d["on_ground"] > 0.5
        td, lo = _crossings(t, d["penetration"], d["penetration_rate"], on)
        feet[name] = FootTrace(d["normal_force"], d["friction_force"], d["penetration"],
                               d["slip_velocity"], d["s"], on, td, lo)
    # heel strikes: touchdown of the non-stance foot clearly ahead of the stance point;
    # other touchdowns of the non-stance foot are scuffs, of the stance foot bounces
    evs = sorted((tt, name) for name in FOOT_NAMES for tt in feet[name].touchdown_times)
    stance = initial_stance
    s_stance = float(np.interp(t[0], t, feet[stance].s))
    hs_t, hs_leg, bounces, scuffs = [], [], [0], [0]
    for tt, name in evs:
        if tt == t[0]:
            continue
        s_here = float(np.interp(tt, t, feet[name].s))
        if name != stance and s_here > s_stance + min_step_m:
            hs_t.append(tt)
            hs_leg.append(name)
            bounces.append(0)
            scuffs.append(0)
            stance, s_stance = name, s_here
        elif name == stance:
            bounces[-1] += 1
        else:
            scuffs[-1] += 1
    if events_only:
        return {"hs_t": hs_t}
    starts = [t[0]] + hs_t
    legs = [initial_stance] + hs_leg
    loaded = {f: (feet[f].penetration > 0) & feet[f].on_ground for f in FOOT_NAMES}
    # double-support intervals: overlaps of the two feet's contact intervals (event times)
    iv = {f: _intervals(feet[f].touchdown_times, feet[f].liftoff_times, float(t[-1]))
          for f in FOOT_NAMES}
    ds = [(max(a1, a2), min(b1, b2)) for a1, b1 in iv["leg1"] for a2, b2 in iv["leg2"]
          if min(b1, b2) > max(a1, a2)]
    steps = []
    for j, (ta, leg) in enumerate(zip(starts, legs)):
        tb = starts[j + 1] if j + 1 < len(starts) else np.nan
        tb_or_end = tb if np.isfinite(tb) else t[-1]
        # stance phases of this leg that begin between its heel strike and its next one
        t_next = starts[j + 2] if j + 2 < len(starts) else np.inf
        ft = feet[leg]
        td = ft.touchdown_times
        if j == 0 and (not td.size or td[0] > t[0]) and loaded[leg][0]:
            td = np.concatenate([[t[0]], td])
        slip = _phase_slip(t, ft.s, td, ft.liftoff_times, ta, t_next)
        lo_mine = ft.liftoff_times[(ft.liftoff_times > ta) & (ft.liftoff_times < t_next)]
        sel = (t >= ta) & (t <= tb_or_end)
        creep = 0.0
        for a, b in ds:
            a, b = max(a, ta), min(b, tb_or_end)
            if b > a:
                creep += sum(abs(float(np.interp(b, t, feet[f].s) - np.interp(a, t, feet[f].s)))
                             for f in FOOT_NAMES)
        peak = max(float(np.max(feet[f].penetration[sel] * feet[f].on_ground[sel]))
                   for f in FOOT_NAMES) if sel.any() else np.nan
        steps.append(StepSummary(j, leg, float(ta), float(tb), float(tb - ta),
                                 float(1e3 * slip), float(1e3 * creep), int(bounces[j]),
                                 int(scuffs[j]), max(peak, 0.0),
                                 float(lo_mine[-1]) if lo_mine.size else np.nan))
    return {"feet": feet, "hs_t": np.array(hs_t), "hs_leg": hs_leg, "steps": steps}
