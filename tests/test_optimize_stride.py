"""A walker whose legs differ optimised over one stride (``walkerlab.optimal.stride``):
configs/asymmetric_optimal.yaml (the paper's walker with leg masses 5 / 5.5 kg, slope
0.0174 rad, a hip torque).  Its CasADi phases are the rigid model's and its mirror's, its
least-effort stride is the passive period-2 gait found independently by shooting
(``fixedpoint``: the stride map's fixed point), a powered stride replays on the rigid model,
and what the transcription does not take is refused in one line."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from walkerlab.config import load_scene
from walkerlab.config.actuation import Actuation, JointTorque, TorqueLaw
from walkerlab.models.hybrid.actuated import actuate
from walkerlab.models.hybrid.rigid import make_rigid_walker
from walkerlab.walker.description import walker_data

CONFIGS = Path(__file__).resolve().parents[1] / "configs"


@pytest.fixture(scope="module")
def asym():
    """(scene, data, rigid walker, passive gait, CasADi stride) built once."""
    pytest.importorskip("casadi")
    from types import SimpleNamespace

    from walkerlab.analysis.gait.scene import solve_scene
    from walkerlab.optimal.stride import stride_functions

    scene = load_scene(CONFIGS / "asymmetric_optimal.yaml")
    data = walker_data(scene.walker, scene.slope.phi_rad)
    _, search = solve_scene(scene)  # the fixedpoint stage's search: the stride map's
    r = search.gaits[search.selected].result
    g = SimpleNamespace(x=np.asarray(r.x, float), step_period=r.period_s / 2,
                        step_periods=np.asarray(r.step_periods_s, float),
                        multipliers=np.asarray(r.multipliers_variational, complex))
    return scene, data, make_rigid_walker(data), g, stride_functions(data)


def _guess(asym, intervals: int = 40):
    from walkerlab.integrate.solver import Solver
    from walkerlab.optimal.stride import stride_guess

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
    from walkerlab.optimal.collocation import CollocationSpec
    from walkerlab.optimal.phased_collocation import collocate_phases
    from walkerlab.optimal.phased_scene import replay_multipliers
    from walkerlab.optimal.stride import replay_stride, step_of

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
    from walkerlab.optimal.collocation import CollocationSpec
    from walkerlab.optimal.phased_collocation import collocate_phases
    from walkerlab.optimal.stride import replay_stride, step_of

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


def test_what_the_stride_does_not_take_is_refused_in_one_line(asym):
    """Objectives other than effort / peak torque, a push-off, friction, another guess:
    refused in one line naming the field (before any work); one step of legs that differ
    stays refused by the one-step transcription."""
    from walkerlab.optimal.collocation import step_functions
    from walkerlab.optimal.scene import optimize_scene

    scene, data, _walker, g, _fns = asym
    for field, value, says in (("objective", "cost_of_transport", "optimize.objective"),
                               ("push_off", "free", "optimize.push_off"),
                               ("friction_coefficient", 0.8, "optimize.friction_coefficient"),
                               ("initial_guess", {"from": "x.h5"}, "optimize.initial_guess")):
        d = scene.model_dump(mode="json", exclude_none=True)
        d["optimize"][field] = value
        bad = type(scene).model_validate(d)
        with pytest.raises(ValueError, match=says) as exc:
            optimize_scene(bad, g.x, g.step_period)
        assert "\n" not in str(exc.value)
    with pytest.raises(ValueError, match="legs that differ take a stride"):
        step_functions(data, None)
    with pytest.raises(ValueError, match="a stride is for legs that differ"):
        from walkerlab.optimal.stride import stride_functions

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
