"""Pseudo-arclength continuation of gaits (issue 23): special points against independent
computations.

The independent checks share no code with :mod:`walkerlab.analysis.continuation.branch`: fixed
points by :func:`scipy.optimize.root` on the (k-step) Poincaré map with MINPACK's own
finite-difference Jacobian, multipliers from a central finite-difference Jacobian of the
map (not the variational equations), and the onset by :func:`scipy.optimize.brentq` in the
parameter on ``1 + (most negative real multiplier)``.  Finite-difference multipliers carry
~1e-7 of error (NOTES.md: ~9 digits for the map's Jacobian at h = 1e-7 ... 1e-5), which moves
an onset by ~1e-7 / |d mu / d p|, far inside the 1e-4 asked.
"""

from __future__ import annotations

from pathlib import Path

import h5py
import numpy as np
import pytest
from scipy.optimize import brentq, root
from typer.testing import CliRunner

from tests.cli_run import run_cli as _cli
from walkerlab.analysis.continuation.branch import SPECIAL_KINDS
from walkerlab.analysis.gait.poincare import poincare_map
from walkerlab.cli import app
from walkerlab.config import load_scene
from walkerlab.integrate.solver import Solver
from walkerlab.models.registry import build_walker
from walkerlab.studies.continuation import run_continuation
from walkerlab.studies.params import apply_point
from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]


def _walker(scene, path, p):
    sc = apply_point(scene.model_dump(mode="json"), [path], (p,))
    return build_walker(Plant.from_scene(sc))


def _kmap(walker, x, solver, k, tmax):
    for _ in range(k):
        x, _T, _n = poincare_map(walker, x, solver, tmax)
    return x


def _independent_orbit(scene, path, p, guess, k):
    """Fixed point of the k-step map (scipy root, MINPACK finite differences) and the
    multipliers of a central finite-difference Jacobian of the map there."""
    w = _walker(scene, path, p)
    s = Solver.from_settings(scene.solver)
    tmax = scene.fixedpoint.max_step_time_s
    sol = root(lambda z: w.section(_kmap(w, w.from_section(z), s, k, tmax)) - z,
               w.section(guess), method="hybr", options={"xtol": 1e-13})
    x = w.from_section(sol.x)
    assert np.max(np.abs(_kmap(w, x, s, k, tmax) - x)) < 1e-10
    n, h = x.size, 1e-6
    J = np.empty((n, n))
    for j in range(n):
        e = np.zeros(n)
        e[j] = h
        J[:, j] = (_kmap(w, x + e, s, k, tmax) - _kmap(w, x - e, s, k, tmax)) / (2 * h)
    return x, np.linalg.eigvals(J)


def _independent_onset(scene, path, lo, hi, guess, k):
    """brentq on 1 + min real multiplier of the independent k-step orbit, in ``p``."""
    state = {"x": guess}

    def g(p):
        x, mu = _independent_orbit(scene, path, p, state["x"], k)
        state["x"] = x
        real = mu[np.abs(mu.imag) < 1e-6].real
        return 1.0 + real.min()

    return brentq(g, lo, hi, xtol=1e-9)


def _special(res, kind, period):
    return [s for s in res.specials if s.kind == kind and s.period == period]


@pytest.fixture(scope="module")
def paper():
    scene = load_scene(ROOT / "configs" / "paper.yaml")
    res, _ = run_continuation(scene, "slope.angle_deg", 3.8, 4.97, switch=1,
                              plant=Plant.from_scene(scene))
    return scene, res


@pytest.fixture(scope="module")
def simplest():
    scene = load_scene(ROOT / "configs" / "simplest.yaml")
    res, _ = run_continuation(scene, "slope.angle_rad", 0.012, 0.0179, switch=1,
                              plant=Plant.from_scene(scene))
    return scene, res


