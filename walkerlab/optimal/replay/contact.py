"""The optimised step replayed in the compliant-contact model: the optimised hip torque (as a
function of the time since each touchdown,
:func:`walkerlab.optimal.transcription.step.torque_of_time`) and push-off drive the scene's
contact walker (its ``contact`` law, or the paper's default one) from the optimised start; the
mean period of its steps is compared with the optimum's (the issue's check: within 3 %). A
walker with phases (:func:`contact_replay_phased`) gets its optimised hip torque between the
thighs (kneed) or the legs (flat feet); a walker whose legs differ
(:func:`contact_replay_stride`) each step's own torque."""

from __future__ import annotations

import numpy as np

from walkerlab import progress
from walkerlab.analysis.contact.verdict import step_trend, walk_verdict
from walkerlab.config import SolverSettings
from walkerlab.models.actuation import TorqueOfTime
from walkerlab.optimal.transcription.free_joint_functions import JOINTS
from walkerlab.optimal.transcription.mode_sequence import phase_torque_of_time
from walkerlab.optimal.transcription.stride import step_of
from walkerlab.safefs import raise_if_interrupted

__all__ = ["SETTLED_STEPS", "contact_replay",
           "contact_replay_controller", "contact_replay_five_link",
           "contact_replay_phased", "contact_replay_stride", "replay_failure"]

#: why a 3D walker's optimised stride is not replayed in the contact model: its two steps'
#: torques switch with the stance leg in a Python law, which keeps the run off the compiled
#: contact model; run so, 2 strides of configs/hip_width_optimal.yaml took over 14 min
STRIDE_3D = ("not replayed: a 3D stride's two torques of time switch with the stance leg in "
             "Python, off the compiled contact model (2 strides ran past 14 min); its rigid "
             "replay is the check")


def contact_replay(scene, res, strides: int = 1, *, plant) -> tuple[float, str]:
    """Run the contact model with the optimised torques.

    Parameters
    ----------
    scene : Scene
        The optimised scene (its ``contact``, ``terrain``, ``contact_solver``: the contact
        default (the compiled run) at rtol 1e-6, atol 1e-8 if none).
    res : walkerlab.optimal.transcription.step.CollocationResult
    strides : int
        Strides to run (2 steps each).
    plant : walkerlab.walker.plant.Plant
        The scene's plant, handed down by the stage (the replay's scene, the optimised
        torques in place of the walker's actuation, is :meth:`~walkerlab.walker.plant.
        Plant.with_` of it).

    Returns
    -------
    step_period_s : float
        Mean period of the run's steps after the first touchdown [s] (NaN if it made
        fewer than two).
    outcome : str
        How the run ended, or why there is no replay (massless legs: the contact view
        needs leg masses).
    """
    from walkerlab.optimal.transcription.step import torque_of_time

    w = scene.walker.model_dump()
    bodies = [b for leg in [w.get("leg")] + list(w.get("legs") or []) if leg
              for b in leg.get("bodies", [])]
    if bodies and all(b.get("mass_kg", 1.0) == 0.0 for b in bodies):
        return float("nan"), "not replayed: massless legs (the contact view needs masses)"
    setup, why = _powered_setup(scene, _hip_actuation(res), strides, plant=plant)
    if setup is None:
        return float("nan"), why
    setup.actuators.laws = TorqueOfTime(torque_of_time(res), _nodes(res))
    solver = scene.contact_solver or SolverSettings.for_contact(rtol=1e-6, atol=1e-8)
    return _run(setup, res.x[0], res.step_period_s, strides, solver)


