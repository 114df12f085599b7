"""Walkers whose step is a sequence of phases optimised by multi-phase direct collocation
(``walkerlab.optimal.transcription.phases`` / ``phased_collocation``): the kneed walker of
configs/kneed.yaml (unlocked swing, knee strike, locked swing, heel strike) and the flat
feet of configs/flat_feet.yaml (heel contact, foot slap, foot flat, mid-stance, heel off,
heel strike).  Their CasADi phases are the rigid model's, a hip torque acts through a lock
(the knee, the flat foot) without breaking it and its power is the energy's rate, and each
walker's least-effort gait on its slope is its passive gait (found independently by
shooting, ``fixedpoint``); the kneed and flat-footed walkers' push-off (Kuo 2002) is the
rigid model's transition, and an optimum that uses it is the rigid gait of that push-off."""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from walkerlab.config import load_scene
from walkerlab.config.actuation import Actuation, JointTorque, PushOff, TorqueLaw
from walkerlab.models.hybrid.actuated import actuate
from walkerlab.models.hybrid.rigid import make_rigid_walker
from walkerlab.walker.description import walker_data
from walkerlab.walker.plant import Plant

CONFIGS = Path(__file__).resolve().parents[1] / "configs"


@pytest.fixture(scope="module")
def kneed():
    scene = load_scene(CONFIGS / "kneed_optimal.yaml")
    data = walker_data(scene.walker, scene.slope.phi_rad)
    return scene, data, make_rigid_walker(data)


@pytest.fixture(scope="module")
def kneed_start(kneed):
    """The kneed walker's passive gait (shooting), one step of it on a 60-interval mesh and
    its CasADi phases (built once for the tests that optimise it)."""
    pytest.importorskip("casadi")
    return _start(kneed, 60)


def _gait(walker_fixture):
    """The passive gait (shooting) of the fixture's rigid walker: flat feet's without their
    double support (the walker the phased transcription optimises; the driver solves its
    fixed point as its start, 0.7576 s against 0.8102 s with the double support), else the
    scene's (``walkerlab fixedpoint``)."""
    import walkerlab as wl
    from walkerlab.analysis.gait.scene import solve_scene

    scene, data, walker = walker_fixture
    if data.structure.foot != "flat":
        return wl.Walker.from_scene(scene).fixed_point()
    r = solve_scene(scene, False, walker=walker, plant=Plant.from_scene(scene))[1].gait.result
    return SimpleNamespace(x=np.asarray(r.x, float), step_period=float(r.period_s))


def _start(walker_fixture, intervals: int):
    """(gait, guess, CasADi phases) of a walker with phases: its passive fixed point, one
    step of it on ``intervals`` and :func:`mode_functions` in that step's phase order."""
    from walkerlab.integrate.solver import Solver
    from walkerlab.optimal.transcription.mode_sequence import phased_guess
    from walkerlab.optimal.transcription.phases import mode_functions, phase_order

    scene, data, walker = walker_fixture
    g = _gait(walker_fixture)
    guess, log = phased_guess(walker, g.x, g.step_period, Solver.from_settings(scene.solver),
                              intervals)
    return g, guess, mode_functions(data, walker, phase_order(walker, log))


def _torqued(data, u: float):
    """The rigid kneed walker with a constant hip torque ``u`` [N m]."""
    spec = Actuation(torques=[JointTorque(joint="hip", law=TorqueLaw(constant_n_m=u),
                                          max_torque_n_m=1e6)])
    return actuate(make_rigid_walker(data), data, spec)


def test_a_hip_torque_on_a_locked_knee_keeps_it_locked_and_its_power_is_the_energy_rate(
        kneed):
    """In both phases dE/dt = u d(hip angle)/dt (the knee lock does no work; dE/dt by central
    differences of the generated energies along the flow, h = 1e-6: ~1e-9 truncation), and
    in the locked phase the shank's acceleration equals the thigh's (the lock holds)."""
    _, data, _ = kneed
    u = 0.7
    w = _torqued(data, u)
    rng = np.random.default_rng(3)
    for _ in range(5):
        x = rng.normal(0.0, [0.2, 0.2, 0.2, 1.0, 1.0, 1.0])
        x[1] = x[0]  # a straight knee (the locked phase's states)
        x[4] = x[3]
        for ph in w.phases:
            f = ph.flow(0.0, x)
            h = 1e-6

            def energy(z):
                return sum(w.energies(z))
            dE = sum((energy(x + h * e) - energy(x - h * e)) / (2 * h) * fi
                     for e, fi in zip(np.eye(6), f))
            hip_rate = x[3] - x[5]  # swing thigh minus stance
            assert dE == pytest.approx(u * hip_rate, abs=1e-7), ph.name
        lk = w.phases[1].flow(0.0, x)
        assert lk[4] == pytest.approx(lk[3], abs=1e-12)


