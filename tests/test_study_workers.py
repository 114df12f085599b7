"""Issue 96: every study gives the same artifact on one worker and on two, planar and 3D.

Each test runs a small study in this process (``workers=1``) and on a pool of two, and
compares every dataset of the two artifacts exactly (NaN equal to NaN), but for the wall
times (``*wall_time*``).  With the rough edges of the same probe: a bifurcation value whose
neighbour's guess misses is found from a fresh start, a 3D walker's contact sweep starts
from the step period, a 3D basin's corner cell off the heel-strike surface is
``unreachable`` and a continuation past the section's domain ends its branch there.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import h5py
import numpy as np
import pytest
import yaml

from walkerlab.config import load_scene, scene_from_dict
from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]
HIP_WIDTH = "walker.hip_width_m"


def _plant(base: dict) -> Plant:
    """The plant of a scene mapping (the study's, as its stage builds it)."""
    return Plant.from_scene(scene_from_dict(base))


def _datasets(path: Path) -> dict:
    """Every dataset of an HDF5 artifact but the wall times: name -> array."""
    out = {}

    def visit(name, obj):
        if isinstance(obj, h5py.Dataset) and "wall_time" not in name:
            out[name] = obj[()]

    with h5py.File(path, "r") as f:
        f.visititems(visit)
    return out


def assert_same_datasets(a: Path, b: Path) -> None:
    """The two artifacts hold the same datasets, bit for bit (but for wall times)."""
    da, db = _datasets(a), _datasets(b)
    assert sorted(da) == sorted(db)
    assert da, "no datasets compared"
    for name in da:
        x, y = np.asarray(da[name]), np.asarray(db[name])
        assert x.shape == y.shape, name
        if x.dtype.kind in "fc":
            np.testing.assert_array_equal(x, y, err_msg=name)  # NaN == NaN here
            assert np.array_equal(np.signbit(x.real), np.signbit(y.real)), name
        else:
            assert np.array_equal(x, y), name


def _scene(tmp_path: Path, name: str, drop=(), **sections):
    """A shipped scene with ``drop`` sections removed and ``sections`` set, as a file."""
    d = yaml.safe_load((ROOT / "configs" / f"{name}.yaml").read_text())
    for k in drop:
        d.pop(k, None)
    d.update(sections)
    p = tmp_path / f"{name}_{len(list(tmp_path.glob('*.yaml')))}.yaml"
    p.write_text(yaml.safe_dump(d))
    return load_scene(p)


# ----------------------------------------------------------------------------- sweep
def _sweep_on_one_and_two(scene, params, tmp_path):
    from walkerlab.stages import sweep as sweep_stage

    return [sweep_stage.run(scene, params, "fixedpoint", workers=w, pool=pool,
                            runs_root=tmp_path, name=f"w{w}", progress=False, figure=False)
            for w, pool in ((1, None), (2, True))]


def test_a_planar_sweep_artifact_is_the_same_on_one_and_two_workers(tmp_path):
    scene = load_scene(ROOT / "configs" / "goswami1996.yaml")
    one, two = _sweep_on_one_and_two(scene, ["slope.angle_deg=2.5,3,3.5"], tmp_path)
    assert_same_datasets(one, two)


def test_a_3d_sweep_artifact_is_the_same_on_one_and_two_workers(tmp_path):
    scene = load_scene(ROOT / "configs" / "hip_width.yaml")
    one, two = _sweep_on_one_and_two(scene, [f"{HIP_WIDTH}=0.09,0.1"], tmp_path)
    assert_same_datasets(one, two)


# ----------------------------------------------------------------------------- bifurcation
def _bifurcation_on_one_and_two(scene, grid, tmp_path, param, **kw):
    from walkerlab.stages import bifurcation as bif_stage

    out = []
    for w in (1, 2):
        r = bif_stage.run(scene, grid, tmp_path / f"w{w}", workers=w, param=param, **kw)
        out.append(r.path)
    return out


def test_a_planar_bifurcation_artifact_is_the_same_on_one_and_two_workers(tmp_path):
    """Five slopes (a run long enough that two workers once dealt it out interleaved)."""
    scene = load_scene(ROOT / "configs" / "goswami1996.yaml")
    one, two = _bifurcation_on_one_and_two(scene, [3.0, 3.25, 3.5, 3.75, 4.0], tmp_path,
                                           "slope.angle_deg", n_transient=4, n_keep=2)
    assert_same_datasets(one, two)


@pytest.mark.slow  # five 3D values (0.06 m from a fresh search), twice: ~10 s
def test_a_3d_bifurcation_over_the_hip_width_finds_every_gait_on_two_workers(tmp_path):
    """The hostile probe of issue 96: over the hip width 0.06 ... 0.1 m two workers recorded
    ``no_fixed_point`` at 0.06 and 0.08 m (their chain started at 0.08 m from the scene's
    guess, which does not converge there) where one worker found every gait.  Now the
    runs do not depend on the workers, and the artifacts are the same."""
    from walkerlab.io.schemas.bifurcation import load_bifurcation

    scene = load_scene(ROOT / "configs" / "hip_width.yaml")
    grid = [0.06, 0.07, 0.08, 0.09, 0.1]
    one, two = _bifurcation_on_one_and_two(scene, grid, tmp_path, HIP_WIDTH,
                                           n_transient=4, n_keep=2)
    assert_same_datasets(one, two)
    assert [str(o) for o in load_bifurcation(two)["fixed_point/outcome"]] == ["ok"] * 5


def test_a_bifurcation_value_the_scenes_guess_misses_is_found_by_a_fresh_search():
    """A 3D walker at 0.06 m hip width alone in its chunk: the scene's guess (the 0.1 m gait)
    does not converge there, the fixedpoint stage's search does: the value is not recorded
    ``no_fixed_point``."""
    from walkerlab.studies.bifurcation_point import BifurcationTask, bifurcation_chunk

    base = load_scene(ROOT / "configs" / "hip_width.yaml").model_dump(mode="json")
    (row,) = bifurcation_chunk(BifurcationTask(base, ((0, (0.06,)),), 4, 2, False,
                                               HIP_WIDTH, 2, plant=_plant(base)))
    assert row["fp_outcome"] == "ok", row["message"]
    assert abs(row["period_s"] - 0.7036) < 1e-3  # per step: the stride's half


# ----------------------------------------------------------------------------- basin
def _basin_on_one_and_two(scene, tmp_path):
    from walkerlab.stages import pipeline

    runs = tmp_path / "runs"
    first = pipeline.run("basin", scene, runs, workers=1).path
    keep = tmp_path / "basin_w1.h5"
    shutil.copy(first, keep)
    second = pipeline.run("basin", scene, runs, workers=2, force=True).path
    return keep, second


def test_a_planar_basin_artifact_is_the_same_on_one_and_two_workers(tmp_path):
    scene = _scene(tmp_path, "paper", ("contact", "terrain", "contact_sim", "contact_solver",
                                       "workprecision", "simulate"),
                   basin={"grid": [5, 3], "max_steps": 25})
    one, two = _basin_on_one_and_two(scene, tmp_path)
    assert_same_datasets(one, two)


def test_a_3d_basin_artifact_is_the_same_on_one_and_two_workers(tmp_path):
    """The 3D walker with hip width, its default axes on a 4 x 4 grid, three strides a cell."""
    scene = _scene(tmp_path, "hip_width", ("contact", "simulate"),
                   basin={"grid": [4, 4], "max_steps": 3})
    one, two = _basin_on_one_and_two(scene, tmp_path)
    assert_same_datasets(one, two)


def test_a_3d_basin_cell_off_the_heel_strike_surface_is_unreachable():
    """The stabilised 3D walker's default axes (stance angle x stance rate) on a 4 x 4 grid:
    the cells at the smallest stance angle have no state on the heel-strike surface
    (OffSection: ``walkerlab basin`` ended in an internal error).  Such a cell is
    ``unreachable``, and the axes are checked at the first cell on the surface."""
    from walkerlab.models.registry import build_walker
    from walkerlab.studies.basin import CODE, BasinTask, _start_pre_impact, axis_values
    from walkerlab.studies.basin_cell import run_basin_chunk, walker_and_settings

    scene = load_scene(ROOT / "configs" / "hip_width_stabilised.yaml")
    names = build_walker(Plant.from_scene(scene)).state_names()
    g = scene.fixedpoint.initial_guess.model_extra  # the gait to 6 decimals
    x_star = np.array([g[n + ("_rad" if n.endswith("_angle") else "_rad_per_s")]
                       for n in names])
    base = scene.model_dump(mode="json")
    base["basin"] = {"grid": [4, 4]}
    walker, st, mst = walker_and_settings(base, _plant(base))
    xs, ys = axis_values(st, walker, x_star, (4, 4))
    assert _start_pre_impact(walker, x_star, st, mst, xs, ys) == ()  # no error
    cells = ((0, float(xs[0]), float(ys[0])), (12, float(xs[0]), float(ys[-1])))
    rows = run_basin_chunk(BasinTask(base, tuple(x_star), cells, (), plant=_plant(base)))
    assert rows == [(0, CODE["unreachable"], 0, 0), (12, CODE["unreachable"], 0, 0)]


# ----------------------------------------------------------------------------- mfpt
@pytest.mark.slow  # ~7 s, ~2 min on a cold numba cache (the step map compiled)
def test_a_planar_mfpt_artifact_is_the_same_on_one_and_two_workers(tmp_path):
    """Monte Carlo walks in two chunks (500 walks a task)."""
    from walkerlab.stages import pipeline

    scene = _scene(tmp_path, "paper", ("contact", "terrain", "contact_sim", "contact_solver",
                                       "workprecision", "simulate"),
                   mfpt={"walks": 600, "max_steps": 20, "method": "montecarlo"})
    runs = tmp_path / "runs"
    first = pipeline.run("mfpt", scene, runs, sigma_rad=[0.008], workers=1).path
    keep = tmp_path / "mfpt_w1.h5"
    shutil.copy(first, keep)
    second = pipeline.run("mfpt", scene, runs, sigma_rad=[0.008], workers=2,
                          force=True).path
    assert_same_datasets(keep, second)


# ----------------------------------------------------------------------------- contact sweep
def test_a_3d_contact_sweep_point_starts_from_the_step_period_as_the_contact_sim_stage(
        tmp_path, monkeypatch):
    """A 3D walker's Poincaré map is a stride of two steps: the contact point took the
    stride's period (1.406 s) for the step's (0.703 s), and simulated twice as long as
    ``contact-sim``.  Now it passes the step period ``fixedpoint.h5`` stores (the one the
    stage starts from), to the bit."""
    from walkerlab.io.schemas.fixedpoint import load_fixedpoint
    from walkerlab.stages import fixedpoint as fixedpoint_stage
    from walkerlab.studies import points as points_mod

    scene = load_scene(ROOT / "configs" / "hip_width.yaml")
    seen = []

    class Stop(Exception):
        pass

    def adapter(sc, x, period, length, plant):
        seen.append((np.asarray(x, float), period))
        raise Stop

    monkeypatch.setattr(points_mod, "contact_adapter", adapter)
    with pytest.raises(Stop):
        points_mod.contact_point(scene, None, {}, Plant.from_scene(scene))
    fp = load_fixedpoint(fixedpoint_stage.run(scene, runs_root=tmp_path).path)
    (x, period), = seen
    assert period == fp.step_period_s
    assert abs(period - 0.7035) < 1e-3 and np.array_equal(x, fp.x)


# ----------------------------------------------------------------------------- continuation
def test_section_coordinates_off_the_heel_strike_surface_fail_the_map_not_the_run():
    """``from_section`` raising OffSection (no state on the heel-strike surface there)
    is a :class:`MapFailed` of the continuation: its branch ends there with a reason."""
    from walkerlab.analysis.continuation.gait_map import MapFailed, state_from_section
    from walkerlab.models.hybrid.base import OffSection

    class OffWalker:
        def from_section(self, z):
            raise OffSection("no state on the heel-strike surface (math domain error)")

    with pytest.raises(MapFailed, match="leave their domain"):
        state_from_section(OffWalker(), np.zeros(3))


@pytest.mark.slow  # the branch from 0.1 m to its end near 0.24 m: ~1 min of CPU
def test_a_continuation_past_the_hip_widths_range_keeps_its_branch(tmp_path):
    """``walkerlab continuation --param walker.hip_width_m=0.1:2.5`` ended in an internal
    error (OffSection) and lost the branch: now the branch ends where the section's
    coordinates leave the heel-strike surface, with that reason, and is stored."""
    from walkerlab.stages import continuation as cont_stage

    scene = load_scene(ROOT / "configs" / "hip_width.yaml")
    out = cont_stage.run(scene, HIP_WIDTH, 0.1, 2.5, runs_root=tmp_path)
    assert out.path.is_file()
    with h5py.File(out.path, "r") as f:
        names = []
        f.visit(names.append)
    assert any("branch" in n for n in names), names