@pytest.mark.slow
def test_paper_period_doubling_onsets_match_independent_brentq(paper):
    """Period 1 -> 2 (Goswami et al. 1996: 4.37 deg; this project's sweep 4.391 deg) and
    period 2 -> 4, each to 1e-4 deg of the independent computation."""
    scene, res = paper
    (pd1,), (pd2,) = _special(res, "period_doubling", 1), _special(res, "period_doubling", 2)
    assert abs(pd1.p - 4.391) < 2e-3  # the project's brute-force sweep (0.05 deg grid)
    ref1 = _independent_onset(scene, "slope.angle_deg", pd1.p - 0.05, pd1.p + 0.05, pd1.x, 1)
    assert abs(pd1.p - ref1) < 1e-4, (pd1.p, ref1)
    ref2 = _independent_onset(scene, "slope.angle_deg", pd2.p - 0.01, pd2.p + 0.01, pd2.x, 2)
    assert abs(pd2.p - ref2) < 1e-4, (pd2.p, ref2)
    # the multiplier at the located points is -1 (variational equations)
    for sp in (pd1, pd2):
        real = sp.multipliers[np.abs(sp.multipliers.imag) < 1e-9].real
        assert abs(real.min() + 1.0) < 1e-6


@pytest.mark.slow
def test_simplest_period_doubling_onsets_match_garcia_and_independent(simplest):
    """Garcia et al. 1998 (J. Biomech. Eng. 120:281): period doubling at gamma ~ 0.0151
    (the scene is nondimensional, slope in rad); period 4 from the period-2 branch."""
    scene, res = simplest
    (pd1,), (pd2,) = _special(res, "period_doubling", 1), _special(res, "period_doubling", 2)
    assert abs(pd1.p - 0.0151) < 1e-4
    ref1 = _independent_onset(scene, "slope.angle_rad", pd1.p - 5e-4, pd1.p + 5e-4, pd1.x, 1)
    assert abs(pd1.p - ref1) < 1e-4 * 1e-2, (pd1.p, ref1)  # rad: far inside 1e-4
    ref2 = _independent_onset(scene, "slope.angle_rad", pd2.p - 3e-4, pd2.p + 3e-4, pd2.x, 2)
    assert abs(pd2.p - ref2) < 1e-6, (pd2.p, ref2)
    assert 0.0151 < pd2.p < 0.019  # after period 2, before Garcia's chaos (~0.019)


@pytest.mark.slow
def test_branches_agree_with_independent_fixed_points():
    """At >= 20 points along the period-1 and along the period-2 branch the continuation's
    state equals an independent fixed-point solve (k-step map) at the same parameter to
    1e-9 (both solved to ~1e-12)."""
    scene = load_scene(ROOT / "configs" / "paper.yaml")
    res, _ = run_continuation(scene, "slope.angle_deg", 4.0, 4.8, switch=1, ds_max=0.04,
                              plant=Plant.from_scene(scene))
    assert [b.period for b in res.branches] == [1, 2]
    for br in res.branches:
        # the period doubling a switched branch starts at is not an isolated fixed point of
        # the 2-step map (a multiplier +1 there: the root finder's answer is only good to
        # ~sqrt(eps)), so it is left out
        pts = [q for q in br.points if np.min(np.abs(q.multipliers - 1.0)) > 1e-3]
        assert len(pts) >= 20, len(pts)
        worst = 0.0
        for q in pts:
            x, _mu = _independent_orbit(scene, "slope.angle_deg", q.p, q.x, br.period)
            worst = max(worst, float(np.max(np.abs(x - q.x))))
        assert worst < 1e-9, (br.period, worst)


@pytest.mark.slow
def test_kneed_gait_ends_in_a_fold_where_a_scan_loses_it():
    """Moving the kneed walker's thigh mass towards the hip the gait ends (issue 23: a sweep
    reported ``no_fixed_point`` near 0.268 m): a fold, multiplier +1 to 1e-6; a natural-
    parameter scan with the root finder (independent of the continuation) finds gaits above
    the fold and none 2 mm below it."""
    from walkerlab.analysis.gait.poincare import FixedPointNotFound, find_fixed_point

    scene = load_scene(ROOT / "configs" / "kneed.yaml")
    path = "walker.leg.bodies.thigh_mass.from_hip_m"
    res, _ = run_continuation(scene, path, 0.255, 0.31, plant=Plant.from_scene(scene))
    folds = _special(res, "fold", 1)
    assert len(folds) == 1
    f = folds[0]
    assert 0.26 < f.p < 0.27
    mu = f.multipliers
    assert np.min(np.abs(mu - 1.0)) < 1e-6
    s = Solver.from_settings(scene.solver)
    x = f.x
    for p in (f.p + 3e-3, f.p + 1e-3, f.p + 2e-4):  # towards the fold from above: found
        x = find_fixed_point(_walker(scene, path, p), x, s, fd_check=False).x
    with pytest.raises(FixedPointNotFound):
        find_fixed_point(_walker(scene, path, f.p - 2e-3), x, s, fd_check=False)