def test_the_casadi_phases_are_the_rigid_models(kneed):
    """Flows (with a hip torque), guards and resets of every phase of the transcription
    against the rigid model's generated code at random states: round-off (1e-12)."""
    from walkerlab.optimal.transcription.phases import mode_functions, phase_order

    _, data, walker = kneed
    assert phase_order(walker) == [("unlocked_swing", "knee_strike", 1),
                                   ("locked_swing", "heel_strike", -1)]
    fns = mode_functions(data, walker)
    torqued = _torqued(data, 0.4)
    rng = np.random.default_rng(5)
    for _ in range(5):
        x = rng.normal(0.0, [0.2, 0.2, 0.2, 1.0, 1.0, 1.0])
        for mp, ph, tph in zip(fns["phases"], walker.phases, torqued.phases):
            g = next(g for g in ph.guards if g.outcome != "fall")
            np.testing.assert_allclose(mp.flow(x, 0.4).full().ravel(), tph.flow(0.0, x),
                                       rtol=0, atol=1e-12)
            assert float(mp.guard(x, 0.0)) == pytest.approx(g.function(0.0, x), abs=1e-14)
            reset = g.reset or walker.reset
            np.testing.assert_allclose(mp.reset(x).full().ravel(), reset(x), rtol=0, atol=1e-12)


def test_a_mode_graph_without_a_fixed_sequence_is_refused_in_one_line():
    from walkerlab.models.registry import build_walker
    from walkerlab.optimal.transcription.phases import phase_order

    with pytest.raises(ValueError, match="no fixed phase sequence"):
        sc = load_scene(CONFIGS / "flat_feet.yaml")
        phase_order(build_walker(Plant.from_scene(sc)))


#: the flat-footed passive gait's phases (configs/flat_feet.yaml's note): the sequence
#: through its mode graph, each ended by its guard (direction as solve_ivp's events)
FLAT_ORDER = [("heel_contact:early_swing", "foot_slap", -1),
              ("foot_flat:early_swing", "midstance", 1),
              ("foot_flat:late_swing", "heel_off", -1),
              ("heel_off:late_swing", "heel_strike", -1)]


@pytest.fixture(scope="module")
def flat():
    scene = load_scene(CONFIGS / "flat_feet_optimal.yaml")
    data = walker_data(scene.walker, scene.slope.phi_rad)
    return scene, data, make_rigid_walker(data, double_support=False)  # as optimize builds it


@pytest.mark.slow
def test_the_flat_feet_phases_are_the_rigid_models(flat):
    """The phase order read from a step's log; each phase's CasADi flow (with a hip torque)
    against the actuated rigid model's, its guard against the rigid guard (heel off: the
    heel's normal force through the actuated flow), its reset against the generated one, at
    states near the gait (1e-12 relative: round-off).  ~12 s under load (the flat feet's
    symbolic modes and ground forces built into CasADi)."""
    from walkerlab.optimal.transcription.phases import mode_functions, phase_order

    _, data, walker = flat
    log = [(n, 0.0, 0.0, g) for n, g, _d in FLAT_ORDER]
    assert phase_order(walker, log) == FLAT_ORDER
    fns = mode_functions(data, walker, FLAT_ORDER)
    u = 0.4
    torqued = {ph.name: ph for ph in _torqued(data, u).phases}
    rng = np.random.default_rng(7)
    x0 = np.array([-0.3, 0.2, -0.05, -1.3, -1.2, 1.2])
    for _ in range(4):
        x = x0 + rng.normal(0.0, 0.03, 6)
        for mp in fns["phases"]:
            ph = torqued[mp.name]
            g = next(g for g in ph.guards if g.name == mp.guard_name)
            want = ph.flow(0.0, x)
            np.testing.assert_allclose(mp.flow(x, u).full().ravel(), want, rtol=1e-12,
                                       atol=1e-12 * np.abs(want).max())
            assert float(mp.guard(x, u)) == pytest.approx(g.function(0.0, x), rel=1e-11,
                                                          abs=1e-12)
            if g.reset is not None:
                np.testing.assert_allclose(mp.reset(x).full().ravel(), g.reset(x), rtol=0,
                                           atol=1e-11)


