"""``walkerlab optimize`` of the 3D straight legs (Kuo 1999's walker: roll and pitch, hip
width, hip-roll joints and their foot-placement law): the planar straight legs'
collocation (:mod:`walkerlab.optimal.transcription.step`, a stride of
:mod:`walkerlab.optimal.transcription.stride` when the steps alternate sides) on the
equations of :func:`walkerlab.codegen.derive_3d.derive_compass`.

Checked against what the collocation does not compute itself: its CasADi flow, heel
strike, push-off and ground reaction against the rigid model's generated code and its
floating view (:class:`walkerlab.models.hybrid.ground_reaction.StanceReaction`), and its
least-effort gait on a passive slope against the gait ``walkerlab fixedpoint`` finds by
shooting (configs/paper_3d.yaml: one step, zero hip width; configs/hip_width_optimal.yaml:
a stride, the hip-roll law in the walker's equations)."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from walkerlab.config import load_scene
from walkerlab.config.actuation import Actuation, JointTorque, PushOff, TorqueLaw
from walkerlab.models.hybrid.actuated import actuate
from walkerlab.models.hybrid.rigid import make_rigid_walker
from walkerlab.walker.description import walker_data
from walkerlab.walker.plant import Plant

CONFIGS = Path(__file__).resolve().parents[1] / "configs"


def _scene(name: str, **optimize):
    """The shipped scene with ``optimize`` (merged into its own section)."""
    scene = load_scene(CONFIGS / f"{name}.yaml")
    d = scene.model_dump(mode="json", exclude_none=True)
    d["optimize"] = {**d.get("optimize", {}), **optimize}
    return type(scene).model_validate(d)


def _guess_of(scene) -> np.ndarray:
    """The scene's ``fixedpoint.initial_guess`` as a state (2n,) [rad, rad/s]."""
    g = scene.fixedpoint.initial_guess.model_dump()
    w = make_rigid_walker(walker_data(scene.walker, scene.slope.phi_rad))
    return np.array([g.get(f"{k}_rad", g.get(f"{k}_rad_per_s", 0.0))
                     for k in w.state_names()], float)


def _states(scene, rng, n: int = 4):
    """``n`` states near the scene's fixed-point guess (its ``fixedpoint.initial_guess``)."""
    x0 = _guess_of(scene)
    return [x0 + rng.normal(0.0, 0.02, x0.size) for _ in range(n)]


@pytest.mark.slow
@pytest.mark.parametrize("name", ["paper_3d", "hip_width_powered"])
def test_the_3d_collocation_functions_are_the_rigid_models(name):
    """At states near the gait, against the rigid model's generated code (not the CasADi
    expressions): the flow with a hip torque of 0.7 N m, the heel strike, the heel strike
    after a 0.8 N s push-off (the extended impact along the trailing leg to its own hip)
    and the stance foot's ground reaction (the rigid model's floating view, Newton's rows):
    round-off (1e-9; the reaction 1e-6 N of ~200 N: the floating view's accelerations by
    differences).  paper_3d: one step's functions (zero hip width); hip_width_powered: the
    stride's first step (hip width, the hip-roll law)."""
    pytest.importorskip("casadi")
    from walkerlab.models.hybrid.ground_reaction import StanceReaction
    from walkerlab.optimal.transcription.step_cache import (
        cached_mode_functions,
        cached_step_functions,
    )
    from walkerlab.optimal.transcription.stride import STEP_PHASES

    scene = load_scene(CONFIGS / f"{name}.yaml")
    data = walker_data(scene.walker, scene.slope.phi_rad)
    if data.mirror is None:
        f = cached_step_functions(data)
        flow, grf = f["flow"], f["grf"]
        reset = lambda x, P: f["reset"](x, P)  # noqa: E731
    else:  # the stride's first step (its late swing ends in the heel strike)
        d = replace(data, mirror_params=None)
        data = d
        late = cached_mode_functions(d, None, list(STEP_PHASES))["phases"][-1]
        flow, grf = late.flow, late.grf
        reset = lambda x, P: late.push_off(x, P)[0]  # noqa: E731
    passive = make_rigid_walker(data)
    torqued = actuate(passive, data, Actuation(torques=[JointTorque(
        joint="hip", law=TorqueLaw(constant_n_m=0.7))]))
    pushed = actuate(passive, data, Actuation(push_off=PushOff(impulse_n_s=0.8)))
    reaction = StanceReaction(passive, data)
    phi = data.slope_rad
    axes = np.array([[np.sin(phi), np.cos(phi), 0.0], [np.cos(phi), -np.sin(phi), 0.0],
                     [0.0, 0.0, 1.0]])
    for x in _states(scene, np.random.default_rng(3)):
        np.testing.assert_allclose(flow(x, 0.7).full().ravel(),
                                   torqued.phases[-1].flow(0.0, x), atol=1e-9)
        np.testing.assert_allclose(reset(x, 0.0).full().ravel(), passive.reset(x), atol=1e-9)
        np.testing.assert_allclose(reset(x, 0.8).full().ravel(), pushed.reset(x), atol=1e-9)
        F = reaction.force(0.0, x, passive.phases[-1].flow)
        np.testing.assert_allclose(grf(x, 0.0).full().ravel(), axes @ F, atol=1e-6)


