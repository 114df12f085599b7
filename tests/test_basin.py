"""Basin of attraction: cell classification, the stage's artifact and resuming (small grids)."""

from pathlib import Path

import numpy as np
import pytest
import yaml

from walkerlab.config import BasinSettings, load_scene
from walkerlab.studies.basin import CODE, NOT_DONE, BasinError, classify_cell, slice_state
from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]


def _scene(tmp_path, walker, fp, **basin):
    """Paper walker, ideal only; basin axes centred on the fixed point ``fp`` (5 x 3 cells,
    so the middle cell is the fixed point itself)."""
    d = yaml.safe_load((ROOT / "configs" / "paper.yaml").read_text())
    for k in ("contact", "terrain", "contact_sim", "contact_solver", "workprecision",
              "simulate"):
        d.pop(k, None)
    names = walker.state_names()
    a, r = float(fp[names.index("stance_angle")]), float(fp[names.index("stance_rate")])
    d["basin"] = {"x_range": [a - 0.3, a + 0.3], "y_range": [r - 1.2, r + 1.2],
                  "grid": [5, 3], "max_steps": 25, **basin}
    p = tmp_path / "basin_scene.yaml"
    p.write_text(yaml.safe_dump(d))
    return load_scene(p)


def test_fixed_point_converges_and_far_cell_falls(paper_walker, paper_fixed_point):
    from walkerlab.integrate.solver import Solver

    fp = paper_fixed_point.x
    st = BasinSettings(max_steps=25)
    sv = Solver("DOP853", st.rtol, st.atol)
    names = paper_walker.state_names()
    x0 = slice_state(paper_walker, fp, ("stance_angle", "stance_rate"),
                     (fp[names.index("stance_angle")], fp[names.index("stance_rate")]))
    np.testing.assert_allclose(x0, fp, atol=1e-15)  # the slice passes through x*
    code, steps, period = classify_cell(paper_walker, x0, fp, sv, st)
    assert (code, steps, period) == (CODE["converged"], 1, 1)
    # a small kick is damped (|multipliers| <= 0.59): back within 1e-4 in < 25 steps
    x1 = slice_state(paper_walker, fp, ("stance_angle", "stance_rate"),
                     (fp[names.index("stance_angle")] + 0.01, fp[names.index("stance_rate")]))
    code, steps, _ = classify_cell(paper_walker, x1, fp, sv, st)
    assert code == CODE["converged"] and 3 <= steps < 25
    # leaning far back with the stance leg rotating backwards: it falls back, first step
    xb = slice_state(paper_walker, fp, ("stance_angle", "stance_rate"), (0.3, 0.5))
    assert classify_cell(paper_walker, xb, fp, sv, st)[:2] == (CODE["fell_backward"], 1)
    # the heel-strike constraint fixes the swing angle: not a free axis
    with pytest.raises(BasinError, match="basin.x_axis"):
        slice_state(paper_walker, fp, ("swing_angle", "stance_rate"), (0.1, -1.0))


@pytest.mark.slow  # in `pytest -m slow`: the quick suite keeps to its CPU budget
def test_basin_stage_artifact_and_resume(tmp_path, paper_walker, paper_fixed_point):
    from walkerlab.io.artifacts import open_artifact
    from walkerlab.stages import pipeline

    sc = _scene(tmp_path, paper_walker, paper_fixed_point.x)
    runs = tmp_path / "runs"
    calls = []

    def interrupt(done, total):
        calls.append(done)
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        pipeline.run("basin", sc, runs, workers=1, on_chunk=interrupt)
    part = runs / sc.name / "basin.h5.partial"
    import h5py

    with h5py.File(part, "r") as f:
        first = f["outcome"][()]
    assert np.sum(first != NOT_DONE) == calls[0] == 5  # one grid row stored
    out = pipeline.run("basin", sc, runs, workers=1)
    assert not out.reused and not part.exists()
    with open_artifact(out.path, "basin") as f:
        assert f["stats/cells_computed"][()] == 10  # the resumed run did the other 2 rows
        outcome = f["outcome"][()]
        assert outcome.shape == (3, 5) and f["x"].attrs["unit"] == "rad"
        assert [str(o) for o in f.attrs["outcomes"]][outcome[1, 2]] == "converged"
        assert f["period"][1, 2] == 1
    kept = first != NOT_DONE
    np.testing.assert_array_equal(outcome[kept], first[kept])
    assert np.all(outcome != NOT_DONE)
    assert (runs / sc.name / "report" / "figures" / "basin.png").is_file()
    assert pipeline.run("basin", sc, runs, workers=1).reused


def _simplest(tmp_path, **basin):
    d = yaml.safe_load((ROOT / "configs" / "schwab_wisse2001.yaml").read_text())
    d["basin"].update(basin)
    p = tmp_path / "sw.yaml"
    p.write_text(yaml.safe_dump(d))
    return load_scene(p)