def test_a_hip_torque_on_a_flat_foot_keeps_it_flat_and_its_power_is_the_energy_rate(flat):
    """In every mode the torque adds u d(hip angle)/dt to dE/dt (the lock and the pinned
    contact do no work; the mode's generated energy, central differences h = 1e-6), and in
    foot flat the foot's angle does not accelerate (stance + ankle)'' = 0."""
    from walkerlab.codegen.cache import functions

    _, data, walker = flat
    u = 0.3
    f = functions(data)
    torqued = _torqued(data, u)
    x = np.array([-0.3, 0.2, -0.2 - data.slope_rad, -1.3, -1.2, 1.2])  # on the foot's lock
    for ph, passive in zip(torqued.phases[:3], walker.phases[:3]):
        pin = "toe" if ph.name.startswith("heel_off") else "heel"

        def rate(flow, energies=f[f"energies_{pin}"]):
            def energy(z):
                return sum(energies(z).values())
            return sum((energy(x + 1e-6 * e) - energy(x - 1e-6 * e)) / 2e-6 * fi
                       for e, fi in zip(np.eye(6), flow))
        extra = rate(ph.flow(0.0, x)) - rate(passive.flow(0.0, x))
        assert extra == pytest.approx(u * (x[3] - x[4]), abs=1e-7), ph.name
    lk = torqued.phases[1].flow(0.0, x)
    assert lk[4] + lk[5] == pytest.approx(0.0, abs=1e-12)


@pytest.mark.slow
def test_the_flat_feet_least_effort_gait_is_their_passive_gait(flat):
    """As the kneed walker's below, on flat feet through four phases (~15-45 s: 200
    intervals, half placed by the flow's fifth derivative - heel contact's fast ankle):
    objective <= 1e-10, the step period within 1e-7 (relative; 5e-9 seen) of the shooting
    gait's, every contact pushing, the replay closing to 1e-6 (3e-7 seen; 8e-7 with
    160 intervals, O(h^4))."""
    pytest.importorskip("casadi")
    from walkerlab.integrate.solver import Solver
    from walkerlab.optimal.transcription.mode_sequence import (
        collocate_phases,
        phased_guess,
        replay_phases,
    )
    from walkerlab.optimal.transcription.phases import mode_functions, phase_order
    from walkerlab.optimal.transcription.step import CollocationSpec

    scene, data, walker = flat
    g = _gait(flat)
    guess, log = phased_guess(walker, g.x, g.step_period, Solver.from_settings(scene.solver),
                              200)
    assert phase_order(walker, log) == FLAT_ORDER
    fns = mode_functions(data, walker, FLAT_ORDER)
    res = collocate_phases(fns, CollocationSpec(intervals=200), guess)
    assert res.status == "Solve_Succeeded"
    assert res.objective <= 1e-10
    assert res.step_period_s == pytest.approx(g.step_period, rel=1e-7)
    assert replay_phases(data, res)[0] <= 1e-6


def test_the_kneed_walkers_least_effort_gait_is_its_passive_gait(kneed, kneed_start):
    """int u^2 dt = 0 at the passive gait, so the optimum is it (from a guess 5 % off it):
    objective <= 1e-10, the step period within 1e-7 (relative) of the shooting fixed
    point's (60 intervals: 4e-8 seen; O(h^4)), the knee strike at the passive gait's
    time, and the replay on the rigid model (its own guards and resets) closing to
    1e-6."""
    from walkerlab.optimal.transcription.mode_sequence import collocate_phases, replay_phases
    from walkerlab.optimal.transcription.step import CollocationSpec

    _, data, _ = kneed
    g, guess, fns = kneed_start
    assert sum(x.shape[0] - 1 for _, _, x in guess) == 2 * 60
    passive_knee_time = guess[0][1][-1]
    guess = [(name, t, x * 1.05) for name, t, x in guess]
    res = collocate_phases(fns, CollocationSpec(intervals=60), guess)
    assert res.status == "Solve_Succeeded"
    assert res.objective <= 1e-10 and np.max(np.abs(res.u)) < 1e-5
    assert res.step_period_s == pytest.approx(g.step_period, rel=1e-7)
    assert res.phase_duration_s[0] == pytest.approx(passive_knee_time, rel=1e-6)
    np.testing.assert_allclose(res.x[0], g.x, atol=1e-6)
    assert replay_phases(data, res)[0] <= 1e-6