def contact_replay_five_link(scene, law, x0, step_period_s: float,
                             strides: int = 1, *, plant) -> tuple[float, str]:
    """Run the contact model of a five-link biped under a phase-variable law.

    The scene's walker gets torques on
    :data:`walkerlab.optimal.transcription.free_joint_functions.JOINTS` whose laws
    are replaced by ``law`` (the contact view evaluates each stance leg's joints and phase
    variable as the rigid one, :class:`walkerlab.models.contact.joint_torques.
    JointTorqueActuators`); the scene's ``contact`` law (the paper's default one if none),
    its terrain (continuous level ground if none: the optimised swing foot clears it) and
    ``contact_solver`` (the contact default, the compiled run, at rtol 1e-8, atol 1e-10 if
    none).

    Parameters
    ----------
    scene : Scene
        The optimised scene.
    law : walkerlab.optimal.replay.phase.PhaseLaw
    x0 : ndarray (2n,)
        The rigid start (post-impact, ``state_names()`` order) [rad, rad/s].
    step_period_s : float
        The rigid step period [s] (sets the run's length).
    strides : int
        Strides to run (2 steps each).
    plant : walkerlab.walker.plant.Plant
        The scene's plant, handed down (the replay's scene is its
        :meth:`~walkerlab.walker.plant.Plant.with_`).

    Returns
    -------
    (step_period_s, outcome) : (float, str)
        The mean period [s] of the run's steps after the first touchdown and how the run
        ended, or why there is no replay (one line), as :func:`contact_replay`.
    """
    setup, why = _powered_setup(scene, {"torques": [{"joint": j, "law": {}} for j in JOINTS]},
                                strides, terrain=True, plant=plant)
    if setup is None:
        return float("nan"), why
    setup.actuators.rigid.laws = law
    solver = scene.contact_solver or SolverSettings.for_contact(rtol=1e-8, atol=1e-10)
    return _run(setup, x0, step_period_s, strides, solver)


def contact_replay_phased(scene, res, strides: int = 1, *, plant) -> tuple[float, str]:
    """Run the contact model of a walker with phases (a kneed or flat-footed walker) with its
    optimised hip torque.

    The scene's walker gets a hip torque whose law is replaced by
    :func:`walkerlab.optimal.transcription.mode_sequence.phase_torque_of_time` of the time since
    each touchdown, and the optimum's push-off impulse before each touchdown if it has one
    (:func:`_hip_actuation`) (the torque between the thighs, or the legs of a flat-footed walker:
    :class:`walkerlab.models.contact.actuation.ContactActuators`), from the collocated start
    ``res.x[0]``; the scene's ``contact`` law (a kneed walker needs its ``knee_stop.latch``
    to hold the stance knee as the rigid model's lock does; flat feet their regularising
    ``flat_foot_mass_kg`` and ``flat_foot_inertia_kg_m2``), ``terrain`` and
    ``contact_solver`` (the contact default, the compiled run, if none; a flat foot's
    rotation rates at 100 times its atol:
    :func:`walkerlab.integrate.contact_powered.powered_atol`).

    Parameters
    ----------
    scene : Scene
        The optimised scene.
    res : walkerlab.optimal.transcription.mode_sequence.PhasedResult
    strides : int
        As :func:`contact_replay`.
    plant : walkerlab.walker.plant.Plant
        The scene's plant, handed down (the replay's scene is its
        :meth:`~walkerlab.walker.plant.Plant.with_`).

    Returns
    -------
    (step_period_s, outcome) : (float, str)
        As :func:`contact_replay`; no replay also for a scene without the contact
        section's flat-foot regularisation or a walker the contact view carries no hip
        torque on (one line).
    """
    # a powered run is on a Python RHS (slow on a flat-footed walker's stride): bounded by
    # its work (contact_sim.max_rhs_evaluations' default), the same on any machine
    setup, why = _powered_setup(scene, _hip_actuation(res), strides, plant=plant)
    if setup is None:
        return float("nan"), why
    setup.actuators.laws = TorqueOfTime(phase_torque_of_time(res),
                                        _phases(res) if _nodes(res) else None)
    return _run(setup, res.x[0], res.step_period_s, strides)


