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


def _least_effort(name: str, intervals: int):
    """The shipped scene's least-effort optimum on ``intervals`` a step, started from the
    gait ``walkerlab fixedpoint`` finds by shooting: ``(optimize's result, that gait's
    search result, its step periods [s])``."""
    from walkerlab.analysis.gait.scene import solve_scene
    from walkerlab.optimal.driver import optimize_scene

    scene = _scene(name, intervals=intervals, objective="effort")
    plant = Plant.from_scene(scene)
    _, search = solve_scene(scene, plant=plant)
    r = search.gaits[search.selected].result
    periods = np.asarray(r.step_periods_s, float)
    out = optimize_scene(scene, np.asarray(r.x, float), float(r.period_s) / len(periods),
                         plant=plant)
    return out, r, periods


def _assert_passive(out, r, periods, objective: float) -> None:
    """The least-effort optimum ``out`` is the passive gait ``r`` (``walkerlab fixedpoint``'s,
    its step periods ``periods`` [s]): IPOPT converged, the objective at most ``objective``
    [N^2 m^2 s], the start within 1e-6 of the fixed point, the mean step period within
    1e-7 relative and the replay on the rigid model closing to 1e-6."""
    assert out.status == "Solve_Succeeded" and out.gait, (out.status, out.replay_error)
    assert out.objective <= objective, out.objective
    x0 = np.array([v[0] for v in out.states.values()])
    np.testing.assert_allclose(x0, r.x, atol=1e-6)
    assert out.step_period_s == pytest.approx(periods.mean(), rel=1e-7)
    assert out.replay_error <= 1e-6


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
@pytest.mark.parametrize("name", ["paper_3d", "hip_width_powered", "torso_bhm_3d_stabilised",
                                  "round_feet_3d"])
def test_the_3d_collocation_functions_are_the_rigid_models(name):
    """At states near the gait, against the rigid model's generated code (not the CasADi
    expressions): the flow with a hip torque of 0.7 N m, the heel strike, the heel strike
    after a 0.8 N s push-off (the extended impact along the trailing leg to its own hip)
    and the stance foot's ground reaction (the rigid model's floating view, Newton's rows):
    round-off (1e-9; the reaction 1e-6 N of ~200 N: the floating view's accelerations by
    differences).  paper_3d: one step's functions (zero hip width); hip_width_powered: the
    stride's first step (hip width, the hip-roll law); torso_bhm_3d_stabilised: the same
    with a 5 kg upper body on the bisecting hip (its mass in the reaction's momentum);
    round_feet_3d: disc feet (the push-off at the trailing disc's material contact point,
    the rigid model's checked against Newton-Euler's in tests/test_round_feet_3d.py)."""
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
                                                 ("hip_width_optimal", 60),
                                                 ("torso_bhm_3d_stabilised", 60),
                                                 ("round_feet_3d", 60)])
def test_the_least_effort_3d_gait_on_its_passive_slope_is_its_passive_gait(name, intervals):
    """int u^2 dt = 0 at the gait that walks without the hip torque, so the optimum is it
    (with hip-roll joints: the gait under the foot-placement law, part of the walker's
    equations): IPOPT converged, objective <= 1e-10 N^2 m^2 s, the start within 1e-6 of
    the fixed point ``walkerlab fixedpoint`` finds by shooting (Hermite-Simpson's O(h^4):
    seen 2.3e-8 (paper_3d) and 9.1e-7 (hip width) on 40 intervals a step, 1.8e-7 (hip
    width) on 60), each step's
    period within 1e-7 relative and the replay on the rigid model closing to 1e-6.  With an
    upper body on the bisecting hip (torso_bhm_3d_stabilised, Wisse, Hobbelen & Schwab
    2007) the same: the upper body is part of the walker's equations, not an input.  On
    disc feet (round_feet_3d, McGeer's round feet in 3D) the heel strike is the extended
    impact at the leading disc's material contact point."""
    pytest.importorskip("casadi")
    out, r, periods = _least_effort(name, intervals)
    _assert_passive(out, r, periods, 1e-10)