def test_paper_rods_bifurcation_chain_keeps_the_stable_long_gait():
    """Issue 23's defect: ``bifurcation --param walker.leg.bodies.rod.mass_kg=3:7:0.5``
    reported the unstable short-period gait at 3 kg (T 0.8227 s, |mu| 3.23).  The chains
    start at the scene's value (5 kg) and follow the branch by pseudo-arclength: at 3 kg the
    stable long gait (T 1.0223 s, |mu| 0.778, as ``fixedpoint`` and ``sweep`` there)."""
    from walkerlab.studies.bifurcation import bifurcation_diagram

    scene = load_scene(ROOT / "configs" / "paper_rods.yaml")
    r = bifurcation_diagram(scene, np.arange(3.0, 7.01, 0.5), steady_state=False, workers=1,
                            param="walker.leg.bodies.rod.mass_kg", plant=Plant.from_scene(scene))
    assert abs(r.step_period_s[0] - 1.0223) < 1e-4
    assert abs(np.max(np.abs(r.multipliers[0])) - 0.778) < 1e-3
    assert np.all(np.max(np.abs(r.multipliers), axis=1) < 1)


@pytest.mark.slow
def test_artifact_round_trip_and_cli(tmp_path):
    """The CLI writes continuation_<field>.h5 (kinds as strings, the parameter in its unit,
    the branch period) and its figure; the loader reads back the located points."""

    from walkerlab.io.schemas.continuation import load_continuation

    r = CliRunner().invoke(app, ["continuation", str(ROOT / "configs" / "paper_rods.yaml"),
                                 "--param", "walker.leg.bodies.rod.mass_kg=2.5:3.0",
                                 "--runs-dir", str(tmp_path)])
    assert r.exit_code == 0, r.output
    assert "period_doubling" in r.output
    path = tmp_path / "paper_rods" / "continuation_walker.leg.bodies.rod.mass_kg.h5"
    data = load_continuation(path)
    assert data.unit == "kg" and set(data.special["kind"]) <= set(SPECIAL_KINDS)
    (i,) = np.flatnonzero(data.special["kind"] == "period_doubling")
    assert 2.6 < data.special["param"][i] < 2.8 and data.special["period"][i] == 1
    b = data.branches[0]
    assert b["period"] == 1 and b["multipliers"].shape[1] == 4
    assert b["stable"][np.argmax(b["param"])] and not b["stable"][np.argmin(b["param"])]
    assert (tmp_path / "paper_rods" / "report" / "figures"
            / "continuation_walker.leg.bodies.rod.mass_kg.png").is_file()
    bad = CliRunner().invoke(app, ["continuation", str(ROOT / "configs" / "paper.yaml"),
                                   "--param", "slope.angle_deg=1:1", "--runs-dir",
                                   str(tmp_path)])
    assert bad.exit_code == 1 and "FIELD=START:STOP" in bad.output


