"""Powered walkers in the compliant-contact view (``walker.actuation`` as forces):
the push-off pulse, ending at the touchdown, converges to the impulse (first order in its
duration) and does the rigid push-off's work within 5 %, the impulse's work equals the rigid
model's push-off (different code: floating kernels against the generated impact matrices),
the energy ledger of a run closes with the contact term named, and the powered rigid gait's
step period and cost of transport are met by the contact model within 3 % and 5 % over more
than 10 heel strikes (configs/powered_compass.yaml)."""

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from walkerlab.api.scenes import with_changes
from walkerlab.config import load_scene
from walkerlab.integrate.contact import integrate_contact
from walkerlab.integrate.solver import Solver
from walkerlab.models.contact.actuation import WORK_NAMES
from walkerlab.models.contact.scene import ContactSceneError, contact_setup
from walkerlab.walker.plant import Plant

SCENE = Path(__file__).resolve().parents[2] / "configs" / "powered_compass.yaml"


@pytest.fixture(scope="module")
def rigid():
    import walkerlab as wl

    w = wl.Walker.from_scene(load_scene(SCENE))
    return w, w.fixed_point()


def _run(scene, x_ideal, t_final, strides=1):
    from walkerlab.analysis.contact.sim import scene_start

    setup = contact_setup(scene, plant=Plant.from_scene(scene))
    walker, x0, limits, _ = scene_start(setup, x_ideal, strides)
    limits = replace(limits, fall_hip_height_m=0.5 * walker.L)
    run = integrate_contact(walker, x0, 0.0, t_final, Solver.from_settings(setup.solver),
                            limits)
    return walker, run


def _rigid_push_off_work(w, gait) -> float:
    """The rigid push-off's work on the gait (its kinetic energy jump, ``transition``)."""
    walk = w.simulate(gait.x, strides=1, sample_rate_hz=200.0)
    first = walk.stance_leg == walk.stance_leg[0]
    tr = w.model.actuators.transition(walk.x[np.flatnonzero(first)[-1]])
    return float(tr["ke_push_off"] - tr["ke_minus"])


# the quick suite's CPU budget (README): a longer run, in `pytest -m slow`
@pytest.mark.slow
def test_pulse_converges_to_the_impulse(rigid):
    """The push-off pulse ends at the predicted touchdown (the rigid push-off comes
    immediately before the heel strike).  From the rigid gait, through the first heel strike
    (touchdown at ~0.70 s) to 60 ms after it, pulses of 1, 0.5, 0.25 and 0.125 ms against
    the impulse at once at the touchdown: the state's error and the pulse's work deficit
    both shrink with an observed order near 1 (measured 1.00: while it lasts the pulse takes
    over the stance foot's weight support), the work from below (0.2148, 0.2214, 0.2247,
    0.2264 J against 0.2280 J).  The scene's pulse does the rigid push-off's work within 5 %
    (rigid 0.2346 J; the impulse on the contact walker's own touchdown state: -2.8 %).  A
    pulse that started at the touchdown did 0.86 J at 5 ms and 0.38 J at 0.5 ms: it worked
    inside the compliant collision, against the ground."""
    w, gait = rigid
    base = load_scene(SCENE)
    out, work = {}, {}
    Ts = (0.0, 0.001, 0.0005, 0.00025, 0.000125)
    for T in Ts:
        sc = with_changes(base, {"contact.push_off_duration_s": T,
                                 "contact_solver.rtol": 1e-10, "contact_solver.atol": 1e-12})
        walker, run = _run(sc, gait.x, 0.76)
        assert run.termination == "t_final", run.message
        out[T], work[T] = run.X[-1], run.work[-1, WORK_NAMES.index("push_off")]
    err = np.array([np.max(np.abs(out[T] - out[0.0])) for T in Ts[1:]])
    short = np.array([work[0.0] - work[T] for T in Ts[1:]])
    assert np.all(np.diff(err) < 0) and err[0] < 2e-2, err
    assert np.all(short > 0) and np.all(np.diff(short) < 0), short
    for e in (err, short):
        orders = np.log2(e[:-1] / e[1:])
        assert np.all((orders > 0.8) & (orders < 1.2)), (e, orders)
    rigid_work = _rigid_push_off_work(w, gait)
    assert abs(work[0.0] / rigid_work - 1.0) < 0.05, (work[0.0], rigid_work)
    scene_T = base.contact.push_off_pulse_s()
    assert scene_T <= Ts[-1]  # the scene's pulse: shorter than the shortest above
    assert abs(work[Ts[-1]] / rigid_work - 1.0) < 0.05, (work, rigid_work)


