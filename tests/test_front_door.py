"""Issue 18, part 1 and its defects: the Python API (walkerlab.api), the artifacts' xarray
view, config errors that name the offending key, and caching that says what it does."""

import json
import os
import re
import subprocess
import sys
import threading
import time
from pathlib import Path

import h5py
import numpy as np
import pytest
import yaml

import walkerlab as wl
from walkerlab.config import SceneError, load_scene

ROOT = Path(__file__).resolve().parents[1]
xr = pytest.importorskip("xarray")
pytest.importorskip("h5netcdf")


def _paper(drop=("contact", "contact_sim", "contact_solver", "terrain", "workprecision",
                 "basin"), **update) -> dict:
    with open(ROOT / "configs" / "paper.yaml") as fh:
        d = yaml.safe_load(fh)
    for k in drop:
        d.pop(k, None)
    d.update(update)
    return d


def _open(path, group):
    with xr.open_dataset(path, engine="h5netcdf", group=group) as ds:
        return ds.load()


def _all_dims(path) -> set[str]:
    """Every dimension name of every group's netCDF view."""
    groups = ["/"]
    with h5py.File(path, "r") as f:
        f.visititems(lambda n, o: groups.append(n) if isinstance(o, h5py.Group) else None)
    return {d for g in groups for d in _open(path, g).dims}


# ---------------------------------------------------------------- xarray view of artifacts
def test_simulate_artifact_groups_open_with_their_time_coordinate(tmp_path, paper_fixed_point):
    sim = wl.simulate(_paper(name="xa"), strides=1, runs_dir=tmp_path)
    path = tmp_path / "xa" / "simulate.h5"
    coords = _open(path, "samples/coordinates")
    assert coords["leg1_angle"].dims == ("time",) and "time" in coords.coords
    assert coords["time"].attrs["units"] == "s" and coords["leg1_angle"].attrs["units"] == "rad"
    with h5py.File(path, "r") as f:
        t = f["samples/time"][()]
        a = f["samples/coordinates/leg1_angle"][()]
    np.testing.assert_array_equal(coords["time"].values, t)  # the parent group's times
    np.testing.assert_array_equal(_open(path, "samples/points/hip")["time"].values, t)
    assert not [d for d in _all_dims(path) if re.search(r"_dim\d+$", d)]
    # the API's dataset is the artifact, read back through the same view
    np.testing.assert_array_equal(sim["leg1_angle"].values, a)
    assert sim["leg1_angle"].dims == ("time",) and sim["energy_total"].attrs["units"] == "J"
    assert sim.attrs["stage"] == "simulate" and sim.sizes["step"] == 2
    # the walker starts on its fixed point (the one the conftest finds independently)
    np.testing.assert_allclose(sim["initial_state"].values, paper_fixed_point.x, atol=1e-9)


def test_sweep_grid_axis_is_named_by_the_swept_field(tmp_path):
    sw = wl.api.sweep(_paper(name="sw"), "slope.angle_deg", [1.0, 1.5, 2.0],
                      runs_dir=tmp_path, name="slopes")
    path = tmp_path / "sw" / "slopes.h5"
    grid = _open(path, "grid")
    assert list(grid.dims) == ["slope.angle_deg"]
    np.testing.assert_array_equal(grid["slope.angle_deg"].values, [1.0, 1.5, 2.0])
    assert grid["slope.angle_deg"].attrs["units"] == "deg"
    pts = _open(path, "points")
    np.testing.assert_array_equal(pts["point"].values, [0, 1, 2])
    assert not [d for d in _all_dims(path) if re.search(r"(_dim\d+|axis_\d+)$", d)]
    # the API reshapes the rows onto the grid
    assert sw["step_period_s"].dims == ("slope.angle_deg",)
    assert list(sw["outcome"].values) == ["ok"] * 3
    # physics: the compass gait's step period grows with the slope (Goswami et al. 1996)
    assert np.all(np.diff(sw["step_period_s"].values) > 1e-4)
    assert np.all(sw["max_abs_multiplier"].values < 1)


