"""Feedback controllers designed by optimisation (``optimize.design: virtual_constraints``):
the walker's Bezier virtual constraints (``walker.actuation.virtual_constraints``: its
outputs, phase variable, degree and gains) optimised with the step by collocation
(:mod:`walkerlab.optimal.transcription.virtual_constraints`, FROST's formulation with
``delta^2 <= optimize.max_multiplier``), one controller per target speed, each checked on
the rigid closed loop it defines: its hybrid zero dynamics (the restricted Poincare map,
:func:`walkerlab.analysis.gait.zero_dynamics.zero_dynamics`) and its full-order fixed point
and Floquet multipliers, which contain ``delta^2`` (Westervelt, Grizzle & Koditschek 2003,
IEEE TAC 48(1):42-56, Theorem 4).

The start is the scene's own controller: one step of its closed loop from its zero
dynamics' fixed point (its coefficients the guess's); each further speed starts from the
previous optimum.  The optimum's coefficients are written as scenes
(:func:`controller_scene_text`): the scene with its ``virtual_constraints`` replaced (its
``optimize`` section dropped), which ``walkerlab fixedpoint``, ``simulate`` and
``contact-sim`` run as they are.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from walkerlab import progress
from walkerlab.analysis.gait.budget import search_budget
from walkerlab.analysis.gait.zero_dynamics import zero_dynamics
from walkerlab.config.contact import ContactSettings
from walkerlab.config.contact_sim import ContactSimSettings
from walkerlab.integrate.rigid import integrate_step
from walkerlab.integrate.solver import Solver
from walkerlab.io.schemas.optimize import ControllerData, OptimizeData
from walkerlab.optimal import outcome as reported
from walkerlab.optimal.replay.contact import contact_replay_controller
from walkerlab.optimal.transcription.virtual_constraints import (
    collocate_virtual_constraints,
    hzd_functions,
    mid_stance_window,
)

__all__ = ["CONTACT_CONE_FRACTION", "CONTROLLER_CONTACT", "DESIGN_ITERATIONS",
           "REPLAY_STRIDES", "ControllerDesign", "check_design", "clearance_report",
           "contact_scene", "controller_scene", "controller_scene_text", "controller_step",
           "design_controllers", "design_failures", "design_spec", "designs_controller",
           "optimize_virtual_constraints", "replay_in_contact"]

KEY = "walker.actuation.virtual_constraints"


@dataclass
class ControllerDesign(ControllerData):
    """One optimised controller (``optimize.h5``'s ``controllers/<i>/``).

    Attributes
    ----------
    target_speed_m_per_s : float
        The speed asked for (NaN: none) [m/s].
    bezier_rad : ndarray (k, M + 1)
        The optimised coefficients in force [rad]: with ``invariant: true``, ``c_0``, ``c_1``
        are the impact map's of the others (as the written scene recomputes them; the
        collocation's own differ by its transcription error), so that the written scene
        is the controller checked here; IPOPT's last iterate when they make no controller.
    output_names : tuple of str
    step_period_s, step_length_m : float
        The collocated step's (the targets hold there: ``step_length_m / step_period_s`` is
        the target speed).
    full_order_step_length_m : float
        The rigid closed loop's fixed point's step length [m] (NaN: none); with
        ``full_order_step_period_s``, the speed the written controller walks.
    objective, effort : float
        ``int |u|^2 dt / step length`` [N^2 m s] and ``int |u|^2 dt`` [N^2 m^2 s].
    delta2 : float
        ``delta^2`` at the optimum (the collocation's CasADi expression) [-].
    delta2_restricted : float
        ``delta^2`` of the written controller's restricted map [-].
    existence_margin : float
        ``delta^2 / (1 - delta^2) V(theta-) + V_max`` (< 0: the orbit exists).
    restricted_step_period_s : float
        The zero dynamics' step period by quadrature [s].
    full_order_step_period_s : float
        The rigid closed loop's fixed point's period [s] (NaN: none found).
    orbit_shift : float
        ``max |x* - x+|``: the full-order fixed point's distance from the zero dynamics'
        post-impact state [rad, rad/s] (inf: none found).
    multipliers : ndarray complex
        Its Floquet multipliers (variational).
    delta2_multiplier : complex
        The multiplier nearest ``delta^2``.
    max_torque_n_m : float
        Largest ``|u|`` of the collocated step [N m].
    max_output, max_output_rate : float
        ``max |y|``, ``max |y'|`` over the collocation points [rad, rad/s] (the
        transcription's error off the first point).
    status : str
    iterations : int
    wall_time_s, build_time_s : float
    scene_file : str
        The written scene's file name (in the run folder).
    t, x, u : ndarray
        The collocated step (times [s], states, torques [N m]).
    friction_ratio : float
        The stance foot's largest ``|F_t / F_n|`` over the collocated step [-].
    min_clearance_m, mid_stance_window_m, mid_stance_low_m : float
        The swing foot's lowest height [m] outside the straight legs' mid-stance window,
        the window's half-width [m] (NaN: none) and the lowest height inside it [m].
    contact_step_period_s, contact_speed_m_per_s, contact_heel_strikes, contact_steady
        The contact replay (:func:`walkerlab.optimal.replay.contact.
        contact_replay_controller`): its settled step period [s] and speed [m/s], heel
        strikes, 1 when it walks and settles (NaN: not replayed).
    x_star : ndarray (2n,)
        The rigid closed loop's fixed point (None: none found).
    contact_outcome : str
        The contact replay's one line.
    violations : str
        When IPOPT did not converge: the constraint groups it left violated.
    note : str
        Why the closed loop has no fixed point, or why the coefficients make no
        controller (``""``: it has one).
    """

    t: np.ndarray = field(repr=False, default=None)
    x: np.ndarray = field(repr=False, default=None)
    u: np.ndarray = field(repr=False, default=None)
    history: dict = field(repr=False, default_factory=dict)
    x_star: np.ndarray = field(repr=False, default=None)
    contact_outcome: str = ""
    violations: str = ""


#: The contact law of a designed controller's scene whose design scene has none: the
#: paper's (the contact defaults) with friction 10 times closer to Coulomb's, as the
#: shipped powered scenes (configs/powered_compass.yaml, configs/rabbit_hzd.yaml).  At the
#: defaults' 100 and 1000 mm/s the stance foot creeps (the three-link design at 0.6 m/s,
#: delta^2 = 0.7: 1.4 mm and 0.42 J of friction work a step), a loss the zero dynamics'
#: fixed point feels 1 / (1 - delta^2) times over: its contact steps lengthened from
#: 0.908 to 1.10 s (+23 % against the rigid 0.898 s); at 10 and 100 mm/s they settle at
#: +1.3 %.
CONTROLLER_CONTACT = {"stiction_velocity_mm_per_s": 10.0, "friction_velocity_mm_per_s": 100.0}
#: The fraction of the contact model's static friction coefficient that bounds a design's
#: friction ratio |F_t / F_n| when the design has a friction cone
#: (``optimize.friction_coefficient``: the smaller of the two) and its scene no contact law
#: of its own (the written scene gets :data:`CONTROLLER_CONTACT`; a scene that names its
#: law, as configs/rabbit_hzd_optimal.yaml, keeps its cone: its controllers walk within
#: 1.3 % in MuJoCo at their 0.6).  Regularised friction lets
#: the stance foot creep at a rate that grows with the ratio's share of the cone (the
#: contact model's stiction ramp, MuJoCo's soft cone), a loss the zero dynamics' fixed
#: point feels 1 / (1 - delta^2) times over: the three-link design at 0.6 m/s, delta^2 =
#: 0.7 with mu = 0.6 pressed its foot to 0.46 (0.51 of mu_s = 0.9) before the heel strike
#: and walked +8.4 % slow in MuJoCo; within 0.3 (a third) -1.06 % (contact model +1.21 %).
CONTACT_CONE_FRACTION = 1.0 / 3.0
#: Strides of a design's contact replay (the strides cap stops a powered run at heel strike
#: 2N + 2: 14, its 13 steps complete)
REPLAY_STRIDES = 6


def contact_scene(scene):
    """``scene`` with what the contact model needs: its own ``contact`` and ``contact_sim``
    sections, or (none) :data:`CONTROLLER_CONTACT` and the run's defaults; ``terrain`` and
    ``contact_solver`` as they are (their defaults when absent: a checkerboard of the
    footfalls, over whose gaps the straight swing foot passes at mid-stance)."""

    update = {}
    if scene.contact is None:
        update["contact"] = ContactSettings.model_validate(CONTROLLER_CONTACT)
    if scene.contact_sim is None:
        update["contact_sim"] = ContactSimSettings()
    return scene.model_copy(update=update) if update else scene


def designs_controller(scene) -> bool:
    """Whether the scene's ``optimize`` section designs virtual constraints
    (``design: virtual_constraints``)."""
    o = getattr(scene, "optimize", None)
    return o is not None and o.design == "virtual_constraints"


def check_design(scene, kind) -> None:
    """Refuse a design the walker cannot take (one line naming the key): no
    ``walker.actuation.virtual_constraints`` to optimise, or a kind whose virtual
    constraints the collocation does not take (the capability table's line).

    Raises
    ------
    ValueError
        As above.
    """
    act = scene.walker.actuation
    if act is None or act.virtual_constraints is None:
        raise ValueError("optimize.design: virtual_constraints optimises the walker's "
                         "virtual constraints: give walker.actuation.virtual_constraints (its "
                         "outputs, phase and degree; their coefficients are the start)")
    kind.require("virtual_constraints", "optimize", KEY)
    ground = "slope" if scene.terrain is None else scene.terrain.kind
    if ground in ("stairs", "footholds", "profile"):  # the kind's cell of that ground
        kind.require(ground, "optimize", f"terrain.kind: {ground}")


def controller_scene(scene, bezier):
    """``scene`` with its virtual constraints' coefficients ``bezier`` (k, M + 1) [rad],
    no ``optimize`` section and the sections ``contact-sim`` needs (:func:`contact_scene`)."""
    act = scene.walker.actuation
    vc = act.virtual_constraints
    outs = [o.model_copy(update={"bezier_rad": [float(c) for c in row]})
            for o, row in zip(vc.outputs, np.asarray(bezier, float))]
    vc = vc.model_copy(update={"outputs": outs})
    walker = scene.walker.model_copy(update={"actuation": act.model_copy(
        update={"virtual_constraints": vc})})
    return contact_scene(scene.model_copy(update={"walker": walker, "optimize": None}))


def controller_scene_text(scene, c: ControllerData, name: str, failures: str = "") -> str:
    """The YAML text of the scene of controller ``c`` (:func:`controller_scene`), named
    ``name``, with a header saying where it comes from: the collocated step (where the
    design's targets hold) and the closed loop of the coefficients written (the rigid
    model's fixed point), each with its speed; a design IPOPT did not converge on says so
    in its first line and its ``source`` (``failures``: the design's failures,
    :func:`design_failures`, said after it)."""
    import yaml

    body = controller_scene(scene, c.bezier_rad).model_dump(mode="json", exclude_none=True)
    body["name"] = name
    speed = c.step_length_m / c.step_period_s
    loop = c.full_order_step_length_m / c.full_order_step_period_s
    walks = (f"the closed loop walks {loop:.6g} m/s" if np.isfinite(loop)
             else "the closed loop has no fixed point")
    failed = (f"FAILED: IPOPT {c.status}, not a designed controller (its last iterate, "
              "written to be inspected; it need not walk)") \
        if c.status != "Solve_Succeeded" else ""
    body["source"] = ((failed + "; " if failed else "")
                      + f"scene {scene.name}'s walker under virtual constraints optimised by "
                      f"walkerlab optimize (design: virtual_constraints): delta^2 = "
                      f"{c.delta2_restricted:.10g}, collocated {speed:.6g} m/s, {walks}")
    failures = getattr(c, "violations", "") or failures
    head = ((f"# {failed}.\n" + (f"# The design's failures: {failures}.\n"
                                  if failures else "")) if failed else "")
    head += (f"# Written by walkerlab optimize from scene '{scene.name}' (design: "
             "virtual_constraints; do not edit: rewritten by the next run).\n"
             + (f"# Its source: {scene.source}\n" if scene.source else "")
             + ("# Collocated step (IPOPT's last iterate: the targets need not hold): "
                if failed else "# Collocated step (the design's targets hold here): ")
             + f"{c.step_length_m:.6g} m "
             f"in {c.step_period_s:.6g} s ({speed:.6g} m/s), int u^2 dt / length = "
             f"{c.objective:.6g} N^2 m s, max |u| = {c.max_torque_n_m:.4g} N m.\n"
             + (f"# Closed loop of the coefficients below (rigid model, its fixed point): "
                f"{c.full_order_step_length_m:.6g} m in {c.full_order_step_period_s:.6g} s "
                f"({loop:.6g} m/s).\n" if np.isfinite(loop) else
                "# Closed loop of the coefficients below: no fixed point"
                + (f" ({c.note})" if getattr(c, "note", "") else "") + ".\n")
             + ("# Bezier coefficients: IPOPT's last iterate's" if not np.isfinite(
                 c.delta2_restricted) else "# Bezier coefficients in force (c_0, c_1 the "
                 "impact map's: invariant: true recomputes the same)")
             + ".  Restricted Poincare map: delta^2 = "
             f"{c.delta2_restricted:.10g}; full-order multiplier nearest it "
             f"{abs(c.delta2_multiplier):.10g}.\n")
    return head + yaml.safe_dump(body, sort_keys=False, width=100)


def controller_step(walker, solver, points: int):
    """One step of the scene's closed loop (``walker``: its rigid walker with the
    controller; ``solver``: a :class:`~walkerlab.integrate.solver.Solver`) from its zero
    dynamics' fixed point, at ``points`` uniform times: ``(t [s], x (points, 2n), u
    (points, k) [N m], alpha (k, M + 1) [rad], zd)`` (``zd``: :class:`~walkerlab.analysis.
    gait.zero_dynamics.ZeroDynamics`), the design's start.

    Raises
    ------
    ValueError
        The scene's controller has no periodic orbit or its step does not end in a heel
        strike (one line naming the key).
    """

    ctrl = walker.actuators.controller
    zd = zero_dynamics(ctrl)
    if not zd.exists:
        raise ValueError(f"{KEY}: the scene's controller, the design's start, has no gait of "
                         f"its own to start from (no periodic orbit of its zero dynamics: "
                         f"delta^2 = {zd.delta2:.4g}, existence margin "
                         f"{zd.existence_margin:.4g}): give coefficients that walk")
    seg = integrate_step(walker, zd.x_plus, solver, max_step_time=3 * zd.step_period_s)
    if seg.termination != "heel_strike":
        raise ValueError(f"{KEY}: the scene's controller does not step from its zero "
                         f"dynamics' orbit ({seg.termination}): give coefficients that walk")
    t = np.linspace(0.0, seg.t_end - seg.t_start, points)
    x = seg.sample(seg.t_start + t).T
    u = np.array([np.real(ctrl.torques(xi)) for xi in x])
    return t, x, u, ctrl.design.alpha.copy(), zd


#: IPOPT's iterations of each designed controller when ``optimize.max_iterations`` is not
#: given (``max_iter``: a bound on work, the same on any machine; RABBIT's 0.8 m/s
#: controller, configs/rabbit_hzd_optimal.yaml, takes 435)
DESIGN_ITERATIONS = 1000


def _evaluate(scene, res, target, name: str, clearance: dict, plant) -> ControllerDesign:
    """The written controller of the optimum ``res`` on the rigid model: its coefficients
    in force, its restricted map and its full-order fixed point (from the zero dynamics'
    orbit; the gait search's work budget,
    :data:`walkerlab.analysis.gait.budget.ROOT_BUDGET_EVALUATIONS`); ``clearance``: the
    swing foot's (:func:`clearance_report`).  IPOPT's last
    iterate whose coefficients make no controller (a failed design) is recorded as it is,
    with the reason in ``note``.  ``plant``: the scene's (the controller's scene is
    :meth:`~walkerlab.walker.plant.Plant.with_` of it)."""
    from walkerlab.analysis.gait.scene import solve_scene  # light
    from walkerlab.models.registry import build_walker

    sc = controller_scene(scene, res.alpha)
    common = dict(
        target_speed_m_per_s=float("nan") if target is None else float(target),
        step_period_s=res.step_period_s, step_length_m=res.step_length_m,
        objective=res.objective, effort=res.effort, delta2=res.delta2,
        max_torque_n_m=float(np.max(np.abs(res.u))), max_output=res.max_output,
        max_output_rate=res.max_output_rate, status=res.status, iterations=res.iterations,
        wall_time_s=res.wall_time_s, build_time_s=res.build_time_s, scene_file=name,
        t=res.t, x=res.x, u=res.u, history=res.history,
        violations=getattr(res, "violations", ""), **clearance)
    plant = plant.with_(sc)  # the designed controller's walker, described once
    try:
        walker = build_walker(plant)
    except ValueError as exc:  # a failed design's last iterate: no controller to check
        if res.status == "Solve_Succeeded":
            raise
        k = np.asarray(res.alpha).shape[0]
        return ControllerDesign(
            bezier_rad=np.asarray(res.alpha, float), output_names=tuple(
                o.name for o in scene.walker.actuation.virtual_constraints.outputs),
            delta2_restricted=np.nan, existence_margin=np.nan,
            restricted_step_period_s=np.nan, full_order_step_period_s=np.nan,
            orbit_shift=np.inf, multipliers=np.full(2 * (k + 1), np.nan + 0j),
            delta2_multiplier=complex(np.nan), note=f"no controller: {exc}", **common)
    ctrl = walker.actuators.controller
    zd = zero_dynamics(ctrl)
    period, length, mult = np.nan, np.nan, np.full(2 * ctrl.n, np.nan + 0j)
    near, shift, note, x_star = complex(np.nan), np.inf, "", None
    if zd.exists:
        try:
            with search_budget():
                fp = solve_scene(sc, False, guess=zd.x_plus, walker=walker,
                                 solver=Solver.from_settings(sc.solver), plant=plant)[1].gait.result
            period = float(fp.period_s)
            length = float(fp.step_lengths_m[0]) if fp.step_lengths_m else np.nan
            mult = np.asarray(fp.multipliers_variational, complex)
            near = complex(mult[int(np.argmin(np.abs(mult - zd.delta2)))])
            shift = float(np.max(np.abs(np.asarray(fp.x, float) - zd.x_plus)))
            x_star = np.asarray(fp.x, float)
        except (ValueError, RuntimeError, ArithmeticError, AttributeError) as exc:
            note = str(exc)  # no fixed point: NaN (the design is reported, not a gait)
    else:
        note = (f"its zero dynamics has no periodic orbit (delta^2 {zd.delta2:.4g}, existence"
                f" margin {zd.existence_margin:.4g})")
    return ControllerDesign(
        bezier_rad=np.array(ctrl.design.alpha, float), output_names=tuple(ctrl.output_names),
        delta2_restricted=zd.delta2, existence_margin=zd.existence_margin,
        restricted_step_period_s=zd.step_period_s, full_order_step_period_s=period,
        full_order_step_length_m=length, orbit_shift=shift,
        multipliers=mult, delta2_multiplier=near, note=note, x_star=x_star, **common)


def design_spec(scene, spec):
    """The collocation ``spec`` of ``scene`` as :func:`design_controllers` solves it: the
    controller's torque bound where the ``optimize`` section gives none, and the friction
    coefficient within :data:`CONTACT_CONE_FRACTION` of the contact model's static one when
    the scene has no contact section (:func:`contact_scene`)."""
    vc = scene.walker.actuation.virtual_constraints
    if spec.max_torque_n_m is None and vc.max_torque_n_m is not None:
        spec = replace(spec, max_torque_n_m=vc.max_torque_n_m)
    if spec.friction_coefficient is not None and scene.contact is None:
        # the written scene's contact law is the design's (CONTROLLER_CONTACT): within a
        # third of its cone too; a scene with its own law keeps its design's cone as given
        mu = CONTACT_CONE_FRACTION * float(contact_scene(scene).contact.mu_static)
        spec = replace(spec, friction_coefficient=min(float(spec.friction_coefficient), mu))
    return spec


def design_controllers(scene, plant, spec, print_level: int = 0,
                       walker=None) -> list[ControllerDesign]:
    """Optimise one controller per target speed of ``scene`` (module docstring).

    Parameters
    ----------
    scene : Scene
        With ``optimize.design: virtual_constraints`` and ``walker.actuation.
        virtual_constraints``.
    plant : walkerlab.walker.plant.Plant
        The scene's walker described once (by the stage).
    spec : walkerlab.optimal.transcription.step.CollocationSpec
        The ``optimize`` section's (:func:`walkerlab.optimal.driver.collocation_spec`; its
        speed replaced by each of ``target_speeds_m_per_s``; its friction coefficient, when
        given, no more than :data:`CONTACT_CONE_FRACTION` of the contact model's static
        one when the scene has no contact section, :func:`contact_scene`; the swing
        foot's clearance outside the straight legs' mid-stance window,
        :func:`walkerlab.optimal.transcription.virtual_constraints.mid_stance_window`).
    print_level : int
        IPOPT's.
    walker : HybridWalker, optional
        The scene's walker (:func:`walkerlab.models.registry.build_walker` of ``scene``)
        when the caller holds it; default: built here.

    Returns
    -------
    list of ControllerDesign
        One per speed, converged or not (IPOPT's status; each controller's IPOPT solve
        stops after ``optimize.max_iterations``, default :data:`DESIGN_ITERATIONS`,
        iterations, or at ``optimize.cpu_budget_s`` of CPU time where a user asked for one;
        its closed loop's gait search has the gait search's work budget).

    Raises
    ------
    ValueError
        The scene's controller does not walk (no start), a spec the walker does not have
        (one line naming the key).
    """
    import time

    from walkerlab.models.registry import build_walker

    o = scene.optimize
    vc = scene.walker.actuation.virtual_constraints
    spec = design_spec(scene, spec)
    data = plant.data
    walker = build_walker(plant.with_(scene)) if walker is None else walker
    K = 2 * int(o.intervals) + 1
    t, x, u, alpha, _zd = controller_step(walker, Solver.from_settings(scene.solver), K)
    t0 = time.perf_counter()
    fns = hzd_functions(data, vc)
    build = time.perf_counter() - t0
    speeds = list(o.target_speeds_m_per_s or [o.target_speed_m_per_s])
    window = None
    if not fns.clearance_guard and spec.min_clearance_m is not None:
        window = mid_stance_window(spec.min_clearance_m, _leg_length_m(scene))
    budget = None if o.cpu_budget_s is None else float(o.cpu_budget_s)
    iterations = int(o.max_iterations or DESIGN_ITERATIONS)
    out = []
    with progress.task(f"optimize: {len(speeds)} controller(s)", len(speeds)) as bar:
        for i, v in enumerate(speeds):
            res = collocate_virtual_constraints(
                fns, replace(spec, target_speed_m_per_s=v), t, x, u, alpha, o.max_multiplier,
                (vc.feedback.kp_per_s2, vc.feedback.kd_per_s), print_level,
                mid_stance_window_m=window, cpu_budget_s=budget, max_iterations=iterations)
            res.build_time_s += build
            out.append(_evaluate(scene, res, v, f"{scene.name}_controller_{i + 1}.yaml",
                                 {**clearance_report(fns, res.x, window),
                                  "friction_ratio": _friction_ratio(fns, res.x, res.u)},
                                 plant))
            speed = "no target speed" if v is None else f"{v:g} m/s"
            bar.advance(info=f"controller {i + 1} ({speed}): {res.status}")
            if res.status == "Solve_Succeeded":  # the next speed starts here
                t, x, u, alpha = res.t, res.x, res.u, res.alpha
    return out


def _leg_length_m(scene) -> float:
    """The walker's longest leg [m] (hip to foot)."""
    w = scene.walker.model_dump()
    legs = [leg for leg in [w.get("leg")] + list(w.get("legs") or []) if leg]
    return max(float(leg["length_m"]) for leg in legs)