def test_impulse_work_equals_the_rigid_push_off(rigid):
    """The contact model's push-off impulse (M dq+ = M dq- + J^T P e at the trailing foot,
    floating coordinates) adds the same kinetic energy as the rigid reset's push-off phase
    (extended coordinates of the generated impact matrices) on the rigid gait's pre-impact
    state."""
    from walkerlab.integrate.contact_powered import impulse_jump

    w, gait = rigid
    walk = w.simulate(gait.x, strides=1, sample_rate_hz=200.0)
    first = walk.stance_leg == walk.stance_leg[0]
    x_pre = walk.x[np.flatnonzero(first)[-1]]  # the first step's last sample: heel strike
    tr = w.model.actuators.transition(x_pre)
    assert np.allclose(tr["x_plus"], walk.x[np.flatnonzero(~first)[0]], atol=1e-9)
    sc = load_scene(SCENE)
    setup = contact_setup(sc, plant=Plant.from_scene(sc))
    walker, _ = setup.build(gait.x, 2)
    x = walker.pinned_to_full(walker.link_state_from_ideal(x_pre), np.zeros(2))
    _, work = impulse_jump(walker, x, 1, tr["impulse"])
    assert work == pytest.approx(tr["ke_push_off"] - tr["ke_minus"], rel=1e-10)


@pytest.fixture(scope="module")
def stage_run(rigid):
    """The shipped scene's contact-sim run (the stage's, without its artifact): 13 heel
    strikes from the contact model's own periodic gait (``contact_sim.start``)."""
    from types import SimpleNamespace

    from walkerlab.analysis.contact.record import contact_sim_run

    w, gait = rigid
    fp = SimpleNamespace(x=gait.x, step_period_s=gait.step_period,
                         state_names=list(w.state_names()))
    sc = load_scene(SCENE)
    return contact_sim_run(contact_setup(sc, plant=Plant.from_scene(sc)), fp)


@pytest.fixture(scope="module")
def walk(stage_run):
    return stage_run.walker, stage_run.result


@pytest.mark.slow  # in `pytest -m slow`: the quick suite keeps to its CPU budget
def test_contact_step_period_within_3_percent_of_the_rigid_gait(rigid, walk):
    _, gait = rigid
    _, res = walk
    hs = np.asarray(res.heel_strike_times)
    assert len(hs) >= 11, res.message
    T = np.mean(np.diff(hs))
    assert abs(T / gait.step_period - 1.0) < 0.03, (T, gait.step_period)


@pytest.mark.slow  # in `pytest -m slow`: the quick suite keeps to its CPU budget
def test_contact_push_off_work_and_cost_of_transport_match_the_rigid_view(rigid, stage_run):
    """Per step (mid-step to mid-step) the contact push-off does the rigid push-off's work
    within 5 % (measured 0.2324 J against 0.2346 J, -0.9 %: the pulse ends at the touchdown;
    one that started at it did 0.82 J, 3.5x) and the contact forces take it out (the gait is
    periodic); the cost of transport agrees within 5 % (0.003480 against 0.003464; the
    contact walker's steps are 1.3 % shorter, 0.3407 m).  The artifact stores the per-step
    ledger (``ledger/steps``) and the samples' times as ``ledger/time`` (were zeros)."""
    import h5py

    from walkerlab.analysis.gait.energy import trajectory_ledger
    from walkerlab.integrate.rigid import simulate_steps
    from walkerlab.io.schemas.contact_sim import write_contact_sim

    w, gait = rigid
    rig = trajectory_ledger(simulate_steps(w.model, gait.x, 2, w.solver))
    led = stage_run.step_ledger
    assert len(led["push_off_work"]) >= 9
    po, cot = np.mean(led["push_off_work"]), np.mean(led["cost_of_transport"])
    assert abs(po / np.mean(rig["push_off_work"]) - 1.0) < 0.05, (po, rig["push_off_work"])
    assert abs(cot / np.mean(rig["cost_of_transport"]) - 1.0) < 0.05
    assert np.allclose(led["contact_work"], -led["push_off_work"], rtol=1e-3)
    assert np.allclose(led["distance"], stage_run.gait.step_length_m, rtol=1e-3)
    with h5py.File("ledger.h5", "w", driver="core", backing_store=False) as f:
        write_contact_sim(f, stage_run)
        assert np.array_equal(f["ledger/time"][()], stage_run.result.t)
        assert np.array_equal(f["ledger/steps/cost_of_transport"][()],
                              led["cost_of_transport"])