def test_contact_artifact_arrays_have_named_dimensions(tmp_path):
    d = _paper(drop=("workprecision", "basin"), name="ct")
    d["contact_sim"].update(n_strides=1, periodic_gait=False, sample_rate_hz=200)
    ct = wl.contact_simulate(d, runs_dir=tmp_path)
    path = tmp_path / "ct" / "contact_sim.h5"
    dims = _all_dims(path)
    assert not [x for x in dims if re.search(r"_dim\d+$", x)], dims
    feet = _open(path, "feet/leg1")
    assert feet["normal_force"].dims == ("time",) and feet["normal_force"].attrs["units"] == "N"
    np.testing.assert_array_equal(feet["time"].values, _open(path, "samples")["time"].values)
    assert _open(path, "drop_test/paper")["restitution"].dims == ("stiffness",)
    root = _open(path, "/")
    assert root["initial_state"].dims == ("contact_state",)
    assert "hip_y" in root["contact_state"].values
    assert ct["feet_leg1_normal_force"].dims == ("time",)
    # the feet carry the walker's weight: mean normal force over the run ~ m g (20 kg)
    total = ct["feet_leg1_normal_force"] + ct["feet_leg2_normal_force"]
    assert float(total.mean()) == pytest.approx(20 * 9.81, rel=0.1)


# ---------------------------------------------------------------- the API and the CLI
def test_api_reuses_the_cli_artifact_and_fixed_points_stack_the_variants(tmp_path):
    from typer.testing import CliRunner

    from walkerlab.cli import app

    r = CliRunner().invoke(app, ["fixedpoint", str(ROOT / "configs" / "paper.yaml"),
                                 "--runs-dir", str(tmp_path)])
    assert r.exit_code == 0, r.output
    path = tmp_path / "paper" / "fixedpoint.h5"
    stamp = path.stat().st_mtime_ns
    gait = wl.fixed_point(ROOT / "configs" / "paper.yaml", runs_dir=tmp_path)
    assert path.stat().st_mtime_ns == stamp  # one code path, one artifact: reused
    with h5py.File(path, "r") as f:
        assert gait.attrs["input_hash"] == f.attrs["input_hash"]
        period = float(f["step_period"][()])
    assert float(gait["step_period"]) == period and gait["step_period"].attrs["units"] == "s"
    assert gait["multipliers"].dtype.kind == "c" and bool(gait["floquet_stable"])
    assert list(gait["state_unit"].values) == ["rad", "rad", "rad/s", "rad/s"]
    every = wl.fixed_points(ROOT / "configs" / "paper.yaml", runs_dir=tmp_path)
    assert every["gait"].values[0] == "derived" and every.sizes["gait"] == 3
    np.testing.assert_array_equal(every["fixed_point"].values[0], gait["fixed_point"].values)


def test_sweep_package_is_a_plain_package_and_the_api_sweep_lives_in_api(tmp_path):
    import types

    import walkerlab.studies as package

    # plain packages: walkerlab itself swaps no module class (the front door's export is
    # ``wl.export_scene``, the package ``walkerlab.export`` is not callable)
    assert not callable(package) and type(package) is types.ModuleType
    assert type(wl) is types.ModuleType
    sw = wl.api.sweep(_paper(name="tl"), "slope.angle_deg", [1.0], runs_dir=tmp_path)
    assert sw["outcome"].values.tolist() == ["ok"]


