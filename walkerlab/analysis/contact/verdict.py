"""How a contact run ended and whether it walks: the typed :class:`Outcome`, its
classification from the integration's termination and the steps, and the one verdict.

Input: the integration's termination (:mod:`walkerlab.integrate.ends`) and the run's
:class:`~walkerlab.analysis.contact.gait.StepSummary` list (:func:`walkerlab.analysis.contact.
gait.gait_events`).  Output: the run's :class:`Outcome` (``kind`` one of the shared run
ends), the likely cause of swing-foot scuffs for the walker's kind, and
:func:`walk_verdict` (heel strikes made, no trip, fall or flight after them, step periods
that settle).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from walkerlab.integrate.ends import CONTACT_WALKED, RUN_END_NAMES
from walkerlab.walker import parts as P

__all__ = ["CONTACT_OUTCOMES", "Outcome", "classify", "classify_complete", "scuff_cause",
           "step_trend", "walk_verdict"]

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
      rigid model ignores that scuffing); on continuous ground (a slope, stairs, a
      profile) the checkerboard (``terrain.lanes: checkerboard``) gives it a gap there (on a
      profile flat across each footfall's patch), knees clear it;
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
    return walker.data.structure.kind.scuff(walker)


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
    if getattr(walker, "ground_line", None) is not None:  # a polyline: stairs or a profile
        return (f"({straight}; terrain.lanes: checkerboard gives it a gap there, on a "
                "profile where it is flat across each footfall's patch; a walker with "
                "knees clears continuous ground)")
    if walker.continuous:  # a slope laid as continuous ground
        return f"({straight}; terrain.lanes: checkerboard gives it a gap there)"
    return f"({straight})"


# each kind's scuff part (:attr:`walkerlab.walker.kinds.Kind.scuff`) given the likely cause
# of its swing foot's scuffs (:func:`scuff_cause`)
P.SCUFF_STRAIGHT_LEG.provide(_straight_leg_scuff)
P.SCUFF_UNLATCHED_KNEE.provide(_unlatched_knee)
P.SCUFF_NONE.provide(_no_cause)


def classify(termination: str, event, t: np.ndarray, hip_height_m: float, steps: list,
             message: str, limits, slip_limit_mm: float | None,
             wall_time_limit_s: float | None, scuff_why: str = "", how: str = ""
             ) -> Outcome:
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
    how : str
        How a fallen walker went down (a walker in 3D: capsized sideways or fell along the
        slope, :meth:`walkerlab.models.contact.model.ContactWalker.fall_how`; ``""``: not
        named).
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
                       f"fall: {how + '; ' if how else ''}hip {hip_height_m:.3f} m above ground "
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
                       f"{te:.4g} s ({n_hs} heel strikes); cut short by the machine's speed "
                       "(contact_sim.wall_time_limit_s): never kept as the scene's result, "
                       "the next run recomputes it")
    if termination == "work_limit":
        return Outcome("work_limit", te, "", np.nan, hip_height_m,
                       f"work limit: {limits.max_rhs_evaluations:,} right-hand-side "
                       f"evaluations used by t = {te:.4g} s ({n_hs} heel strikes); raise "
                       "contact_sim.max_rhs_evaluations for a longer run")
    return classify_complete(steps, slip_limit_mm, hip_height_m, end=termination)