@pytest.mark.slow
@pytest.mark.parametrize(("name", "intervals"), [("paper_3d", 60),
                                                 ("hip_width_optimal", 60)])
def test_the_least_effort_3d_gait_on_its_passive_slope_is_its_passive_gait(name, intervals):
    """int u^2 dt = 0 at the gait that walks without the hip torque, so the optimum is it
    (with hip-roll joints: the gait under the foot-placement law, part of the walker's
    equations): IPOPT converged, objective <= 1e-10 N^2 m^2 s, the start within 1e-6 of
    the fixed point ``walkerlab fixedpoint`` finds by shooting (Hermite-Simpson's O(h^4):
    seen 2.3e-8 (paper_3d) and 9.1e-7 (hip width) on 40 intervals a step, 1.8e-7 (hip
    width) on 60), each step's
    period within 1e-7 relative and the replay on the rigid model closing to 1e-6."""
    pytest.importorskip("casadi")
    from walkerlab.analysis.gait.scene import solve_scene
    from walkerlab.optimal.driver import optimize_scene

    scene = _scene(name, intervals=intervals, objective="effort")
    plant = Plant.from_scene(scene)
    _, search = solve_scene(scene, plant=plant)
    r = search.gaits[search.selected].result
    periods = np.asarray(r.step_periods_s, float)
    out = optimize_scene(scene, np.asarray(r.x, float), float(r.period_s) / len(periods),
                         plant=plant)
    assert out.status == "Solve_Succeeded" and out.gait, (out.status, out.replay_error)
    assert out.objective <= 1e-10
    x0 = np.array([v[0] for v in out.states.values()])
    np.testing.assert_allclose(x0, r.x, atol=1e-6)
    assert out.step_period_s == pytest.approx(periods.mean(), rel=1e-7)
    assert out.replay_error <= 1e-6


def test_a_3d_walker_on_footholds_is_refused_before_any_stage(tmp_path):
    """The 3D straight legs' optimize cell that cannot hold - footholds (the stride of two
    mirrored steps lands both at one depth; which leg lands on which foothold is part of a
    gait on footholds of several heights) - is refused in one line before fixedpoint runs,
    with the capability table's reason."""
    import yaml
    from typer.testing import CliRunner

    from walkerlab.cli import app
    from walkerlab.walker.capability_cells import FOOTHOLDS_OPTIMIZE_3D

    d = yaml.safe_load((CONFIGS / "hip_width_footholds.yaml").read_text())
    d["optimize"] = {"objective": "effort", "intervals": 40}
    scene = tmp_path / "footholds_3d.yaml"
    scene.write_text(yaml.safe_dump(d))
    r = CliRunner().invoke(app, ["optimize", str(scene), "--runs-dir", str(tmp_path / "r")])
    assert r.exit_code != 0 and r.output.count("error:") == 1, r.output
    assert FOOTHOLDS_OPTIMIZE_3D[:40] in " ".join(r.output.split()), r.output
    assert "Traceback" not in r.output
    assert not list((tmp_path / "r").rglob("*.h5"))