@pytest.mark.slow
def test_two_parameter_period_doubling_curve_matches_independent_onsets():
    """The paper walker's period-doubling boundary in the plane slope x hip mass (Goswami
    et al.'s chart over mu = m_H / m, m = 5 kg): the curve's point at m_H = 20 kg equals an
    independent brentq onset there to 1e-4 deg; the onset falls as the hip gets heavier
    (Goswami, Thuilot & Espiau 1998, Fig. 10: the period-doubling slope decreases with mu)."""
    scene = load_scene(ROOT / "configs" / "paper.yaml")
    _res, curves = run_continuation(scene, "slope.angle_deg", 4.2, 4.6, 0,
                                    "walker.hip_mass_kg", (10.0, 20.0), n2=3,
                                    plant=Plant.from_scene(scene))
    (c,) = curves
    assert c.kind == "period_doubling" and list(c.p2) == [10.0, 15.0, 20.0]
    assert np.all(np.diff(c.p) < 0)
    assert np.all(np.abs(c.multiplier + 1.0) < 1e-6)
    heavy = apply_point(scene.model_dump(mode="json"), ["walker.hip_mass_kg"], (20.0,))
    ref = _independent_onset(heavy, "slope.angle_deg", c.p[-1] - 0.05, c.p[-1] + 0.05,
                             c.x[-1], 1)
    assert abs(c.p[-1] - ref) < 1e-4, (c.p[-1], ref)


def test_a_gait_found_with_from_is_reused_by_a_run_without_it(tmp_path, monkeypatch):
    """``fixedpoint --from`` writes the scene's gait; before, every later command without
    ``--from`` (``report``, ``simulate``) recomputed it by the plain search ("an upstream
    artifact or a stage option changed") - and failed where only the homotopy finds it.
    Now the artifact says which start found it and is reused while the scene and the code
    are unchanged; a changed scene still recomputes."""
    import yaml

    from walkerlab.analysis.gait import scene as gait_scene
    from walkerlab.stages import fixedpoint as stage

    d = yaml.safe_load((ROOT / "configs" / "paper.yaml").read_text())
    d["walker"]["hip_mass_kg"] = 10.5
    path = tmp_path / "heavier.yaml"
    path.write_text(yaml.safe_dump(d))
    scene = load_scene(path)
    made = stage.run(scene, tmp_path, known=ROOT / "configs" / "paper.yaml")
    assert not made.reused

    def search(*a, **k):  # the plain search must not run again
        raise AssertionError("fixedpoint recomputed without --from")
    monkeypatch.setattr(gait_scene, "fixed_point_run", search)
    for variants in (True, False):  # the report's run (variants) and simulate's
        again = stage.run(scene, tmp_path, compare_variants=variants)
        assert again.reused and again.path == made.path
    assert stage.fresh_artifact(scene, tmp_path) == made.path
    d["walker"]["hip_mass_kg"] = 11.0  # another scene: not this gait
    path.write_text(yaml.safe_dump(d))
    with pytest.raises(AssertionError, match="recomputed without --from"):
        stage.run(load_scene(path), tmp_path)


@pytest.mark.slow
def test_homotopy_and_initial_guess_from_an_artifact(tmp_path):
    """``fixedpoint --from`` carries the kneed gait to a steeper, heavier-hipped design (both
    fields change at once) and reports the period doubling passed on the way; an
    ``initial_guess`` naming a continuation artifact and a parameter value starts the root
    finder on that branch: it converges to the continuation's own fixed point there."""
    import yaml


    d = yaml.safe_load((ROOT / "configs" / "kneed.yaml").read_text())
    d["slope"]["angle_rad"], d["walker"]["hip_mass_kg"] = 0.12, 1.0
    del d["fixedpoint"]["initial_guess"]
    new = tmp_path / "kneed_steep.yaml"
    new.write_text(yaml.safe_dump(d))
    r = CliRunner().invoke(app, ["fixedpoint", str(new), "--from",
                                 str(ROOT / "configs" / "kneed.yaml"), "--runs-dir",
                                 str(tmp_path / "runs")])
    assert r.exit_code == 0, r.output
    assert "by homotopy over slope.angle_rad, walker.hip_mass_kg" in r.output
    assert "period doubling at lambda" in r.output
    assert "step period     0.65393" in r.output  # the gait the seeds find too
    # a design whose straight line leaves the gait: one line naming where and why
    d["slope"]["angle_rad"], d["walker"]["hip_mass_kg"] = 0.02, 0.5
    far = tmp_path / "kneed_shallow.yaml"
    far.write_text(yaml.safe_dump(d))
    r = CliRunner().invoke(app, ["fixedpoint", str(far), "--from",
                                 str(ROOT / "configs" / "kneed.yaml"), "--runs-dir",
                                 str(tmp_path / "runs")])
    assert r.exit_code == 1 and "fold at lambda" in r.output
    # initial_guess from a continuation artifact
    scene = load_scene(ROOT / "configs" / "paper_rods.yaml")
    from walkerlab.stages import continuation as stage

    out = stage.run(scene, "walker.leg.bodies.rod.mass_kg", 3.0, 5.0, runs_root=tmp_path)
    data = out.summary["data"]
    rod = scene.model_dump(mode="json")
    rod["fixedpoint"]["initial_guess"] = {"from": str(out.path), "at": 3.5}
    rod["walker"]["leg"]["bodies"][0]["mass_kg"] = 3.5
    from walkerlab.analysis.gait.scene import solve_scene
    from walkerlab.config import scene_from_dict

    sc = scene_from_dict(rod)
    _w, search = solve_scene(sc, fd_check=False, plant=Plant.from_scene(sc))
    ref = _independent_orbit(scene_from_dict(rod), "walker.leg.bodies.rod.mass_kg", 3.5,
                             data.state_at(3.5), 1)[0]
    assert np.max(np.abs(search.result.x - ref)) < 1e-9
    assert search.gait.source == "initial_guess"