def _pushed(data, P: float):
    """The rigid kneed walker with Kuo's push-off ``P`` [N s] before every heel strike (its
    transition holds the locked swing knee: walkerlab.models.hybrid.push_off)."""
    return actuate(make_rigid_walker(data), data, Actuation(push_off=PushOff(impulse_n_s=P)))


def _assert_push_off_is_the_rigid_transition(strike, acts, x, P):
    """The collocation's push-off and heel strike at ``x`` with impulse ``P`` [N s] equal the
    rigid model's transition (``acts``) to 1e-10, its work the rigid kinetic-energy gain;
    with no impulse, the plain heel strike."""
    x_plus, work = strike.push_off(x, P)
    ref = acts.transition(x)
    np.testing.assert_allclose(x_plus.full().ravel(), ref["x_plus"], rtol=0, atol=1e-10)
    assert float(work) == pytest.approx(ref["ke_push_off"] - ref["ke_minus"], abs=1e-10)
    if P == 0.0:
        np.testing.assert_allclose(x_plus.full().ravel(), strike.reset(x).full().ravel(),
                                   atol=1e-12)


@pytest.mark.slow
def test_the_kneed_push_off_reset_is_the_rigid_models_push_off_and_heel_strike(kneed):
    """The transcription's heel strike after a push-off ``P`` (the extended impact with the
    swing knee held, in CasADi) against the rigid model's numpy transition at random
    states and impulses: the post-impact state to 1e-10, the push-off's work to the rigid
    transition's kinetic energy gain (1e-10 J); with ``P = 0`` the plain heel strike."""
    pytest.importorskip("casadi")
    from walkerlab.optimal.transcription.phases import mode_functions

    _, data, walker = kneed
    strike = mode_functions(data, walker)["phases"][-1]
    assert strike.guard_name == "heel_strike" and strike.push_off is not None
    rng = np.random.default_rng(11)
    for P in (0.0, 0.05, 0.3, 1.0):
        acts = _pushed(data, P).actuators
        for _ in range(4):
            x = rng.normal(0.0, [0.2, 0.2, 0.2, 1.0, 1.0, 1.0])
            x[1], x[4] = x[0], x[3]  # the swing knee locked straight, as at a heel strike
            _assert_push_off_is_the_rigid_transition(strike, acts, x, P)


@pytest.mark.slow
def test_a_kneed_optimum_with_a_free_push_off_is_the_rigid_gait_of_that_push_off(kneed):
    """configs/kneed.yaml's walker on its slope asked for 0.55 m steps, longer than its
    passive gaits' (0.4747 m, 0.468 m), with the push-off free (its square in the effort):
    the optimum supplies energy by both inputs, P = 0.1622 N s and int u^2 dt = 0.0128
    N^2 m^2 s (60 intervals, from the gait of a 0.05 N s push-off).  Independent check: the
    rigid model with that push-off and the optimised hip torque of time (its generated code,
    guards and transition) has a fixed point ``walkerlab fixedpoint``'s root finder finds
    within 1e-6 of the optimum's start (1.5e-7 seen), with the optimum's step period
    (1e-6 relative), and the replay closes to 1e-6 (2.6e-7 seen)."""
    pytest.importorskip("casadi")
    from walkerlab.analysis.gait.poincare import find_fixed_point
    from walkerlab.integrate.solver import Solver
    from walkerlab.optimal.transcription.mode_sequence import (
        collocate_phases,
        phased_guess,
        replay_phases,
    )
    from walkerlab.optimal.transcription.phases import mode_functions, phase_order
    from walkerlab.optimal.transcription.step import CollocationSpec

    scene, data, walker = kneed
    solver = Solver.from_settings(scene.solver)
    start = _pushed(data, 0.05)
    g = find_fixed_point(start, _gait(kneed).x, solver, fd_check=False)
    guess, log = phased_guess(start, g.x, g.period_s, solver, 60)
    fns = mode_functions(data, walker, phase_order(walker, log))
    res = collocate_phases(fns, CollocationSpec(intervals=60, push_off_free=True,
                                                push_off_n_s=0.05,
                                                target_step_length_m=0.55), guess)
    assert res.status == "Solve_Succeeded"
    assert res.step_length_m == pytest.approx(0.55, abs=1e-9)
    assert res.push_off_n_s == pytest.approx(0.1622, abs=5e-4)
    assert res.terms["effort"] == pytest.approx(0.01283, rel=2e-3)
    assert res.objective == pytest.approx(res.terms["effort"] + res.push_off_n_s ** 2,
                                          rel=1e-9)
    err, replayed = replay_phases(data, res)
    assert err <= 1e-6
    assert replayed.actuators.impulse(res.x[-1]) == res.push_off_n_s
    fp = find_fixed_point(replayed, res.x[0], solver, xtol=1e-10, fd_check=False)
    np.testing.assert_allclose(fp.x, res.x[0], rtol=0, atol=1e-6)
    assert fp.period_s == pytest.approx(res.step_period_s, rel=1e-6)