def contact_replay_stride(scene, res, strides: int = 2, *, plant) -> tuple[float, str]:
    """Run the contact model of a walker whose legs differ with its optimised stride's hip
    torques: leg A's step's (:func:`walkerlab.optimal.transcription.stride.step_of` 0) while
    ``leg2`` is
    in stance, leg B's while ``leg1`` is, each as a function of the time since that step's
    touchdown (:func:`walkerlab.optimal.transcription.mode_sequence.phase_torque_of_time`), from the
    collocated start ``res.x[0]`` (leg2 in stance, as the rigid model's); the scene's
    ``contact`` law (the paper's default one if none), ``terrain``; LSODA at rtol 1e-6,
    atol 1e-8 (a powered contact run uses scipy's event location).  A 3D walker's stride
    is not replayed (:data:`STRIDE_3D`).

    Parameters
    ----------
    scene : Scene
        The optimised scene.
    res : walkerlab.optimal.transcription.mode_sequence.PhasedResult
        The optimised stride (its ``step_period_s`` the stride's).
    strides : int
        As :func:`contact_replay`.
    plant : walkerlab.walker.plant.Plant
        The scene's plant, handed down (the replay's scene is its
        :meth:`~walkerlab.walker.plant.Plant.with_`).

    Returns
    -------
    (step_period_s, outcome) : (float, str)
        As :func:`contact_replay` (``outcome`` one line).
    """
    if plant.kind.in_3d:
        return float("nan"), STRIDE_3D
    setup, why = _powered_setup(scene, _hip_actuation(res), strides, plant=plant)
    if setup is None:
        return float("nan"), why
    acts = setup.actuators
    laws = [_law_of_time(phase_torque_of_time(step_of(res, k))) for k in (0, 1)]
    own = acts.hip_torque

    def hip_torque(x, stance: int, t_step: float = 0.0):  # stance 1: leg2, leg A's step
        acts.laws = laws[0] if stance == 1 else laws[1]
        return own(x, stance, t_step)
    acts.hip_torque = hip_torque
    # a fixed solver, whatever the scene's contact_solver (configs/asymmetric_optimal.yaml's
    # replay is kept as it was): the outcome of a failure says so
    solver = SolverSettings.for_contact(method="LSODA", rtol=1e-6, atol=1e-8)
    return _run(setup, res.x[0], res.step_period_s / 2, strides, solver, fixed=True)


def _hip_actuation(res) -> dict:
    """The actuation section of a replay of ``res``: a hip torque (its law set after) and the
    optimum's push-off impulse before each touchdown (as in the rigid model) if it has one."""
    act = {"torques": [{"joint": "hip", "law": {}}]}
    push_off = getattr(res, "push_off_n_s", 0.0)   # a result without one: none
    if push_off > 0.0:
        act["push_off"] = {"impulse_n_s": float(push_off)}
    return act


def _nodes(res) -> list | None:
    """The collocation nodes [s] and controls [N m] of a result (one phase), or None when it
    carries none (its torque then stays a Python law)."""
    t, u = getattr(res, "t", None), getattr(res, "u", None)
    return None if t is None or u is None else [(t, u)]


def _phases(res) -> list:
    """Each phase's collocation nodes (times since the heel strike [s]) and controls [N m]
    of a phased result (:func:`walkerlab.optimal.transcription.mode_sequence.
    phase_torque_of_time`'s pieces)."""
    bounds = list(res.phase_start) + [res.t.size]
    return [(res.t[a:b], res.u[a:b]) for a, b in zip(bounds[:-1], bounds[1:])]


def _law_of_time(tau):
    """A hip torque law ``(delta, ddelta, s, ds, t) -> [tau(t)]`` [N m] of the time ``t`` [s]
    since the step's touchdown alone."""
    return lambda delta, ddelta, s, ds, t: np.array([tau(float(t))])


