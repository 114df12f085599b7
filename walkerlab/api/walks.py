"""The records of the in-memory walker's runs (:mod:`walkerlab.api.walker`): a rigid
gait (:class:`Gait`), one step of the Poincaré map (:class:`Step`), a rigid walk
(:class:`Walk`) and a walk of the contact view (:class:`ContactWalk`, with the step table's
columns :data:`STEP_FIELDS`).  Plain frozen dataclasses: they hold arrays and numbers and run
nothing."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from walkerlab.rigid_walker import Gait

if TYPE_CHECKING:  # pragma: no cover
    import numpy as np

__all__ = ["STEP_FIELDS", "ContactWalk", "Gait", "Step", "Walk", "recorded_contact_walk",
           "sampled_walk"]


@dataclass(frozen=True)
class Step:
    """One application of the Poincaré map (a step, or a stride when the legs differ).

    Attributes
    ----------
    x_next : ndarray, shape (2n,)
        State just after the last heel strike.
    period : float
        Duration [s].
    events : list of (str, float, float, str)
        Each phase of each step: ``(phase, t_start [s], t_end [s], guard that ended it)``.
    """

    x_next: np.ndarray
    period: float
    events: list


@dataclass(frozen=True)
class Walk:
    """A simulated walk.

    Attributes
    ----------
    t : ndarray, shape (m,)
        Sample times [s].
    x : ndarray, shape (m, 2n)
        Role-ordered states at ``t`` (roles swap at every heel strike).
    stance_leg : ndarray, shape (m,), str
        Physical leg in stance at each sample.
    heel_strikes : ndarray, shape (k,)
        Times of the heel strikes [s].
    events : list of (int, str, str, float, float, str)
        ``(step, stance leg, phase, t_start, t_end, guard)`` of every phase.
    termination : str
        How the walk ended (``heel_strike`` after the last step, ``fall``, ...).
    steps : dict[str, ndarray (k,)]
        The step table of the ``simulate`` stage
        (:func:`walkerlab.analysis.gait.metrics.step_table`): ``period`` [s],
        ``step_length`` [m], ``hip_speed`` [m/s], ``impact_energy_loss`` [J],
        ``termination``, ``stance_leg`` ... of each step (the last one may have fallen).
    ledger : dict[str, ndarray (k,)]
        The energy ledger of each step, as :attr:`Gait.ledger` (NaN for a step that did
        not end by a heel strike; empty for flat feet on legs that differ).
    """

    t: np.ndarray
    x: np.ndarray
    stance_leg: np.ndarray
    heel_strikes: np.ndarray
    events: list
    termination: str
    steps: dict = field(default_factory=dict)
    ledger: dict = field(default_factory=dict)

    @property
    def step_length(self) -> np.ndarray:
        """Length of each step [m] (``steps["step_length"]``)."""
        return self.steps["step_length"]

    @property
    def speed(self) -> np.ndarray:
        """Hip speed of each step [m/s] (``steps["hip_speed"]``): the hip's horizontal
        displacement over the step's period.  :attr:`Gait.speed` is the distance along the
        slope over the period: on a slope of angle phi a walk on the fixed point has
        ``cos(phi)`` times the gait's speed (the paper's scene: 1.5e-4 lower)."""
        return self.steps["hip_speed"]

    @property
    def cost_of_transport(self) -> np.ndarray:
        """Cost of transport of each step [-] (``ledger["cost_of_transport"]``)."""
        return self.ledger["cost_of_transport"]


def sampled_walk(traj, rate: float) -> Walk:
    """The :class:`Walk` of a rigid trajectory (:meth:`walkerlab.api.walker.Walker.simulate`):
    each step sampled on its own time grid at ``rate`` [Hz] (at least its two ends), its heel
    strikes, phases, step table and energy ledger.

    Raises
    ------
    walkerlab.config.SceneError
        More samples than :data:`~walkerlab.config.MAX_SIMULATE_SAMPLES` (one line).
    """
    import numpy as np

    from walkerlab.analysis.gait.energy import trajectory_ledger  # light
    from walkerlab.analysis.gait.metrics import step_table  # light
    from walkerlab.config import MAX_SIMULATE_SAMPLES, SceneError  # light

    counts = [max(2, int(np.ceil((seg.t_end - seg.t_start) * rate)) + 1)
              for seg in traj.segments]
    if sum(counts) > MAX_SIMULATE_SAMPLES:
        span = traj.segments[-1].t_end - traj.segments[0].t_start
        raise SceneError(f"simulate: sample_rate_hz={rate:g} Hz over {span:.3g} s gives "
                         f"{sum(counts):,} samples; at most {MAX_SIMULATE_SAMPLES:,} are "
                         "kept (lower sample_rate_hz or strides)")
    ts, xs, legs, events = [], [], [], []
    for seg, n in zip(traj.segments, counts):
        t = np.linspace(seg.t_start, seg.t_end, n)
        ts.append(t)
        xs.append(seg.sample(t).T)
        legs.append(np.full(n, seg.stance_leg))
        events += [(seg.index, seg.stance_leg, *entry) for entry in seg.phase_log]
    hs = np.array([s.t_end for s in traj.segments if s.termination == "heel_strike"])
    return Walk(np.concatenate(ts), np.concatenate(xs), np.concatenate(legs), hs, events,
                traj.termination, step_table(traj), trajectory_ledger(traj))


@dataclass(frozen=True)
class ContactWalk:
    """A walk of the contact walker (:meth:`~walkerlab.api.walker.ContactWalker.simulate`),
    as the ``contact-sim`` stage records it (units named in SI; in a ``units:
    nondimensional`` scene every quantity is in the walker's own units, time in √(l/g), as
    :class:`Walk`'s).

    Attributes
    ----------
    t : ndarray, shape (m,)
        Sample times [s] (at ``contact_sim.sample_rate_hz``; the last one is the event time
        if an event ended the run).
    x : ndarray, shape (m, N)
        States of the floating walker, columns named by ``state_names`` [m, rad, m/s, rad/s].
    state_names : tuple of str
        The contact walker's state names (:meth:`~walkerlab.api.walker.ContactWalker.state_names`).
    heel_strikes : ndarray, shape (k,)
        Heel-strike times [s] (touchdowns of the swing foot ahead of the stance foot).
    heel_strike_legs : tuple of str
        Leg that struck at each heel strike.
    steps : dict[str, ndarray (s,)]
        The step table of ``contact_sim.h5``'s ``steps/``: ``t_start``, ``t_end``, ``period``
        [s], ``stance_leg``, ``stance_slip_mm`` [mm], ``double_support_creep_mm`` [mm],
        ``bounce_count``, ``scuff_count``, ``peak_penetration_m`` [m], ``liftoff_time`` [s],
        ``stance_slip_path_mm`` [mm], ``friction_work_j`` [J].
    normal_force, friction_force : dict[str, ndarray (m,)]
        IMPACT normal force and Coulomb friction (down-slope) [N] at each contact point, by
        its name (:meth:`~walkerlab.api.walker.ContactWalker.contact_names`: ``leg1``,
        ``leg2``; flat feet ``leg1_heel``, ``leg1_toe``, ...).
    penetration : dict[str, ndarray (m,)]
        Signed penetration of each contact point [m] (< 0: above the ground).
    termination : str
        How the integration stopped (:mod:`walkerlab.integrate.ends`: ``heel_strike`` when
        the strides asked for were made, ``t_final``, ``trip``, ``fall``, ...).
    outcome : str
        The run's verdict (``termination``, or ``slip``, ``scuff``, ``no_heel_strike``).
    message : str
        The outcome in one line.
    walks : bool
        The walker walked the run
        (:attr:`~walkerlab.analysis.contact.result.ContactResult.verdict`).
    x0 : ndarray, shape (N,)
        The initial state [m, rad, m/s, rad/s].
    x_ideal : ndarray, shape (2n,)
        The rigid state the run started from (rigid role order) [rad, rad/s].
    initial_rate_scale : ndarray, shape (2,)
        Multipliers on the (swing, stance) rates of ``x_ideal`` [-].
    step_length_m : float
        Spacing of the terrain's patches [m] (the ideal step length, or the periodic gait's).
    gait : walkerlab.analysis.contact.periodic.ContactPeriodicGait or None
        The periodic gait the run started from (``contact_sim.start: periodic_gait``).
    work : dict[str, ndarray (m,)]
        A powered walker's work integrals since the start [J], by name
        (``hip_torque_positive``, ``push_off``, ``contact``, ...); empty when passive.
    step_ledger : dict[str, ndarray]
        A powered walker's energy ledger per step
        (:func:`walkerlab.analysis.contact.ledger.contact_step_ledger`); empty when passive.
    result : walkerlab.analysis.contact.result.ContactResult
        The library's whole result (feet traces, touchdowns, counters).
    """

    t: np.ndarray
    x: np.ndarray
    state_names: tuple
    heel_strikes: np.ndarray
    heel_strike_legs: tuple
    steps: dict
    normal_force: dict
    friction_force: dict
    penetration: dict
    termination: str
    outcome: str
    message: str
    walks: bool
    x0: np.ndarray
    x_ideal: np.ndarray
    initial_rate_scale: np.ndarray
    step_length_m: float
    gait: Any = None
    work: dict = field(default_factory=dict)
    step_ledger: dict = field(default_factory=dict)
    result: Any = None

    @property
    def step_periods(self) -> np.ndarray:
        """Period of each step [s] (``steps["period"]``)."""
        return self.steps["period"]

    def column(self, name: str) -> np.ndarray:
        """One state's samples (m,) by name (``walk.column("hip_x")``).

        Raises
        ------
        KeyError
            No state of that name (the message lists the names).
        """
        if name not in self.state_names:
            raise KeyError(f"no state {name!r}; the contact walker's states are "
                           f"{', '.join(self.state_names)}")
        return self.x[:, self.state_names.index(name)]


#: the step table's columns (the ``steps/`` group of ``contact_sim.h5``)
STEP_FIELDS = ("t_start", "t_end", "period", "stance_slip_mm", "double_support_creep_mm",
                "bounce_count", "scuff_count", "peak_penetration_m", "liftoff_time",
                "stance_slip_path_mm", "friction_work_j")


def recorded_contact_walk(walker, res, x_start, x_ideal, step_length: float, scale,
                          gait) -> ContactWalk:
    """The :class:`ContactWalk` of a contact run
    (:meth:`walkerlab.api.walker.ContactWalker.simulate`; the outputs of
    :func:`walkerlab.analysis.contact.record.contact_walk`): ``walker`` the run's contact
    model, ``res`` its :class:`~walkerlab.analysis.contact.result.ContactResult`, ``x_start``
    (N,) its initial state, ``x_ideal`` (2n,) the rigid state it started from,
    ``step_length`` [m] the patches' spacing, ``scale`` (2,) the rates' multipliers and
    ``gait`` the periodic gait it started from (or None); the step table by
    :data:`STEP_FIELDS`, the contact forces by point and, powered, the work integrals and
    the energy ledger per step."""
    import numpy as np

    from walkerlab.analysis.contact.ledger import contact_step_ledger  # light

    steps = {k: np.array([getattr(s, k) for s in res.steps], dtype=float)
             for k in STEP_FIELDS}
    steps["stance_leg"] = np.array([s.stance_leg for s in res.steps], dtype=str)
    points = res.points or res.feet
    work, ledger = {}, {}
    if res.work is not None:
        names = tuple(walker.actuators.work_names)
        work = {n: res.work[:, k] for k, n in enumerate(names)}
        ledger = contact_step_ledger(walker, res.t, res.x, res.work,
                                     res.heel_strike_times)
    return ContactWalk(
        t=res.t, x=res.x, state_names=tuple(res.state_names),
        heel_strikes=np.asarray(res.heel_strike_times, float),
        heel_strike_legs=tuple(res.heel_strike_legs), steps=steps,
        normal_force={n: p.normal_force for n, p in points.items()},
        friction_force={n: p.friction_force for n, p in points.items()},
        penetration={n: p.penetration for n, p in points.items()},
        termination=res.termination, outcome=res.outcome.kind,
        message=res.outcome.message, walks=bool(res.verdict[0]),
        x0=np.asarray(x_start, float), x_ideal=np.asarray(x_ideal, float),
        initial_rate_scale=np.asarray(scale, float),
        step_length_m=float(step_length), gait=gait, work=work, step_ledger=ledger,
        result=res)