@pytest.mark.slow
def test_the_flat_feet_push_off_reset_is_the_rigid_models_toe_push_off_and_heel_strike(flat):
    """The flat feet's heel strike after a push-off ``P`` at the trailing toe (in heel off,
    the toe pinned; the stance ankle held through the impulse) in CasADi against the rigid
    model's numpy transition (walkerlab.models.hybrid.toe_push_off) at random states and
    impulses: the post-impact state to 1e-10, the push-off's work to the rigid transition's
    kinetic energy gain (1e-10 J); ``P = 0``: the plain heel strike."""
    pytest.importorskip("casadi")
    from walkerlab.optimal.transcription.phases import mode_functions

    _, data, walker = flat
    strike = mode_functions(data, walker, FLAT_ORDER)["phases"][-1]
    assert strike.name == "heel_off:late_swing" and strike.push_off is not None
    rng = np.random.default_rng(3)
    for P in (0.0, 0.05, 0.3, 1.0):
        pushed = actuate(make_rigid_walker(data, double_support=False), data,
                         Actuation(push_off=PushOff(impulse_n_s=P)))
        acts = pushed.actuators.at("toe")
        for _ in range(4):
            x = rng.normal(0.0, [0.2, 0.2, 0.1, 1.0, 1.0, 0.5])
            _assert_push_off_is_the_rigid_transition(strike, acts, x, P)


@pytest.mark.slow
def test_a_flat_footed_optimum_with_a_free_push_off_is_the_rigid_gait_of_that_push_off(flat):
    """Flat feet (without the double support, as optimize collocates them: passive steps of
    0.598 m) asked for 0.62 m steps with the toe push-off free: P = 0.1768 N s and a hip
    torque (300 intervals, from the gait of a 0.05 N s push-off); the rigid model with that
    push-off and the optimised torque of time (its generated flows, guards and toe
    push-off) returns to the optimum's start within 1e-6 in one step (3.8e-8 seen; 9.1e-7
    on 200 intervals), through the optimum's phases, with its step period (1e-7
    relative).  (The root finder on that walker, whose torque law runs in Python on flat
    feet, takes ~5 min: the kneed walker's test above runs it.)  ~1-2 min."""
    pytest.importorskip("casadi")
    from walkerlab.analysis.gait.poincare import find_fixed_point
    from walkerlab.integrate.rigid import integrate_step
    from walkerlab.integrate.solver import Solver
    from walkerlab.optimal.transcription.mode_sequence import (
        collocate_phases,
        phased_guess,
        replay_phases,
    )
    from walkerlab.optimal.transcription.phases import mode_functions, phase_order
    from walkerlab.optimal.transcription.step import CollocationSpec

    scene, data, walker = flat
    solver = Solver.from_settings(scene.solver)
    start = actuate(walker, data, Actuation(push_off=PushOff(impulse_n_s=0.05)))
    g = find_fixed_point(start, _gait(flat).x, solver, fd_check=False)
    guess, log = phased_guess(start, g.x, g.period_s, solver, 300)
    assert phase_order(walker, log) == FLAT_ORDER
    res = collocate_phases(mode_functions(data, walker, FLAT_ORDER),
                           CollocationSpec(intervals=300, push_off_free=True,
                                           push_off_n_s=0.05, target_step_length_m=0.62),
                           guess)
    assert res.status == "Solve_Succeeded"
    assert res.push_off_n_s == pytest.approx(0.1768, abs=5e-4)
    assert res.terms["effort"] > 0.01  # the hip torque works too
    err, replayed = replay_phases(data, res)
    assert err <= 1e-6
    seg = integrate_step(replayed, res.x[0], solver, max_step_time=3.0 * res.step_period_s)
    assert seg.termination == "heel_strike"
    assert tuple(ph.name for ph, _s, _ab in seg.pieces) == res.phase_names
    assert seg.t_end - seg.t_start == pytest.approx(res.step_period_s, rel=1e-7)
    np.testing.assert_allclose(seg.x_next, res.x[0], rtol=0, atol=1e-6)


