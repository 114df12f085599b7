"""How a run ended: one vocabulary for the rigid hybrid model and the compliant-contact model.

The rigid side's segment terminations (:mod:`walkerlab.analysis.hybrid`: a step ends in
``heel_strike``, ``fall``, ``t_final`` or ``solver_failure``) extended with what only the
contact model can do (trip, scuff, slip, fly away) and with the verdicts a whole run needs
(no heel strike at all, the wall-time limit).  Every producer and reader uses these names:
the contact integration (:mod:`walkerlab.integrate.contact`: ``termination``), the contact
gait analysis (:class:`walkerlab.analysis.contact_gait.Outcome`: ``kind``), the stages'
artifacts (attribute ``termination`` / ``outcome``), the report, the CLI's exit code and the
sweeps (:mod:`walkerlab.sweep.outcomes`, which add their own verdicts such as
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
``time_limit``     the wall-time limit ran out first
=================  ==========================================================================
"""

from __future__ import annotations

__all__ = ["CONTACT_WALKED", "RUN_ENDS", "RUN_END_NAMES", "describe"]

#: name -> one line (the table above).
RUN_ENDS: dict[str, str] = {
    "heel_strike": "ended at a heel strike (rigid step; contact run: the heel strikes asked "
                   "for were made)",
    "t_final": "reached its end time (rigid step: cut after max_step_time_s, the walker "
               "stalled)",
    "fall": "the hip fell below the fall height / a fall guard fired",
    "trip": "a foot hit the side of a ground patch below its top",
    "scuff": "the swing foot touched the ground before its heel strike",
    "slip": "a stance foot slid farther than the slip limit",
    "airborne": "the hip rose above the airborne height (the walker flew off the ground)",
    "no_heel_strike": "the walker made no step (no heel strike, or a step that ended where "
                      "it began)",
    "solver_failure": "the integrator stopped",
    "time_limit": "the wall-time limit ran out first",
}

#: The names, in the order of :data:`RUN_ENDS`.
RUN_END_NAMES: tuple[str, ...] = tuple(RUN_ENDS)

#: Contact outcomes of a run that walked (exit code 0): made its heel strikes or reached its
#: end time, possibly with a scuff or a slip beyond the limit noted on the way.
CONTACT_WALKED: tuple[str, ...] = ("heel_strike", "t_final", "scuff", "slip")


def describe(name: str) -> str:
    """The one-line meaning of a run end ``name``.

    Raises
    ------
    KeyError
        ``name`` is not one of :data:`RUN_END_NAMES`.
    """
    return RUN_ENDS[name]