def test_stance_foot_normal_force_from_the_equations_of_motion():
    """The branch-end check 'stance foot lifting' differentiates the centre of mass on the
    dense output; here the same force from the equations of motion instead: the centre of
    mass of the paper walker's masses by name (hip 10 kg, two 5 kg leg masses, Table 1),
    its acceleration as the derivative of its velocity along the flow vector field, N = M (a .
    n + g cos phi) with n the slope normal.  The smallest N / (M g) over the step agrees to
    1e-5 (the second difference on 200 points a phase errs by ~h^2 |d^4 com/dt^4| / 12,
    measured 3e-6 here; at a branch end this moves the located parameter by 1e-5 / |dN/dp|)."""
    from walkerlab.analysis.continuation.gait_map import step_map
    from walkerlab.analysis.continuation.validity import normal_force_ratio

    scene = load_scene(ROOT / "configs" / "paper.yaml")
    w = build_walker(Plant.from_scene(scene))
    s = Solver.from_settings(scene.solver)
    x0 = np.array([-0.3234, 0.2187, -0.3801, -1.0932])  # near the gait: any step will do
    segs = step_map(w, w.from_section(w.section(x0)), s, 1, segments=True)[3]
    got = normal_force_ratio(w, segs)
    masses = {"hip": 10.0, "stance_mass": 5.0, "swing_mass": 5.0}
    M, g, phi = 20.0, 9.81, 0.0174
    nrm = np.array([np.sin(phi), np.cos(phi)])
    n = w.n_coordinates

    def com(x):
        pts = w.points(x)
        return sum(m * np.asarray(pts[k], float) for k, m in masses.items()) / M

    def v_com(x):  # d com / dt = D com(q) . qdot, by a central difference along qdot
        e = np.concatenate([x[n:], np.zeros(n)]) * 1e-6
        return (com(x + e) - com(x - e)) / 2e-6

    low = np.inf
    for seg in segs:
        for ph, dense, (ta, tb) in seg.pieces:
            for t in np.linspace(ta, tb, 200)[2:-2]:
                x = np.asarray(dense(t), float).ravel()[:2 * n]
                f = np.asarray(ph.flow(t, x), float)
                a = (v_com(x + 1e-6 * f) - v_com(x - 1e-6 * f)) / 2e-6
                low = min(low, float((nrm @ a + g * np.cos(phi)) / g))
    assert 0.5 < low < 1.0
    assert abs(got - low) < 1e-5, (got, low)


def test_no_cost_of_transport_figure_without_finite_measures():
    """A branch whose gait measures are all NaN (a walker without a ledger) gets no cost-of-
    transport figure, not an empty one."""
    from types import SimpleNamespace

    import numpy as np

    from walkerlab.plotting.continuation_figures import cost_of_transport_figure

    nan = np.full(3, np.nan)
    b = {"gait": {"speed": nan, "cost_of_transport": nan}, "stable": np.ones(3, bool),
         "param": np.arange(3.0), "period": 1}
    assert cost_of_transport_figure(SimpleNamespace(branches=[b], path="x", unit="-")) is None