def test_what_the_phased_transcription_does_not_take_is_refused_in_one_line():
    from walkerlab.optimal.transcription.mode_sequence import collocate_phases
    from walkerlab.optimal.transcription.step import CollocationSpec

    for spec, field in ((CollocationSpec(objective="push_off_work"), "optimize.objective"),
                        (CollocationSpec(objective="weighted",
                                         weights=(("push_off_work", 1.0),)),
                         "optimize.objective"),
                        (CollocationSpec(push_off_n_s=1.0), "optimize.push_off"),
                        (CollocationSpec(push_off_free=True), "optimize.push_off")):
        with pytest.raises(ValueError, match=field) as e:
            collocate_phases({"phases": []}, spec, [])
        assert "\n" not in str(e.value)


def test_optimize_h5_keeps_the_phases(tmp_path, kneed):
    """The writer and the reader side by side: the phases' names, first points and
    durations round-trip (and reach the report's line); a step without phases writes
    none."""
    from walkerlab.io.artifacts import write_artifact
    from walkerlab.io.schemas import optimize as schema

    t = np.array([0.0, 0.1, 0.2, 0.2, 0.3, 0.4])
    d = schema.OptimizeData(t, {"a_angle": t, "a_rate": t}, 0 * t, 0.4, 0.5, 0.0, 0.0, 1e-9,
                            np.array([0.5, 0.1], complex), True, "Solve_Succeeded", 3, 0.1,
                            {"a_angle": "rad", "a_rate": "rad/s"},
                            phase_names=("unlocked_swing", "locked_swing"),
                            phase_start=np.array([0, 3]),
                            phase_duration_s=np.array([0.2, 0.2]), build_time_s=0.5)
    path = tmp_path / "optimize.h5"
    write_artifact(path, schema.STAGE, kneed[0], "x", lambda f: schema.write(f, d), 0.0)
    back = schema.load(path)
    assert back.phase_names == d.phase_names and back.build_time_s == 0.5
    np.testing.assert_array_equal(back.phase_start, [0, 3])
    np.testing.assert_array_equal(back.phase_duration_s, [0.2, 0.2])
    from walkerlab.report.figures_section import optimize_lines

    assert "Phases (each with its own mesh and free duration): unlocked_swing 0.200000 s, " \
        "locked_swing 0.200000 s." in optimize_lines(back)[0]
    d.phase_names = ()
    write_artifact(path, schema.STAGE, kneed[0], "x", lambda f: schema.write(f, d), 0.0)
    assert schema.load(path).phase_names == () and schema.load(path).phase_start is None