@pytest.mark.slow
def test_the_3d_kneed_strides_functions_are_the_rigid_models():
    """The 3D kneed walker's stride (configs/kneed_3d_stabilised.yaml: locking knees, hip
    width, hip-roll joints and Kuo's law) goes through each step's rigid phases - unlocked
    swing, knee strike, locked swing, heel strike - leg A's with the walker's numbers, leg
    B's with its mirror's: each phase's CasADi flow (with a hip torque between the thighs)
    is the rigid model's actuated flow and its reset the rigid model's, for both legs."""
    pytest.importorskip("casadi")
    from walkerlab.optimal.transcription.phases import phase_order
    from walkerlab.optimal.transcription.stride import stride_functions, stride_phases

    scene = _scene("kneed_3d_stabilised")
    data = walker_data(scene.walker, scene.slope.phi_rad)
    order = phase_order(make_rigid_walker(data))
    assert [p for p, _g, _d in order] == ["unlocked_swing", "locked_swing"]
    fns = stride_functions(data, order=order)
    assert tuple(p.name for p in fns["phases"]) == stride_phases(order)
    x = _guess_of(scene)
    rng = np.random.default_rng(5)
    for k, d in enumerate((replace(data, mirror_params=None), data.mirror)):
        w = actuate(make_rigid_walker(d), d, Actuation(torques=[JointTorque(
            joint="hip", law=TorqueLaw(constant_n_m=0.3))]))
        for ph, rigid in zip(fns["phases"][2 * k:2 * k + 2], w.phases):
            for _ in range(3):
                xs = x + 0.05 * rng.standard_normal(x.size)
                if ph.name.endswith("locked_swing") and "unlocked" not in ph.name:
                    xs[2], xs[8] = xs[1], xs[7]  # the swing knee locked straight
                np.testing.assert_allclose(ph.flow(xs, 0.3).full().ravel(),
                                           rigid.flow(0.0, xs), atol=1e-9)
        np.testing.assert_allclose(fns["phases"][2 * k + 1].reset(x).full().ravel(),
                                   w.reset(x), atol=1e-9)


@pytest.mark.slow
def test_the_3d_kneed_strides_push_off_reset_is_the_rigid_models_for_both_legs():
    """The 3D kneed stride's heel strikes after a push-off ``P`` (configs/kneed_3d.yaml,
    the push-off cell's walker: the extended impact in world axes along the trailing leg to
    its own hip, the swing knee held, in CasADi) against the rigid model's transition with
    that push-off, leg A's with the walker's numbers and leg B's with its mirror's, at
    states about its gait and random impulses: the post-impact state to 1e-10, the
    push-off's work to the rigid transition's kinetic energy gain (1e-10 J)."""
    pytest.importorskip("casadi")
    from walkerlab.optimal.transcription.phases import phase_order
    from walkerlab.optimal.transcription.stride import stride_functions

    scene = _scene("kneed_3d")
    data = walker_data(scene.walker, scene.slope.phi_rad)
    fns = stride_functions(data, order=phase_order(make_rigid_walker(data)))
    strikes = [p for p in fns["phases"] if p.guard_name == "heel_strike"]
    assert len(strikes) == 2 and all(p.push_off is not None for p in strikes)
    x = _guess_of(scene)
    rng = np.random.default_rng(7)
    for strike, d in zip(strikes, (replace(data, mirror_params=None), data.mirror)):
        for P in rng.uniform(0.0, 0.5, 3):
            acts = actuate(make_rigid_walker(d), d,
                           Actuation(push_off=PushOff(impulse_n_s=float(P)))).actuators
            xs = x + 0.05 * rng.standard_normal(x.size)
            xs[2], xs[6] = xs[1], xs[5]  # the swing knee locked straight
            x_plus, work = strike.push_off(xs, P)
            ref = acts.transition(xs)
            np.testing.assert_allclose(x_plus.full().ravel(), ref["x_plus"], rtol=0,
                                       atol=1e-10)
            assert float(work) == pytest.approx(ref["ke_push_off"] - ref["ke_minus"],
                                                abs=1e-10)


