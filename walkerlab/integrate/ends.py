"""How a run ended: one vocabulary for the rigid hybrid model and the compliant-contact model.

The rigid side's segment terminations (:mod:`walkerlab.integrate.rigid`: a step ends in
``heel_strike``, ``fall``, ``t_final`` or ``solver_failure``) extended with what only the
contact model can do (trip, scuff, slip, fly away) and with the verdicts a whole run needs
(no heel strike at all, the wall-time limit, the work bound).  Every producer and reader
uses these names: the contact integration (:mod:`walkerlab.integrate.contact`:
``termination``), the contact gait analysis
(:class:`walkerlab.analysis.contact.verdict.Outcome`: ``kind``), the stages'
artifacts (attribute ``termination`` / ``outcome``), the report, the CLI's exit code and the
sweeps (:mod:`walkerlab.studies.outcomes`, which add their own verdicts such as
``no_fixed_point``).

=================  ==========================================================================
``heel_strike``    ended at a heel strike: a rigid step; a rigid run whose last step did; a
                   contact run that made the heel strikes it was asked for (strides cap)
``t_final``        reached its end time: a contact run that walked to its end time; a rigid
                   step cut after ``max_step_time_s`` without a heel strike (the walker
                   stalled; the ``simulate`` stage counts that as not walking)
``fall``           the hip fell below the fall height (contact) / a fall guard fired (rigid)
``trip``           contact: a foot hit the side of a ground patch below the patch's top
``scuff``          contact: the swing foot touched the ground before its heel strike
``slip``           contact: a stance foot slid farther than the slip limit
``airborne``       contact: the hip rose above the airborne height (the walker flew off)
``no_heel_strike`` the walker made no step: a contact run that reached its end without a
                   heel strike; a rigid step that ended where it began (a walker that
                   never moves)
``solver_failure`` the integrator stopped
``time_limit``     the wall-time limit a user set ran out first (a result of the machine's
                   speed: never stored as the scene's result)
``work_limit``     the work bound ran out first (right-hand-side evaluations of a run:
                   ``contact_sim.max_rhs_evaluations``): the same end on any machine
=================  ==========================================================================

:class:`RunEnd` is the vocabulary: a ``str``-valued enum, so ``RunEnd.FALL == "fall"``.  The
integrators decide with its members and hand their results over with the member's value (a
plain ``str``, which h5py stores as it stores any string: artifacts, JSON and pickles carry
the same names as before).
"""

from __future__ import annotations

from enum import StrEnum

__all__ = ["CONTACT_WALKED", "RIGID_ENDS", "RUN_ENDS", "RUN_END_NAMES", "RunEnd", "describe",
           "solver_words"]


class RunEnd(StrEnum):
    """How a run (or a rigid step) ended; the value is the name written to artifacts."""

    HEEL_STRIKE = "heel_strike"
    T_FINAL = "t_final"
    FALL = "fall"
    TRIP = "trip"
    SCUFF = "scuff"
    SLIP = "slip"
    AIRBORNE = "airborne"
    NO_HEEL_STRIKE = "no_heel_strike"
    SOLVER_FAILURE = "solver_failure"
    TIME_LIMIT = "time_limit"
    WORK_LIMIT = "work_limit"


#: run end -> one line (the table above).
RUN_ENDS: dict[RunEnd, str] = {
    RunEnd.HEEL_STRIKE: "ended at a heel strike (rigid step; contact run: the heel strikes "
                        "asked for were made)",
    RunEnd.T_FINAL: "reached its end time (rigid step: cut after max_step_time_s, the walker "
                    "stalled)",
    RunEnd.FALL: "the hip fell below the fall height / a fall guard fired",
    RunEnd.TRIP: "a foot hit the side of a ground patch below its top",
    RunEnd.SCUFF: "the swing foot touched the ground before its heel strike",
    RunEnd.SLIP: "a stance foot slid farther than the slip limit",
    RunEnd.AIRBORNE: "the hip rose above the airborne height (the walker flew off the ground)",
    RunEnd.NO_HEEL_STRIKE: "the walker made no step (no heel strike, or a step that ended "
                           "where it began)",
    RunEnd.SOLVER_FAILURE: "the integrator stopped",
    RunEnd.TIME_LIMIT: "the wall-time limit ran out first",
    RunEnd.WORK_LIMIT: "the work bound (right-hand-side evaluations) ran out first",
}