@pytest.mark.slow
def test_optimize_command_on_the_kneed_walker(tmp_path):
    """``walkerlab optimize configs/kneed_optimal.yaml``: a gait, its multipliers the
    passive gait's (0.741, configs/kneed.yaml's note), the phases in the artifact, the
    contact replay (the optimised hip torque between the thighs, 2 strides) within 3 % of
    the optimum's step period (the issue's check; measured +1.26 %), the figure drawn, the
    phase-variable replays (~25 s: fixedpoint, build, IPOPT, replay, contact replay,
    figure; + ~80 s the phase replays)."""
    pytest.importorskip("casadi")
    from typer.testing import CliRunner

    from walkerlab.cli import app
    from walkerlab.io.schemas.optimize import load

    r = CliRunner().invoke(app, ["optimize", str(CONFIGS / "kneed_optimal.yaml"),
                                 "--runs-dir", str(tmp_path)])
    assert r.exit_code == 0, r.output
    d = load(tmp_path / "kneed_optimal" / "optimize.h5")
    assert d.gait and d.replay_error < 1e-6 and d.objective < 1e-10
    assert max(abs(d.multipliers)) == pytest.approx(0.741, abs=1e-3)
    assert d.phase_names == ("unlocked_swing", "locked_swing")
    assert d.phase_duration_s.sum() == pytest.approx(d.step_period_s, rel=1e-12)
    assert d.contact_outcome == "heel_strike", d.contact_outcome
    assert abs(d.contact_step_period_s / d.step_period_s - 1.0) <= 0.03, d.contact_step_period_s
    assert (tmp_path / "kneed_optimal" / "report" / "figures" / "optimize.png").is_file()
    # optimize.phase_replay: one phase-variable law per phase, the PD one closed and more
    # stable than the feed-forward alone (measured 0.446 against 0.741; ~80 s of CPU)
    fb, ff = d.phase_replays["feedback"], d.phase_replays["feedforward"]
    assert fb.closed and fb.return_error <= 1e-6 and not d.phase_replay_outcome
    assert max(abs(fb.multipliers)) < max(abs(ff.multipliers)) < 1.0


def _powered(data, start, intervals: int, speed: float):
    """The least-effort step of a walker with phases at a target speed (``start`` from
    :func:`_start`: its passive gait's step as the guess) and its replay error."""
    from walkerlab.optimal.transcription.mode_sequence import collocate_phases, replay_phases
    from walkerlab.optimal.transcription.step import CollocationSpec

    _g, guess, fns = start
    res = collocate_phases(fns, CollocationSpec(intervals=intervals,
                                                target_speed_m_per_s=speed), guess)
    return res, replay_phases(data, res)[0]


def test_a_powered_kneed_gait_replays_on_the_rigid_model(kneed, kneed_start):
    """The kneed walker made to walk at 0.9 m/s (its passive gait: 0.870 m/s) by the least
    hip torque: the speed met, the torque not zero (~0.01 N m), and the torque fed as a
    function of time to the rigid model (its knee strike, its locked knee carrying the
    torque through the lock, its heel strike) returns to the start within 1e-6 (2.5e-8
    seen): the torque's path through both phases is the rigid model's."""
    pytest.importorskip("casadi")
    res, err = _powered(kneed[1], kneed_start, 60, 0.9)
    assert res.status == "Solve_Succeeded"
    assert res.step_length_m / res.step_period_s == pytest.approx(0.9, rel=1e-9)
    assert 1e-3 < np.max(np.abs(res.u)) < 1.0
    assert err <= 1e-6


@pytest.mark.slow
def test_a_powered_flat_footed_gait_replays_on_the_rigid_model(flat):
    """Flat feet made to walk at 0.8 m/s (passive: 0.789 m/s) by the least hip torque
    (~0.8 N m peak; ~30 s): the replay on the rigid model - its heel-off guard reading the
    ground force through the torqued flow - closes within 1e-6 (3e-7 seen).

    Replayed in the contact model (the torque between the legs, one stride: 3 steps; ~17 s
    CPU more) it walks, and the torque shortens its mean step period as it shortens the
    rigid one: contact 0.8012 s against the passive contact model's 0.8121 s (-1.34 %),
    rigid 0.7475 s against 0.7576 s (-1.33 %), within 0.3 % of each other.  Against the
    rigid optimum the contact period is +7.2 % (the passive one's offset: the flat-footed
    contact model walks slower than the rigid one, configs/flat_feet_optimal.yaml's note),
    outside the issue's 3 %."""
    pytest.importorskip("casadi")
    from walkerlab.analysis.contact.sim import simulate_from
    from walkerlab.api.scenes import with_changes
    from walkerlab.models.contact.scene import contact_setup
    from walkerlab.optimal.replay.contact import contact_replay_phased

    start = _start(flat, 200)
    res, err = _powered(flat[1], start, 200, 0.8)
    assert res.status == "Solve_Succeeded"
    assert res.step_length_m / res.step_period_s == pytest.approx(0.8, rel=1e-9)
    assert 0.1 < np.max(np.abs(res.u)) < 10.0
    assert err <= 1e-6
    period, outcome = contact_replay_phased(flat[0], res, strides=1,
                                            plant=Plant.from_scene(flat[0]))
    assert outcome == "heel_strike"
    g = start[0]
    rigid_change = res.step_period_s / g.step_period - 1.0
    assert rigid_change < -0.01
    # the passive contact model over the same 3 steps (the compiled passive run, < 1 s)
    # (from the gait's heel strike as the replay starts: ``start: ideal``, not a passive
    # flat-footed walker's default mid-stance)
    sc = with_changes(flat[0], {"contact_sim": {"n_strides": 2, "sample_rate_hz": 500,
                                                "start": "ideal",
                                                "t_final_s": 4.6 * g.step_period}})
    hs = simulate_from(contact_setup(sc,
            plant=Plant.from_scene(sc)), g.x, g.step_period, strides=2)[1].heel_strike_times
    passive = float(np.mean(np.diff(np.asarray(hs, float)[:4])))
    assert abs(period / passive - 1.0 - rigid_change) < 0.003, (period, passive)
    assert 0.06 < period / res.step_period_s - 1.0 < 0.08