def test_heel_strike_cells_of_the_simplest_walker(tmp_path):
    """``basin.start: heel_strike`` gives Schwab & Wisse's cells: for the simplest walker the
    post-impact states satisfy phi = 2 theta and phi-dot = (1 - cos 2 theta) theta-dot
    (Garcia et al. 1998, heel-strike equations, written here independently of the model's
    generated reset), and the cell at the fixed point's values is the fixed point."""
    from walkerlab.analysis.gait.poincare import find_fixed_point
    from walkerlab.integrate.solver import Solver
    from walkerlab.models.registry import build_walker
    from walkerlab.studies.basin import heel_strike_slice, pre_impact_fixed_point

    sc = _simplest(tmp_path)
    w = build_walker(Plant.from_scene(sc))
    names = w.state_names()
    th, ph, thd, phd = (names.index(n) for n in ("stance_angle", "hip_angle", "stance_rate",
                                                   "hip_rate"))
    fp = find_fixed_point(w, sc.fixedpoint.initial_guess.as_array(names),
                          Solver("DOP853", 1e-12, 1e-12), max_step_time=20.0,
                          fd_check=False).x
    pre = pre_impact_fixed_point(w, fp, sc.basin, 20.0)
    hs = heel_strike_slice(w, pre, ("stance_angle", "stance_rate"))
    np.testing.assert_allclose(hs.state(w, (fp[th], fp[thd])), fp, atol=1e-9)
    for a, r in ((0.05, -0.5), (0.2, -0.1), (0.35, -0.3), (0.15, 0.0)):
        x = hs.state(w, (a, r))
        assert x is not None
        np.testing.assert_allclose([x[th], x[thd]], [a, r], atol=1e-12)
        assert abs(x[ph] - 2 * a) < 1e-12
        assert abs(x[phd] - (1 - np.cos(2 * a)) * r) < 1e-12
    # the heel strike ties the hip angle to the stance angle: not a 2-D slice
    with pytest.raises(BasinError, match="relation"):
        heel_strike_slice(w, pre, ("stance_angle", "hip_angle"))


@pytest.mark.slow  # in `pytest -m slow`: the quick suite keeps to its CPU budget
def test_heel_strike_basin_of_the_simplest_walker_is_thin(tmp_path):
    """Schwab & Wisse (2001): the basin is "a small, thin area".  On a coarse 40 x 40 grid over
    their window (theta 0-0.4, theta-dot -0.6-0) the cell holding x* converges, under 2 % of
    the cells do (0.6 % measured), the rest fall, and the converged cells lie along a line:
    the standard deviations of their positions along and across it differ by > 8x (21.7x
    measured)."""
    from walkerlab.stages import pipeline

    sc = _simplest(tmp_path, grid=[40, 40])
    out = pipeline.run("basin", sc, tmp_path / "runs", workers=1)
    from walkerlab.io.artifacts import open_artifact

    with open_artifact(out.path, "basin") as f:
        o, x, y = f["outcome"][()], f["x"][()], f["y"][()]
        assert f.attrs["start"] == "heel_strike"
        fp = (f["fixed_point/stance_angle"][()], f["fixed_point/stance_rate"][()])
    conv = o == CODE["converged"]
    assert conv[np.argmin(abs(y - fp[1])), np.argmin(abs(x - fp[0]))]
    assert 5 <= conv.sum() < 0.02 * o.size
    assert np.all(conv | np.isin(o, [CODE["fell_forward"], CODE["fell_backward"]]))
    jy, ix = np.nonzero(conv)
    ev = np.linalg.eigvalsh(np.cov(np.c_[x[ix], y[jy]].T))
    assert np.sqrt(ev[1] / ev[0]) > 8


# ---- on a 3D walker: the rimless wheel (its heading neutral, Coleman et al. 1997) -------

DISC = ROOT / "configs" / "rimless_wheel_3d_disc.yaml"


def _wheel_scene(tmp_path, d: dict, name: str, **basin):
    d = {**d, "name": name, "basin": basin}
    p = tmp_path / f"{name}.yaml"
    p.write_text(yaml.safe_dump(d))
    return load_scene(p)


