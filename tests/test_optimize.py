"""Optimal gaits by direct collocation (``walkerlab optimize``; CasADi + IPOPT): the
compass walker's least-effort gait on a slope is its passive gait (found independently by
shooting, ``fixedpoint``), a powered gait at a target speed replays on the rigid model's own
code, and the command writes its artifact."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import walkerlab as wl
from walkerlab.codegen import legged
from walkerlab.config import load_scene
from walkerlab.optimal.transcription.mode_sequence import collocate_step
from walkerlab.optimal.transcription.step import CollocationSpec, replay
from walkerlab.walker.description import walker_data
from walkerlab.walker.plant import Plant

pytest.importorskip("casadi")
CONFIGS = Path(__file__).resolve().parents[1] / "configs"


def _start(scene):
    w = wl.Walker.from_scene(scene)
    g = w.fixed_point()
    walk = w.simulate(g.x, strides=1, sample_rate_hz=2000.0)
    first = walk.stance_leg == walk.stance_leg[0]
    return g, walk.t[first], walk.x[first]


@pytest.mark.parametrize("slope", [0.0174, 0.035, 0.0525])
@pytest.mark.slow  # in `pytest -m slow`: the quick suite keeps to its CPU budget
def test_the_least_effort_gait_on_a_slope_is_the_passive_gait(slope):
    """int u^2 dt = 0 at the passive gait, so the optimum is it: objective <= 1e-10, step
    period within 1e-7 s of the shooting fixed point (Hermite-Simpson with 40 intervals:
    O(h^4) ~ 1e-7), the start state within 1e-6, the replay closing to 1e-6."""
    d = load_scene(CONFIGS / "compass_optimal.yaml").model_dump(mode="json", exclude_none=True)
    d["slope"] = {"angle_rad": slope}
    scene = load_scene(CONFIGS / "compass_optimal.yaml").model_validate(d)
    g, t, x = _start(scene)
    data = walker_data(scene.walker, scene.slope.phi_rad)
    # a guess off the gait: the optimiser must find its way back
    res = collocate_step(data, legged.derive_legged(data.structure), CollocationSpec(intervals=40),
                         t, x * 1.05, np.full(t.size, 0.5))
    assert res.status == "Solve_Succeeded"
    assert res.objective <= 1e-10 and np.max(np.abs(res.u)) < 1e-5
    assert res.step_period_s == pytest.approx(g.step_period, abs=1e-7)
    np.testing.assert_allclose(res.x[0], g.x, atol=1e-6)
    assert replay(data, res)[0] <= 1e-6


def test_a_powered_gait_at_a_target_speed_replays_on_the_rigid_model():
    """configs/powered_compass.yaml (level ground, push-off 3 N s) made to walk at 0.55
    m/s (its own gait: 0.499 m/s) by the least hip torque: the speed is met, the torque is
    not zero, and the optimised torque fed as a function of time to the rigid model's
    generated code (its own guard and push-off + heel-strike reset) returns to the start
    within 1e-6."""
    scene = load_scene(CONFIGS / "powered_compass.yaml")
    g, t, x = _start(scene)
    data = walker_data(scene.walker, scene.slope.phi_rad)
    res = collocate_step(data, legged.derive_legged(data.structure),
                         CollocationSpec(intervals=40, push_off_n_s=3.0,
                                         target_speed_m_per_s=0.55), t, x)
    assert res.status == "Solve_Succeeded"
    assert res.step_length_m / res.step_period_s == pytest.approx(0.55, rel=1e-9)
    assert 0.01 < np.max(np.abs(res.u)) < 10.0
    err, _ = replay(data, res)
    assert err <= 1e-6


@pytest.mark.slow  # in `pytest -m slow`: the quick suite keeps to its CPU budget
def test_optimize_command_writes_its_artifact_and_refuses_what_it_cannot(tmp_path):
    from typer.testing import CliRunner

    from walkerlab.cli import app
    from walkerlab.io.schemas.optimize import load

    r = CliRunner().invoke(app, ["optimize", str(CONFIGS / "compass_optimal.yaml"),
                                 "--runs-dir", str(tmp_path)])
    assert r.exit_code == 0, r.output
    assert "a gait (the replay closes)" in r.output
    d = load(tmp_path / "compass_optimal" / "optimize.h5")
    assert d.gait and d.replay_error < 1e-6 and d.objective < 1e-10
    assert max(abs(d.multipliers)) == pytest.approx(0.5798, abs=1e-3)
    # the contact model (the paper's law) driven by the optimised (zero) torque: its step
    # 0.77 % longer than the rigid one (the compliant feet), within the 3 % asked
    assert d.contact_step_period_s == pytest.approx(d.step_period_s, rel=0.03)
    assert d.contact_outcome == "heel_strike" and "contact model driven" in r.output
    figs = tmp_path / "compass_optimal" / "report" / "figures"  # the SVG on request (--svg)
    assert (figs / "optimize.png").is_file() and not (figs / "optimize.svg").exists()
    # recomputed to the same result (--force): the figure drawn from it is kept, not redrawn
    drawn = (figs / "optimize.png").stat()
    r = CliRunner().invoke(app, ["optimize", str(CONFIGS / "compass_optimal.yaml"),
                                 "--runs-dir", str(tmp_path), "--force"])
    assert r.exit_code == 0 and f"figure: {figs / 'optimize.png'}" in r.output, r.output
    kept = (figs / "optimize.png").stat()
    assert (kept.st_ino, kept.st_mtime_ns) == (drawn.st_ino, drawn.st_mtime_ns)
    # arc feet: the generated equations transcribed as any straight-legged walker's (they
    # were refused before issue 48); their least effort on the passive slope is the passive
    # gait (tests/test_optimize_least_effort.py checks the numbers)
    r = CliRunner().invoke(app, ["optimize", str(CONFIGS / "round_feet.yaml"),
                                 "--runs-dir", str(tmp_path)])
    assert r.exit_code == 0 and "Traceback" not in r.output and "error:" not in r.output, \
        r.output
    assert load(tmp_path / "round_feet" / "optimize.h5").objective < 1e-8


def test_design_gradient_through_the_fixed_point_equals_central_differences():
    """d(step period)/d(hip mass) and d(speed)/d(leg mass) of the paper walker's gait by the
    implicit function theorem on the Poincaré map, against central differences of the
    re-solved fixed point (h = 1e-3 kg: truncation ~1e-9 relative): <= 1e-6 relative."""
    from walkerlab.optimal.design.gradients import _Gaits, measure_gradient

    scene = load_scene(CONFIGS / "paper.yaml")
    g = wl.Walker.from_scene(scene).fixed_point()
    fields = ["walker.hip_mass_kg", "walker.leg_mass_kg"]
    gaits = _Gaits(scene, fields, g.x, plant=Plant.from_scene(scene))
    p = np.array([10.0, 5.0])
    for name in ("step_period", "speed"):
        _, grad = measure_gradient(gaits, p, name)
        for j in range(2):
            h = np.zeros(2)
            h[j] = 1e-3
            fd = (measure_gradient(gaits, p + h, name)[0]
                  - measure_gradient(gaits, p - h, name)[0]) / 2e-3
            assert grad[j] == pytest.approx(fd, rel=1e-6, abs=1e-12), (name, j, grad, fd)


def test_design_gradient_of_step_length_and_cost_of_transport():
    """The other two smooth measures by the implicit function theorem against central
    differences of the re-solved fixed point (h = 1e-3): <= 1e-6 relative - the paper
    walker's step length in its hip mass (1e-7 seen), and powered_compass.yaml's cost of
    transport in its push-off impulse (a passive walker's is 0; 9e-9 seen)."""
    from walkerlab.optimal.design.gradients import _Gaits, measure_gradient

    for name, scene_name, field, p in (
            ("step_length", "paper", "walker.hip_mass_kg", 10.0),
            ("cost_of_transport", "powered_compass", "walker.actuation.push_off.impulse_n_s",
             3.0)):
        scene = load_scene(CONFIGS / f"{scene_name}.yaml")
        gaits = _Gaits(scene, [field], wl.Walker.from_scene(scene).fixed_point().x,
                       plant=Plant.from_scene(scene))
        _, grad = measure_gradient(gaits, [p], name)
        fd = (measure_gradient(gaits, [p + 1e-3], name)[0]
              - measure_gradient(gaits, [p - 1e-3], name)[0]) / 2e-3
        assert abs(grad[0]) > 1e-4
        assert grad[0] == pytest.approx(fd, rel=1e-6), (name, grad, fd)


def test_design_optimisation_follows_the_gait_to_a_bounded_optimum():
    """The hip mass (5-20 kg) that maximises the paper walker's speed on its slope: SLSQP
    with the fixed-point gradient ends at a bound or where the gradient vanishes, and the
    speed there is at least the scene's."""
    from walkerlab.optimal.design.search import design_optimize

    scene = load_scene(CONFIGS / "paper.yaml")
    g = wl.Walker.from_scene(scene).fixed_point()
    res = design_optimize(scene, {"walker.hip_mass_kg": (5.0, 20.0)}, "speed", g.x,
                          maximize=True, max_evaluations=20, plant=Plant.from_scene(scene))
    start = [v for p, v in res.history if abs(p[0] - 10.0) < 1e-12][0]
    assert res.value >= start - 1e-12
    m = res.values[0]
    at_bound = min(abs(m - 5.0), abs(m - 20.0)) < 1e-6
    assert at_bound or abs(res.gradient[0]) < 1e-6 * max(1.0, abs(res.value))


@pytest.mark.slow  # in `pytest -m slow`: the quick suite keeps to its CPU budget
def test_design_command_prints_the_optimum_and_refuses_bad_input_in_one_line(tmp_path):
    """``walkerlab optimize --design``: the paper walker's hip mass within 5-20 kg that
    minimises its largest Floquet multiplier (SLSQP with the eigenvalue-perturbation
    gradient) is the heaviest (0.574 at 20 kg against 0.580 at the scene's 10 kg)."""
    from typer.testing import CliRunner

    from walkerlab.cli import app

    scene = str(CONFIGS / "paper.yaml")
    r = CliRunner().invoke(app, ["optimize", scene, "--design", "walker.hip_mass_kg=5:20",
                                 "--objective", "max_abs_multiplier",
                                 "--runs-dir", str(tmp_path)])
    assert r.exit_code == 0, r.output
    assert "walker.hip_mass_kg = 20" in r.output
    first = tmp_path / "paper" / "optimize_design_walker.hip_mass_kg_max_abs_multiplier.h5"
    assert first.is_file()
    # another objective: an artifact of its own, the first one left as it was
    before = first.stat().st_mtime_ns
    r = CliRunner().invoke(app, ["optimize", scene, "--design", "walker.hip_mass_kg=5:20",
                                 "--objective", "speed", "--maximize",
                                 "--runs-dir", str(tmp_path)])
    assert r.exit_code == 0, r.output
    assert (tmp_path / "paper" / "optimize_design_walker.hip_mass_kg_speed_maximize.h5"
            ).is_file() and first.stat().st_mtime_ns == before
    fresh = tmp_path / "fresh"  # refused before the upstream stages run
    for bad, msg in ((["--design", "walker.hip_mass_kg=5:x"], "FIELD=LO:HI"),
                     (["--design", "walker.hip_mass_kg=5:20", "--objective", "nope"],
                      "--objective"),
                     (["--design", "walker.hip_mas_kg=5:20"],
                      "--design walker.hip_mas_kg: unknown field walker.hip_mas_kg"),
                     (["--design", "walker.hip_mass_kg=5:20", "--design",
                       "walker.hip_mass_kg=6:8"], "walker.hip_mass_kg: given twice"),
                     (["--design", "walker.hip_mass_kg=-1:20"], "greater than or equal to 0"),
                     (["--design", "walker.actuation.push_off.impulse_n_s=1:2"],
                      "leaves it unset")):
        r = CliRunner().invoke(app, ["optimize", scene, *bad, "--runs-dir", str(fresh)])
        assert r.exit_code != 0 and r.output.count("error:") == 1 and msg in r.output, r.output
        assert "internal error" not in r.output and "--param" not in r.output
        assert not (fresh / "paper" / "fixedpoint.h5").exists(), bad


def test_design_from_a_zero_stiffness_bound_stays_inside_the_bounds():
    """A hip spring's stiffness within 0-30 N m/rad for the least speed of hip_spring.yaml
    (speed rises with stiffness: 0.528 m/s at 0): the optimum is the bound 0, no walker is
    built below it (every evaluation and the difference stencil stay >= 0; before, the
    central difference at 0 built a spring of -1e-6 N m/rad and the run stopped), and the
    gradient there is the one-sided difference of the re-solved speed (h = 1e-3 N m/rad:
    truncation ~1e-7 relative)."""
    from walkerlab.optimal.design.gradients import _Gaits, measure_gradient
    from walkerlab.optimal.design.search import MAX_STEP_SHARE, design_optimize

    scene = load_scene(CONFIGS / "hip_spring.yaml")
    field = "walker.springs.0.stiffness_n_m_per_rad"
    x = wl.Walker.from_scene(scene).fixed_point().x
    res = design_optimize(scene, {field: (0.0, 30.0)}, "speed", x, max_evaluations=10,
                          plant=Plant.from_scene(scene))
    assert all(p[0] >= 0.0 for p, _ in res.history)
    assert res.values[0] == pytest.approx(0.0, abs=1e-9) and res.gradient[0] > 0
    # from the scene's 20 N m/rad down to 0 in the design search's sub-steps (natural-
    # parameter continuation, as design_optimize walks it): in one jump the root finder's
    # path is the machine's round-off, and on some machines it falls off the gait
    gaits = _Gaits(scene, [field], x, max_step=MAX_STEP_SHARE * np.array([30.0]),
                   bounds=([0.0], [30.0]), plant=Plant.from_scene(scene))
    v0, g0 = measure_gradient(gaits, [0.0], "speed")
    fd = (measure_gradient(gaits, [1e-3], "speed")[0] - v0) / 1e-3
    assert g0[0] == pytest.approx(fd, rel=1e-3)


@pytest.fixture(scope="module")
def robust_paper():
    """The paper walker with a small MFPT study (100 walks of at most 100 steps at sigma
    0.02 rad) and a 6 x 6 basin map: seconds per design point."""
    scene = load_scene(CONFIGS / "paper.yaml")
    d = scene.model_dump(mode="json", exclude_none=True)
    d["mfpt"] = {"sigma_rad": [0.02], "walks": 100, "max_steps": 100, "method": "montecarlo"}
    d["basin"] = {**d.get("basin", {}), "grid": [6, 6]}
    scene = type(scene).model_validate(d)
    return scene, wl.Walker.from_scene(scene).fixed_point().x


@pytest.mark.parametrize("objective,maximize", [("gait_sensitivity_norm", False),
                                                ("basin_share", True), ("mfpt", True)])
def test_design_on_robustness_measures(robust_paper, objective, maximize):
    """The hip mass (8-12 kg) for the gait sensitivity norm (SLSQP, its gradient by central
    differences of the re-solved gait), the basin share and the MFPT (Nelder-Mead: both are
    piecewise constant in the design, no gradient): the optimum is at least as good as the
    scene's 10 kg, the gradient is given only where the measure is smooth."""
    from walkerlab.optimal.design.search import design_optimize

    scene, x = robust_paper
    res = design_optimize(scene, {"walker.hip_mass_kg": (8.0, 12.0)}, objective, x,
                          maximize=maximize, max_evaluations=4, plant=Plant.from_scene(scene))
    start = [v for p, v in res.history if abs(p[0] - 10.0) < 1e-12][0]
    assert (res.value >= start - 1e-12) if maximize else (res.value <= start + 1e-12)
    assert np.isfinite(res.gradient[0]) == (objective == "gait_sensitivity_norm")
    assert 8.0 <= res.values[0] <= 12.0


def test_gait_sensitivity_norm_gradient_converges(robust_paper):
    """The GSN's differenced gradient (step 1e-4 of the field) and one with a ten times
    larger step agree to O(h^2) (<= 1e-4 relative): the measure is smooth and its
    differences are not noise (its own B, C, D are differences at 1e-6 of the state)."""
    from walkerlab.optimal.design.gradients import _Gaits

    scene, x = robust_paper
    gaits = _Gaits(scene, ["walker.hip_mass_kg"], x, plant=Plant.from_scene(scene))
    v1, g1 = gaits.differenced([10.0], "gait_sensitivity_norm", h_rel=1e-4)
    v2, g2 = gaits.differenced([10.0], "gait_sensitivity_norm", h_rel=1e-3)
    assert v1 == pytest.approx(v2, rel=1e-9)
    assert g1[0] == pytest.approx(g2[0], rel=1e-4)
