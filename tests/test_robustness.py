"""Robustness beyond |lambda| (issue 24): the mid-stance push, the bisection of the largest
single disturbance, the push's gait sensitivity norm, the robustness stage and report."""

from pathlib import Path

import numpy as np
import pytest
import yaml

from walkerlab.analysis.robustness import measures as R
from walkerlab.analysis.robustness import push
from walkerlab.config import load_scene
from walkerlab.integrate.batch_step import BatchStepMap
from walkerlab.models.registry import build_walker
from walkerlab.studies.mfpt import scene_walker_at
from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def tight_map(paper_scene):
    return BatchStepMap(build_walker(plant := Plant.from_scene(paper_scene)),
                        scene_walker_at(paper_scene, plant), 1e-12, 1e-12)


def _angular_momentum(walker, x, masses):
    """Angular momentum about the stance foot [kg m^2/s] of point masses (name -> kg), each
    velocity from central differences of walker.points along the rates (independent of
    the mass matrix)."""
    n = walker.n_coordinates
    h = 1e-6
    xp, xm = np.array(x, float), np.array(x, float)
    xp[:n] += h * x[n:]
    xm[:n] -= h * x[n:]
    P, Pp, Pm = walker.points(x), walker.points(xp), walker.points(xm)
    H = 0.0
    for name, m in masses.items():
        r = np.asarray(P[name])
        v = (np.asarray(Pp[name]) - np.asarray(Pm[name])) / (2 * h)
        H += m * (r[0] * v[1] - r[1] * v[0])
    return H


def test_push_is_a_physical_impulse(paper_walker, paper_fixed_point):
    """A horizontal impulse P at the hip, the stance foot pinned: the angular momentum
    about the stance foot changes by (r_hip x P)_z = -y_hip P (the ground's impulse acts at
    the foot: no moment about it), the hip's forward velocity by the requested dv, and the
    kinetic energy by P (v_before + v_after) / 2 (work of an impulse).  The paper walker's
    masses are points (hip 10 kg, legs 5 kg), so H is computed from positions alone;
    tolerance 1e-7 relative: velocities by central differences (h = 1e-6, error ~1e-12)."""
    w, x = paper_walker, paper_fixed_point.x.copy()
    x[w.state_names().index("stance_angle")] = 0.05  # a state of the swing, not the section
    masses = {"hip": 10.0, "stance_mass": 5.0, "swing_mass": 5.0}
    dv = 0.2
    xp, P = push.apply_push(w, x, dv)
    dH = _angular_momentum(w, xp, masses) - _angular_momentum(w, x, masses)
    y_hip = float(np.asarray(w.points(x)["hip"])[1])
    assert abs(dH - (-y_hip * P)) < 1e-7 * abs(y_hip * P)
    J = push.hip_jacobian(w, x)
    n = w.n_coordinates
    v0, v1 = J @ x[n:], J @ xp[n:]
    assert abs((v1[0] - v0[0]) - dv) < 1e-9
    T0, T1 = (float(np.asarray(w.energies(s))[0]) for s in (x, xp))
    assert abs((T1 - T0) - P * (v0[0] + v1[0]) / 2) < 1e-8 * abs(T1 - T0)
    assert 0 < P < 20 * dv  # less than the whole walker's momentum change (20 kg * dv)


def test_push_gsn_linear_equals_nonlinear(tight_map, paper_fixed_point):
    """The push's GSN from the linearised step map equals the nonlinear response to a
    1e-5 m/s push to 1e-3 relative (measured ~1e-11: both central, O(e^2))."""
    x = paper_fixed_point.x
    lin = R.linearise(tight_map, x, paper_fixed_point.jacobian_variational, "push")
    g_lin, g_nl = lin.gsn(), R.gsn_nonlinear(tight_map, x, "push", 1e-5, steps=60)
    assert g_lin > 0.1
    assert abs(g_lin - g_nl) / g_lin < 1e-3