def test_phase_functions_cached_on_disk_are_the_same_graph(tmp_path, monkeypatch):
    """A flat-footed walker's phases (configs/flat_feet_optimal.yaml: the heel-contact,
    foot-flat and heel-off flows, their normal forces kept >= 0) are built once per walker
    and phase order and read back from the code cache (the build not called on a warm
    start), computing bit for bit what the built ones do; a damaged file is rebuilt and
    written again (~6 s: one build of the flat feet's CasADi functions)."""
    pytest.importorskip("casadi")
    from walkerlab.codegen import casadi_functions
    from walkerlab.optimal.transcription import phases, step_cache

    monkeypatch.setenv("WALKERLAB_CACHE_DIR", str(tmp_path))
    scene = load_scene(CONFIGS / "flat_feet_optimal.yaml")
    data = walker_data(scene.walker, scene.slope.phi_rad)
    walker = make_rigid_walker(data, double_support=False)  # as optimize builds it
    from walkerlab.optimal.driver import starting_phases

    x0 = scene.fixedpoint.initial_guess.as_array(walker.state_names())
    order = starting_phases(scene, walker, x0, 0.76, 40)[2]  # the gait's phase sequence
    monkeypatch.setattr(casadi_functions, "_memo", {})
    built = step_cache.cached_mode_functions(data, walker, order)
    files = list((tmp_path / "models").glob("*-modes-*.casadi"))
    assert len(files) == 1
    monkeypatch.setattr(casadi_functions, "_memo", {})

    def no_build(*_a, **_k):
        raise AssertionError("built again")

    monkeypatch.setattr(phases, "mode_functions", no_build)
    read = step_cache.cached_mode_functions(data, walker, order)
    x = np.array([-0.2, 0.19, 0.01, -0.9, -0.85, -0.5])
    assert [p.name for p in read["phases"]] == [p.name for p in built["phases"]]
    assert sum(p.keep is not None for p in read["phases"]) >= 3
    for a, b in zip(read["phases"], built["phases"]):
        assert (a.guard_name, a.direction) == (b.guard_name, b.direction)
        for f in ("flow", "guard_rate", "keep", "grf"):
            if getattr(b, f) is not None:
                np.testing.assert_array_equal(np.asarray(getattr(a, f)(x, 0.3)),
                                              np.asarray(getattr(b, f)(x, 0.3)))
        for f in ("guard", "reset", "clearance", "step"):
            fa, fb = getattr(a, f), getattr(b, f)
            args = (x, 0.3) if fb.n_in() == 2 else (x,)
            np.testing.assert_array_equal(np.asarray(fa(*args)), np.asarray(fb(*args)))
    np.testing.assert_array_equal(np.asarray(read["power"](x, 0.3)),
                                  np.asarray(built["power"](x, 0.3)))
    files[0].write_text("damaged")
    monkeypatch.setattr(casadi_functions, "_memo", {})
    calls = []
    monkeypatch.setattr(phases, "mode_functions",
                        lambda *a: calls.append(a) or built)
    assert step_cache.cached_mode_functions(data, walker, order) is built
    assert len(calls) == 1 and files[0].read_text() != "damaged"  # rebuilt and rewritten