def clearance_report(fns, x, window_m: float | None) -> dict:
    """The swing foot's lowest height [m] over the collocated states ``x`` (2N + 1, 2n)
    inside the step (its ends on the ground excluded): outside the mid-stance window of
    half-width ``window_m`` [m] and inside it (``window_m`` None: every point outside,
    NaN inside), as :class:`ControllerDesign` keywords."""
    feet = np.array([np.asarray(fns.feet(xi), float).ravel() for xi in np.asarray(x)[1:-1]])
    height, ahead = feet[:, 3], feet[:, 2]
    inside = np.abs(ahead) < window_m if window_m is not None else np.zeros(len(height), bool)

    def low(mask):
        return float(np.min(height[mask])) if np.any(mask) else float("nan")
    return {"min_clearance_m": low(~inside),
            "mid_stance_window_m": float("nan") if window_m is None else float(window_m),
            "mid_stance_low_m": low(inside)}


def _friction_ratio(fns, x, u) -> float:
    """The largest ``|F_t / F_n|`` of the stance foot over the collocated step."""
    f = np.array([np.asarray(fns.grf(xi, ui), float).ravel() for xi, ui in zip(x, u)])
    return float(np.max(np.abs(f[:, 1]) / np.maximum(f[:, 0], 1e-12)))