def test_a_homotopy_from_a_scene_with_the_same_numbers_says_so_without_an_empty_list(
        monkeypatch):
    """Issue 56 item 16: ``fixedpoint.from`` a scene whose walker and slope are this one's
    said "by homotopy over  (8 continuation points" (an empty field list)."""
    from types import SimpleNamespace

    from walkerlab.studies import continuation as C

    sc = load_scene(Path(__file__).resolve().parents[1] / "configs" / "paper.yaml")
    same = SimpleNamespace(reached=True, fields={}, specials=[], x=np.zeros(4),
                           branch=SimpleNamespace(points=[None] * 8))
    monkeypatch.setattr(C, "homotopy_gait", lambda known, new, plant: same)
    _, note = C.homotopy_start(sc, sc, plant=Plant.from_scene(sc))
    assert "over  (" not in note and "by homotopy over" not in note
    assert note == ("initial guess: the gait of scene paper, whose walker and slope have this "
                    "scene's numbers (nothing to carry by homotopy)")


# -------------------- --param of a continuation, a fall named once, a two-parameter artifact


def _one_line(*args) -> str:
    code, err, _ = _cli(*args)
    assert code == 1, (code, err)
    assert len(err.splitlines()) == 1, err
    return err


@pytest.mark.filterwarnings("error")
def test_a_continuation_to_infinity_is_one_line_and_no_numpy_warning(tmp_path):
    err = _one_line("continuation", ROOT / "configs" / "paper.yaml", "--param",
                    "slope.angle_deg=1:inf", "--runs-dir", tmp_path)
    assert err == "error: --param slope.angle_deg: stop inf is not a finite number"


@pytest.mark.parametrize("param2", ["slope.angle_deg=1:2", "slope.angle_rad=0.01:0.02"])
def test_param2_the_same_field_as_param_is_refused(tmp_path, param2):
    err = _one_line("continuation", ROOT / "configs" / "paper.yaml", "--param",
                    "slope.angle_deg=1:2", "--param2", param2, "--runs-dir", tmp_path)
    assert "the same field as --param slope.angle_deg" in err


def test_an_index_past_an_unnamed_list_says_its_indices(tmp_path):
    err = _one_line("continuation", ROOT / "configs" / "asymmetric_legs.yaml", "--param",
                    "walker.legs.5.length_m=0.9:1", "--runs-dir", tmp_path)
    assert err.endswith("index 5 is out of range (the list has 2 items, indices 0-1)")
    assert "None" not in err


def test_a_continuation_over_a_whole_number_field_is_refused_as_typed(tmp_path):
    err = _one_line("continuation", ROOT / "configs" / "paper.yaml", "--param",
                    "simulate.strides=1:2", "--runs-dir", tmp_path)
    assert err.startswith("error: --param simulate.strides: the field takes whole numbers")
    assert "<sweep>" not in err and "2.0" not in err


def test_a_fall_is_named_once():
    from types import SimpleNamespace

    from walkerlab.analysis.continuation.gait_map import _cause

    walker = SimpleNamespace(phases=[])
    seg = SimpleNamespace(termination="event", event="fall", phase_times={})
    assert _cause(walker, seg) == "fall"
    seg.event = "stance_heel_touches_down"
    assert _cause(walker, seg) == "fall (stance_heel_touches_down)"


# ------------------------------ 11: a two-parameter run keeps the one-parameter artifact
def test_a_two_parameter_continuation_has_its_own_artifact_name():
    from walkerlab.io.runpaths import continuation_stem

    one = continuation_stem("walker.leg.bodies.rod.mass_kg")
    two = continuation_stem("walker.leg.bodies.rod.mass_kg", "walker.hip_mass_kg")
    assert one == "continuation_walker.leg.bodies.rod.mass_kg"
    assert two == "continuation_walker.leg.bodies.rod.mass_kg+walker.hip_mass_kg"