@pytest.mark.slow
def test_the_least_effort_3d_kneed_gait_on_its_passive_slope_is_its_passive_gait():
    """The 3D kneed walker with hip-roll joints (configs/kneed_3d_stabilised.yaml) as a
    stride of two phased steps: with nothing imposed the least effort is the gait that walks
    without the hip torque (the foot-placement law part of the walker's equations): IPOPT
    converged, objective <= 1e-8 N^2 m^2 s (seen 1.6e-20), the start within 1e-6 of the
    fixed point ``walkerlab fixedpoint`` finds by shooting, the mean step period within
    1e-7 relative and the replay on the rigid model closing to 1e-6.  Hermite-Simpson's
    O(h^4) in the start's distance: 7.5e-6 on 40 intervals a step, 1.5e-6 on 60, 8.2e-7 on
    70, 4.8e-7 on 80 (the replay 6.9e-7 on 60, 2.2e-7 on 80), so 80 here."""
    pytest.importorskip("casadi")
    from walkerlab.optimal.transcription.stride import stride_phases

    out, r, periods = _least_effort("kneed_3d_stabilised", 80)
    assert tuple(out.phase_names) == stride_phases([("unlocked_swing", "knee_strike", 1),
                                                    ("locked_swing", "heel_strike", -1)])
    _assert_passive(out, r, periods, 1e-8)


@pytest.mark.slow
def test_the_least_effort_3d_kneed_gait_on_disc_feet_is_its_passive_gait():
    """configs/kneed_round_feet_3d.yaml (locking knees, a disc on each shank, zero hip
    width: one step of the phased modes, unlocked swing, knee strike, locked swing, heel
    strike on the extended impact at the leading disc's material contact point, the swing
    knee held): the least effort is the passive gait, as on point feet: IPOPT converged,
    objective <= 1e-8 N^2 m^2 s, the start within 1e-6 of the fixed point ``walkerlab
    fixedpoint`` finds by shooting, the period within 1e-7 relative (4e-7 on 40
    intervals, Hermite-Simpson's O(h^4)) and the replay on the rigid model closing to
    1e-6."""
    pytest.importorskip("casadi")
    out, r, periods = _least_effort("kneed_round_feet_3d", 80)
    _assert_passive(out, r, periods, 1e-8)


@pytest.mark.parametrize("name", ["hip_width_footholds", "kneed_3d_stabilised_footholds"])
def test_a_3d_walker_on_three_footholds_is_refused_before_any_stage(tmp_path, name):
    """Footholds of three heights for the hip-width walker or the 3D kneed walker (a stride
    of two steps, each landing on its foothold; three make a period of six steps) are
    refused in one line before fixedpoint runs, naming terrain.foothold_heights_m."""
    import yaml
    from typer.testing import CliRunner

    from walkerlab.cli import app
    from walkerlab.optimal.transcription.landing import FOOTHOLDS_STRIDE

    d = yaml.safe_load((CONFIGS / f"{name}.yaml").read_text())
    d["optimize"] = {"objective": "effort", "intervals": 40}
    d["terrain"]["foothold_heights_m"] = [0.0005, -0.0005, 0.0]
    scene = tmp_path / "footholds_3d.yaml"
    scene.write_text(yaml.safe_dump(d))
    r = CliRunner().invoke(app, ["optimize", str(scene), "--runs-dir", str(tmp_path / "r")])
    assert r.exit_code != 0 and r.output.count("error:") == 1, r.output
    assert FOOTHOLDS_STRIDE[:60] in " ".join(r.output.split()), r.output
    assert "Traceback" not in r.output
    assert not list((tmp_path / "r").rglob("*.h5"))