def test_importing_walkerlab_and_its_api_loads_nothing_heavy():
    code = ("import sys, json, walkerlab, walkerlab.api\n"
            "f = walkerlab.simulate\n"
            "print(json.dumps({m: m in sys.modules for m in ('numpy', 'xarray', 'h5py', "
            "'pydantic', 'scipy', 'matplotlib')}))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         cwd=ROOT, env={**os.environ, "PYTHONPATH": str(ROOT)}, timeout=120)
    assert out.returncode == 0, out.stderr
    assert not any(json.loads(out.stdout.strip().splitlines()[-1]).values())


# ---------------------------------------------------------------- config errors
def test_misspelt_field_is_named_first_with_the_field_it_resembles(tmp_path):
    p = tmp_path / "typo.yaml"
    p.write_text((ROOT / "configs" / "paper.yaml").read_text().replace("hip_mass_kg",
                                                                       "hip_mas_kg"))
    with pytest.raises(SceneError) as exc:
        load_scene(p)
    lines = str(exc.value).splitlines()
    assert lines[0] == f"{p}: walker.hip_mas_kg: unknown field (did you mean hip_mass_kg?)"
    # the "walker.hip_mass_kg: Field required" it causes is the same mistake: not repeated
    assert len(lines) == 1  # (issue 26, item 10)


def test_every_config_error_one_line_each_unknown_keys_first():
    d = yaml.safe_load((ROOT / "configs" / "kneed.yaml").read_text())
    d["walker"]["leg"]["bodies"][0]["mas_kg"] = 1.0
    d["simulate"] = {"stride": 3}
    d["slope"] = {"angle_rad": "steep"}
    with pytest.raises(SceneError) as exc:
        wl.load_scene(d)
    lines = str(exc.value).splitlines()
    assert "walker.leg.bodies.0.mas_kg: unknown field (did you mean mass_kg?)" in lines[0]
    assert "simulate.stride: unknown field (did you mean strides?)" in lines[1]
    assert any("slope.angle_rad:" in ln and "'steep'" in ln for ln in lines[2:])


def test_cli_prints_every_config_error_without_traceback_even_in_debug(tmp_path):
    p = tmp_path / "typo.yaml"
    p.write_text((ROOT / "configs" / "paper.yaml").read_text().replace("hip_mass_kg",
                                                                       "hip_mas_kg"))
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    for debug in ("0", "1"):
        out = subprocess.run([sys.executable, "-m", "walkerlab.cli", "fixedpoint", str(p),
                              "--runs-dir", str(tmp_path)], capture_output=True, text=True,
                             env={**env, "WALKERLAB_DEBUG": debug}, timeout=120)
        assert out.returncode == 1
        assert "walker.hip_mas_kg: unknown field (did you mean hip_mass_kg?)" in out.stderr
        if debug == "0":
            assert out.stderr.splitlines()[0].startswith("error: ")
            assert "Traceback" not in out.stderr


# ---------------------------------------------------------------- caching and locks
def test_no_lock_file_is_left_behind(tmp_path):
    from walkerlab.stages import pipeline

    pipeline.run("simulate", wl.load_scene(_paper(name="lk")), tmp_path, strides=1)
    assert (tmp_path / "lk" / "simulate.h5").is_file()
    assert list((tmp_path / "lk").glob(".*.lock")) == []


def test_lock_stays_exclusive_when_the_holder_removes_its_file(tmp_path):
    """Writers that queue on a lock file its holder removes still run one at a time."""
    from walkerlab.io.runpaths import artifact_lock

    target = tmp_path / "x.h5"
    inside, most, log = [0], [0], []
    guard = threading.Lock()

    def writer(k):
        with artifact_lock(target, wait=True):
            with guard:
                inside[0] += 1
                most[0] = max(most[0], inside[0])
            time.sleep(0.05)
            log.append(k)
            with guard:
                inside[0] -= 1

    threads = [threading.Thread(target=writer, args=(k,)) for k in range(6)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(30)
    assert sorted(log) == list(range(6)) and most[0] == 1
    assert not (tmp_path / ".x.h5.lock").exists()


def test_fixedpoint_command_writes_the_artifact_the_report_needs(tmp_path):
    from walkerlab.io.artifacts import content_hash
    from walkerlab.stages import fixedpoint

    sc = wl.load_scene(ROOT / "configs" / "paper.yaml")
    first = fixedpoint.run(sc, tmp_path)  # what `walkerlab fixedpoint` runs
    h = content_hash(first.path)
    again = fixedpoint.run(sc, tmp_path, compare_variants=True)  # what the report runs
    assert again.reused and content_hash(first.path) == h  # contact-sim keys on this hash
    with h5py.File(first.path, "r") as f:
        assert {"appendix_a", "appendix_a_literal"} <= set(f["variants"])


def test_a_longer_simulate_run_is_kept_and_said_and_a_recompute_says_why(tmp_path, capfd):
    from walkerlab.stages import pipeline

    sc = wl.load_scene(_paper(name="st", simulate={"strides": 1, "sample_rate_hz": 200}))
    long = pipeline.run("simulate", sc, tmp_path, strides=3)
    capfd.readouterr()
    out = pipeline.run("simulate", sc, tmp_path)  # the scene's 1 stride, as the report asks
    assert out.reused and "kept 3 strides" in out.note and out.path == long.path
    with h5py.File(out.path, "r") as f:
        assert int(f.attrs["strides_requested"]) == 3
    pipeline.run("simulate", sc, tmp_path, strides=2)  # fewer than stored: recomputed, and said why
    err = capfd.readouterr().err
    assert "simulate: recomputing" in err and "simulate.strides 3 -> 2" in err


@pytest.mark.slow  # end to end: a whole report
def test_report_uses_only_the_artifacts_the_scene_produces(tmp_path):
    from walkerlab.stages import pipeline, report

    sc = wl.load_scene(_paper(drop=("simulate", "contact", "contact_sim", "contact_solver",
                                    "terrain", "workprecision", "basin"), name="ideal"))
    pipeline.run("simulate", sc, tmp_path, strides=1)  # a standalone run leaves simulate.h5 behind
    said: list[str] = []
    html = report.run(sc, tmp_path, echo=said.append)
    md = (html.parent / "report.md").read_text()
    # simulate.h5 is named only where the report says it leaves it out (issue 64 item 10)
    assert "Per-step data" not in md
    assert all("leaves out" in ln.lower() for ln in md.splitlines() if "simulate.h5" in ln), \
        [ln for ln in md.splitlines() if "simulate.h5" in ln]
    assert any(s.startswith("report: leaves out simulate.h5") and "'simulate' section" in s
               for s in said), said
    assert any("no trajectory figures" in s for s in said)


# ---------------------------------------------------------------- the example notebook
def _tour_cells() -> list[str]:
    nb = json.loads((ROOT / "examples" / "walkerlab_tour.ipynb").read_text())
    return ["".join(c["source"]) for c in nb["cells"] if c["cell_type"] == "code"]


@pytest.mark.parametrize("cwd", [".", "examples"])
def test_the_notebooks_first_cell_finds_its_scene_from_the_root_and_from_examples(
        tmp_path, monkeypatch, cwd):
    """Issue 64: the tour loaded ``../configs/paper_rods.yaml``, so ``jupyter nbconvert
    --execute examples/walkerlab_tour.ipynb`` from the repository root failed in its first
    cell (scene file not found).  Its first cell (imports, runs folder, scene) now runs from
    the root and from ``examples/`` and loads the shipped rod-legged walker."""
    monkeypatch.setenv("WALKERLAB_TOUR_RUNS", str(tmp_path / "runs"))
    monkeypatch.chdir(ROOT / cwd)
    ns: dict = {}
    exec(compile(_tour_cells()[0], "walkerlab_tour.ipynb[1]", "exec"), ns)  # noqa: S102
    assert ns["scene"].name == "paper_rods"
    assert ns["scene"] == load_scene(ROOT / "configs" / "paper_rods.yaml")
    assert ns["runs"] == tmp_path / "runs"


@pytest.mark.slow  # end to end: every stage the notebook calls
@pytest.mark.parametrize("cwd", [".", "examples"])
def test_example_notebook_runs(tmp_path, monkeypatch, cwd):
    """``examples/walkerlab_tour.ipynb`` executes top to bottom (nbclient), writing only into
    a temporary runs folder, with its kernel started in the repository root (``jupyter
    nbconvert --execute examples/walkerlab_tour.ipynb`` there) or in ``examples/``."""
    nbformat = pytest.importorskip("nbformat")
    nbclient = pytest.importorskip("nbclient")
    monkeypatch.setenv("WALKERLAB_TOUR_RUNS", str(tmp_path / "runs"))
    monkeypatch.setenv("PYTHONPATH", os.pathsep.join(
        [str(ROOT)] + [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p]))
    nb = nbformat.read(ROOT / "examples" / "walkerlab_tour.ipynb", as_version=4)
    before = set((ROOT / "runs").rglob("*")) if (ROOT / "runs").exists() else set()
    nbclient.NotebookClient(nb, timeout=300, kernel_name="python3",
                            resources={"metadata": {"path": str(ROOT / cwd)}}).execute()
    outputs = [o for c in nb.cells if c.cell_type == "code" for o in c.outputs]
    assert not [o for o in outputs if o.output_type == "error"]
    assert any("image/png" in o.get("data", {}) for o in outputs)  # the figure
    text = "".join(o.get("text", "") for o in outputs)
    assert "step period" in text and "-> stable" in text
    # a grid other than the scene's (200x200) has its own artifact (issue 26, item 6)
    assert (tmp_path / "runs" / "paper_rods" / "basin_10x10.h5").is_file()
    after = set((ROOT / "runs").rglob("*")) if (ROOT / "runs").exists() else set()
    assert after == before  # nothing written into the repository


# -------------------- the API makes the command line's checks
PAPER = ROOT / "configs" / "paper.yaml"


# ------------------------------------------- 4: the API makes the command line's checks
def test_mfpt_is_on_the_package_face():
    import walkerlab as wl

    assert "mfpt" in wl.__all__ and wl.mfpt is wl.api.mfpt


@pytest.mark.parametrize("call, says", [
    (lambda wl, r: wl.api.mfpt(ROOT / "configs" / "simplest.yaml", sigma_rad="0.004",
                               runs_dir=r), "--sigma-rad '0.004': give a sequence"),
    (lambda wl, r: wl.api.mfpt(ROOT / "configs" / "simplest.yaml", sigma_rad=0.004,
                               runs_dir=r), "--sigma-rad 0.004: give a sequence"),
    (lambda wl, r: wl.basin(ROOT / "configs" / "simplest.yaml", grid="10x10", runs_dir=r),
     "--grid '10x10': give a sequence"),
    (lambda wl, r: wl.continuation(PAPER, "slope.angle_deg", 1, 2,
                                   param2="walker.hip_mass_kg", runs_dir=r),
     "--param2 walker.hip_mass_kg: no range"),
    (lambda wl, r: wl.continuation(PAPER, "slope.angle_deg", 1, 2, param2="walker.hip_mass_kg",
                                   range2=(1.0,), runs_dir=r), "range2 must be two numbers"),
    (lambda wl, r: wl.continuation(PAPER, "slope.angle_deg", 1, 2, param2="walker.hip_mass_kg",
                                   range2="ab", runs_dir=r), "range2 must be two numbers"),
    (lambda wl, r: wl.continuation(PAPER, "slope.angle_deg", 1, 2, range2=(1, 2),
                                   runs_dir=r), "range2 given without param2"),
    (lambda wl, r: wl.continuation(PAPER, "slope.angle_deg", 1, 1, runs_dir=r),
     "start and stop are both 1"),
    (lambda wl, r: wl.continuation(PAPER, None, 1, 2, runs_dir=r),
     "--param: give a dotted numeric scene field"),
    (lambda wl, r: wl.continuation(PAPER, "slope.angle_deg", 1, float("inf"), runs_dir=r),
     "stop inf is not a finite number"),
], ids=["mfpt-str", "mfpt-float", "basin-str", "no-range2", "range2-short", "range2-str",
        "range2-alone", "start-eq-stop", "param-none", "inf"])
def test_the_api_refuses_what_the_command_refuses_in_one_line(tmp_path, call, says):
    import walkerlab as wl

    with pytest.raises(SceneError) as exc:
        call(wl, tmp_path)
    assert says in str(exc.value) and "\n" not in str(exc.value)
    assert not list(tmp_path.rglob("*.h5"))  # refused before anything ran


def test_a_kept_longer_run_that_falls_later_is_judged_and_averaged_on_the_scenes_strides(
        tmp_path):
    """hip_width's gait falls after 17 heel strikes (its lateral multiplier, about 11 a step,
    grows the fixed point's round-off: 15 before the 3D trees were simplified product-to-sum);
    its scene asks 5 strides (10 heel strikes), which walk.  A kept 10-stride run (the fall
    inside it) must give the scene's
    run the fresh run's verdict and means: the steps are the same run's, each step sampled
    from its own start."""
    from walkerlab.io.schemas.simulate import load_simulate
    from walkerlab.stages import pipeline

    sc = wl.load_scene(ROOT / "configs" / "hip_width.yaml")
    assert sc.simulate.strides == 5
    long = pipeline.run("simulate", sc, tmp_path / "kept", strides=10)
    assert long.failure and load_simulate(long.path).termination == "fall"
    kept = pipeline.run("simulate", sc, tmp_path / "kept")
    assert kept.reused and "kept 10 strides" in kept.note
    assert not kept.failure  # the scene's 5 strides walk
    fresh = pipeline.run("simulate", sc, tmp_path / "fresh")
    assert not fresh.reused and not fresh.failure
    got = load_simulate(kept.path, sc.simulate.strides)
    want = load_simulate(fresh.path, sc.simulate.strides)
    assert got.termination == want.termination == "heel_strike"
    assert got.heel_strike_count() == want.heel_strike_count() == 10
    for k in ("mean_period_s", "mean_step_length_m", "mean_hip_speed_m_per_s",
              "mean_total_energy_J", "steps_completed"):
        assert got.summary[k] == want.summary[k], k  # the same steps: the same numbers
    assert got.samples.time.size == want.samples.time.size
    assert got.summary["cut_from_strides"] == 10 and "cut_from_strides" not in want.summary