def _powered_setup(scene, actuation: dict, strides: int, terrain: bool = False, *,
                   plant):
    """The contact set-up of ``scene`` with ``actuation`` in place of its walker's and a run
    section of ``strides`` strides sampled at 500 Hz (its ``contact`` law, the paper's
    default one if none;
    ``terrain``: continuous level ground if none), or ``(None, why)`` in one line; the
    replay's walker is :meth:`~walkerlab.walker.plant.Plant.with_` of ``plant`` (the
    scene's, handed down)."""
    from walkerlab.models.contact.scene import ContactSceneError, contact_setup

    d = scene.model_dump(mode="json", exclude_none=True)
    d["walker"]["actuation"] = actuation
    d.setdefault("contact", {})
    if terrain:
        d.setdefault("terrain", {})
    d["contact_sim"] = {"n_strides": strides, "sample_rate_hz": 500}
    try:
        sc = type(scene).model_validate(d)  # the replay's scene: a neighbour of the plant's
        return contact_setup(sc, plant=plant.with_(sc)), ""
    except (ContactSceneError, ValueError) as exc:
        return None, f"not replayed: {exc}"


def _run(setup, x0, step_period_s: float, strides: int, solver=None,
         fixed: bool = False) -> tuple[float, str]:
    """The powered contact run from ``x0``: the mean period of its steps after the first
    touchdown [s] (NaN if fewer than two) and how it ended (``fixed``: ``solver`` is the
    replay's own, not the scene's ``contact_solver``; :func:`replay_failure`)."""
    from walkerlab.analysis.contact.sim import simulate_from

    kw = {} if solver is None else {"solver": solver}
    with progress.task(f"optimize: the contact replay ({strides} strides)"):
        try:
            _, run, _, _ = simulate_from(setup, np.asarray(x0, float), step_period_s,
                                         strides=strides, **kw)
        except (ValueError, ArithmeticError, RuntimeError) as exc:
            # a failure that followed an interrupt a library swallowed (raised inside a
            # ctypes callback while numba compiled the contact model) is the interrupt
            raise_if_interrupted()
            # the replay is a report on the optimum, not its gate: its solver's failure
            # (scipy's event location on a PD law's stiff contact: "f(a) and f(b) must
            # have different signs") is its outcome, the rigid optimum and replays stand
            return float("nan"), replay_failure(exc, solver, fixed)
    raise_if_interrupted()
    hs = np.asarray(run.heel_strike_times, float)
    period = float(np.mean(np.diff(hs))) if hs.size >= 2 else float("nan")
    return period, str(run.termination)


def replay_failure(exc: BaseException, solver=None, fixed: bool = False) -> str:
    """The contact replay's outcome when its integration raised ``exc`` (one line): what
    failed, in the run's terms, and what to try.

    Parameters
    ----------
    exc : BaseException
        What the contact run raised (a solver's own message: scipy's event location
        ``f(a) and f(b) must have different signs`` when a contact or heel-strike event
        function changes sign between two evaluations of the dense output but not at
        the step's ends).
    solver : walkerlab.config.SolverSettings, optional
        The run's contact solver (named in the advice).
    fixed : bool
        The replay runs ``solver`` whatever the scene's ``contact_solver`` (a stride's
        replay): the advice is then ``walkerlab contact-sim``, which runs the scene's, not
        a change of ``contact_solver``.

    Returns
    -------
    str
        ``"not replayed: the contact model's solver failed ..."``.
    """
    which = "" if solver is None else f" ({solver.method}, rtol {solver.rtol:g})"
    what = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
    advice = ("this replay's solver is fixed (the scene's contact_solver is not used "
              "here): walkerlab contact-sim runs the walker with the scene's" if fixed else
              "set another contact_solver (method, rtol) in the scene: the replay runs it")
    return (f"not replayed: the contact model's solver{which} failed while locating a "
            f"contact event ({type(exc).__name__}: {what}); the rigid optimum and its "
            f"replays stand; {advice}")


#: Steps at the end of a controller's contact replay whose mean period and speed are
#: compared with the rigid gait's (the earlier ones: the start's transient)
SETTLED_STEPS = 4