def test_an_undisturbed_step_is_the_plain_map_and_a_zero_step_down_agrees_with_it(
        tight_map, paper_fixed_point):
    """The steps after a disturbance (``one_step`` with every value 0) are the plain step
    map, bit for bit, for every disturbance: the compiled per-row integrator, not the
    stacked step-down one.  The step-down path with a drop of 0 (the same heel-strike guard,
    integrated by scipy's DOP853 on the stacked rows) lands on the same state to the
    integrators' tolerance (1e-12 relative: 1e-9 absolute on states of order 1); an unknown
    disturbance is one line naming it."""
    X = np.tile(paper_fixed_point.x, (2, 1))
    X[1, 0] += 1e-3
    plain = tight_map.step(X)
    for d in R.disturbances_of(tight_map.walker):
        xn, _, ok = R.one_step(tight_map, X, d, np.zeros(2))
        assert ok.all() and np.array_equal(xn, plain.x_next), d
    stacked = tight_map.step(X, None, drop_m=np.zeros(2))
    assert np.abs(stacked.x_next - plain.x_next).max() < 1e-9
    with pytest.raises(ValueError, match="disturbance: unknown 'wind'"):
        R.one_step(tight_map, X, "wind", np.zeros(2))


def test_bisection_bracket_flips_survival(paper_scene, paper_fixed_point):
    """The largest single step-down by bracketing bisection: bracket <= 1 mm, the lower end
    survives 40 steps and the upper end falls; it lies within 1 mm of the 1 mm grid scan
    (R.largest_tolerable), an independent search."""
    sm = BatchStepMap(build_walker(plant := Plant.from_scene(paper_scene)),
                        scene_walker_at(paper_scene, plant), 1e-10, 1e-10)
    x = paper_fixed_point.x
    lo, hi = R.largest_by_bisection(sm, x, "floor_height", 0.05, 0.001)
    assert 0 < hi - lo <= 0.001
    alive = R.survives(sm, x, "floor_height", [lo, hi])
    assert alive[0] and not alive[1]
    grid = R.largest_tolerable(sm, x, "floor_height", 0.05, 0.001)
    assert abs(lo - grid) <= 0.001


@pytest.mark.slow
def test_robustness_stage_round_trip_and_report_section(tmp_path):
    """walkerlab robustness writes robustness.h5, read back by its loader with every
    field; the report of a scene with the section shows it, of one without does not."""
    from walkerlab.io.schemas.robustness import SCALARS, load
    from walkerlab.stages import pipeline
    from walkerlab.stages import report as report_stage

    d = yaml.safe_load((ROOT / "configs" / "paper.yaml").read_text())
    base = {k: d[k] for k in ("walker", "slope", "ideal", "solver", "fixedpoint")}
    with_sec = dict(base, name="rob", robustness={
        "sigma_rad": 0.008, "montecarlo_walks": 8, "montecarlo_max_steps": 40,
        "disturbances": ["slope", "push"], "resolution_m": 0.004,
        "push_resolution_m_per_s": 0.02, "survival_steps": 10})
    (tmp_path / "rob.yaml").write_text(yaml.safe_dump(with_sec))
    (tmp_path / "plain.yaml").write_text(yaml.safe_dump(dict(base, name="plain")))
    sc, plain = load_scene(tmp_path / "rob.yaml"), load_scene(tmp_path / "plain.yaml")
    runs = tmp_path / "runs"
    out = pipeline.run("robustness", sc, runs, workers=1)
    r = load(out.path)
    assert r.disturbances == ["slope", "push"] and r.units["push"] == "m/s"
    assert set(SCALARS) <= set(r.scalars)
    assert abs(r.max_abs_multiplier["absolute"] - 0.5859) < 1e-3
    assert abs(r.gsn["slope"] - r.gsn_nonlinear["slope"]) < 1e-3 * r.gsn["slope"]
    assert 0 < r["step_down_m/hi"] - r["step_down_m/lo"] <= 0.004
    assert r["montecarlo_walks"] == 8 and r["mfpt_steps"] >= 0
    assert pipeline.run("robustness", sc, runs, workers=1).reused
    assert "robustness" in pipeline.report_plan(sc)
    assert "robustness" not in pipeline.report_plan(plain)
    for scene, shown in ((sc, True), (plain, False)):
        report_stage.run(scene, runs, echo=lambda s: None)
        md = (runs / scene.name / "report" / "report.md").read_text()
        assert ("## Robustness" in md) == shown
        assert ("Jin et al." in md) == shown


