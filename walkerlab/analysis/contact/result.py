"""What a contact run returns: the records of :mod:`walkerlab.analysis.contact.gait`.

:class:`FootTrace` (one foot's sampled contact quantities and its touchdown / lift-off
times), :class:`StepSummary` (one step: its stance leg, period, length, slip, creep,
bounces, scuffs, peak penetration, foot modes) and :class:`ContactResult` (the run's samples,
heel strikes, steps and typed outcome, and the summaries read from them).  Lengths in [m]
unless the name says ``_mm``, times [s], forces [N]; states named by ``walker.state_names()``.
The gait module, which fills them, re-exports them.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from walkerlab.analysis.contact.verdict import Outcome, walk_verdict


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
    lateral_slip_velocity, spin_rate : ndarray (n,) or None
        A walker in 3D: the foot's slip across the slope [m/s] and its spin about the
        slope's normal [rad/s]; None in the plane.
    """

    normal_force: np.ndarray
    friction_force: np.ndarray
    penetration: np.ndarray
    slip_velocity: np.ndarray
    s: np.ndarray
    on_ground: np.ndarray
    touchdown_times: np.ndarray
    liftoff_times: np.ndarray
    lateral_slip_velocity: np.ndarray | None = None
    spin_rate: np.ndarray | None = None


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
        contact table, :func:`~walkerlab.analysis.contact.gait.foot_modes`; modes shorter
        than two samples left out); "" for other feet.
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
    stance_lateral_slip_mm, stance_turn_mrad : float
        A walker in 3D: the stance foot's slide across the slope [mm] and its turn about
        the slope's normal [mrad] over the same phase(s) as ``stance_slip_path_mm`` (the
        integrals of its lateral slip velocity and its spin: what the torsional friction
        lets through).  NaN in the plane.
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
    stance_lateral_slip_mm: float = float("nan")
    stance_turn_mrad: float = float("nan")


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
        """Whether the run walks and, if not, why
        (:func:`~walkerlab.analysis.contact.verdict.walk_verdict`)."""
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