def test_a_3d_walkers_disc_feet_are_refused_before_any_stage(tmp_path):
    """configs/round_feet_3d.yaml (disc feet in each leg's plane) with an optimize section:
    refused in one line naming walker.foot_radius_m, with the capability table's reason
    (the collocation's heel strike is the extended impact system, which the disc foot's
    equations do not have), before fixedpoint runs."""
    import yaml
    from typer.testing import CliRunner

    from walkerlab.cli import app
    from walkerlab.walker.capability_cells import ROUND_FEET_OPTIMIZE_3D

    d = yaml.safe_load((CONFIGS / "round_feet_3d.yaml").read_text())
    d["optimize"] = {"objective": "effort", "intervals": 40}
    scene = tmp_path / "discs.yaml"
    scene.write_text(yaml.safe_dump(d))
    r = CliRunner().invoke(app, ["optimize", str(scene), "--runs-dir", str(tmp_path / "r")])
    out = " ".join(r.output.split())
    assert r.exit_code != 0 and r.output.count("error:") == 1, r.output
    assert "walker.foot_radius_m" in out and ROUND_FEET_OPTIMIZE_3D[:50] in out, r.output
    assert not list((tmp_path / "r").rglob("*.h5"))


@pytest.mark.slow
def test_a_powered_3d_stride_on_level_ground_replays_on_the_rigid_model():
    """configs/hip_width_powered.yaml's walker (hip width, the hip-roll law) on level ground,
    where it has no passive gait: a hip torque and a free push-off at 0.5 m/s, least effort
    (``int u^2 dt + P^2`` a strike), from its pushed gait on its 0.0174 rad slope (40
    intervals a step).  Seen: IPOPT converged in 23 iterations, the push-off 2.906 N s, the
    stride 1.080 s, a peak hip torque 3.83 N m, the replay on the rigid model (its
    generated code, the push-off's extended impact, the mirror step) closing to 3.9e-7;
    gate 1e-6, the scene's replay tolerance."""
    pytest.importorskip("casadi")
    import yaml

    from walkerlab.integrate.solver import Solver
    from walkerlab.optimal.transcription.mode_sequence import collocate_phases
    from walkerlab.optimal.transcription.step import CollocationSpec
    from walkerlab.optimal.transcription.stride import (
        replay_stride,
        step_of,
        stride_functions,
        stride_guess,
    )

    raw = yaml.safe_load((CONFIGS / "hip_width_powered.yaml").read_text())
    scene = load_scene(CONFIGS / "hip_width_powered.yaml")
    data = walker_data(scene.walker, scene.slope.phi_rad)
    walker = actuate(make_rigid_walker(data), data, scene.walker.actuation)
    x0 = _guess_of(scene)
    guess = stride_guess(walker, x0, 0.70, Solver.from_settings(scene.solver), 40)
    raw["slope"] = {"angle_rad": 0.0}
    level = type(scene).model_validate(raw)
    ldata = walker_data(level.walker, 0.0)
    spec = CollocationSpec(intervals=40, push_off_free=True, push_off_n_s=1.0,
                           target_speed_m_per_s=0.5)
    res = collocate_phases(stride_functions(ldata), spec, guess)
    assert res.status == "Solve_Succeeded"
    assert 0.0 < res.push_off_n_s < spec.push_off_max_n_s and np.max(np.abs(res.u)) > 0.1
    steps = [step_of(res, k).step_period_s for k in (0, 1)]
    assert sum(steps) == pytest.approx(res.step_period_s, rel=1e-12)
    err, _walker = replay_stride(ldata, res)
    assert err <= 1e-6