def test_contact_ledger_closes_with_the_contact_term_named(walk):
    """E(t) - E(0) = hip-torque + push-off + contact work at every sample, to 1e-4 of the
    kinetic energy; the push-off does positive work, the contact forces take it out."""
    walker, res = walk
    assert res.work is not None and res.work.shape == (len(res.t), len(WORK_NAMES))
    E = walker.energies(res.x)["total"]
    resid = (E - E[0]) - res.work.sum(axis=1)
    ke = float(walker.energies(res.x[:1])["kinetic"][0])
    assert np.max(np.abs(resid)) < 1e-4 * ke
    w = dict(zip(WORK_NAMES, res.work[-1]))
    assert w["push_off"] > 1.0 and w["contact"] < -1.0
    assert w["hip_torque_positive"] == w["hip_torque_negative"] == 0.0


def test_refusals_are_one_line(tmp_path):
    base = load_scene(SCENE)
    with pytest.raises(ContactSceneError, match="pin_stance_until"):
        sc = with_changes(base, {"contact_sim.pin_stance_until": "first_touchdown"})
        contact_setup(sc, plant=Plant.from_scene(sc))
    with pytest.raises(ContactSceneError, match="contact_sim.start"):
        sc = with_changes(base, {"contact_sim.start": "adjusted"})
        contact_setup(sc, plant=Plant.from_scene(sc))
    # the contact periodic gait needs state-based laws: time since the heel strike is not
    # a state of the mid-stance section
    law = {"stiffness_n_m_per_rad": 30.0, "damping_n_m_s_per_rad": 1.0,
           "time_reference": {"time_s": [0.0, 0.3, 0.6], "hip_angle_rad": [-0.3, 0.0, 0.3]}}
    timed = with_changes(base, {"walker.actuation.torques": [{"joint": "hip", "law": law}],
                                "contact_sim.start": "periodic_gait"})
    with pytest.raises(ContactSceneError, match="time since the heel strike"):
        contact_setup(timed, plant=Plant.from_scene(timed))


@pytest.mark.slow  # ~10 s CPU: 40 step maps, each with a pulse on solve_ivp
def test_the_powered_contact_periodic_gait_returns_to_itself_near_the_rigid_one(rigid):
    """The contact periodic gait of the push-off-powered compass walker (level ground, the
    scene's 0.1 ms pulse ending at the touchdown): the step map (mid-stance, passive flow on
    the compiled integrator, the pulse on the powered one) returns the fixed point to itself
    (scaled residual; the map's noise at rtol 1e-12 is ~1e-10) with its period, and the
    period is within 3 % of the rigid gait's (measured 0.692987 s against 0.691585 s,
    +0.20 %; +1.8 % with the paper's friction velocities, whose stance-foot creep took 31 %
    of the push-off's work).  Stable: the slow multipliers 0.667 +- 0.278j, 0.202 (rigid
    view of the same walker: 0.683 +- 0.284j, 0.193)."""
    from walkerlab.analysis.contact.periodic import MAP_SOLVER, find_contact_periodic_gait
    from walkerlab.analysis.contact.sim import scene_start
    from walkerlab.analysis.contact.step_map import StepMap

    _, gait = rigid
    sc = load_scene(SCENE)
    setup = contact_setup(sc, plant=Plant.from_scene(sc))
    probe = scene_start(setup, gait.x, 2)[0]
    g = find_contact_periodic_gait(probe, gait.x, check_fd=False, warmup_steps=4)
    assert g.converged and g.residual < 1e-8
    P = StepMap(probe, solver=MAP_SOLVER)  # a fresh map: one step from the fixed point
    z1, T, _ = P(g.z)
    assert np.max(np.abs((z1 - g.z) / P.scale)) < 1e-8
    assert T == pytest.approx(g.period_s, abs=1e-9)
    assert g.period_s == pytest.approx(gait.step_period, rel=0.03)
    assert g.stable and 0.5 < g.max_multiplier < 0.9
    assert g.patch_margin_m > 0.05