def test_a_3d_wheel_that_settles_rolling_at_another_heading_has_converged():
    """The disc wheel's steady rolling motions form a family along the heading (multiplier
    1): the member at heading 0.05 rad (leaning -0.0101 rad, found with the heading held) is
    a cell that has converged at its first heel strike, not another attractor (as it was
    judged against the gait at heading 0: 0.05 rad away)."""
    from walkerlab.analysis.gait.poincare import find_fixed_point
    from walkerlab.integrate.solver import Solver
    from walkerlab.models.registry import build_walker

    sc = load_scene(DISC)
    w = build_walker(Plant.from_scene(sc))
    st = BasinSettings(max_steps=10)
    sv = Solver("DOP853", st.rtol, st.atol)
    guess = np.array([0.0, 0.0, np.pi / 8 - 0.2, 0.0, 0.0, -1.9])
    fp = find_fixed_point(w, guess, sv, fd_check=False).x
    guess[0] = 0.05
    member = find_fixed_point(w, guess, sv, fd_check=False).x
    assert member[0] == 0.05 and abs(member[1] + 0.0101) < 1e-4  # it leans: not x* turned
    assert classify_cell(w, member, fp, sv, st) == (CODE["converged"], 1, 1)


def test_a_3d_wheels_basin_names_and_draws_the_lean_axes_its_cells_were_computed_on(
        tmp_path):
    """The disc wheel (stable: |multipliers| 0.918 besides the neutral 1) on its default
    axes: its section fixes the stance angle, so the cells lie in lean and lean rate and the
    artifact and the figure say so; the star is the fixed point there (upright: 0, 0), in
    the middle cell.  Every cell of a small window (lean +-1 mrad, lean rate +-4 mrad/s)
    converges, each to straight rolling at its own heading (a lean of 1 mrad settles at
    -0.071 rad heading in ~70 steps): with the heading set aside they have converged."""
    from walkerlab.io.schemas.basin import load_basin
    from walkerlab.plotting.basin_figures import basin_figure
    from walkerlab.stages import pipeline

    d = yaml.safe_load(DISC.read_text())
    sc = _wheel_scene(tmp_path, d, "disc", x_range=[-0.0015, 0.0015],
                      y_range=[-0.006, 0.006], grid=[3, 3], max_steps=150)
    b = load_basin(pipeline.run("basin", sc, tmp_path / "runs", workers=1).path)
    assert (b.x_axis, b.y_axis, b.x_unit, b.y_unit) == ("lean_angle", "lean_rate", "rad",
                                                        "rad/s")
    star = (b.fixed_point[b.x_axis], b.fixed_point[b.y_axis])
    assert np.max(np.abs(star)) < 1e-12
    assert np.argmin(abs(b.x - star[0])) == 1 and np.argmin(abs(b.y - star[1])) == 1
    assert np.all(b.outcome == CODE["converged"]), b.outcome
    fig = basin_figure(b)
    ax = fig.axes[0]
    assert ax.get_xlabel() == "lean angle [rad]" and ax.get_ylabel() == "lean rate [rad/s]"
    np.testing.assert_array_equal(ax.lines[0].get_xydata(), [star])


def test_a_3d_wheels_basin_in_its_stance_plane_is_the_planar_wheels(tmp_path):
    """Its planar embedding: the upright disc wheel started in the stance phase's phase plane
    (Coleman, Chatterjee & Ruina 1997; lean, heading and their rates 0) rolls as the planar
    wheel with the disc's axle inertia (0.5 kg m^2), so the two basin maps on the same 4 x 4
    grid agree cell by cell, in outcome and in steps (the 3D wheel's lateral coordinates stay
    at round-off, ~1e-20, far below the 1e-4 convergence test)."""
    from walkerlab.io.schemas.basin import load_basin
    from walkerlab.stages import pipeline

    a, g = np.pi / 8, 0.2
    basin = {"start": "phase_plane", "x_axis": "stance_angle", "y_axis": "stance_rate",
             "x_range": [-a - g, a - g], "y_range": [-4.0, 0.5], "grid": [4, 4],
             "max_steps": 50}
    d3 = yaml.safe_load(DISC.read_text())
    dp = yaml.safe_load((ROOT / "configs" / "rimless_wheel.yaml").read_text())
    for k in ("contact", "terrain", "contact_sim", "mfpt"):
        dp.pop(k, None)
    dp["walker"]["hub_inertia_kg_m2"] = 0.5
    dp["slope"]["angle_rad"] = g
    dp["fixedpoint"]["initial_guess"] = {"stance_angle_rad": a - g,
                                         "stance_rate_rad_per_s": -1.9}
    b3, bp = (load_basin(pipeline.run("basin", _wheel_scene(tmp_path, d, n, **basin),
                                      tmp_path / "runs", workers=1).path)
              for d, n in ((d3, "disc3d"), (dp, "planar")))
    np.testing.assert_array_equal(b3.x, bp.x)
    np.testing.assert_array_equal(b3.y, bp.y)
    np.testing.assert_array_equal(b3.outcome, bp.outcome)
    np.testing.assert_array_equal(b3.steps, bp.steps)
    found = set(b3.outcome.ravel())
    assert {CODE["converged"], CODE["fell_backward"]} <= found  # not one outcome throughout