def test_a_3d_walkers_toroidal_feet_are_refused_before_any_stage(tmp_path):
    """configs/collins2001.yaml (feet curved in both directions, whose travel along the fall
    line is no function of the configuration) with an optimize section: refused in one line
    naming walker.leg.foot.kind, with the capability table's reason, before fixedpoint
    runs (disc feet, lateral_radius_m 0's limit, are transcribed: the tests below)."""
    import yaml
    from typer.testing import CliRunner

    from walkerlab.cli import app
    from walkerlab.walker.capability_cells import TOROIDAL_OPTIMIZE

    d = yaml.safe_load((CONFIGS / "collins2001.yaml").read_text())
    d["optimize"] = {"objective": "effort", "intervals": 40}
    scene = tmp_path / "torus.yaml"
    scene.write_text(yaml.safe_dump(d))
    r = CliRunner().invoke(app, ["optimize", str(scene), "--runs-dir", str(tmp_path / "r")])
    out = " ".join(r.output.split())
    assert r.exit_code != 0 and r.output.count("error:") == 1, r.output
    assert "walker.leg.foot.kind" in out and TOROIDAL_OPTIMIZE[:60] in out, r.output
    assert "Traceback" not in r.output
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


def _stairs_optimum(tread_m: float | None = None):
    """configs/hip_width_stairs.yaml (treads ``tread_m`` [m] if given) optimised for least
    effort on 40 intervals a step (the capability cell's section), from its passive stair
    gait; returns ``(optimum, fixed point (2n,), mean step period [s], the passive gait's
    advance a step [m]: its swing foot's horizontal distance ahead at heel strike)``."""
    from walkerlab.analysis.gait.scene import solve_scene
    from walkerlab.integrate.rigid import simulate_steps
    from walkerlab.integrate.solver import Solver
    from walkerlab.models.hybrid.ground import on_landing
    from walkerlab.optimal.driver import optimize_scene

    scene = _scene("hip_width_stairs", intervals=40, objective="effort")
    if tread_m is not None:
        d = scene.model_dump(mode="json", exclude_none=True)
        d["terrain"]["tread_m"] = tread_m
        scene = type(scene).model_validate(d)
    plant = Plant.from_scene(scene)
    _, search = solve_scene(scene, plant=plant)
    r = search.gaits[search.selected].result
    period = float(np.mean(r.step_periods_s))
    data = walker_data(scene.walker, scene.slope.phi_rad)
    walker = on_landing(make_rigid_walker(data), data, scene.terrain.riser_m)
    run = simulate_steps(walker, np.asarray(r.x, float), 1,
                         Solver(method="DOP853", rtol=1e-12, atol=1e-12),
                         max_step_time=3.0 * period)
    advance = float(walker.points(run.segments[0].x_end)["swing_foot"][0])
    out = optimize_scene(scene, np.asarray(r.x, float), period, plant=plant)
    return out, np.asarray(r.x, float), period, advance