def contact_replay_controller(scene, x_star, period_s: float, step_length_m: float,
                              strides: int | None = None, *, plant) -> dict:
    """Run the contact model of a designed controller's scene (its walker under virtual
    constraints, with its ``contact``, ``terrain``, ``contact_sim`` and ``contact_solver``)
    from the rigid closed loop's fixed point and compare its steps with the rigid gait's.

    Parameters
    ----------
    scene : Scene
        The controller's scene with a ``contact`` section
        (:func:`walkerlab.optimal.virtual_constraints.contact_scene`).
    x_star : ndarray (2n,)
        The rigid closed loop's fixed point (post-impact, ``state_names()`` order).
    period_s, step_length_m : float
        The rigid gait's step period [s] and length [m].
    strides : int, optional
        Strides to run (default the scene's ``contact_sim.n_strides``).
    plant : walkerlab.walker.plant.Plant
        The optimised scene's plant, handed down (the controller's scene is
        :meth:`~walkerlab.walker.plant.Plant.with_` of it).

    Returns
    -------
    dict
        ``periods`` (ndarray, each step's [s]), ``step_period_s`` and ``speed_m_per_s``
        (the mean over the last :data:`SETTLED_STEPS` steps: the period, the hip's
        advance over their time), ``heel_strikes``, ``trend`` (""
        when the steps settle, else :func:`walkerlab.analysis.contact.verdict.step_trend`'s
        phrase), ``walks`` (bool) and ``outcome`` (one line: the run's end and the
        comparison, or why there is no replay).
    """
    from walkerlab.analysis.contact.sim import simulate_from
    from walkerlab.models.contact.scene import ContactSceneError, contact_setup

    nan = float("nan")
    out = {"periods": np.zeros(0), "step_period_s": nan, "speed_m_per_s": nan,
           "heel_strikes": 0, "trend": "", "walks": False}
    try:
        setup = contact_setup(scene, plant=plant.with_(scene))
        walker, run, _, _ = simulate_from(setup, np.asarray(x_star, float), period_s,
                                          strides=strides)
    except (ContactSceneError, ValueError, ArithmeticError, RuntimeError) as exc:
        raise_if_interrupted()
        out["outcome"] = f"not replayed: {str(exc).strip().splitlines()[0]}"
        return out
    raise_if_interrupted()
    T = np.array([s.period for s in run.steps], float)
    T = T[np.isfinite(T)]
    hs = np.asarray(run.heel_strike_times, float)
    out["periods"], out["heel_strikes"] = T, int(hs.size)
    walks, why = walk_verdict(run.outcome, run.steps)
    out["trend"], out["walks"] = step_trend(T), bool(walks)
    if T.size >= SETTLED_STEPS and hs.size > SETTLED_STEPS:
        out["step_period_s"] = float(np.mean(T[-SETTLED_STEPS:]))
        names = list(run.state_names)
        hip = np.interp(hs[[-SETTLED_STEPS - 1, -1]], run.t, run.x[:, names.index("hip_x")])
        cos = np.cos(float(scene.slope.phi_rad))  # along the slope
        out["speed_m_per_s"] = float((hip[1] - hip[0]) / cos / (hs[-1] - hs[-SETTLED_STEPS - 1]))
    v_rigid = step_length_m / period_s
    dT = 100 * (out["step_period_s"] / period_s - 1)
    dv = 100 * (out["speed_m_per_s"] / v_rigid - 1)
    state = ("steady" if walks and not out["trend"] else
             out["trend"] or why or "does not walk")
    out["outcome"] = (f"the controller's scene from the rigid fixed point: "
                      f"{run.outcome.kind}, {hs.size} heel strikes, step period "
                      f"{out['step_period_s']:.6g} s ({dT:+.2f} % against the rigid "
                      f"{period_s:.6g} s), speed {out['speed_m_per_s']:.6g} m/s ({dv:+.2f} % "
                      f"against {v_rigid:.6g}) over the last {SETTLED_STEPS} steps; {state}")
    return out