def replay_in_contact(scene, c: ControllerDesign, plant) -> ControllerDesign:
    """``c`` with its contact replay (:func:`walkerlab.optimal.replay.contact.
    contact_replay_controller` of :func:`controller_scene`, :data:`REPLAY_STRIDES`
    strides from the rigid fixed point); not replayed without one.  ``plant``: the
    scene's, from the stage."""

    if c.x_star is None or not np.isfinite(c.full_order_step_period_s):
        return replace(c, contact_outcome="not replayed: the rigid closed loop has no "
                       "fixed point")
    r = contact_replay_controller(controller_scene(scene, c.bezier_rad), c.x_star,
                                  c.full_order_step_period_s, c.step_length_m,
                                  strides=REPLAY_STRIDES, plant=plant)
    steady = float("nan") if r["outcome"].startswith("not replayed") else \
        float(r["walks"] and not r["trend"])
    return replace(c, contact_step_period_s=r["step_period_s"],
                   contact_speed_m_per_s=r["speed_m_per_s"],
                   contact_heel_strikes=float(r["heel_strikes"]), contact_steady=steady,
                   contact_outcome=r["outcome"])


def optimize_virtual_constraints(scene, plant, spec):
    """``optimize.h5``'s record of the designed controllers
    (:class:`walkerlab.io.schemas.optimize.OptimizeData`: the first controller's step as
    its optimum, every controller in ``controllers``; a gait when IPOPT converged, the
    restricted map's ``delta^2`` is the optimum's and the full-order fixed point exists).

    Parameters
    ----------
    scene : Scene
    plant : walkerlab.walker.plant.Plant
        The scene's walker described once (by the stage).
    spec : walkerlab.optimal.transcription.step.CollocationSpec

    Raises
    ------
    ValueError
        As :func:`design_controllers`.
    """
    from walkerlab.models.registry import build_walker

    walker = build_walker(plant.with_(scene))  # one build for the design and the record
    cs = [replay_in_contact(scene, c, plant) for c in design_controllers(scene, plant, spec,
                                                                          walker=walker)]
    c = cs[0]
    res = _AsResult(c)
    states, units = reported.named_states(walker, res)
    tol = scene.optimize.replay_tolerance
    gait = bool(c.status == "Solve_Succeeded" and np.isfinite(c.full_order_step_period_s)
                and abs(c.delta2_restricted - c.delta2) <= tol)
    return OptimizeData(
        c.t, states, c.u, c.step_period_s, c.step_length_m, 0.0, c.objective,
        c.orbit_shift, c.multipliers, gait,
        c.status, c.iterations, c.wall_time_s, units,
        objective_name="effort_per_step_length", objective_unit="N^2 m s",
        terms={"effort": c.effort}, torque_names=tuple(walker.actuators.controller.joints),
        build_time_s=c.build_time_s, ipopt_history=c.history,
        phase_replay_outcome="not replayed: the design is a feedback controller (its scene "
        "runs in fixedpoint, simulate and contact-sim)",
        contact_outcome="; ".join(f"controller {i + 1}: {d.contact_outcome}"
                                  for i, d in enumerate(cs)) if len(cs) > 1
        else c.contact_outcome,
        controllers=tuple(cs), violations=design_failures(cs))


def design_failures(cs) -> str:
    """What went wrong with the controllers ``cs`` that IPOPT did not converge on, one
    clause (``""``: none): each one's IPOPT status, the constraint groups it left violated
    and why its coefficients make no controller, if they do not."""
    out = []
    for i, c in enumerate(cs):
        if c.status == "Solve_Succeeded":
            continue
        text = f"controller {i + 1} ({c.target_speed_m_per_s:g} m/s): IPOPT {c.status}"
        if getattr(c, "violations", ""):
            text += f", largest violations {c.violations}"
        if getattr(c, "note", "").startswith("no controller"):
            text += f" ({c.note})"
        out.append(text)
    return "; ".join(out)


class _AsResult:
    """The attributes :func:`walkerlab.optimal.outcome.named_states` reads of a
    collocation's result (``x``)."""

    def __init__(self, c: ControllerDesign):
        self.x, self.t, self.u = c.x, c.t, c.u