def test_a_powered_run_is_the_passive_loop_with_an_actuation_hook(rigid, monkeypatch):
    """One contact integrator loop: a powered walker's run goes through the passive run's
    loop (:func:`walkerlab.integrate.contact._run_free`) with its actuation hook.  The
    walker with a zero hip-torque law and no push-off walks as the passive walker: through
    its first heel strike (~0.70 s, the stance leg switched) to 0.9 s the states agree
    within 2e-5 (the powered hook integrates on solve_ivp's LSODA with event location and
    the work integrals in its error norm, the passive run on the scene's backend: the two
    agree to the integrator's tolerance, rtol 1e-6), and the actuators' work integrals are
    exactly 0."""
    from walkerlab.analysis.contact.sim import scene_start
    from walkerlab.integrate import contact

    _, gait = rigid
    scene = with_changes(load_scene(SCENE), {
        "walker.actuation.push_off": None,
        "walker.actuation.torques": [{"joint": "hip", "law": {}}]})
    setup = contact_setup(scene, plant=Plant.from_scene(scene))
    assert setup.actuators is not None and setup.actuators.spec.push_off is None
    hooks = []
    loop = contact._run_free

    def spy(*a, **kw):
        hooks.append(a[8] if len(a) > 8 else kw.get("hook"))
        return loop(*a, **kw)

    monkeypatch.setattr(contact, "_run_free", spy)
    runs = []
    for acts in (setup.actuators, None):
        walker, x0, limits, _ = scene_start(replace(setup, actuators=acts), gait.x, 1)
        limits = replace(limits, fall_hip_height_m=0.5 * walker.L)
        runs.append(integrate_contact(walker, x0, 0.0, 0.9, Solver.from_settings(
            setup.solver), limits))
    powered, passive = runs
    assert len(hooks) == 2 and hooks[0] is not None and hooks[1] is None
    assert powered.termination == passive.termination == "t_final"
    common, i, j = np.intersect1d(powered.t, passive.t, return_indices=True)
    assert common.size > 400
    assert np.max(np.abs(powered.X[i] - passive.X[j])) < 2e-5
    names = setup.actuators.work_names
    for k in ("hip_torque_positive", "hip_torque_negative", "push_off"):
        assert np.all(powered.work[:, names.index(k)] == 0.0), k


def test_a_compiled_powered_run_walks_as_the_solve_ivp_run(rigid, monkeypatch):
    """With ``contact_solver.method: cyrk_bdf`` a powered run is compiled segments
    (:mod:`walkerlab.integrate.compiled_segments`: the walker's discrete state data of the
    compiled right-hand side, its events found on the segments' samples and located on
    CyRK's dense output), and walks as the solve_ivp run does (the scene's LSODA, rtol 1e-8)
    through two heel strikes with their push-off pulses (to 1.6 s): the states on the common
    samples within 1e-4 (a touchdown located ~1e-7 s apart by the two integrators shifts the
    stiff contact transient), the push-off and contact work within 1e-5 J."""
    from walkerlab.integrate import _cyrk

    _, gait = rigid
    calls = []
    build = _cyrk.ChunkSolver.__init__

    def spy(self, *a, **kw):  # the compiled solvers' right-hand sides
        calls.append(kw["kernels"].__name__)
        build(self, *a, **kw)

    monkeypatch.setattr(_cyrk.ChunkSolver, "__init__", spy)
    runs = []
    for method in ("LSODA", "cyrk_bdf"):
        scene = with_changes(load_scene(SCENE), {"contact_solver.method": method})
        runs.append(_run(scene, gait.x, 1.6)[1])
    old, new = runs
    assert calls and all(c.endswith("_powered") for c in calls)
    assert old.termination == new.termination == "t_final"
    common, i, j = np.intersect1d(old.t, new.t, return_indices=True)
    assert common.size > 1500
    assert np.max(np.abs(old.X[i] - new.X[j])) < 1e-4
    assert np.max(np.abs(old.work[-1] - new.work[-1])) < 1e-5
    assert new.work[-1, list(WORK_NAMES).index("push_off")] > 0.1  # the pulses ran