#: The names (plain strings), in the order of :class:`RunEnd`.
RUN_END_NAMES: tuple[str, ...] = tuple(e.value for e in RunEnd)

#: How a rigid step can end (:func:`walkerlab.integrate.rigid.integrate_step`).
RIGID_ENDS: tuple[RunEnd, ...] = (RunEnd.HEEL_STRIKE, RunEnd.FALL, RunEnd.T_FINAL,
                                  RunEnd.SOLVER_FAILURE, RunEnd.NO_HEEL_STRIKE)

#: Contact outcomes of a run that walked (exit code 0): made its heel strikes or reached its
#: end time, possibly with a scuff or a slip beyond the limit noted on the way.
CONTACT_WALKED: tuple[str, ...] = tuple(e.value for e in (RunEnd.HEEL_STRIKE, RunEnd.T_FINAL,
                                                          RunEnd.SCUFF, RunEnd.SLIP))


def describe(name: str) -> str:
    """The one-line meaning of a run end ``name``.

    Raises
    ------
    ValueError
        ``name`` is not one of :data:`RUN_END_NAMES`.
    """
    return RUN_ENDS[RunEnd(name)]


#: an integrator's own stop messages (ODEPACK's LSODA through scipy's odeint, solve_ivp's
#: methods) -> walkerlab's words: what happened to the run and what to look at
_SOLVER_WORDS = (
    ("Excess work done", "the integrator spent its step budget (LSODA's mxstep) without "
     "reaching the next sample: the contact became too stiff to step through at its "
     "tolerances (a foot chattering or pressed deep into a patch: a contact law far "
     "stiffer than its damping, which the rigid-limit family scales with it: walkerlab "
     "compare --rigid-limit; or a gait that barely lifts its swing foot)"),
    ("Excess accuracy requested", "the integrator cannot meet its tolerances in floating "
     "point (loosen contact_solver.rtol / atol)"),
    ("Repeated error test failures", "the integrator's step failed its error test again "
     "and again (a discontinuity it cannot step across: a contact switching on and off)"),
    ("Repeated convergence failures", "the integrator's corrector did not converge again "
     "and again (a contact law too stiff for its Jacobian)"),
    ("Required step size is less than spacing between numbers", "the integrator's step "
     "shrank below the resolution of time (a force it cannot step through: a contact law "
     "too stiff, or a foot striking a patch's side)"),
)


def solver_words(message: str) -> str:
    """An integrator's stop message in walkerlab's words (unchanged when it holds none of
    :data:`_SOLVER_WORDS`' known messages): the integrator's sentence is replaced, where it
    stands, by what happened, with its own words after it in brackets for a search; a
    diagnosis walkerlab wrote around it (a trip, a fall) keeps its place first.

    Parameters
    ----------
    message : str
        The message (e.g. odeint's "Excess work done on this call (perhaps wrong Dfun
        type).", or a run end's diagnosis quoting CyRK's "Required step size is less than
        spacing between numbers.").
    """
    for head, words in _SOLVER_WORDS:
        at = message.find(head)
        if at < 0 or words in message:  # not this one, or said already
            continue
        ends = [i for i in (message.find(".", at), message.find(")", at)) if i >= 0]
        end = min(ends) + 1 if ends else len(message)
        if message[end - 1:end] == ")" and "(" in message[at:end - 1]:  # its own bracket
            end = message.find(")", end) + 1 or len(message)
            end = end if message[end - 1:end] == ")" else len(message)
        said = f"{words} [the integrator's message: {message[at:end].strip()}]"
        return message[:at] + said + message[end:]
    return message
