"""A walker whose legs differ optimised over one stride
(``walkerlab.optimal.transcription.stride``):
configs/asymmetric_optimal.yaml (the paper's walker with leg masses 5 / 5.5 kg, slope
0.0174 rad, a hip torque).  Its CasADi phases are the rigid model's and its mirror's, its
least-effort stride is the passive period-2 gait found independently by shooting
(``fixedpoint``: the stride map's fixed point), a powered stride replays on the rigid model,
and what the transcription does not take is refused in one line."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from walkerlab.config import load_scene
from walkerlab.config.actuation import Actuation, JointTorque, TorqueLaw
from walkerlab.models.hybrid.actuated import actuate
from walkerlab.models.hybrid.rigid import make_rigid_walker
from walkerlab.walker.description import walker_data
from walkerlab.walker.plant import Plant

CONFIGS = Path(__file__).resolve().parents[1] / "configs"


@pytest.fixture(scope="module")
def asym():
    """(scene, data, rigid walker, passive gait, CasADi stride) built once."""
    pytest.importorskip("casadi")
    from walkerlab.analysis.gait.scene import solve_scene
    from walkerlab.optimal.transcription.stride import stride_functions

    scene = load_scene(CONFIGS / "asymmetric_optimal.yaml")
    data = walker_data(scene.walker, scene.slope.phi_rad)
    _, search = solve_scene(scene,
            plant=Plant.from_scene(scene))  # the fixedpoint stage's search: the stride map's
    r = search.gaits[search.selected].result
    g = SimpleNamespace(x=np.asarray(r.x, float), step_period=r.period_s / 2,
                        step_periods=np.asarray(r.step_periods_s, float),
                        multipliers=np.asarray(r.multipliers_variational, complex))
    return scene, data, make_rigid_walker(data), g, stride_functions(data)


def _guess(asym, intervals: int = 40):
    from walkerlab.integrate.solver import Solver
    from walkerlab.optimal.transcription.stride import stride_guess

    scene, _data, walker, g, _fns = asym
    return stride_guess(walker, g.x, g.step_period, Solver.from_settings(scene.solver),
                        intervals)


def test_the_stride_phases_are_the_rigid_models_and_its_mirrors(asym):
    """Leg A's phases against the rigid walker's generated code, leg B's against its mirror's
    (flows with a hip torque, guards, the heel-strike resets; midstance has no jump) at random
    states: round-off (1e-12).  The two steps' flows and resets differ (the legs' masses)."""
    _scene, data, walker, _g, fns = asym
    spec = Actuation(torques=[JointTorque(joint="hip", law=TorqueLaw(constant_n_m=0.4),
                                          max_torque_n_m=1e6)])
    torqued = actuate(walker, data, spec)
    rng = np.random.default_rng(5)
    for _ in range(4):
        x = rng.normal(0.0, [0.2, 0.2, 1.0, 1.0])
        for k, mp in enumerate(fns["phases"]):
            w, tw = (walker, torqued) if k < 2 else (walker.mirror, torqued.mirror)
            ph = w.phases[k % 2]
            g = next(g for g in ph.guards if g.outcome != "fall")
            assert (mp.name.split(":")[1], mp.guard_name) == (ph.name, g.name)
            np.testing.assert_allclose(mp.flow(x, 0.4).full().ravel(),
                                       tw.phases[k % 2].flow(0.0, x), rtol=0, atol=1e-12)
            assert float(mp.guard(x, 0.0)) == pytest.approx(g.function(0.0, x), abs=1e-14)
            reset = w.reset if g.outcome == "heel_strike" else (lambda z: z)
            np.testing.assert_allclose(mp.reset(x).full().ravel(), reset(x), rtol=0,
                                       atol=1e-12)
        A, B = fns["phases"][1], fns["phases"][3]
        assert np.max(np.abs(A.flow(x, 0.0).full() - B.flow(x, 0.0).full())) > 1e-3
        assert np.max(np.abs(A.reset(x).full() - B.reset(x).full())) > 1e-4


def test_the_least_effort_stride_is_the_passive_period_two_gait(asym):
    """int u^2 dt = 0 at the passive gait, so the optimum is it: from a guess 5 % off the
    gait, objective <= 1e-10, each step's period within 1e-7 relative of the shooting fixed
    point's (Hermite-Simpson on 60 intervals a step, as the shipped scene: O(h^4); 1.6e-8 seen,
    7.5e-8 on 40), the start
    within 1e-6, the replay over the stride closing to 1e-6 and the stride map's
    multipliers those of the fixed point (1e-6: the start's distance)."""
    from walkerlab.optimal.outcome import replay_multipliers
    from walkerlab.optimal.transcription.mode_sequence import collocate_phases
    from walkerlab.optimal.transcription.step import CollocationSpec
    from walkerlab.optimal.transcription.stride import replay_stride, step_of

    scene, data, _walker, g, fns = asym
    guess = [(name, t, 1.05 * x) for name, t, x in _guess(asym, 60)]
    res = collocate_phases(fns, CollocationSpec(intervals=60), guess)
    assert res.status == "Solve_Succeeded"
    assert res.objective <= 1e-10 and np.max(np.abs(res.u)) < 1e-5
    periods = [step_of(res, k).step_period_s for k in (0, 1)]
    np.testing.assert_allclose(periods, g.step_periods, rtol=1e-7, atol=0)
    assert abs(periods[1] / periods[0] - 1) > 0.05  # a stride of two different steps
    np.testing.assert_allclose(res.x[0], g.x, atol=1e-6)
    err, replayed = replay_stride(data, res)
    assert err <= 1e-6
    mu = replay_multipliers(replayed, res, scene, err)
    np.testing.assert_allclose(np.sort_complex(mu), np.sort_complex(g.multipliers),
                               atol=1e-6)


@pytest.mark.slow
def test_a_powered_stride_at_a_target_speed_replays_on_the_rigid_model(asym):
    """The walker made to walk at 0.6 m/s (its passive gait: 0.528 m/s) by the least hip
    torque: the stride's mean speed is met, the torque is not zero and differs between the
    steps (the legs differ), and the torques fed as functions of time to the rigid model and
    its mirror return to the start within 1e-6 over the stride (~11 s under load: the
    optimisation and the replay of the torqued walker in Python)."""
    from walkerlab.optimal.transcription.mode_sequence import collocate_phases
    from walkerlab.optimal.transcription.step import CollocationSpec
    from walkerlab.optimal.transcription.stride import replay_stride, step_of

    _scene, data, _walker, _g, fns = asym
    res = collocate_phases(fns, CollocationSpec(intervals=40, target_speed_m_per_s=0.6),
                           _guess(asym))
    assert res.status == "Solve_Succeeded"
    steps = [step_of(res, k) for k in (0, 1)]
    lengths = [float(fns["phases"][2 * k + 1].step(s.x[-1])) for k, s in enumerate(steps)]
    assert sum(lengths) / res.step_period_s == pytest.approx(0.6, rel=1e-9)
    assert 0.01 < np.max(np.abs(res.u)) < 20.0
    assert np.max(np.abs(steps[0].u)) != pytest.approx(np.max(np.abs(steps[1].u)), rel=1e-3)
    err, _ = replay_stride(data, res)
    assert err <= 1e-6


def _pushed(scene, impulse_n_s: float):
    """``scene`` with a push-off of ``impulse_n_s`` [N s] before every heel strike."""
    d = scene.model_dump(mode="json", exclude_none=True)
    d["walker"]["actuation"] = {"push_off": {"impulse_n_s": impulse_n_s}}
    return type(scene).model_validate(d)


def test_a_stride_with_a_push_off_is_the_rigid_walkers_pushed_gait(asym):
    """A fixed push-off of 0.5 N s before both heel strikes (each with its own leg's
    impact): the least-effort stride has no hip torque (objective <= 1e-10), so it is the
    pushed walker's passive period-2 gait, found independently by shooting on the rigid
    model with the push-off (``fixedpoint``'s search on the scene with
    ``walker.actuation.push_off``): each step's period within 1e-6 relative (the passive
    stride's 7.5e-8 on 40 intervals), the start within 1e-5; its replay with the push-off
    closes to 1e-6; and it is not the unpushed gait (both steps longer by > 1e-3)."""
    from walkerlab.analysis.gait.scene import solve_scene
    from walkerlab.optimal.transcription.mode_sequence import collocate_phases
    from walkerlab.optimal.transcription.step import CollocationSpec
    from walkerlab.optimal.transcription.stride import replay_stride, step_of

    scene, data, _walker, g, fns = asym
    sc = _pushed(scene, 0.5)
    _, search = solve_scene(sc, plant=Plant.from_scene(sc))
    r = search.gaits[search.selected].result
    res = collocate_phases(fns, CollocationSpec(intervals=40, push_off_n_s=0.5),
                           _guess(asym))
    assert res.status == "Solve_Succeeded" and res.objective <= 1e-10
    assert res.push_off_n_s == 0.5 and res.terms["push_off_work"] > 0.0
    periods = [step_of(res, k).step_period_s for k in (0, 1)]
    np.testing.assert_allclose(periods, r.step_periods_s, rtol=1e-6, atol=0)
    assert np.min(np.abs(np.array(periods) / g.step_periods - 1.0)) > 1e-3  # pushed: not
    # the passive gait (measured: 0.68002 / 0.71581 s against 0.67839 / 0.71442 s)
    np.testing.assert_allclose(res.x[0], r.x, atol=1e-5)
    err, _ = replay_stride(data, res)
    assert err <= 1e-6


@pytest.mark.slow
def test_a_free_push_off_stride_on_level_ground(asym):
    """Level ground at 0.5 m/s, least cost of transport, the push-off free (~15 s): the
    optimum pushes off (P > 0) and replays with it on the rigid model within 1e-6 (60
    intervals a step); its push-off work is both heel strikes' kinetic-energy jumps by the
    push-off in the rigid model's own transition (numpy, :class:`walkerlab.models.hybrid.
    actuated.Actuators`; the collocation's is CasADi's) to 1e-9 relative, and it is a part
    of the cost of transport, ``(hip positive work + push-off work) / (M g d)``."""
    from walkerlab.optimal.transcription.mode_sequence import collocate_phases
    from walkerlab.optimal.transcription.step import CollocationSpec
    from walkerlab.optimal.transcription.stride import replay_stride, step_of

    scene, data, _walker, _g, _fns = asym
    d = _pushed(scene, 2.0).model_dump(mode="json", exclude_none=True)
    d["slope"] = {"angle_rad": 0.0}
    level = type(scene).model_validate(d)
    from walkerlab.analysis.gait.scene import solve_scene
    from walkerlab.integrate.solver import Solver
    from walkerlab.optimal.transcription.stride import stride_functions, stride_guess

    ldata = walker_data(level.walker, level.slope.phi_rad)
    _, search = solve_scene(level, plant=Plant.from_scene(level))
    r = search.gaits[search.selected].result
    lw = make_rigid_walker(ldata)
    guess = stride_guess(actuate(lw, ldata, level.walker.actuation), np.asarray(r.x),
                         r.period_s / 2, Solver.from_settings(level.solver), 60)
    spec = CollocationSpec(intervals=60, push_off_n_s=2.0, push_off_free=True,
                           objective="cost_of_transport", target_speed_m_per_s=0.5)
    res = collocate_phases(stride_functions(ldata), spec, guess)
    assert res.status == "Solve_Succeeded" and res.push_off_n_s > 0.5
    err, replayed = replay_stride(ldata, res)
    assert err <= 1e-6
    jumps = []
    for k, w in enumerate((replayed, replayed.mirror)):
        tr = w.actuators.transition(step_of(res, k).x[-1])
        jumps.append(tr["ke_push_off"] - tr["ke_minus"])
    assert res.terms["push_off_work"] == pytest.approx(sum(jumps), rel=1e-9)
    weight = ldata.total_mass_kg * ldata.gravity_m_per_s2
    distance = 0.5 * res.step_period_s
    assert res.terms["cost_of_transport"] > sum(jumps) / (weight * distance)


def test_what_the_stride_does_not_take_is_refused_in_one_line(asym):
    """The push-off's work as an objective without a push-off is refused in one line
    naming the field (before any work); the cost of transport, the friction cone and a
    free push-off pass the stride's checks, and a guess is read from its artifact (a
    missing one refused naming ``optimize.initial_guess``); one step of legs that differ
    stays refused by the one-step transcription."""
    from walkerlab.optimal.driver import _check_stride as _check
    from walkerlab.optimal.driver import optimize_scene
    from walkerlab.optimal.transcription.step import step_functions

    scene, data, _walker, g, _fns = asym

    def with_(field, value):
        d = scene.model_dump(mode="json", exclude_none=True)
        d["optimize"][field] = value
        return type(scene).model_validate(d)

    for field, value, says in (("objective", "push_off_work", "optimize.objective"),
                               ("initial_guess", {"from": "x.h5"}, "optimize.initial_guess")):
        with pytest.raises(ValueError, match=says) as exc:
            sc = with_(field, value)
            optimize_scene(sc, g.x, g.step_period, plant=Plant.from_scene(sc))
        assert "\n" not in str(exc.value)
    for field, value in (("objective", "cost_of_transport"), ("friction_coefficient", 0.8),
                         ("push_off", "free")):
        _check(with_(field, value).optimize, False)  # accepted
    _check(with_("objective", "push_off_work").optimize, True)  # with a push-off
    with pytest.raises(ValueError, match="legs that differ take a stride"):
        step_functions(data, None)
    with pytest.raises(ValueError, match="a stride is for legs that differ"):
        from walkerlab.optimal.transcription.stride import stride_functions

        stride_functions(replace(data, mirror_params=None))


@pytest.mark.slow
def test_optimize_command_on_legs_that_differ(tmp_path):
    """``walkerlab optimize configs/asymmetric_optimal.yaml``: a gait whose mean step is the
    fixed point's (1e-7), phases of both steps stored, the stride map's multipliers, and the
    contact model driven by the optimised (zero) torques within 3 % of the rigid step
    (~60 s under load: the fixed point, the CasADi build, the contact run)."""
    from typer.testing import CliRunner

    from walkerlab.cli import app
    from walkerlab.io.schemas.fixedpoint import load_fixedpoint
    from walkerlab.io.schemas.optimize import load

    r = CliRunner().invoke(app, ["optimize", str(CONFIGS / "asymmetric_optimal.yaml"),
                                 "--runs-dir", str(tmp_path)])
    assert r.exit_code == 0, r.output
    d = load(tmp_path / "asymmetric_optimal" / "optimize.h5")
    fp = load_fixedpoint(tmp_path / "asymmetric_optimal" / "fixedpoint.h5")
    assert d.gait and d.replay_error < 1e-6 and d.objective < 1e-10
    assert d.step_period_s == pytest.approx(fp.step_period_s, rel=1e-7)
    assert len(d.phase_names) == 4 and d.time[-1] == pytest.approx(fp.stride_period_s,
                                                                   rel=1e-7)
    assert max(abs(d.multipliers)) == pytest.approx(0.3531, abs=1e-3)
    assert d.contact_step_period_s == pytest.approx(d.step_period_s, rel=0.03)


def _torqued_pair(data):
    """The actuated rigid walker and its mirror whose hip torque is ``cur["u"]`` [N m]."""
    spec = Actuation(torques=[JointTorque(joint="hip", law=TorqueLaw(), max_torque_n_m=1e6)])
    tw, cur = actuate(make_rigid_walker(data), data, spec), {"u": 0.0}
    for w in (tw, tw.mirror):
        w.actuators.torques = lambda t, x: np.array([cur["u"]])
    return tw, cur


def _newton_euler(w, data, x, qdd):
    """The ground's resultant on the rigid walker ``w`` (or its mirror) along the slope's
    normal and tangent [N]: ``sum m_i (a_i + g y)`` over its three mass points (the hip,
    ``m_sw_mass`` on the swing leg, ``m_st_mass`` on the stance leg: each step's own), the
    points' positions from its generated code, their accelerations by the Cauchy integral
    (:func:`tests.test_optimize_phased_terms._com_acceleration`) along ``qdd``."""
    from tests.test_optimize_phased_terms import _com_acceleration

    p = w.params
    masses = {"hip": p["M_hip"], "swing_mass": p["m_sw_mass"], "stance_mass": p["m_st_mass"]}
    total = sum(masses.values())
    assert total == pytest.approx(float(w.total_mass_kg), rel=1e-14)

    def com(qc):
        X = np.concatenate([qc, np.zeros(2)]).astype(complex)[:, None]
        pts = w.points(w.layout().state_rows(X))
        return sum(m * np.asarray(pts[k]).ravel() for k, m in masses.items()) / total

    a = _com_acceleration(com, x[:2].astype(complex), x[2:].astype(complex),
                          np.asarray(qdd, complex))
    F = total * (a + np.array([0.0, float(data.gravity_m_per_s2)]))
    s, c = np.sin(data.slope_rad), np.cos(data.slope_rad)
    return np.array([s * F[0] + c * F[1], c * F[0] - s * F[1]])


def test_each_steps_power_hip_angle_and_ground_reaction_are_its_own_walkers(asym):
    """The stride's ``power``, ``hip_angle`` and ``ahead`` are leg A's CasADi functions,
    used on leg B's step too: at random states they equal both the rigid walker's and its
    mirror's own (the torque times the rate of its hip angle, swing minus stance; the
    midstance guard) to round-off - the same expressions, no leg's number in them.  Each
    phase's ground reaction (the friction cone's) is its own walker's: Newton-Euler on the
    rigid walker for leg A's phases, on the mirror (the other masses) for leg B's, to 1e-10
    of the weight, and the two steps' differ (the legs' masses: 1e-4 of the weight)."""
    _scene, data, _walker, _g, fns = asym
    tw, cur = _torqued_pair(data)
    weight = float(data.total_mass_kg) * float(data.gravity_m_per_s2)
    rng = np.random.default_rng(7)
    for _ in range(4):
        x, cur["u"] = rng.normal(0.0, [0.2, 0.2, 1.0, 1.0]), float(rng.normal(0.0, 2.0))
        for w in (tw, tw.mirror):
            delta, ddelta, _s, _ds = w.actuators.hip_angles(x)
            assert float(fns["power"](x, cur["u"])) == pytest.approx(
                w.actuators.power(0.0, x), rel=1e-13, abs=1e-14)
            assert float(fns["power"](x, cur["u"])) == pytest.approx(cur["u"] * ddelta,
                                                                    rel=1e-13, abs=1e-14)
            assert float(fns["hip_angle"](x)) == pytest.approx(delta, abs=1e-15)
            ahead = next(g for g in w.phases[0].guards if g.name == "midstance")
            assert float(fns["ahead"](x)) == pytest.approx(ahead.function(0.0, x), abs=1e-15)
        got = []
        for k, mp in enumerate(fns["phases"]):
            w = tw if k < 2 else tw.mirror
            want = _newton_euler(w, data, x, w.phases[k % 2].flow(0.0, x)[2:])
            got.append(mp.grf(x, cur["u"]).full().ravel())
            np.testing.assert_allclose(got[-1], want, rtol=0, atol=1e-10 * weight)
        assert np.max(np.abs(got[0] - got[2])) > 1e-5 * weight  # 1e-4 of it seen


def test_the_least_cost_of_transport_stride_on_its_slope_is_the_passive_gait(asym):
    """Cost of transport (slack variables, the effort weight 1e-2 of the phased scenes' test
    on the passive slope) from the passive stride: CoT ~0 (1.5e-11 seen: the interior
    point's slack floor), torques ~0 (4e-5 N m seen), each step's period within 1e-4 of the
    shooting fixed point's (6e-6 seen: the objective, ~1e-11, resolves no closer; the least
    effort's 7.5e-8 on this mesh) and the replay closing (<= 1e-6; 1.1e-8 seen)."""
    from walkerlab.optimal.transcription.mode_sequence import collocate_phases
    from walkerlab.optimal.transcription.step import CollocationSpec
    from walkerlab.optimal.transcription.stride import replay_stride, step_of

    _scene, data, _walker, g, fns = asym
    res = collocate_phases(fns, CollocationSpec(intervals=40, objective="cost_of_transport",
                                                cost_of_transport_effort_weight=1e-2),
                           _guess(asym))
    assert res.status == "Solve_Succeeded"
    assert res.terms["cost_of_transport"] <= 1e-10
    assert np.max(np.abs(res.u)) < 1e-3
    periods = [step_of(res, k).step_period_s for k in (0, 1)]
    np.testing.assert_allclose(periods, g.step_periods, rtol=1e-4, atol=0)
    assert replay_stride(data, res)[0] <= 1e-6


@pytest.fixture(scope="module")
def fast(asym):
    """The least-effort stride at 0.6 m/s (the passive gait: 0.528 m/s) on 40 intervals a
    step from the passive stride, and its spec."""
    from walkerlab.optimal.transcription.mode_sequence import collocate_phases
    from walkerlab.optimal.transcription.step import CollocationSpec

    spec = CollocationSpec(intervals=40, target_speed_m_per_s=0.6)
    return spec, collocate_phases(asym[4], spec, _guess(asym))


def _replayed_cost_of_transport(data, res):
    """The cost of transport of ``res`` from its rigid replay, independent of the
    transcription's CasADi terms: the hip's positive work ``int max(tau d(delta)/dt, 0)
    dt`` along the replayed stride (each step's torque of time, ``delta`` the hip angle of
    its own walker's generated code; the trapezoidal rule on 20001 points a phase) over
    ``M g`` and the stride's distance (each step's length between the feet of the rigid
    model's points at its heel strike)."""
    from walkerlab.analysis.gait.poincare import poincare_map
    from walkerlab.integrate.solver import Solver
    from walkerlab.optimal.transcription.mode_sequence import phase_torque_of_time
    from walkerlab.optimal.transcription.stride import step_of, stride_walker

    w, segs = stride_walker(data, res), []
    poincare_map(w, np.asarray(res.x[0], float), Solver(method="DOP853", rtol=1e-12,
                                                        atol=1e-12),
                 max_step_time=3.0 * res.step_period_s, steps=segs)
    work, distance = 0.0, 0.0
    for k, (seg, wk) in enumerate(zip(segs, (w, w.mirror))):
        tau = phase_torque_of_time(step_of(res, k))
        for _ph, sol, (a, b) in seg.pieces:
            t = np.linspace(a, b, 20001)
            X = np.asarray(sol(t), float)[:4]
            rate = np.array([wk.actuators.hip_angles(X[:, j])[1] for j in range(t.size)])
            u = np.array([tau(tj - seg.t_start) for tj in t])
            work += np.trapezoid(np.maximum(u * rate, 0.0), t)
        pts = wk.points(wk.layout().state_rows(np.asarray(seg.x_end, float)[:, None]))
        distance += float(np.linalg.norm(np.ravel(pts["swing_foot"])
                                         - np.ravel(pts["stance_foot"])))
    return work / (float(data.total_mass_kg) * float(data.gravity_m_per_s2) * distance)


@pytest.mark.slow
def test_the_least_cost_of_transport_stride_at_a_target_speed(asym, fast):
    """At 0.6 m/s with the effort weight 1e-2 (~15 s: 72 IPOPT iterations, the replay and
    the independent work integral): the stride's mean speed is met, its cost of transport
    is positive and below the least-effort stride's (0.00330 vs 0.00378 seen), the replay
    closes (<= 1e-6; 5.5e-8 seen), and the cost of transport from the rigid replay's own
    power and step lengths is the stored one within 1e-3 relative (1.6e-4 seen: Simpson on
    ``max(p, 0)`` at the points, whose kinks where the power changes sign cost O(h^2))."""
    from dataclasses import replace as with_

    from walkerlab.optimal.transcription.mode_sequence import collocate_phases
    from walkerlab.optimal.transcription.stride import replay_stride, step_of

    _scene, data, _walker, _g, fns = asym
    spec, least_effort = fast
    res = collocate_phases(fns, with_(spec, objective="cost_of_transport",
                                      cost_of_transport_effort_weight=1e-2), _guess(asym))
    assert res.status == "Solve_Succeeded"
    cot = res.terms["cost_of_transport"]
    assert 1e-4 < cot < 0.95 * least_effort.terms["cost_of_transport"]
    lengths = [float(fns["phases"][2 * k + 1].step(step_of(res, k).x[-1])) for k in (0, 1)]
    assert sum(lengths) / res.step_period_s == pytest.approx(0.6, rel=1e-9)
    assert replay_stride(data, res)[0] <= 1e-6
    assert _replayed_cost_of_transport(data, res) == pytest.approx(cot, rel=1e-3)


def _cone_ratios(data, res):
    """``F_t / F_n`` and ``F_n`` [N] at every point of the stride ``res`` from the rigid
    model (Newton-Euler with each step's own walker and torqued flow), not the CasADi."""
    tw, cur = _torqued_pair(data)
    bounds = list(res.phase_start) + [res.t.size]
    out = []
    for p, (a, b) in enumerate(zip(bounds[:-1], bounds[1:])):
        w = tw if p < 2 else tw.mirror
        for k in range(a, b):
            cur["u"] = float(res.u[k])
            F = _newton_euler(w, data, res.x[k], w.phases[p % 2].flow(0.0, res.x[k])[2:])
            out.append((F[1] / F[0], F[0]))
    return np.array(out)


@pytest.mark.slow  # in `pytest -m slow`: the quick suite keeps to its CPU budget
def test_a_friction_cone_that_binds_changes_the_stride_and_it_replays(asym, fast):
    """The least-effort stride at 0.6 m/s needs |F_t| / F_n up to 0.1785 (leg B's step,
    at its heel strike; from the rigid model); with mu = 0.9 of that the cone binds in
    every phase of both steps (the largest ratio is mu to 1e-7 relative: 4e-10 seen), the
    effort rises (1.514 -> 1.584 N^2 m^2 s seen), the normal force stays positive, the
    speed is met and the replay closes (<= 1e-6; 1.0e-7 seen)."""
    from dataclasses import replace as with_

    from walkerlab.optimal.transcription.mode_sequence import collocate_phases
    from walkerlab.optimal.transcription.stride import replay_stride

    _scene, data, _walker, _g, fns = asym
    spec, free = fast
    mu_free = np.max(np.abs(_cone_ratios(data, free)[:, 0]))
    assert 0.15 < mu_free < 0.2
    mu = 0.9 * mu_free
    res = collocate_phases(fns, with_(spec, friction_coefficient=mu), _guess(asym))
    assert res.status == "Solve_Succeeded"
    r = _cone_ratios(data, res)
    assert np.max(np.abs(r[:, 0])) == pytest.approx(mu, rel=1e-7)
    assert np.min(r[:, 1]) > 0.0
    assert res.objective > 1.02 * free.objective
    assert res.terms["effort"] == pytest.approx(res.objective, rel=1e-12)
    lengths = [float(fns["phases"][p].step(res.x[k - 1])) for p, k in
               ((1, res.phase_start[2]), (3, res.t.size))]
    assert sum(lengths) / res.step_period_s == pytest.approx(0.6, rel=1e-9)
    assert replay_stride(data, res)[0] <= 1e-6


def _as_artifact(res, walker, path, scene):
    """The stride ``res`` written as an ``optimize.h5`` at ``path`` (its states, torque and
    phases: what :func:`walkerlab.io.schemas.optimize.load` reads back)."""
    from walkerlab.io.artifacts import write_artifact
    from walkerlab.io.schemas import optimize as schema

    names = list(walker.state_names())
    d = schema.OptimizeData(res.t, {n: res.x[:, k] for k, n in enumerate(names)}, res.u,
                            res.step_period_s / 2, 0.35, 0.0, res.objective, 1e-9,
                            np.zeros(4, complex), True, res.status, res.iterations, 0.1,
                            dict.fromkeys(names, "-"), phase_names=res.phase_names,
                            phase_start=res.phase_start,
                            phase_duration_s=res.phase_duration_s, steps=2)
    write_artifact(path, schema.STAGE, scene, "x", lambda f: schema.write(f, d), 0.0)
    return d


def _with_guess(scene, guess: dict):
    d = scene.model_dump(mode="json", exclude_none=True)
    d["optimize"]["initial_guess"] = guess
    return type(scene).model_validate(d)


def test_a_stride_starts_from_another_strides_optimize_h5(asym, fast, tmp_path):
    """``optimize.initial_guess`` naming a converged stride's optimize.h5 (the 0.6 m/s
    least effort): its four phases' states and torque come back exactly (the same mesh,
    2 x 40 intervals), IPOPT's first iterate is the optimum (its objective to 1e-9; 0 from
    the passive stride, whose torque is 0) and it returns to the same objective (1e-9) in
    a few iterations with the barrier started small (``warm_start``, as the scene does for
    an optimize.h5 guess; with IPOPT's default 0.1: 11, against 12 from the passive
    stride, the start left for the central path)."""
    from walkerlab.optimal.driver import starting_stride
    from walkerlab.optimal.transcription.mode_sequence import collocate_phases

    scene, _data, walker, g, fns = asym
    spec, free = fast
    path = tmp_path / "optimize.h5"
    _as_artifact(free, walker, path, scene)
    guess, torque = starting_stride(_with_guess(scene, {"from": str(path)}), walker, g.x,
                                    g.step_period, 40)
    np.testing.assert_array_equal(np.concatenate([x for _n, _t, x in guess]), free.x)
    np.testing.assert_array_equal(np.concatenate(torque), free.u)
    again = collocate_phases(fns, replace(spec, warm_start=True), guess, torque)
    assert again.status == "Solve_Succeeded"
    assert again.objective == pytest.approx(free.objective, rel=1e-9)
    assert again.history["objective"][0] == pytest.approx(free.objective, rel=1e-9)
    assert again.iterations <= min(8, free.iterations)


def test_a_stride_starts_from_a_continuation_gait_and_refuses_other_artifacts(asym, fast,
                                                                             tmp_path):
    """A continuation artifact's branch at ``at`` gives the stride map's start there: one
    stride of the rigid walker and its mirror simulated from it (the scene's own gait's at
    its slope: the same guess to 1e-12); a one-step optimize.h5 (no phases) and another
    walker's (other states) are refused in one line naming ``optimize.initial_guess``."""
    from tests.test_optimize_phased_terms import _continuation
    from walkerlab.optimal.driver import starting_stride

    scene, _data, walker, g, _fns = asym
    names = list(walker.state_names())
    slope = scene.slope.phi_rad
    cpath = tmp_path / "continuation_slope.h5"
    _continuation(cpath, scene, names, [slope - 0.001, slope + 0.001], np.array([g.x, g.x]),
                  [g.step_period] * 2)
    got, torque = starting_stride(_with_guess(scene, {"from": str(cpath), "at": slope}),
                                  walker, np.zeros(4), g.step_period, 40)
    assert torque is None
    for (n1, t1, x1), (n2, t2, x2) in zip(got, _guess(asym), strict=True):
        assert n1 == n2
        np.testing.assert_allclose(t1, t2, rtol=0, atol=1e-12)
        np.testing.assert_allclose(x1, x2, rtol=0, atol=1e-12)
    path = tmp_path / "optimize.h5"
    d = _as_artifact(fast[1], walker, path, scene)
    d.phase_names, d.phase_start = (), None  # a one-step optimisation
    from walkerlab.io.artifacts import write_artifact
    from walkerlab.io.schemas import optimize as schema

    write_artifact(path, schema.STAGE, scene, "x", lambda f: schema.write(f, d), 0.0)
    other = tmp_path / "other.h5"
    d = _as_artifact(fast[1], walker, other, scene)
    d.states = {f"{n}_2": v for n, v in d.states.items()}  # another walker's states
    d.state_units = dict.fromkeys(d.states, "-")
    write_artifact(other, schema.STAGE, scene, "x", lambda f: schema.write(f, d), 0.0)
    for p, why in ((path, "has no phases"), (other, "are not the walker's")):
        with pytest.raises(ValueError, match="optimize.initial_guess") as e:
            starting_stride(_with_guess(scene, {"from": str(p)}), walker, g.x, g.step_period,
                            40)
        assert why in str(e.value) and "\n" not in str(e.value)


@pytest.mark.slow
def test_the_stride_scene_takes_the_cost_of_transport_a_cone_and_a_guess(asym, fast,
                                                                          tmp_path):
    """``optimize_scene`` on the shipped scene (60 intervals a step) asking the least cost of
    transport at 0.6 m/s (effort weight 1e-2) inside a friction cone that does not bind
    (mu 0.5), started from the 40-interval least-effort stride's optimize.h5 (resampled to
    2 x 60): a gait (the replay <= 1e-6), the stored terms those of the optimum, the mean
    speed met, the cone kept at every point (from the rigid model), its four phases stored
    (~25 s: the CasADi build, IPOPT, the replays and two contact strides)."""
    from walkerlab.optimal.driver import optimize_scene
    from walkerlab.optimal.transcription.stride import STRIDE_PHASES

    scene, data, walker, g, _fns = asym
    path = tmp_path / "optimize.h5"
    _as_artifact(fast[1], walker, path, scene)
    d = scene.model_dump(mode="json", exclude_none=True)
    d["optimize"].update(objective="cost_of_transport", cost_of_transport_effort_weight=1e-2,
                         target_speed_m_per_s=0.6, friction_coefficient=0.5,
                         initial_guess={"from": str(path)})
    sc = type(scene).model_validate(d)
    out = optimize_scene(sc, g.x, g.step_period, plant=Plant.from_scene(sc))
    assert out.gait and out.replay_error <= 1e-6 and out.status == "Solve_Succeeded"
    assert out.objective_name == "cost_of_transport"
    assert out.objective == pytest.approx(out.terms["cost_of_transport"]
                                          + 1e-2 * out.terms["effort"], rel=1e-9)
    assert 1e-4 < out.terms["cost_of_transport"] < 1e-2
    assert out.step_length_m / out.step_period_s == pytest.approx(0.6, rel=1e-9)
    assert tuple(out.phase_names) == STRIDE_PHASES
    assert np.sum(np.diff([*out.phase_start, out.time.size]) // 2) == 120
    X = np.stack(list(out.states.values()), axis=1)
    res = SimpleNamespace(x=X, u=out.torque, t=out.time, phase_start=out.phase_start)
    assert np.max(np.abs(_cone_ratios(data, res)[:, 0])) <= 0.5 + 1e-9


@pytest.mark.slow
def test_the_least_effort_stride_on_two_footholds_is_the_passive_gait_there():
    """configs/asymmetric_optimal.yaml on footholds +0.5 mm and -0.5 mm (leg A's step lands
    on the first, leg B's on the second: :func:`walkerlab.models.hybrid.ground.
    on_footholds`' order; 40 intervals a step): the passive stride there is feasible, so
    the least effort is it - effort <= 1e-10 N^2 m^2 s (seen 4e-23), the start within 1e-6
    of the fixed point found by shooting, the replay on the footholds closing to 1e-6
    (seen 7.2e-9).  The raised foothold's guard is not kept inside late swing (the planar
    swing foot is level with the stance foot as the legs cross, 0.5 mm below that
    landing: the scuff the rigid model ignores); kept, the passive gait was infeasible and
    the optimum cost 0.11 N^2 m^2 s."""
    pytest.importorskip("casadi")
    from walkerlab.analysis.gait.scene import solve_scene
    from walkerlab.optimal.driver import optimize_scene

    scene = load_scene(CONFIGS / "asymmetric_optimal.yaml")
    d = scene.model_dump(mode="json", exclude_none=True)
    d["terrain"] = {"kind": "footholds", "foothold_heights_m": [0.0005, -0.0005]}
    d["optimize"] = {"objective": "effort", "intervals": 40}
    scene = type(scene).model_validate(d)
    plant = Plant.from_scene(scene)
    _, search = solve_scene(scene, plant=plant)
    r = search.gaits[search.selected].result
    out = optimize_scene(scene, np.asarray(r.x, float), float(r.period_s) / 2, plant=plant)
    assert out.status == "Solve_Succeeded" and out.gait, (out.status, out.replay_error)
    assert out.objective <= 1e-10, out.objective
    x0 = np.array([v[0] for v in out.states.values()])
    np.testing.assert_allclose(x0, r.x, atol=1e-6)
    assert out.replay_error <= 1e-6