def test_a_reused_robustness_artifact_prints_its_numbers(tmp_path, monkeypatch):
    """Issue 64 item 10: ``walkerlab robustness`` on an up-to-date artifact printed only
    "reused", none of its numbers."""
    from tests.cli_run import run_cli
    from walkerlab.io.artifacts import write_artifact
    from walkerlab.io.schemas import robustness as schema
    from walkerlab.stages import pipeline
    from walkerlab.stages.common import StageOutcome

    sc = load_scene(Path(__file__).resolve().parents[1] / "configs" / "paper.yaml")
    scalars = {k: 0.5 for k in schema.SCALARS} | {"mfpt_steps": 123.4, "sigma_rad": 0.01}
    d = schema.RobustnessData(["slope"], {"slope": "rad"}, {"absolute": 0.6, "relative": 0.6},
                              {"slope": 7.25}, {"slope": 7.3},
                              {c: {"slope": 1.0} for c in schema.COORDINATES}, scalars)
    path = write_artifact(tmp_path / "robustness.h5", "robustness", sc, "x",
                          lambda f: schema.write(f, d), 1.0)
    monkeypatch.setattr(pipeline, "run", lambda *a, **k: StageOutcome(
        "robustness", path, True, 0.0))  # reused: no summary of the study
    code, err, out = run_cli("robustness", "paper", "--runs-dir", tmp_path)
    assert code == 0, err
    assert "GSN slope: 7.25" in out and "MFPT 123.4" in out


def test_stability_map_prints_the_path_of_the_figure_it_drew(tmp_path, monkeypatch):
    """Issue 64 item 10: ``walkerlab stability-map`` did not say where its figure is."""
    from tests.cli_run import run_cli
    from walkerlab.stages import stability_map
    from walkerlab.stages.common import StageOutcome

    art = tmp_path / "paper" / "stability_map_friction.h5"
    monkeypatch.setattr(stability_map, "run", lambda *a, **k: StageOutcome(
        "stability-map", art, True, 0.0))
    code, err, out = run_cli("stability-map", "paper", "--kind", "friction", "--runs-dir",
                             tmp_path)
    assert code == 0, err
    assert f"figure: {tmp_path / 'paper' / 'report' / 'figures' / 'stability_map_friction.png'}" \
        in out


@pytest.mark.parametrize("name, why", [("rimless_wheel_3d", "a spoked wheel")])
def test_robustness_refuses_the_3d_kinds_it_does_not_take_before_any_work(tmp_path, monkeypatch,
                                                                           name, why):
    """The robustness study takes the 3D straight legs and the 3D locking knees
    (tests/test_robustness_3d.py); the 3D spoked wheel (no hip to push, no legs to read) is
    refused in one line naming walker.space, from the table
    (:data:`walkerlab.walker.capability_cells.STAGE_CELLS`), before the gait is searched or
    the walker built (building it fails this test); the study's own entry refuses it too,
    and nothing is written."""
    from walkerlab.models import registry
    from walkerlab.stages import pipeline
    from walkerlab.stages.common import StageError
    from walkerlab.studies.robustness_study import scene_robustness
    from walkerlab.walker.kinds import KindRefused

    scene = load_scene(ROOT / "configs" / f"{name}.yaml")

    def built(*a, **k):
        raise AssertionError("the walker was built before the refusal")

    monkeypatch.setattr(registry, "build_walker", built)
    pattern = rf"^walker\.space: 3d: .*{why}"
    with pytest.raises(StageError, match=pattern):
        pipeline.run("robustness", scene, tmp_path)
    with pytest.raises(KindRefused, match=pattern):
        scene_robustness(scene, np.zeros(6), plant=Plant.from_scene(scene))
    assert not any(tmp_path.iterdir())