def test_a_zero_gain_hip_laws_compiled_step_map_is_the_passive_map():
    """The powered step map (the whole step on compiled segments: CyRK's BDF over the
    generated powered right-hand side, the touchdown, the roles swap and the mid-stance
    section located on its dense output) of the paper walker with a hip law of zero gains
    is the passive map (compiled grid runs, the section by brentq on short runs): one step
    from the passive contact gait's section state at the map's tolerances (rtol 1e-12) lands
    on the same section state within 1e-7 of each coordinate's scale and the same step
    period and length within 1e-10 s and m (the two locate the section differently: the
    powered one on an interpolant; measured 1.1e-9 of the scale, 6e-13 s, 1.3e-12 m), so the
    search finds the passive gait (0.710968 s) on it; on solve_ivp (Python RHS, LSODA at rtol
    1e-10) its search did not converge (scaled residual 2.5e-8)."""
    from walkerlab.analysis.contact.periodic import MAP_SOLVER, ideal_gait
    from walkerlab.analysis.contact.sim import scene_start
    from walkerlab.analysis.contact.step_map import StepMap, section_guess_from_ideal

    paper = load_scene(SCENE.with_name("paper.yaml"))
    hip = with_changes(paper, {"walker.actuation": {"torques": [{"joint": "hip", "law": {
        "stiffness_n_m_per_rad": 0.0, "damping_n_m_s_per_rad": 0.0}}]}})
    gait = ideal_gait(paper, plant=Plant.from_scene(paper))
    maps = []
    for sc in (paper, hip):
        walker = scene_start(contact_setup(sc, plant=Plant.from_scene(sc)), gait.x, 2)[0]
        maps.append(StepMap(walker, solver=MAP_SOLVER))
    passive, powered = maps
    assert powered.powered and not passive.powered
    z = section_guess_from_ideal(passive, gait.x, (1.0, 1.1))
    z1, T1, s1 = passive(z)
    z2, T2, s2 = powered(z)
    assert np.max(np.abs(z2 - z1) / passive.scale) < 1e-7
    assert T2 == pytest.approx(T1, abs=1e-10) and s2 == pytest.approx(s1, abs=1e-10)


def _contact_takes(path) -> bool:
    """Whether the contact view takes the scene's actuators (the table's cells: a 3D
    walker's hip torque and push-off are the rigid model's so far)."""
    from walkerlab.stages.registry import contact_walks_ground

    return contact_walks_ground(load_scene(path))


POWERED_SCENES = sorted(p.stem for p in SCENE.parent.glob("*.yaml")
                        if "actuation:" in p.read_text() and "\ncontact:" in p.read_text()
                        and _contact_takes(p))


@pytest.mark.parametrize("name", POWERED_SCENES)
def test_every_shipped_powered_scene_runs_the_compiled_contact_run_or_says_why_not(name):
    """A powered scene's contact run is the compiled one (``contact_solver.method:
    cyrk_bdf``, the run ``walkerlab bench powered`` times) when its actuators are data of the
    compiled right-hand side (:func:`walkerlab.models.contact.powered_data.powered_data`);
    a scene on a ``solve_ivp`` method says why in the comment of its ``method:`` line (none
    does since the virtual-constraint controller became compiled data: a replay's Python
    callables would be the reason)."""
    from walkerlab.integrate._cyrk import CYRK_METHODS
    from walkerlab.models.contact.powered_data import powered_data

    path = SCENE.with_name(f"{name}.yaml")
    sc = load_scene(path)
    setup = contact_setup(sc, plant=Plant.from_scene(sc))
    data = powered_data(setup.model())
    if setup.solver.method in CYRK_METHODS:
        assert data is not None, f"{name}: a compiled solver for actuators that are no data"
        return
    line = next(ln for ln in path.read_text().splitlines()
                if ln.strip().startswith("method:") and setup.solver.method in ln
                and "#" in ln)
    assert data is None and "no compiled data" in line, (
        f"{name}: contact_solver.method {setup.solver.method} on actuators that are compiled "
        "data, or no reason given")


def test_grid_inside_is_the_grids_samples_strictly_inside_the_span():
    """:func:`walkerlab.integrate.compiled_segments.grid_inside` (bisection) selects what
    the whole-grid mask did, on sample grids and spans of every placement (an end on a
    sample, within 1e-12 s of one, outside the grid, an empty span)."""
    from walkerlab.integrate.compiled_segments import grid_inside

    rng = np.random.default_rng(0)
    grid = np.arange(0.0, 3.0, 1.0 / 500)
    spans = [(0.0, 3.0), (0.002, 0.002), (0.1, 0.1 + 1e-13), (-1.0, 0.5), (2.9, 9.0),
             (0.004 + 5e-13, 0.01 - 5e-13)]
    spans += [tuple(np.sort(rng.uniform(-0.1, 3.1, 2))) for _ in range(200)]
    spans += [(grid[i], grid[j]) for i, j in rng.integers(0, grid.size, (100, 2))]
    for t0, t1 in spans:
        want = grid[(grid > t0 + 1e-12) & (grid < t1 - 1e-12)]
        assert np.array_equal(grid_inside(grid, t0, t1), want), (t0, t1)