@pytest.mark.slow
def test_switch_and_param2_runs_are_both_kept(tmp_path):
    from walkerlab.io.schemas.continuation import load_continuation

    scene, runs = ROOT / "configs" / "simplest.yaml", tmp_path / "runs"
    base = ["continuation", scene, "--param", "slope.angle_rad=0.0085:0.0095", "--runs-dir",
            runs]
    code, err, out = _cli(*base, "--switch")
    assert code == 0, err
    code, err, out2 = _cli(*base, "--param2", "walker.leg.length_m=0.95:1.05")
    assert code == 0, err
    d = runs / "simplest"
    one = load_continuation(d / "continuation_slope.angle_rad.h5")
    two = load_continuation(d / "continuation_slope.angle_rad+walker.leg.length_m.h5")
    assert not one.curves and {b["period"] for b in one.branches} >= {1}
    assert len(one.branches) >= len(two.branches)
    figs = d / "report" / "figures"
    assert (figs / "continuation_slope.angle_rad.png").is_file()
    assert (figs / "continuation_slope.angle_rad+walker.leg.length_m.png").is_file()
    assert "continuation_slope.angle_rad+walker.leg.length_m.h5" in out2


# -------------------- a stride map on a branch where the legs start to differ


# ------------------------------------------------------------------ 6: a stride map on a branch
@pytest.mark.slow
def test_continuation_where_the_legs_start_to_differ_writes_its_artifact(tmp_path):
    """A hip spring's rest angle from 0 (legs alike: a one-step map) to 0.01 rad (legs that
    differ: a stride) - before: 9-15 s of work, then "setting an array element with a
    sequence" while writing (orbits of 1 and 2 heel strikes on one branch).  The branch has
    one map, a stride, throughout; the fixed points at 0 are the gait's, as before."""
    from walkerlab.io.schemas.continuation import load_continuation

    code, err, _ = _cli("continuation", ROOT / "configs" / "hip_spring.yaml", "--param",
                        "walker.springs.0.rest_angle_rad=0:0.01", "--runs-dir", tmp_path)
    assert code == 0, err
    path = tmp_path / "hip_spring" / "continuation_walker.springs.0.rest_angle_rad.h5"
    with h5py.File(path, "r") as f:
        orbit = f["branches/0/orbit/swing_angle"][()]
    assert orbit.ndim == 2 and orbit.shape[1] == 2  # two heel strikes a map at every point
    d = load_continuation(path)
    assert np.all(np.isfinite(d.branches[0]["param"]))
    assert d.steps_per_map == 2  # the one map, recorded: its multipliers are per stride


def test_a_homotopy_turned_back_by_a_fold_says_how_far_it_got_not_only_where_it_ended(
        monkeypatch):
    """Issue 64 item 5: a branch turned back by a fold said "stopped at lambda = 0: fold at
    lambda 0.2343" (where it ended after turning back, as if it had not started)."""
    from types import SimpleNamespace

    from walkerlab.studies import continuation as C

    sc = load_scene(Path(__file__).resolve().parents[1] / "configs" / "paper.yaml")
    pts = [SimpleNamespace(p=p) for p in (0.0, 0.1, 0.2, 0.2343, 0.2, 0.1, 0.0)]
    fold = SimpleNamespace(kind="fold", p=0.2343, cause="")
    res = SimpleNamespace(reached=False, fields={"slope.angle_rad": 1}, specials=[fold],
                          x=np.zeros(4), branch=SimpleNamespace(points=pts))
    monkeypatch.setattr(C, "homotopy_gait", lambda known, new, plant: res)
    with pytest.raises(ValueError) as exc:
        C.homotopy_start(sc, sc, plant=Plant.from_scene(sc))
    msg = str(exc.value)
    assert "stopped at lambda = 0" not in msg
    assert "got as far as lambda = 0.2343, then turned back and ended at lambda = 0" in msg
    assert msg.endswith("fold at lambda 0.2343)")


def test_the_from_option_says_the_two_walkers_must_share_their_structure():
    """Issue 64 item 5: ``--from`` refuses scenes whose body lists differ; its help did not
    say so."""
    code, _err, out = _cli("fixedpoint", "--help")
    assert code == 0
    assert "must have the same structure" in " ".join(out.replace("│", " ").split())


