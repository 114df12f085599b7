"""Basin of attraction: cell classification, the stage's artifact and resuming (small grids)."""

from pathlib import Path

import numpy as np
import pytest
import yaml

from walkerlab.config import BasinSettings, load_scene
from walkerlab.studies.basin import CODE, NOT_DONE, BasinError, classify_cell, slice_state

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
    w = build_walker(sc)
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