@pytest.mark.slow
def test_the_least_effort_3d_gait_down_stairs_is_the_passive_stair_gait():
    """The stabilised hip-width walker down stairs of its slope's step
    (configs/hip_width_stairs.yaml: riser 5.9328 mm, tread 0.34093 m), least effort: the
    stride's heel strikes land on the next tread (the planar stairs' guard
    ``swing_clearance + riser``, one tread a step) and the optimum replays on the rigid
    walker on the stairs to 1e-6 (the optimize view's tolerance; seen 7.9e-7 on 40
    intervals a step, 1.6e-7 on 60).  The passive stair gait (``walkerlab fixedpoint``)
    advances 0.3409354 m a step, 5 um more than the tread the stride holds, so on the
    shipped treads the least effort is small, not zero: seen 2.3e-7 N^2 m^2 s (peak torque
    0.6 mN m), the start 1e-4 off the passive gait.  On treads of the passive advance the
    rigid passive gait's advance (0.34093545 m) the optimum is that gait to the mesh's error:
    the effort <= 1e-9 N^2 m^2 s (seen 2.2e-10), the start within 1e-5 of the fixed point
    (seen 3.7e-6, against 1e-4 on the shipped treads), the mean step period within 1e-5
    relative (seen 3.3e-6, against 1.0e-4): the collocated passive gait advances 0.2 um
    less than the rigid one on 40 intervals (0.04 um on 60; Hermite-Simpson's O(h^4)), and
    the held tread pays for that mesh error (with the advance free: effort 1e-25, the start
    within 9.6e-7)."""
    pytest.importorskip("casadi")
    out, x_fix, period, advance = _stairs_optimum()
    assert out.status == "Solve_Succeeded" and out.gait, (out.status, out.replay_error)
    assert out.replay_error <= 1e-6
    assert out.step_length_m == pytest.approx(0.34093, abs=1e-9)
    assert 1e-8 < out.objective <= 1e-6, out.objective
    assert advance == pytest.approx(0.3409354, abs=1e-7)
    out, x_fix, period, _ = _stairs_optimum(advance)
    assert out.status == "Solve_Succeeded" and out.gait, (out.status, out.replay_error)
    assert out.replay_error <= 1e-6
    assert out.objective <= 1e-9, out.objective
    x0 = np.array([v[0] for v in out.states.values()])
    np.testing.assert_allclose(x0, x_fix, atol=1e-5)
    assert out.step_period_s == pytest.approx(period, rel=1e-5)


@pytest.mark.parametrize("heights", [[0.0], [0.0, 0.0]])
def test_footholds_at_the_stance_foots_level_are_the_plane_slopes_stride(heights):
    """Footholds of height 0 (a zero riser: stairs take risers > 0) are the plane slope:
    :func:`~walkerlab.optimal.transcription.landing.step_ground` returns None, so the stride
    is the slope's, its heel strikes the generated ``heel_strike`` guard bit for bit (not
    the landing's ``swing_clearance + 0``), and on stairs each step's is the landing's."""
    pytest.importorskip("casadi")
    from walkerlab.optimal.transcription.landing import step_ground
    from walkerlab.optimal.transcription.stride import stride_functions

    scene = _scene("hip_width_stairs", objective="effort")
    data = walker_data(scene.walker, scene.slope.phi_rad)
    d = scene.model_dump(mode="json", exclude_none=True)
    d["terrain"] = {"kind": "footholds", "foothold_heights_m": heights}
    assert step_ground(type(scene).model_validate(d)) is None
    plane = stride_functions(data)
    stairs = stride_functions(data, step_ground(scene))
    assert [p.name for p in stairs["phases"]] == [p.name for p in plane["phases"]]
    for k, (a, b) in enumerate(zip(plane["phases"], stairs["phases"])):
        assert (a.guard is b.guard) == (k % 2 == 0)  # early swing kept, late swing landed
    assert "constrain" in stairs and "constrain" not in plane


@pytest.mark.slow
def test_the_least_effort_3d_gait_on_two_footholds_is_the_passive_period_two_gait():
    """configs/hip_width_footholds.yaml (footholds +0.5 mm and -0.5 mm, a period-2 stride
    gait), least effort on 60 intervals a step (the capability cell's section): leg A's
    step lands on the first foothold, leg B's on the second, the advance free, so the
    passive gait ``walkerlab fixedpoint`` finds is feasible and the optimum is it:
    IPOPT converged, effort <= 1e-10 N^2 m^2 s (seen 1e-25), the start within 1e-6 of the
    fixed point, the mean step period within 1e-7 relative and the replay on the rigid
    walker on the footholds closing to 1e-6 (seen 2.0e-7; 1.0e-6 on 40 intervals)."""
    pytest.importorskip("casadi")
    out, r, periods = _least_effort("hip_width_footholds", 60)
    _assert_passive(out, r, periods, 1e-10)
