"""What a contact run's samples mean: touchdowns, heel strikes, steps, and how the run ended.

Input: the samples of :func:`walkerlab.integrate.contact.integrate_contact` (times, states
named by ``walker.state_names()``) and the model's per-foot contact quantities
(``walker.foot_quantities``: per leg; a flat foot's heel and toe combined, and
``walker.contact_quantities`` per contact point).  Output: per-foot traces with touchdown /
lift-off times,
the heel strikes, one :class:`StepSummary` per step (slip, creep, bounces, scuffs, peak
penetration) and the run's typed :class:`Outcome`, whose ``kind`` is one of the shared run
ends (:mod:`walkerlab.integrate.ends`).  Nothing here integrates or reads a state by row.

Touchdown and lift-off are the zero crossings of the penetration, located on the cubic
Hermite interpolant of the samples and their rates; a heel strike is a touchdown of the
non-stance foot at least ``min_step_m`` downhill of the stance foot's touchdown point, other
touchdowns of that foot are scuffs, of the stance foot bounces.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from walkerlab.integrate.contact import hermite_root
from walkerlab.integrate.ends import CONTACT_WALKED, RUN_END_NAMES

__all__ = ["CONTACT_OUTCOMES", "FOOT_MODES", "ContactResult", "FootTrace", "Outcome",
           "PatchFit", "StepSummary", "classify", "classify_complete", "foot_modes",
           "gait_events", "heel_strike_count", "patch_fit", "phase_slip", "step_trend",
           "walk_verdict"]

#: Outcome kinds of a contact run: the shared run ends (:mod:`walkerlab.integrate.ends`)
#: that the contact model can produce.
CONTACT_OUTCOMES = tuple(k for k in RUN_END_NAMES)


@dataclass
class Outcome:
    """How a contact run ended (``kind``: one of :data:`CONTACT_OUTCOMES`).

    Attributes
    ----------
    kind : str
    time_s : float
        Event time [s] (trip, fall, airborne: the event; scuff, slip: start of the offending
        step; solver failure / time limit: last sample); NaN when the run walked to its end.
    foot : str
        The foot of a trip, scuff or slip ("" otherwise).
    patch_edge_m : float
        Along-slope position [m] of the patch side hit (trip), else NaN.
    hip_height_m : float
        Hip height above the ground line at ``time_s`` (or at the end) [m].
    message : str
        One line for people.
    after : str
        A run that made the heel strikes asked for and then met another end (``trip``,
        ``fall``, ``airborne``, ``solver_failure``, ``time_limit``): that end's kind ("" when
        none followed).  ``kind`` stays the strides cap's (the run made its promise); the
        message names what followed, and :func:`walk_verdict` does not call it a walk.
    after_time_s : float
        Time [s] of that end (NaN when none).
    after_message : str
        What followed, in a few words (e.g. "fell into a gap (...) at t = 9.445 s").
    """

    kind: str
    time_s: float = float("nan")
    foot: str = ""
    patch_edge_m: float = float("nan")
    hip_height_m: float = float("nan")
    message: str = ""
    after: str = ""
    after_time_s: float = float("nan")
    after_message: str = ""

    @property
    def ok(self) -> bool:
        """The walker walked: made its heel strikes or reached its end time."""
        return self.kind in ("heel_strike", "t_final")

    @property
    def walked(self) -> bool:
        """A run that counts as a walk (exit code 0): :data:`CONTACT_WALKED`."""
        return self.kind in CONTACT_WALKED


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
        The foot in stance (a key of ``walker.contact_quantities``).
    t_start, t_end : float
        [s]; ``t_end`` is nan if the run ended first.
    period : float
        ``t_end - t_start`` [s] (nan if incomplete).
    stance_slip_mm : float
        Along-slope slide of the stance foot over its stance phase(s) that start in this
        step (before the other foot's heel strike: the swing foot's scuffs are not stance),
        each from touchdown to lift-off (flight between bounces excluded) [mm]; positive =
        downhill.  NaN when the stance phase does not end before the run does.
    double_support_creep_mm : float
        Along-slope travel of both feet (sum of ``|displacement|``) while both are loaded, within
        the step [mm] (the smoothed-stiction creep; reported apart from the slip).
    bounce_count : int
        Touchdowns of the stance foot within the step after the one that starts it.
    scuff_count : int
        Touchdowns of the swing foot within the step that are not its heel strike.
    peak_penetration_m : float
        Largest penetration of either foot within the step [m].
    liftoff_time : float
        Lift-off of the stance foot ending its stance [s] (nan if none).
    foot_modes : str
        Flat feet: the stance foot's modes over the step with their start times
        (``"heel_contact (0.7736 s) > foot_flat (1.0382 s) > heel_off (1.3785 s)"``, from the
        contact table, :func:`foot_modes`; modes shorter than two samples left out); "" for
        other feet.
    stance_slip_path_mm : float
        Path of the stance foot's slip over the same stance phase(s) as ``stance_slip_mm``,
        the integral of ``|slip velocity|`` [mm]: the to-and-fro creep of the regularised
        friction law that the net slide hides.  Each phase counts from the first sample one
        sample interval after its touchdown (the heel-strike collision, shorter than a
        sample interval, is the heel strike's, and the samples do not resolve it).  NaN as
        ``stance_slip_mm``.
    friction_work_j : float
        Work the friction forces of the stance foot's contact points take over the same
        phase(s) as ``stance_slip_path_mm``, ``-sum of the integrals of F_t v_t`` [J]
        (>= 0: dissipated).  NaN as ``stance_slip_mm``.
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
    foot_modes: str = ""
    stance_slip_path_mm: float = float("nan")
    friction_work_j: float = float("nan")


@dataclass
class ContactResult:
    """A contact run: samples, gait events, steps and outcome (all SI unless named otherwise).

    Attributes
    ----------
    t : ndarray (n,)
        Sample times [s] (the last one is the event time if an event ended the run).
    x : ndarray (n, N)
        States, columns named by ``state_names``.
    state_names : tuple of str
        ``walker.state_names()``.
    feet : dict[str, FootTrace]
        Keyed by foot name (leg).
    heel_strike_times : ndarray
        [s] (touchdowns of the swing foot ahead of the stance foot).
    heel_strike_legs : list[str]
        Foot that struck.
    steps : list[StepSummary]
    termination : str
        How the integration stopped (:mod:`walkerlab.integrate.ends`): ``heel_strike``
        (strides cap), ``t_final``, ``trip``, ``fall``, ``airborne``, ``solver_failure`` or
        ``time_limit``.
    outcome : Outcome
        The run's verdict: the termination, or after a run that reached its end: ``slip``
        beyond the slip limit, ``scuff``, ``no_heel_strike``.
    message : str
        Solver message.
    nfev, njev : int
        Right-hand side / Jacobian evaluations.
    wall_time_s : float
        Wall time of the integration (excluding post-processing) [s].
    method : str
    pin_end_time : float
        End of the pinned phase [s] (= t0 if none).
    points : dict[str, FootTrace]
        Per contact point (``walker.contact_names()``; a flat foot's ``leg1_heel``,
        ``leg1_toe``, ...): its trace and touchdown / lift-off times; ``feet`` again
        when each leg has one point.
    work : ndarray (n, 4) or None
        A powered walker's work integrals at the samples [J]
        (:data:`walkerlab.models.contact.actuation.WORK_NAMES`); None when passive.
    """

    t: np.ndarray
    x: np.ndarray
    state_names: tuple
    feet: dict
    heel_strike_times: np.ndarray
    heel_strike_legs: list
    steps: list
    termination: str
    message: str
    nfev: int
    njev: int
    wall_time_s: float
    method: str
    pin_end_time: float = 0.0
    outcome: Outcome = field(default_factory=lambda: Outcome("t_final"))
    points: dict = field(default_factory=dict)
    work: np.ndarray | None = None

    def column(self, name: str) -> np.ndarray:
        """Samples (n,) of the state ``name``, in its unit (the walker's
        ``state_units()``: [m], [rad], [m/s] or [rad/s]).

        Raises
        ------
        ValueError
            ``name`` is not one of :attr:`state_names`.
        """
        return self.x[:, list(self.state_names).index(name)]

    @property
    def walked_steps(self) -> int:
        """Number of heel strikes."""
        return len(self.heel_strike_times)

    @property
    def verdict(self) -> tuple[bool, str]:
        """Whether the run walks and, if not, why (:func:`walk_verdict`)."""
        return walk_verdict(self.outcome, self.steps)

    @property
    def fall_time(self) -> float | None:
        """[s] time of the trip or fall that ended the run, else None."""
        return self.outcome.time_s if self.outcome.kind in ("trip", "fall") else None

    @property
    def max_stance_slip_mm(self) -> float:
        """Largest ``|stance slip|`` over the stance phases that ended [mm] (0 if none)."""
        v = [abs(s.stance_slip_mm) for s in self.steps if np.isfinite(s.stance_slip_mm)]
        return float(max(v, default=0.0))


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
            r = hermite_root(t[k - 1], t[k], pen[k - 1], pen[k], rate[k - 1], rate[k],
                             rising=bool(c[k]))
            if r is not None:
                tc = r
        (td if c[k] else lo).append(tc)
    return np.array(td), np.array(lo)


def phase_slip(t, s, td, lo, ta, tb, v=None):
    """Slide [m] of a foot over its contact phases starting in [ta, tb): sum of s(lo) - s(td)
    per phase (a point foot: its contact point is its material point), or, given the
    material point's tangential velocity ``v`` (n,) [m/s], its integral over each phase (an
    arc foot: the contact point also moves as the foot rolls, ``R dtheta``, which is not
    slip); NaN if the last such phase has no lift-off."""
    total, any_phase = 0.0, False
    for tdj in td:
        if not (ta - 1e-12 <= tdj < tb):
            continue
        any_phase = True
        nxt = lo[lo > tdj]
        if not nxt.size:
            return np.nan
        if v is None:
            total += float(np.interp(nxt[0], t, s) - np.interp(tdj, t, s))
        else:
            m = (t > tdj) & (t < nxt[0])
            tt = np.concatenate([[tdj], t[m], [nxt[0]]])
            vv = np.concatenate([[np.interp(tdj, t, v)], v[m], [np.interp(nxt[0], t, v)]])
            total += float(np.trapezoid(vv, tt))
    return total if any_phase else np.nan


def stance_phases(td, lo, ta, tb) -> list[tuple[float, float]] | None:
    """Contact phases [(touchdown, lift-off)] [s] of a foot that start in [ta, tb); None if
    the last such phase has no lift-off (as :func:`phase_slip`'s NaN)."""
    out = []
    for tdj in td:
        if ta - 1e-12 <= tdj < tb:
            nxt = lo[lo > tdj]
            if not nxt.size:
                return None
            out.append((float(tdj), float(nxt[0])))
    return out


def phase_integral(t, y, phases) -> float:
    """Trapezoidal integral of the samples ``y`` (n,) on ``t`` (n,) [s] over ``phases``
    [(a, b)] [s], the ends interpolated; NaN if ``phases`` is None (an unfinished phase)."""
    if phases is None:
        return np.nan
    total = 0.0
    for a, b in phases:
        m = (t > a) & (t < b)
        tt = np.concatenate([[a], t[m], [b]])
        yy = np.concatenate([[np.interp(a, t, y)], y[m], [np.interp(b, t, y)]])
        total += float(np.trapezoid(yy, tt))
    return total


def _intervals(td, lo, t_end):
    """Contact intervals [(touchdown, lift-off)] of a foot (lift-off = ``t_end`` if none)."""
    out = []
    for a in td:
        nxt = lo[lo > a]
        out.append((float(a), float(nxt[0]) if nxt.size else t_end))
    return out


def _foot_traces(walker, t, X, points: bool = False) -> dict[str, FootTrace]:
    """Traces per leg (``walker.foot_quantities``), or per contact point (``points``)."""
    cq = walker.contact_quantities(X) if points else walker.foot_quantities(X)
    feet = {}
    for name, d in cq.items():
        on = d["on_ground"] > 0.5
        td, lo = _crossings(t, d["penetration"], d["penetration_rate"], on)
        feet[name] = FootTrace(d["normal_force"], d["friction_force"], d["penetration"],
                               d["slip_velocity"], d["s"], on, td, lo)
    return feet


def _first_stance(feet, initial_stance: str) -> str:
    """The foot in stance at the start: ``initial_stance``, or, for a walker whose feet are
    not legs (a rimless wheel's spokes, ``spoke0``, ...), its first contact point (the
    stance spoke of the rigid view's state it starts from)."""
    return initial_stance if initial_stance in feet else next(iter(feet))


def _heel_strikes(t, feet, min_step_m, initial_stance):
    """Heel strikes (times, feet) and the bounces / scuffs counted per step; the feet are
    the legs or, for a rimless wheel, its spokes (a heel strike is a spoke other than the
    stance spoke touching down ahead of it)."""
    evs = sorted((tt, name) for name in feet for tt in feet[name].touchdown_times)
    stance = _first_stance(feet, initial_stance)
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
    return hs_t, hs_leg, bounces, scuffs


def heel_strike_count(walker, t, X, min_step_m: float = 0.05,
                      initial_stance: str = "leg2") -> int:
    """Heel strikes in the samples ``t`` (n,) [s], ``X`` (n, N) (``walker.state_names()``)
    (the strides cap's count); a touchdown counts only ``min_step_m`` [m] downhill of the
    stance foot (as :func:`gait_events`)."""
    feet = _foot_traces(walker, t, X)
    return len(_heel_strikes(t, feet, min_step_m, initial_stance)[0])


def gait_events(walker, t, X, min_step_m: float = 0.05, initial_stance: str = "leg2") -> dict:
    """Foot traces, heel strikes and step summaries of a contact run's samples.

    Parameters
    ----------
    walker : ContactWalker
    t : ndarray (n,)
        [s].
    X : ndarray (n, N)
        States named by ``walker.state_names()``.
    min_step_m : float
        A touchdown of the swing foot counts as a heel strike only if it lands at least this
        far [m] downhill of the stance foot's touchdown point (else it is a scuff).
    initial_stance : str
        The foot in stance at ``t[0]``.

    Returns
    -------
    dict
        ``feet`` {foot: FootTrace}, ``hs_t`` (k,) [s], ``hs_leg`` [foot], ``steps``
        [StepSummary], ``points`` {contact point: FootTrace} (the contact table per point
        with its touchdowns and lift-offs: a flat foot's heel and toe; the same traces as
        ``feet`` for one point per leg).
    """
    feet = _foot_traces(walker, t, X)
    hs_t, hs_leg, bounces, scuffs = _heel_strikes(t, feet, min_step_m, initial_stance)
    initial_stance = _first_stance(feet, initial_stance)
    # an arc's contact point moves as it rolls, a flat foot's loaded point changes from heel
    # to toe: their slip is the integral of the material point's tangential velocity
    rolling = getattr(getattr(walker, "structure", None), "foot", "point") in ("arc", "flat")
    names = list(feet)
    starts = [t[0]] + hs_t
    legs = [initial_stance] + hs_leg
    loaded = {f: (feet[f].penetration > 0) & feet[f].on_ground for f in names}
    # double-support intervals: overlaps of the feet's contact intervals (event times)
    iv = {f: _intervals(feet[f].touchdown_times, feet[f].liftoff_times, float(t[-1]))
          for f in names}
    # (a wheel: any two of its spokes, each overlap with the pair of spokes in contact)
    ds = [(max(a1, a2), min(b1, b2), (f1, f2)) for j, f1 in enumerate(names)
          for f2 in names[j + 1:] for a1, b1 in iv[f1] for a2, b2 in iv[f2]
          if min(b1, b2) > max(a1, a2)]
    points = feet if tuple(walker.contact_names()) == tuple(feet) else \
        _foot_traces(walker, t, X, points=True)
    leg_of = getattr(walker, "contact_leg", None)
    dt_sample = float(np.median(np.diff(t))) if t.size > 1 else 0.0
    steps = []
    for j, (ta, leg) in enumerate(zip(starts, legs)):
        tb = starts[j + 1] if j + 1 < len(starts) else np.nan
        tb_or_end = tb if np.isfinite(tb) else t[-1]
        # stance phases of this leg that begin between its heel strike and the other foot's
        # (its touchdowns after that are the swing foot's scuffs, not stance)
        t_other = starts[j + 1] if j + 1 < len(starts) else np.inf
        t_next = starts[j + 2] if j + 2 < len(starts) else np.inf
        ft = feet[leg]
        td = ft.touchdown_times
        if j == 0 and (not td.size or td[0] > t[0]) and loaded[leg][0]:
            td = np.concatenate([[t[0]], td])
        slip = phase_slip(t, ft.s, td, ft.liftoff_times, ta, t_other,
                          ft.slip_velocity if rolling else None)
        phases = stance_phases(td, ft.liftoff_times, ta, t_other)
        # the slip path and friction work of the stance, from the first sample one sample
        # interval after each touchdown: the heel-strike collision (a fraction of a
        # millisecond) falls between the samples, and a sample that happens to land in it
        # would alias its sliding (0.6 m/s against ~0.01 m/s of creep) into the sum (its
        # loss is the heel strike's)
        held = None if phases is None else [
            (a if a <= t[0] else float(t[min(np.searchsorted(t, a + dt_sample), t.size - 1)]),
             b) for a, b in phases]
        held = held if held is None else [(a, b) for a, b in held if b > a]
        path = phase_integral(t, np.abs(ft.slip_velocity), held)
        mine = [p for name, p in points.items()
                if name == leg or (name not in feet and leg_of is not None
                                   and leg_of(name) == leg)]
        friction = -sum(phase_integral(t, p.friction_force * p.slip_velocity, held)
                        for p in mine) if phases else np.nan
        lo_mine = ft.liftoff_times[(ft.liftoff_times > ta) & (ft.liftoff_times < t_next)]
        sel = (t >= ta) & (t <= tb_or_end)
        creep = 0.0
        for a, b, pair in ds:
            a, b = max(a, ta), min(b, tb_or_end)
            if b > a:
                creep += sum(abs(float(np.interp(b, t, feet[f].s) - np.interp(a, t, feet[f].s)))
                             for f in pair)
        peak = max(float(np.max(feet[f].penetration[sel] * feet[f].on_ground[sel]))
                   for f in names) if sel.any() else np.nan
        steps.append(StepSummary(j, leg, float(ta), float(tb), float(tb - ta),
                                 float(1e3 * slip), float(1e3 * creep), int(bounces[j]),
                                 int(scuffs[j]), max(peak, 0.0),
                                 float(lo_mine[-1]) if lo_mine.size else np.nan,
                                 stance_slip_path_mm=float(1e3 * path) if phases else np.nan,
                                 friction_work_j=float(friction) if phases else np.nan))
    if all(f"{st.stance_leg}_heel" in points and f"{st.stance_leg}_toe" in points
           for st in steps):  # flat feet: each step's mode sequence from the contact table
        dt = 2.0 * float(np.median(np.diff(t))) if t.size > 1 else 0.0
        for st in steps:
            tb = st.t_end if np.isfinite(st.t_end) else float(t[-1])
            segs = [(m, a) for m, a, b in foot_modes(t, points, st.stance_leg, st.t_start, tb)
                    if b - a >= dt]
            merged = [s_ for k, s_ in enumerate(segs) if k == 0 or s_[0] != segs[k - 1][0]]
            st.foot_modes = " > ".join(f"{m} ({a:.4f} s)" for m, a in merged)
    return {"feet": feet, "hs_t": np.array(hs_t), "hs_leg": hs_leg, "steps": steps,
            "points": points}


# ---------------------------------------------------------------------------- foot modes
#: Mode of a flat foot by which of its points carry load (heel, toe): the rigid view's
#: names (:mod:`walkerlab.models.hybrid.rigid_foot_modes`), ``off`` when neither does.
FOOT_MODES = {(True, False): "heel_contact", (True, True): "foot_flat",
              (False, True): "heel_off", (False, False): "off"}


def foot_modes(t, points: dict, leg: str, t0: float = -np.inf,
               t1: float = np.inf) -> list[tuple[str, float, float]]:
    """The modes of ``leg``'s flat foot read from the contact table: which of its heel and
    toe carry a normal force, sample by sample (:data:`FOOT_MODES`), merged into segments.

    Parameters
    ----------
    t : ndarray (n,)
        Sample times [s].
    points : dict[str, FootTrace]
        Per contact point (``ContactResult.points``), with ``<leg>_heel``, ``<leg>_toe``.
    leg : str
    t0, t1 : float
        Window [s] (e.g. one step, heel strike to heel strike).

    Returns
    -------
    list of (mode, start [s], end [s])
        Consecutive segments at the samples' resolution.
    """
    sel = (t >= t0) & (t <= t1)
    heel = points[f"{leg}_heel"].normal_force[sel] > 0
    toe = points[f"{leg}_toe"].normal_force[sel] > 0
    ts = t[sel]
    out: list[tuple[str, float, float]] = []
    for k in range(ts.size):
        m = FOOT_MODES[(bool(heel[k]), bool(toe[k]))]
        if out and out[-1][0] == m:
            out[-1] = (m, out[-1][1], float(ts[k]))
        else:
            out.append((m, float(ts[k]), float(ts[k])))
    return out


# ---------------------------------------------------------------------------- terrain fit
#: a footfall this far (as a fraction of the smaller margin of :class:`PatchFit`) from its
#: patch's centre has used up most of the room the checkerboard gives it
PATCH_MARGIN_USED = 0.5


@dataclass
class PatchFit:
    """Where a contact run's footfalls landed on the checkerboard laid out for its gait.

    Footfall ``k`` of the gait has a patch centred at ``s = k l`` in its leg's lane
    (:func:`walkerlab.models.contact.model.checkerboard_lanes`, ``l`` the patch spacing,
    the rigid gait's step); a patch is ``2 h`` wide.  A footfall lands on ground while it is
    within ``h`` of its patch's centre; at mid-stance the swing foot passes the stance foot
    (a straight leg's swing foot dips below the ground line there) over the gap of its own
    lane, which reaches ``l - h`` either side of the stance footfall's patch centre.  The
    footfalls of a contact gait whose steps differ from the spacing drift through both.

    Attributes
    ----------
    spacing_m : float
        Patch spacing ``l`` [m] (footfall to footfall).
    half_width_m : float
        ``h`` [m] (``terrain.patch_width_m / 2``).
    offsets_m : ndarray (k,)
        Each heel strike's footfall minus its patch's centre [m] (negative: short of it).
    steps_m : ndarray (k,)
        Each step's length, footfall to footfall [m] (the first from the initial stance
        foot).
    """

    spacing_m: float
    half_width_m: float
    offsets_m: np.ndarray
    steps_m: np.ndarray

    @property
    def margin_m(self) -> float:
        """The smaller room [m] a footfall has: ``h`` (on its patch) or ``l - h`` (the swing
        foot over its lane's gap beside it)."""
        return min(self.half_width_m, self.spacing_m - self.half_width_m)

    @property
    def drift_m_per_step(self) -> float:
        """Least-squares slope of the footfalls' offsets over the heel strikes [m/step]
        (NaN with fewer than two)."""
        k = self.offsets_m.size
        return float(np.polyfit(np.arange(k), self.offsets_m, 1)[0]) if k >= 2 else np.nan

    def note(self) -> str:
        """Why the checkerboard does not suit the gait, when the last footfall used more
        than :data:`PATCH_MARGIN_USED` of :attr:`margin_m` ("" otherwise): its offset, the
        drift per step, the contact steps against the spacing, both margins, and the
        patch width that balances them."""
        if self.offsets_m.size < 2 or not np.isfinite(self.margin_m) or self.margin_m <= 0:
            return ""
        last = float(self.offsets_m[-1])
        if abs(last) < PATCH_MARGIN_USED * self.margin_m:
            return ""
        sp, h = self.spacing_m, self.half_width_m
        mean = float(np.mean(self.steps_m))
        return (f"the patches ({2 * h:.3g} m wide at {sp:.4g} m spacing, the rigid gait's "
                f"step) do not suit this gait's step: its contact steps average {mean:.4g} m, "
                f"its footfalls drifted {1e3 * self.drift_m_per_step:+.3g} mm a step and "
                f"heel strike {self.offsets_m.size} landed {last:+.3f} m from its patch's "
                f"centre, where a footfall has ±{h:.3g} m on its patch and the swing foot "
                f"±{sp - h:.3g} m over its lane's gap at mid-stance (terrain.patch_width_m "
                f"near {sp:.3g} m balances the two; contact_sim.start: periodic_gait lays the "
                "patches at the contact gait's own footfalls)")


def patch_fit(walker, t, feet: dict, hs_t, hs_leg, initial_stance: str = "leg2"
              ) -> PatchFit | None:
    """The footfalls of a contact run against its checkerboard (:class:`PatchFit`); None on
    continuous ground or without heel strikes.

    Parameters
    ----------
    walker : ContactWalker
        Its lanes (``walker.lane(leg)``, patch centres [m]) and ``patch_half_width`` [m].
    t : ndarray (n,)
        Sample times [s].
    feet : dict[str, FootTrace]
        Per leg (:func:`gait_events`' ``feet``).
    hs_t, hs_leg : sequence
        Heel-strike times [s] and legs.
    initial_stance : str
        The leg in stance at ``t[0]`` (its foot is footfall 0).
    """
    if getattr(walker, "continuous", True) or not len(hs_t):
        return None
    s_prev = float(feet[initial_stance].s[0])
    off, steps = [], []
    for th, leg in zip(hs_t, hs_leg):
        s = float(np.interp(th, t, feet[leg].s))
        lane = np.asarray(walker.lane(leg), float)
        if not lane.size:
            return None
        off.append(s - float(lane[np.argmin(np.abs(lane - s))]))
        steps.append(s - s_prev)
        s_prev = s
    c1, c2 = np.asarray(walker.lane("leg1"), float), np.asarray(walker.lane("leg2"), float)
    spacing = float(abs(c1[0] - c2[0])) if c1.size and c2.size else np.nan
    return PatchFit(spacing, float(walker.patch_half_width), np.array(off), np.array(steps))


# ---------------------------------------------------------------------------- verdict
#: ends after the strides asked for that are the walker's own (not the solver's or the
#: wall clock's): a run that meets one does not walk
WALKER_ENDS = ("trip", "fall", "airborne")
#: a contact run's steps have settled when the last change of a leg's step period (against
#: that leg's previous step: an asymmetric gait alternates) is below this fraction of it ...
STEADY_PERIOD_CHANGE = 0.005
#: ... or smaller than this fraction of the changes before it (they die out)
SETTLING_RATIO = 0.5


def step_trend(periods) -> str:
    """"" when a contact run's step periods [s] settle, else what they do.

    A leg's step is compared with that leg's previous one (``T_k - T_{k-2}``: a period-2
    gait's steps alternate).  The steps have not settled when the last three such changes
    share a sign, the last exceeds :data:`STEADY_PERIOD_CHANGE` of the period and is at
    least :data:`SETTLING_RATIO` of the first of them (no decay towards a gait).

    Parameters
    ----------
    periods : array_like (k,)
        Step periods [s] (NaN: a step the run did not finish, left out).

    Returns
    -------
    str
        e.g. "its steps shorten monotonically (0.583 → 0.509 s)"; "" with fewer than five
        finished steps.
    """
    T = np.asarray(periods, float)
    T = T[np.isfinite(T)]
    if T.size < 5:
        return ""
    d = T[2:] - T[:-2]
    last3 = d[-3:]
    if not (np.all(last3 > 0) or np.all(last3 < 0)):
        return ""
    if abs(last3[-1]) <= STEADY_PERIOD_CHANGE * T[-1] \
            or abs(last3[-1]) < SETTLING_RATIO * abs(last3[0]):
        return ""
    way = "shorten" if last3[-1] < 0 else "lengthen"
    mono = np.all(np.diff(T) < 0) if way == "shorten" else np.all(np.diff(T) > 0)
    return (f"its steps {way}{' monotonically' if mono else ''} ({T[0]:.3f} → {T[-1]:.3f} s"
            f", the last by {100 * abs(last3[-1]) / T[-1]:.2g} % against the same leg's "
            "step before): no steady gait")


def walk_verdict(outcome: Outcome, steps) -> tuple[bool, str]:
    """Whether a contact run walks, one verdict from its steps: it made its heel strikes
    (:attr:`Outcome.walked`), no trip, fall or flight (:data:`WALKER_ENDS`) ended it after
    them (:attr:`Outcome.after`; a solver failure or the wall-time limit there is named in
    the message only), and its step periods settle (:func:`step_trend`).

    Returns
    -------
    walks : bool
    why : str
        "" when it walks, else the reason (one phrase).
    """
    if not outcome.walked:
        return False, outcome.message
    why = []
    if outcome.after in WALKER_ENDS:  # a solver's failure or the wall time is no fall
        what = outcome.after_message or (f"a {outcome.after.replace('_', ' ')} ended it at "
                                         f"t = {outcome.after_time_s:.4g} s")
        why.append(f"it made the heel strikes asked for, then {what}")
    trend = step_trend([st.period for st in steps])
    if trend:
        why.append(trend)
    return (not why), "; ".join(why)


# ---------------------------------------------------------------------------- outcome
def classify_complete(steps, slip_limit_mm: float | None, hip_height_m: float,
                      end: str = "t_final") -> Outcome:
    """Outcome of a run that reached its end (``end``: ``t_final`` or ``heel_strike``):
    ``no_heel_strike`` if it made no step, ``slip`` if a stance phase slid farther than
    ``slip_limit_mm`` [mm], ``scuff`` if the swing foot touched down before its heel strike,
    else ``end``."""
    if len(steps) <= 1:
        return Outcome("no_heel_strike", hip_height_m=hip_height_m,
                       message="no heel strike: the walker reached the end of the run "
                       "without taking a step")
    if slip_limit_mm is not None:
        for st in steps:
            if np.isfinite(st.stance_slip_mm) and abs(st.stance_slip_mm) > slip_limit_mm:
                return Outcome("slip", st.t_start, st.stance_leg, np.nan, hip_height_m,
                               f"slip: {st.stance_leg} slid {st.stance_slip_mm:.3g} mm in the "
                               f"stance phase from t = {st.t_start:.4g} s (limit "
                               f"{slip_limit_mm:g} mm)")
    for st in steps:
        if st.scuff_count:
            return Outcome("scuff", st.t_start, _other(steps, st.stance_leg), np.nan,
                           hip_height_m, f"scuff: the swing foot touched ground "
                           f"{st.scuff_count} time(s) before its heel strike in step "
                           f"{st.index}")
    return Outcome(end, hip_height_m=hip_height_m,
                   message=f"walked: {len(steps) - 1} heel strikes"
                   + (" (the number asked for)" if end == "heel_strike" else
                      " by the end time"))


def _other(steps, leg: str) -> str:
    """The other foot than ``leg`` among the steps' stance legs ("" if unknown)."""
    return next((s.stance_leg for s in steps if s.stance_leg != leg), "")


def scuff_cause(walker) -> str:
    """The likely cause of swing-foot scuffs before a fall, for the walker and its ground,
    and what helps (a parenthesis; ``""``: none to name).

    - a kneed walker whose stance knee is not latched
      (``contact.knee_stop.latch: false``): the stance knee flexes under load, the hip
      sinks and the swing foot meets the ground; the latch holds it as the rigid model's
      knee lock does;
    - straight legs: the swing foot passes below the ground line near mid-stance (the
      rigid model ignores that scuffing); on continuous slope or stairs the checkerboard
      (``terrain.lanes: checkerboard``) gives it a gap there; a profile is continuous
      ground only (the checkerboard is refused there): knees clear it;
    - a latched kneed walker, flat feet, free knees: nothing general to name.

    Parameters
    ----------
    walker : walkerlab.models.contact.model.ContactWalker
        The run's walker (its ``data.structure``, ``knee_stop``, ``continuous`` and
        ``ground_line``).

    Returns
    -------
    str
    """
    return _SCUFF_CAUSES.get(walker.data.structure.kind.name, _no_cause)(walker)


def _no_cause(walker) -> str:
    """Flat feet, free knees, a wheel: nothing general to name."""
    return ""


def _unlatched_knee(walker) -> str:
    """A kneed walker's scuff: its stance knee not latched."""
    if walker.knee_stop is not None and not walker.knee_stop.latch:
        return ("(the stance knee is not latched: it flexes under the load and the hip "
                "sinks; contact.knee_stop.latch: true holds it as the rigid model's "
                "knee lock does)")
    return ""


def _straight_leg_scuff(walker) -> str:
    """Straight legs: the swing foot below the ground line near mid-stance."""
    straight = "a straight leg's swing foot passes below the ground line near mid-stance"
    if getattr(walker, "ground_line", None) is not None:  # a profile: continuous only
        return (f"({straight}; a profile is continuous ground, where straight legs scuff: "
                "a walker with knees clears it)")
    if walker.continuous:
        return f"({straight}; terrain.lanes: checkerboard gives it a gap there)"
    return f"({straight})"


#: kind name -> the likely cause of its swing foot's scuffs (:func:`scuff_cause`; a kind
#: not listed has none to name)
_SCUFF_CAUSES = {"straight_legs": _straight_leg_scuff, "locking_knees": _unlatched_knee}


def classify(termination: str, event, t: np.ndarray, hip_height_m: float, steps: list,
             message: str, limits, slip_limit_mm: float | None,
             wall_time_limit_s: float | None, scuff_why: str = "") -> Outcome:
    """The typed outcome of a contact run from how its integration stopped.

    Parameters
    ----------
    termination : str
        :attr:`walkerlab.integrate.contact.ContactIntegration.termination`.
    event : tuple or None
        Its ``event``.
    t : ndarray (n,)
        Sample times [s].
    hip_height_m : float
        Hip height at the last sample [m].
    steps : list[StepSummary]
    message : str
        The solver's message.
    limits : ContactLimits
    slip_limit_mm, wall_time_limit_s : float or None
    scuff_why : str
        The likely cause of swing-foot scuffs before a fall, and what helps
        (:func:`scuff_cause` of the run's walker; ``""``: none named).
    """
    n_hs = max(len(steps) - 1, 0)
    te = float(t[-1])
    if termination == "trip":
        _, _, te, foot, edge = event
        return Outcome("trip", te, foot, edge, hip_height_m,
                       f"trip: {foot} hit the side of the patch edge at s = {edge:.4f} m at "
                       f"t = {te:.4g} s after {n_hs} heel strikes")
    if termination == "fall":
        scuffs = sum(st.scuff_count for st in steps)
        why = ""
        if scuffs:  # the run's own table counts them: name the likely cause
            why = (f"; the swing foot scuffed the ground {scuffs} time(s) before"
                   + (f" {scuff_why}" if scuff_why else ""))
        return Outcome("fall", te, "", np.nan, hip_height_m,
                       f"fall: hip {hip_height_m:.3f} m above ground "
                       f"(< {limits.fall_hip_height_m:g} m) at t = {te:.4g} s after {n_hs} "
                       f"heel strikes{why}")
    if termination == "airborne":
        return Outcome("airborne", te, "", np.nan, hip_height_m,
                       f"airborne: the hip rose {hip_height_m:.3g} m above the ground "
                       f"(> {limits.airborne_hip_height_m:g} m) at t = {te:.4g} s after "
                       f"{n_hs} heel strikes: the walker flew off the ground")
    if termination == "solver_failure":
        return Outcome("solver_failure", te, "", np.nan, hip_height_m,
                       f"solver failure at t = {te:.4g} s: {message}")
    if termination == "time_limit":
        return Outcome("time_limit", te, "", np.nan, hip_height_m,
                       f"time limit: {wall_time_limit_s:g} s of wall time used by t = "
                       f"{te:.4g} s ({n_hs} heel strikes)")
    return classify_complete(steps, slip_limit_mm, hip_height_m, end=termination)
