"""The five-link biped's least-effort step (``walkerlab optimize configs/rabbit_optimal.yaml``,
Kelly 2017's set-up: 0.5 m in 0.7 s, least int |u|^2 dt over the hip and knee torques): the
CasADi step functions against the independent derivation, the optimum against its targets
and constraints, and the step - closed by shooting under the open-loop torques - replayed
on the rigid model's generated code."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from tests.independent import five_link as ref
from tests.test_five_link import SCENE, P, from_ref, states, to_ref
from walkerlab.config import load_scene, scene_from_dict
from walkerlab.walker.description import walker_data

pytest.importorskip("casadi")
CONFIGS = Path(__file__).resolve().parents[1] / "configs"
#: torques [N m] on the joints in walkerlab.optimal.transcription.free_joint_functions.JOINTS order
TAU = np.array([7.0, -3.0, 11.0, -5.0])


@pytest.fixture(scope="module")
def fns_and_params():
    from walkerlab.optimal.transcription.free_joint_functions import five_link_functions

    data = walker_data(scene_from_dict(SCENE).walker, 0.0)
    return five_link_functions(data.structure), np.asarray(data.params, float)


@pytest.mark.slow  # in `pytest -m slow`: the quick suite keeps to its CPU budget
def test_casadi_step_matches_the_independent_derivation(fns_and_params):
    """The collocation's flow (with the four joint torques as the relative coordinates'
    generalised forces), heel-strike reset and swing-foot height against the independent
    Lagrangian of tests/independent/five_link.py (relative coordinates, extended-coordinate
    impact): to 1e-9 of the accelerations, 1e-10 of the post-impact rates."""
    fns, p = fns_and_params
    for x in states():
        r, dr = to_ref(x)
        want = from_ref(ref.acceleration(r, dr, P, [0.0, *TAU]))
        got = np.asarray(fns["flow"](x, TAU, p)).ravel()
        np.testing.assert_allclose(got[:5], x[5:], rtol=0, atol=0)
        np.testing.assert_allclose(got[5:], want, rtol=0, atol=1e-9 * max(1, abs(want).max()))
        rp, drp = ref.heel_strike(r, dr, P)
        after = np.asarray(fns["reset"](x, p)).ravel()
        np.testing.assert_allclose(after[:5], from_ref(rp), atol=1e-12)
        np.testing.assert_allclose(after[5:], from_ref(drp), atol=1e-10 * max(1, abs(drp).max()))
        feet = np.asarray(fns["feet"](x, p)).ravel()
        foot = ref.swing_foot(r, P)
        assert feet[0] == pytest.approx(foot[1], abs=1e-12)  # height: the heel-strike guard
        assert feet[1] == pytest.approx(foot[0], abs=1e-12)  # ahead of the stance foot


def test_the_step_functions_are_built_once_and_cached(fns_and_params, tmp_path,
                                                     monkeypatch):
    """A miss derives (sympy) and writes the user cache; the next process reads it back
    (no derivation) and computes the same; a damaged file is derived again."""
    from walkerlab.codegen import casadi_functions
    from walkerlab.optimal.transcription import free_joint_functions as fl

    built = {k: v for k, v in fns_and_params[0].items() if k != "n"}
    calls = []
    monkeypatch.setenv("WALKERLAB_CACHE_DIR", str(tmp_path))
    monkeypatch.setattr(fl, "_build", lambda s: calls.append(s) or dict(built))
    monkeypatch.setattr(casadi_functions, "_memo", {})
    structure = walker_data(scene_from_dict(SCENE).walker, 0.0).structure
    fl.five_link_functions(structure)
    assert len(calls) == 1
    casadi_functions.clear_memo()
    got = fl.five_link_functions(structure)
    assert len(calls) == 1 and got["n"] == 5
    x, p = states()[0], fns_and_params[1]
    np.testing.assert_array_equal(np.asarray(got["flow"](x, TAU, p)),
                                  np.asarray(built["flow"](x, TAU, p)))
    (path,) = (tmp_path / "models").glob("*-collocation-*.casadi")
    path.write_text(path.read_text()[:-40])
    casadi_functions.clear_memo()
    fl.five_link_functions(structure)
    assert len(calls) == 2


def test_a_five_link_scene_optimises_without_an_upstream_gait():
    """rabbit_optimal has no passive gait on level ground: optimize needs no fixedpoint."""
    from walkerlab.stages import pipeline

    scene = load_scene(CONFIGS / "rabbit_optimal.yaml")
    assert pipeline.order("optimize", scene) == ["optimize"]
    assert pipeline.report_plan(scene) == ["optimize"]
    assert pipeline.order("optimize", load_scene(CONFIGS / "compass_optimal.yaml")) == [
        "fixedpoint", "optimize"]


def test_a_five_link_walker_without_torso_is_refused_in_one_line(tmp_path):
    """Its hips would have no torso to push against: one line naming the fields."""
    import copy

    import yaml
    from typer.testing import CliRunner

    from walkerlab.cli import app

    d = copy.deepcopy(SCENE)
    d.pop("torso", None)
    d["walker"].pop("torso", None)
    d["name"] = "no_torso"
    d["optimize"] = {"target_step_length_m": 0.5}
    (tmp_path / "no_torso.yaml").write_text(yaml.safe_dump(d))
    r = CliRunner().invoke(app, ["optimize", str(tmp_path / "no_torso.yaml"), "--runs-dir",
                                 str(tmp_path / "runs")])
    assert r.exit_code == 1 and "Traceback" not in r.output
    assert r.output.count("error:") == 1 and "walker.torso.coupling" in r.output, r.output


def test_torques_of_time_is_the_intervals_quadratic():
    """Exact on a quadratic (Hermite-Simpson's control), extrapolated past the end."""
    from walkerlab.optimal.transcription.free_joints import torques_of_time

    t = np.linspace(0.0, 0.7, 11)
    u = np.stack([3 * t ** 2 - t + 2, -t ** 2], axis=1)
    tau = torques_of_time(t, u)
    for s in (0.0, 0.013, 0.35, 0.699, 0.7, 0.71):
        np.testing.assert_allclose(tau(s), [3 * s ** 2 - s + 2, -s ** 2], atol=1e-12)


@pytest.fixture(scope="module")
def optimised(tmp_path_factory):
    """``walkerlab optimize configs/rabbit_optimal.yaml`` once (~10 s CPU, the
    phase-variable replays ~3 s on compiled flows (~30 s more to compile them on a cold
    cache), the contact replay ~10 s)."""
    from typer.testing import CliRunner

    from walkerlab.cli import app
    from walkerlab.io.schemas.optimize import load

    runs = tmp_path_factory.mktemp("runs")
    r = CliRunner().invoke(app, ["optimize", str(CONFIGS / "rabbit_optimal.yaml"),
                                 "--runs-dir", str(runs)])
    assert r.exit_code == 0, r.output
    return load(runs / "rabbit_optimal" / "optimize.h5"), r.output, runs


def check_kellys_step_meets_its_targets_and_constraints(optimised, fns_and_params):
    """0.5 m in 0.7 s exactly; the swing foot above the ground at every interior point and
    on it at the end, moving down there; no knee hyper-extended; torques finite, within
    RABBIT's 150 N m; IPOPT converged; the torques stored by joint name."""
    from walkerlab.optimal.transcription.free_joint_functions import JOINTS, five_link_functions

    d, out, _ = optimised
    assert d.status == "Solve_Succeeded"
    assert d.step_period_s == pytest.approx(0.7, abs=1e-12)
    assert d.step_length_m == pytest.approx(0.5, abs=1e-9)
    assert d.torque_names == JOINTS and d.torque.shape == (len(d.time), 4)
    assert np.all(np.isfinite(d.torque)) and np.abs(d.torque).max() <= 150.0 + 1e-9
    assert 0.0 < d.objective < 1e4 and np.isfinite(d.objective)
    scene = load_scene(CONFIGS / "rabbit_optimal.yaml")
    data = walker_data(scene.walker, 0.0)
    fns = five_link_functions(data.structure)
    x = np.stack(list(d.states.values()), axis=1)
    feet = np.array([np.asarray(fns["feet"](xk, data.params)).ravel() for xk in x])
    assert feet[1:-1, 0].min() >= -1e-9 and abs(feet[-1, 0]) <= 1e-9
    assert feet[-1, 2] < 0 and feet[0, 2] >= -1e-9
    assert feet[:, 3:].max() <= 1e-9
    assert "stance_hip" in out and "a gait (the replay closes)" in out
    assert "phase-variable feedback law" in out and "phase-variable feedforward law" in out


def check_the_closed_step_replays_on_the_rigid_model(optimised):
    """The open-loop torques do not close the collocated step (the gait is unstable under
    them: an error of ~1e-5 at the start grows to >1e-3), the shooting closes it a few 1e-5
    away with the step period within 1e-5 s of 0.7, and the rigid model's generated code
    replays that step back to its start within 1e-6: a gait (open-loop unstable)."""
    d, _, runs = optimised
    assert d.collocated_start_error > 1e-3
    assert d.start_shift < 1e-4
    assert d.replay_step_period_s == pytest.approx(0.7, abs=1e-5)
    assert d.replay_error <= 1e-6 and d.gait
    assert np.max(np.abs(d.multipliers)) > 1.0
    assert (runs / "rabbit_optimal" / "report" / "figures" / "optimize.png").is_file()


def check_the_report_shows_the_optimised_step(optimised):
    """tests/test_scenes_end_to_end.py leaves this scene out (no gait for fixedpoint): its
    report is built here, the optimised step its only section."""
    from walkerlab.stages import report

    _, _, runs = optimised
    html = report.run(load_scene(CONFIGS / "rabbit_optimal.yaml"), runs, echo=lambda s: None)
    md = (html.parent / "report.md").read_text()
    assert "closed by shooting" in md and "**a gait**" in md and "optimize.png" in md
    assert "virtual constraints" in md and "feed-forward alone" in md


def check_the_transcription_error_falls_at_hermite_simpsons_order(optimised):
    """The open-loop return error of the collocated start (the transcription's error grown
    over the step by the same linearised map at both meshes) falls by 2^p when the mesh is
    halved: observed p >= 3.5 for Hermite-Simpson's 4 (measured 3.7: at 25 intervals the
    error, 0.67, is large enough to be past the linear growth, which lowers p)."""
    from walkerlab.optimal.replay.shooting import open_loop_error
    from walkerlab.optimal.transcription.free_joint_functions import five_link_functions
    from walkerlab.optimal.transcription.free_joints import collocate_five_link
    from walkerlab.optimal.transcription.step import CollocationSpec

    d, _, _ = optimised
    assert len(d.time) == 101
    scene = load_scene(CONFIGS / "rabbit_optimal.yaml")
    data = walker_data(scene.walker, 0.0)
    coarse = collocate_five_link(data, CollocationSpec(
        intervals=25, max_torque_n_m=150.0, target_step_length_m=0.5,
        target_step_period_s=0.7))
    assert coarse.status == "Solve_Succeeded"
    assert coarse.objective == pytest.approx(d.objective, rel=1e-4)
    fns = five_link_functions(data.structure)
    e25 = open_loop_error(fns, data.params, coarse.t, coarse.x, coarse.u)
    e50 = d.collocated_start_error
    assert np.log2(e25 / e50) >= 3.5, (e25, e50)


def check_the_phase_variable_replay_closes_stable_with_the_optimal_torques(optimised):
    """The optimum as virtual constraints (the torques as a function of the stance leg's
    angle, plus PD tracking of the collocated joint trajectory at RABBIT's gains): one step
    from the collocated start returns within the transcription's error (measured 4.2e-5);
    closed, the rigid model's step returns to 1e-6 (measured ~2e-12) with every multiplier
    inside the unit circle (largest measured 0.393: the zero dynamics'), and the law's
    torque stays within 0.5 % of the largest optimal torque of the optimal torques at the
    same time (the PD part is zero on the collocated step; measured ~0.1 %).  The
    feed-forward alone is recorded: unstable (largest |multiplier| ~1e4), not closed."""
    d, _, _ = optimised
    fb, ff = d.phase_replays["feedback"], d.phase_replays["feedforward"]
    assert fb.closed and fb.return_error <= 1e-6
    assert fb.collocated_start_error < 1e-4 and fb.start_shift < 2e-4
    assert np.max(np.abs(fb.multipliers)) < 1.0
    assert fb.step_period_s == pytest.approx(d.step_period_s, abs=1e-4)
    assert fb.torque_error <= 5e-3 * np.abs(d.torque).max()
    assert not ff.closed and ff.collocated_start_error > 1e-2
    assert np.max(np.abs(ff.multipliers)) > 1.0


def check_the_phase_variable_law_walks_the_contact_model_at_the_optimums_period(optimised):
    """The scene's contact replay: the feed-forward + PD law in the contact model (the
    paper's contact law with the scene's friction regularisation of 10 mm/s: the paper's
    100 mm/s lets the stance foot creep under the optimum's tangential load, |Ft/Fn| up to
    0.50, and the steps slow by ~6 %): 2 strides, the mean step period within 3 % of the
    optimum's (the issue's check; measured +0.61 %), stored in optimize.h5."""
    d, _, _ = optimised
    scene = load_scene(CONFIGS / "rabbit_optimal.yaml")
    assert scene.contact.written("stiction_velocity")[0] == 10.0
    assert d.contact_outcome == "heel_strike", d.contact_outcome
    assert abs(d.contact_step_period_s / d.step_period_s - 1.0) <= 0.03, d.contact_step_period_s


def check_the_phase_laws_compiled_flows_are_its_python_flows(optimised):
    """The phase-variable replays run the law inside the compiled flows (its law block,
    :meth:`walkerlab.optimal.replay.phase.PhaseLaw.packed`, on CyRK's DOP853): at the
    collocated states, perturbed by 0.01, each phase's cfunc gives the walker's Python flow
    (the generated passive flow + ``M^-1 B tau`` with the law called in Python) to 1e-11 of
    its largest entry, and its guards' outputs the Python guards."""
    import ctypes

    from walkerlab.optimal.replay.virtual_constraints import (
        RABBIT_GAINS,
        phase_law,
        phased_walker,
        rigid_actuators,
    )

    d, _, _ = optimised
    scene = load_scene(CONFIGS / "rabbit_optimal.yaml")
    data = walker_data(scene.walker, scene.slope.phi_rad)
    x = np.stack(list(d.states.values()), axis=1)
    law = phase_law(rigid_actuators(data), x, d.torque, *RABBIT_GAINS, t=d.time)
    w = phased_walker(data, law)
    rng = np.random.default_rng(11)
    p = ctypes.POINTER(ctypes.c_double)
    for ph in w.phases:
        cf = ph.compiled
        mod = cf.module()
        n_extra, cols, offs = cf.guard_columns()
        for xi in x[::10] + rng.normal(0, 0.01, x[::10].shape):
            dy, y, data_vec = np.zeros(x.shape[1] + n_extra), np.ascontiguousarray(xi), cf.data()
            mod.cfunc_of("flow").ctypes(dy.ctypes.data_as(p), 0.0, y.ctypes.data_as(p),
                            data_vec.ctypes.data_as(p))
            want = np.asarray(ph.flow(0.0, xi))
            np.testing.assert_allclose(dy[:x.shape[1]], want, rtol=0,
                                       atol=1e-11 * np.abs(want).max())
            for g, c, o in zip(ph.guards, cols, offs):
                assert dy[x.shape[1] + c] + o == pytest.approx(g.function(0.0, xi), abs=1e-12)


@pytest.mark.slow  # one optimisation of rabbit_optimal (~25 s CPU warm, ~1 min cold)
def test_the_shipped_five_link_optimum(optimised, fns_and_params):
    """The checks of the shipped five-link optimum, in one test: pytest-xdist 3.8 with
    pytest 9.2 ignored ``xdist_group`` marks (pyproject now pins pytest < 9.2), so separate
    tests ran the fixture on both workers (2 x 240 s of the slow set)."""
    check_kellys_step_meets_its_targets_and_constraints(optimised, fns_and_params)
    check_the_closed_step_replays_on_the_rigid_model(optimised)
    check_the_report_shows_the_optimised_step(optimised)
    check_the_transcription_error_falls_at_hermite_simpsons_order(optimised)
    check_the_phase_variable_replay_closes_stable_with_the_optimal_torques(optimised)
    check_the_phase_variable_law_walks_the_contact_model_at_the_optimums_period(optimised)
    check_the_phase_laws_compiled_flows_are_its_python_flows(optimised)