def test_the_disc_wheels_critical_slope_is_a_branch_point_the_family_passes_through():
    """Issue 82 item 14: the disc wheel's (configs/rimless_wheel_3d_disc.yaml) loss of
    stability at 0.18567 rad was labelled a fold, a turning point in the parameter.  The
    family passes straight through it (the slope grows monotonically along the branch) while
    a real multiplier, besides the heading's neutral 1, crosses +1: a branch point
    (transcritical or pitchfork), no fold.  The kneed walker's fold, where the branch does
    turn back, stays a fold (test_kneed_gait_ends_in_a_fold_where_a_scan_loses_it)."""
    scene = load_scene(ROOT / "configs" / "rimless_wheel_3d_disc.yaml")
    res, _ = run_continuation(scene, "slope.angle_rad", 0.18, 0.19, plant=Plant.from_scene(scene))
    assert res.steps_per_map == 1  # the wheel's map is one step: multipliers per step
    assert [s.kind for s in res.specials] == ["branch_point"]
    bp = res.specials[0]
    assert bp.p == pytest.approx(0.18567, abs=1e-5)
    mu = bp.multipliers
    # two at +1: the neutral heading's and the critical one (a double eigenvalue: the
    # computed pair splits by ~sqrt(machine eps) of the Jacobian's error, hence 1e-5)
    near_one = np.sort(np.abs(mu - 1.0))
    assert near_one[1] < 1e-5 and near_one[2] > 0.1
    p = res.branches[0].params()
    assert np.all(np.diff(p) > 0)  # no turning back: the branch passes through
    # either side of it the critical multiplier is off +1 the other way (1.07 below,
    # 0.99 above): stability is lost through +1 (an independent root finder's run each)
    s = Solver.from_settings(scene.solver)
    from walkerlab.analysis.gait.poincare import find_fixed_point

    side = []
    for a in (0.18, 0.19):
        sc = apply_point(scene.model_dump(mode="json"), ["slope.angle_rad"], (a,))
        w = build_walker(Plant.from_scene(sc))
        r = find_fixed_point(w, bp.x, s, fd_check=False)
        m = np.sort(np.abs(r.multipliers_variational))[::-1]
        side.append(m[0] if m[0] > 1 + 1e-6 else m[1])  # the largest besides the neutral 1
    assert side[0] > 1.01 and side[1] < 0.995



@pytest.mark.slow  # ~35 s: a stride-map branch over 10 cm of hip width
def test_a_3d_continuation_over_hip_width_is_per_stride_from_the_planar_embedding_on(
        tmp_path):
    """Issue 82 item 1, the continuation's side: over the hip width from 0 (a step map of
    its own) to 0.1 m the branch has one map, a stride, recorded in the artifact and named
    on the figure: at zero width its largest multiplier is the zero-width walker's per-step
    11.2303 (configs/paper_3d.yaml on its own step map: an independent run) squared, and it
    falls with the hip width to the hip-width walker's 99.93."""
    from walkerlab.analysis.gait.scene import solve_scene
    from walkerlab.io.schemas.continuation import load_continuation
    from walkerlab.plotting.continuation_figures import continuation_figure
    from walkerlab.stages import continuation as stage

    out = stage.run(load_scene(ROOT / "configs" / "hip_width.yaml"), "walker.hip_width_m",
                    0.0, 0.1, runs_root=tmp_path)
    data = load_continuation(out.path)
    assert data.steps_per_map == 2
    br = data.branches[0]
    p, big = br["param"], np.max(np.abs(br["multipliers"]), axis=1)
    sc = load_scene(ROOT / "configs" / "paper_3d.yaml")
    _w, search = solve_scene(sc, fd_check=False, plant=Plant.from_scene(sc))
    step = np.max(np.abs(search.result.multipliers_variational))
    assert big[np.argmin(p)] == pytest.approx(step ** 2, rel=1e-6)
    assert big[np.argmax(p)] == pytest.approx(99.9294, rel=1e-5)
    assert np.all(np.diff(big[np.argsort(p)]) < 0)  # the instability falls with the width
    fig = continuation_figure(data)
    assert any("per stride" in ax.get_ylabel() for ax in fig.axes)
