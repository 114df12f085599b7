"""Resumable files that cannot lie, bounded inputs, hashes of results not timings, YAML
limits, bit-identical resume (issue 19 items 4, 5, 11, 12, 13) and progress (issue 18 part 4).

Each test fails on the code before the fix.  The physics is replaced by small fakes where
the behaviour under test (partial files, caps, hashing, progress plumbing) does not depend
on it.
"""

from __future__ import annotations

import copy
import os
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from walkerlab import progress
from walkerlab.cli import app
from walkerlab.config import (
    MAX_BASIN_CELLS_PER_AXIS,
    MAX_SOURCE_CHARS,
    MAX_WORKERS,
    SceneError,
    load_scene,
    scene_from_dict,
)
from walkerlab.io.artifacts import content_hash, write_artifact
from walkerlab.io.freshness import input_hash
from walkerlab.io.sweep_store import complete_sweep, load_sweep, partial_path
from walkerlab.stages import common
from walkerlab.studies import basin as basin_mod
from walkerlab.studies import runner
from walkerlab.studies.outcomes import empty_row
from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]
PAPER = yaml.safe_load((ROOT / "configs" / "paper.yaml").read_text())
IDEAL = {k: v for k, v in PAPER.items() if k in ("walker", "slope", "solver", "fixedpoint",
                                                  "simulate")}
X_GUESS = np.array([-0.2022, 0.1674, -0.60, -0.84])  # paper Eq. (11), role order


def _write(path: Path, data: dict | str) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(data if isinstance(data, str) else yaml.safe_dump(data))
    return path


def _cli(*args):
    r = CliRunner().invoke(app, [str(a) for a in args])
    return r.exit_code, r.stderr.strip(), r.stdout


class Recorder:
    """A progress sink that keeps every call (issue 18 part 4)."""

    def __init__(self):
        self.tasks: dict[int, dict] = {}
        self.notes: list[str] = []

    def start(self, key, description, total, completed):
        self.tasks[key] = {"description": description, "total": total, "counts": [completed],
                           "finished": False}

    def update(self, key, completed, total, info):
        self.tasks[key]["counts"].append(completed)
        self.tasks[key]["total"] = total

    def finish(self, key):
        self.tasks[key]["finished"] = True

    def note(self, message):
        self.notes.append(message)

    def one(self, word: str) -> dict:
        found = [t for t in self.tasks.values() if word in t["description"]]
        assert len(found) == 1, self.tasks
        return found[0]


def _assert_monotone_to_total(t: dict) -> None:
    c = t["counts"]
    assert all(b >= a for a, b in zip(c, c[1:])), c
    assert c[-1] == t["total"] and t["finished"]


# ------------------------------------------------------------------ item 4: basin partial
def _fake_basin_chunk(calls):
    def run(task):
        calls.append(len(task.cells))
        return [(int(i), basin_mod.CODE["fell_forward"], 3, 0) for i, _, _ in task.cells]
    return run


def _basin(tmp_path, on_chunk=None):
    sc = scene_from_dict({**IDEAL, "name": "paper", "basin": {"grid": [4, 5]}})
    return basin_mod.compute_basin(sc, X_GUESS, "key", tmp_path / "basin.h5", workers=1,
                                   on_chunk=on_chunk, plant=Plant.from_scene(sc))


def _interrupt_after(n):
    def stop(done, total):
        if done >= n:
            raise KeyboardInterrupt
    return stop


def test_edited_basin_partial_rows_are_computed_again(tmp_path, monkeypatch):
    calls: list[int] = []
    monkeypatch.setattr(basin_mod, "run_basin_chunk", _fake_basin_chunk(calls))
    with pytest.raises(KeyboardInterrupt):
        _basin(tmp_path, _interrupt_after(8))  # two grid rows of 4 cells
    part = tmp_path / "basin.h5.partial"
    with h5py.File(part, "a") as f:  # a user marks every done cell "converged"
        o = f["outcome"][()]
        assert np.sum(o >= 0) == 8
        o[o >= 0] = basin_mod.CODE["converged"]
        f["outcome"][...] = o
    calls.clear()
    res = _basin(tmp_path)
    assert not np.any(res["outcome"] == basin_mod.CODE["converged"])  # the edit did not stick
    assert sum(calls) == 20 and res["cells_computed"] == 20


def test_intact_basin_partial_rows_are_kept(tmp_path, monkeypatch):
    calls: list[int] = []
    monkeypatch.setattr(basin_mod, "run_basin_chunk", _fake_basin_chunk(calls))
    with pytest.raises(KeyboardInterrupt):
        _basin(tmp_path, _interrupt_after(8))
    calls.clear()
    rec = Recorder()
    with progress.use(rec):
        res = _basin(tmp_path)
    assert sum(calls) == 12 and res["cells_computed"] == 12  # only the 3 rows not done
    assert rec.notes == []
    t = rec.one("basin")
    assert t["counts"][0] == 8  # a resumed map starts at what the partial file had
    _assert_monotone_to_total(t)


# ------------------------------------------------------------------ items 4, 13: sweeps
def _fake_evaluate(stage, base, paths, values, index, guess, options, origin, *, plant):
    """A continuation-dependent fake point: each row depends on the guess it started from,
    as a real point's fixed point does (to round-off) on its predictor."""
    g = 0.0 if guess is None else float(np.asarray(guess).ravel()[0])
    row = empty_row(stage, index)
    v = float(values[0]) + 1e-3 * g
    row.update(outcome="ok", wall_time_s=0.0, residual=v, step_period_s=1.0 + v,
               guess_source="previous" if guess is not None else "scene")
    return row, np.array([v])


@pytest.fixture
def fake_points(monkeypatch):
    monkeypatch.setattr(runner, "evaluate", _fake_evaluate)
    monkeypatch.setattr(runner, "warm_up", lambda: None)


def _sweep(tmp_path, name, **kw):
    from walkerlab.stages import sweep as sweep_stage

    sc = scene_from_dict({**IDEAL, "name": "paper"})
    return sweep_stage.run(sc, ["slope.angle_deg=1:30:1", "walker.hip_mass_kg=8,10"],
                           "fixedpoint", workers=1, runs_root=tmp_path, name=name,
                           progress=False, **kw)


def _rows(path) -> dict:
    pts = load_sweep(path)["points"]
    return {k: v for k, v in pts.items() if k != "wall_time_s"}


def _interrupted(tmp_path, name, at=20, edit=None, **kw):
    with pytest.raises(KeyboardInterrupt):
        _sweep(tmp_path, name, on_chunk=_interrupt_after(at), **kw)
    part = partial_path(tmp_path / "paper" / f"{name}.h5")
    if edit is not None:
        with h5py.File(part, "a") as f:
            edit(f)
    return _sweep(tmp_path, name, resume=True, **kw)


def _assert_same_rows(a: dict, b: dict) -> None:
    assert a.keys() == b.keys()
    for k in a:
        if a[k].dtype.kind == "f":
            np.testing.assert_array_equal(a[k], b[k], err_msg=k)  # bit for bit (NaN = NaN)
        else:
            assert list(a[k]) == list(b[k]), k


def test_resumed_sweep_is_bit_identical_to_an_uninterrupted_one(tmp_path, fake_points):
    ref = _rows(_sweep(tmp_path, "ref"))
    got = _rows(_interrupted(tmp_path, "cut", at=20))
    _assert_same_rows(got, ref)


def test_edited_sweep_partial_rows_are_computed_again(tmp_path, fake_points):
    ref = _rows(_sweep(tmp_path, "ref"))
    rec = Recorder()

    def edit(f):
        f["points/step_period_s"][...] = 999.0

    with progress.use(rec):
        out = _interrupted(tmp_path, "edited", at=20, edit=edit)
    got = _rows(out)
    assert not np.any(got["step_period_s"] == 999.0)
    _assert_same_rows(got, ref)
    assert len(rec.notes) == 1 and "failed their integrity check" in rec.notes[0]


def test_edited_checkpoint_restarts_its_chain(tmp_path, fake_points):
    ref = _rows(_sweep(tmp_path, "ref"))

    def edit(f):  # a forged continuation state
        f["plan/guess"][0] = '{"array": [123.0], "dtype": "<f8"}'

    _assert_same_rows(_rows(_interrupted(tmp_path, "forged", at=20, edit=edit)), ref)


def test_unreadable_checkpoints_restart_every_chain(tmp_path, fake_points):
    ref = _rows(_sweep(tmp_path, "ref"))

    def edit(f):  # as after a kill in the middle of a checkpoint write
        del f["plan/guess"]

    _assert_same_rows(_rows(_interrupted(tmp_path, "lost", at=20, edit=edit)), ref)


def test_finished_sweep_carries_a_content_hash(tmp_path, fake_points):
    out = _sweep(tmp_path, "fin")
    from walkerlab.studies.sweep_plan import sweep_input_hash

    with h5py.File(out, "r") as f:
        key = str(f.attrs["input_hash"])
        assert "plan" not in f and "row_hash" not in f["points"]
    assert complete_sweep(out, key)
    with h5py.File(out, "a") as f:
        f["points/step_period_s"][0] = 999.0
    assert not complete_sweep(out, key)
    assert sweep_input_hash  # imported: the key is the runner's


# ------------------------------------------------------------------ item 11: timings
def _fake_fixedpoint(wall: float, value: float = -0.8):
    def compute():
        def writer(f):
            f.create_dataset("fixed_point/stance_rate", data=value)
            f.create_dataset("stats/wall_time", data=wall)
            f.create_dataset("stats/nfev", data=120)
        return writer, {}
    return compute


def test_content_hash_covers_results_not_timings(tmp_path):
    sc = scene_from_dict({**IDEAL, "name": "paper"})
    first = common.run_cached("fixedpoint", sc, tmp_path, ("walker",), (), _fake_fixedpoint(1.2))
    key = input_hash("simulate", sc, ("walker",), (first.path,))
    again = common.run_cached("fixedpoint", sc, tmp_path, ("walker",), (), _fake_fixedpoint(3.4),
                              force=True)  # same result, other timing
    assert not again.reused
    assert input_hash("simulate", sc, ("walker",), (again.path,)) == key
    changed = common.run_cached("fixedpoint", sc, tmp_path, ("walker",), (),
                                _fake_fixedpoint(3.4, -0.81), force=True)
    assert input_hash("simulate", sc, ("walker",), (changed.path,)) != key


def test_run_records_are_not_hashed(tmp_path):
    sc = scene_from_dict({**IDEAL, "name": "paper"})

    def writer(wall, cells):
        def w(f):
            f.create_dataset("outcome", data=np.arange(6))
            f.create_dataset("stats/cells_computed", data=cells)
            f.create_dataset("summary/wall_time_s", data=wall)
        return w

    a = write_artifact(tmp_path / "a.h5", "basin", sc, "k", writer(1.0, 6), 1.0,
                       {"workers": 2, "scheduler": ""})
    b = write_artifact(tmp_path / "b.h5", "basin", sc, "k", writer(9.0, 2), 7.0,
                       {"workers": 4, "scheduler": "tcp://x:1"})
    assert content_hash(a) == content_hash(b)


# ------------------------------------------------------------------ item 12: YAML
@pytest.mark.parametrize("text, match", [
    ("a: " + "[" * 20000 + "]" * 20000 + "\n", "nesting deeper than"),
    (yaml.safe_dump(IDEAL) + "foo: " + "9" * 5000 + "\n", "integer longer than"),
    (yaml.safe_dump(IDEAL) + "slope:\n  angle_deg: 3.0\n", "duplicate key 'slope'"),
    ("walker:\n  a: 1\n  a: 2\n", "duplicate key 'a'"),
])
def test_yaml_limits_are_one_line_naming_the_file(tmp_path, text, match):
    p = _write(tmp_path / "bad.yaml", text)
    with pytest.raises(SceneError, match=match) as exc:
        load_scene(p)
    assert str(exc.value).startswith(str(p)) and "\n" not in str(exc.value)
    rc, err, _ = _cli("fixedpoint", p, "--runs-dir", tmp_path / "runs")
    assert rc == 1 and err.startswith(f"error: {p}") and len(err.splitlines()) == 1


def test_moderate_nesting_and_merge_keys_still_load(tmp_path):
    d = copy.deepcopy(IDEAL)
    text = "base: &b\n  angle_deg: 2.0\nslope:\n  <<: *b\n" + yaml.safe_dump(
        {k: v for k, v in d.items() if k != "slope"})
    from walkerlab.config import parse_yaml

    assert parse_yaml(text)["slope"] == {"angle_deg": 2.0}
    assert parse_yaml("a: " + "[" * 20 + "]" * 20)["a"] is not None


# ------------------------------------------------------------------ item 5: caps
@pytest.fixture
def paper_scene(tmp_path):
    return _write(tmp_path / "paper.yaml", IDEAL)


@pytest.mark.parametrize("args, match", [
    (["basin", "--grid", "5000x5000"], f"less than or equal to {MAX_BASIN_CELLS_PER_AXIS}"),
    (["basin", "--grid", "100000x100000"], "as basin.grid"),
    (["basin", "--workers", "300"], f"less than or equal to {MAX_WORKERS}"),
    (["sweep", "--param", "slope.angle_deg=1", "--workers", "300"], "--workers 300"),
    (["stability-map", "--n", "100000"], "--n 100000"),
    (["stability-map", "--workers", "300", "--kind", "friction"], "--workers 300"),
    (["bifurcation", "--transient", "1000000000"], "--transient"),
    (["bifurcation", "--keep", "1000000000"], "--keep"),
])
def test_cli_sizes_have_the_yaml_caps(tmp_path, paper_scene, args, match):
    sc = _write(tmp_path / "full.yaml", {**PAPER, "name": "paper"}) if args[0] == \
        "stability-map" else paper_scene
    rc, err, _ = _cli(args[0], sc, *args[1:], "--runs-dir", tmp_path / "runs")
    assert rc == 1 and match in err and len(err.splitlines()) == 1, err
    assert not (tmp_path / "runs" / "paper" / "fixedpoint.h5").exists()  # refused up front


def test_basin_grid_cap_is_the_scene_field(tmp_path):
    with pytest.raises(SceneError, match="basin.grid"):
        scene_from_dict({**IDEAL, "basin": {"grid": [MAX_BASIN_CELLS_PER_AXIS + 1, 10]}})


def test_tiny_max_step_is_refused(tmp_path):
    p = _write(tmp_path / "s.yaml", {**IDEAL, "solver": {**IDEAL["solver"],
                                                         "max_step_s": 1e-12}})
    with pytest.raises(SceneError, match=r"s\.yaml: solver\.max_step_s: 1e-12 s would allow"):
        load_scene(p)
    ok = _write(tmp_path / "t.yaml", {**IDEAL, "solver": {**IDEAL["solver"],
                                                          "max_step_s": 1e-3}})
    assert load_scene(ok).solver.max_step_s == 1e-3


def test_long_source_is_refused():
    with pytest.raises(SceneError, match="source"):
        scene_from_dict({**IDEAL, "source": "x" * (MAX_SOURCE_CHARS + 1)})


def test_sample_count_is_capped_before_memory_runs_out(tmp_path):
    p = _write(tmp_path / "paper.yaml", {**IDEAL, "simulate": {"strides": 1000,
                                                              "sample_rate_hz": 1e6}})
    rc, err, _ = _cli("simulate", p, "--runs-dir", tmp_path / "runs")
    assert rc == 1 and "simulate.sample_rate_hz" in err and "samples" in err
    assert not (tmp_path / "runs" / "paper" / "simulate.h5").exists()


def test_sample_trajectory_checks_the_count_first():
    from walkerlab.analysis.gait.metrics import sample_trajectory

    class Seg:
        t_start, t_end = 0.0, 1e4

    class Traj:
        segments = [Seg()]

    with pytest.raises(ValueError, match="simulate.sample_rate_hz"):
        sample_trajectory(Traj(), 1e6)


@pytest.mark.parametrize("kind", ["fifo", "dev_zero", "huge"])
def test_files_read_are_bounded_regular_files(tmp_path, paper_scene, kind):
    marker = tmp_path / "runs" / "paper" / ".scene"
    marker.parent.mkdir(parents=True)
    if kind == "fifo":
        os.mkfifo(marker)
    elif kind == "dev_zero":
        os.symlink("/dev/zero", marker)
    else:
        marker.write_bytes(b"x" * 100_000)
    rc, err, _ = _cli("fixedpoint", paper_scene, "--runs-dir", tmp_path / "runs")
    assert rc == 1 and ".scene" in err and len(err.splitlines()) == 1, err


@pytest.mark.parametrize("kind", ["fifo", "dev_zero", "big"])
def test_scene_file_is_a_bounded_regular_file(tmp_path, kind):
    p = tmp_path / "s.yaml"
    if kind == "fifo":
        os.mkfifo(p)
    elif kind == "dev_zero":
        os.symlink("/dev/zero", p)
    else:
        p.write_text("source: '" + "x" * 1_100_000 + "'\n")
    with pytest.raises(SceneError, match=r"s\.yaml: (scene file is|not a regular file)"):
        load_scene(p)


# ------------------------------------------------------------------ issue 18: progress
def test_progress_basin_counts_are_monotone_and_end_at_the_total(tmp_path, monkeypatch):
    monkeypatch.setattr(basin_mod, "run_basin_chunk", _fake_basin_chunk([]))
    rec = Recorder()
    with progress.use(rec):
        _basin(tmp_path)
    t = rec.one("basin")
    assert t["total"] == 20 and len(t["counts"]) == 6  # start + one per grid row
    _assert_monotone_to_total(t)


def test_progress_bifurcation_counts_are_monotone_and_end_at_the_total(tmp_path):
    from walkerlab.studies.bifurcation import bifurcation_diagram

    sc = scene_from_dict({**IDEAL, "name": "paper"})
    rec = Recorder()
    with progress.use(rec):
        bifurcation_diagram(sc, [1.0, 1.5, 2.0], n_transient=2, n_keep=1, workers=1,
                            steady_state=False, plant=Plant.from_scene(sc))
    t = rec.one("bifurcation")
    assert t["total"] == 3
    _assert_monotone_to_total(t)


def test_progress_sweep_counts_are_monotone_and_end_at_the_total(tmp_path, fake_points):
    rec = Recorder()
    from walkerlab.stages import sweep as sweep_stage

    sc = scene_from_dict({**IDEAL, "name": "paper"})
    with progress.use(rec):
        sweep_stage.run(sc, ["slope.angle_deg=1:30:1"], "fixedpoint", workers=1,
                        runs_root=tmp_path, name="p")
    t = rec.one("sweep")
    assert t["total"] == 30
    _assert_monotone_to_total(t)


def test_progress_module_and_libraries_do_not_load_rich():
    code = ("import sys, walkerlab.progress, walkerlab.studies.basin, walkerlab.studies.runner, "
            "walkerlab.studies.bifurcation; print('rich' in sys.modules)")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                       env=dict(os.environ, PYTHONPATH=str(ROOT)), timeout=120)
    assert r.stdout.strip() == "False", r.stderr


def test_progress_sink_follows_the_terminal_and_quiet():
    class Tty:
        def isatty(self):
            return True

    class Pipe:
        def isatty(self):
            return False

    assert isinstance(progress.sink_for_terminal(False, Tty()), progress.RichSink)
    assert isinstance(progress.sink_for_terminal(False, Pipe()), progress.LineSink)
    quiet = progress.sink_for_terminal(True, Tty())
    assert isinstance(quiet, progress.QuietSink) and quiet.silent


def _run_cli(tmp_path, *args):
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    return subprocess.run([sys.executable, "-m", "walkerlab.cli", *map(str, args)],
                          capture_output=True, text=True, cwd=tmp_path, env=env, timeout=300)


def test_progress_non_tty_sweep_prints_a_plain_line_per_point_and_nothing_under_quiet(
        tmp_path, paper_scene):
    """Issue 64 item 7: without a terminal (a pipe, nohup, CI) a long run printed nothing;
    now a line per finished unit, no terminal codes; ``-q``: nothing."""
    r = _run_cli(tmp_path, "sweep", paper_scene, "--param", "slope.angle_deg=1,1.1",
                 "--workers", "1", "--runs-dir", "runs")
    lines = r.stderr.strip().splitlines()  # a line per chunk of points finished
    assert r.returncode == 0 and 1 <= len(lines) <= 2, r.stderr
    assert all(ln.startswith("sweep fixedpoint (2 points): ") for ln in lines)
    assert lines[-1].startswith("sweep fixedpoint (2 points): 2/2") and "\x1b" not in r.stderr
    r = _run_cli(tmp_path, "-q", "sweep", paper_scene, "--param", "slope.angle_deg=1,1.1",
                 "--workers", "1", "--runs-dir", "runs", "--name", "again")
    assert r.returncode == 0 and r.stderr == "", r.stderr


def test_a_line_sink_prints_each_unit_of_a_short_task_and_tenths_of_a_long_one():
    import io

    out = io.StringIO()
    with progress.use(progress.LineSink(out)):
        with progress.task("mfpt: 3 sigma value(s)", 3) as t:
            for sd in (0.001, 0.002, 0.003):
                t.advance(info=f"sigma {sd:g} rad")
        with progress.task("basin 100x100 cells", 10_000) as t:
            for _ in range(10_000):
                t.advance()
        with progress.task("optimize: the contact replay"):
            pass
    lines = out.getvalue().splitlines()
    assert [ln.rsplit(" (", 1)[0] for ln in lines[:3]] == [
        f"mfpt: 3 sigma value(s): {k}/3 sigma 0.00{k} rad" for k in (1, 2, 3)]
    assert len(lines) == 3 + 10  # ten tenths; the task of no count (a spinner): nothing
    assert lines[12].startswith("basin 100x100 cells: 10000/10000")


def test_the_mfpt_study_reports_each_sigma_it_finishes(monkeypatch):
    from types import SimpleNamespace

    from walkerlab.studies import mfpt as study

    monkeypatch.setattr(study, "build_walker", lambda plant: SimpleNamespace(
        state_names=lambda: ["a"]), raising=False)
    monkeypatch.setattr("walkerlab.models.registry.build_walker",
                        lambda plant: SimpleNamespace(state_names=lambda: ["a"]))
    monkeypatch.setattr("walkerlab.integrate.python_step.needs_python_path", lambda w: False)
    monkeypatch.setattr(study, "step_map_for", lambda *a, **k: None)

    def one(scene, x_star, st, i, sd, vals, *rest):
        vals["mfpt_steps_montecarlo"][i] = 100.0 * (i + 1)
    monkeypatch.setattr(study, "_one_sigma", one)
    st = SimpleNamespace(sigma_rad=[0.01, 0.02], method="montecarlo", model="rigid",
                         seed=0, distribution="normal")
    scene = SimpleNamespace(model_dump=lambda mode: {}, terrain=None)
    got = []

    class Rec(progress.QuietSink):
        def update(self, key, completed, total, info):
            got.append((completed, total, info))
    with progress.use(Rec()):
        # build_walker stood in: the plant only hands itself on
        study.mfpt_study(scene, np.zeros(2), st, plant=SimpleNamespace(with_=lambda sc: None))
    assert got == [(1, 2, "sigma 0.01 rad: Monte Carlo MFPT 100 steps"),
                   (2, 2, "sigma 0.02 rad: Monte Carlo MFPT 200 steps")]


@pytest.mark.parametrize("quiet", [True, False])
@pytest.mark.slow  # in `pytest -m slow`: the quick suite keeps to its CPU budget
def test_progress_quiet_silences_notices(tmp_path, paper_scene, monkeypatch, quiet):
    """A resumed sweep with an edited row: without a terminal only the one-line notice
    reaches stderr; under --quiet nothing does."""
    from walkerlab.stages import sweep as sweep_stage

    params = ["slope.angle_deg=1,1.1,1.2"]
    monkeypatch.setattr(runner, "evaluate", _fake_evaluate)
    monkeypatch.setattr(runner, "warm_up", lambda: None)
    with pytest.raises(KeyboardInterrupt):  # all rows written, not finalized
        sweep_stage.run(str(paper_scene), params, workers=1, runs_root=tmp_path / "runs",
                        name="q", progress=False, on_chunk=_interrupt_after(1))
    with h5py.File(partial_path(tmp_path / "runs" / "paper" / "q.h5"), "a") as f:
        f["points/residual"][0] = 5.0
    r = _run_cli(tmp_path, *(["--quiet"] if quiet else []), "sweep", paper_scene, "--param",
                 params[0], "--workers", "1", "--runs-dir", "runs", "--name", "q", "--resume")
    assert r.returncode == 0, r.stderr
    if quiet:
        assert r.stderr == ""
    else:
        notices = [ln for ln in r.stderr.strip().splitlines()
                   if not ln.startswith("sweep ")]  # the progress lines: a pipe's log
        assert len(notices) == 1 and "integrity" in notices[0]


def test_progress_adjust_counts_contact_runs(monkeypatch):
    """contact-sim --adjust: one count per contact run, up to the most there can be."""
    from types import SimpleNamespace

    from walkerlab.analysis.contact import adjust
    from walkerlab.analysis.contact import sim as contact_sim
    from walkerlab.models.contact.scene import contact_setup

    calls = []

    def fake_simulate_from(setup, x_fp, period, rate_scale=None):
        calls.append(rate_scale)
        return None, SimpleNamespace(heel_strike_times=[], termination="fall"), None, None

    monkeypatch.setattr(contact_sim, "simulate_from", fake_simulate_from)
    rec = Recorder()
    with progress.use(rec):
        sc = scene_from_dict({**PAPER, "name": "paper"})
        out = adjust.adjust_rates(contact_setup(sc, plant=Plant.from_scene(sc)),
                                  X_GUESS, 0.7, grid=(0.8, 1.5, 3))
    t = rec.one("adjust")
    c = t["counts"]
    assert all(b > a for a, b in zip(c, c[1:])) and c[-1] == len(calls) == out["evaluations"]
    assert c[-1] <= t["total"] and t["finished"]


def test_contact_text_shows_the_rate_scale_adjust_found(tmp_path):
    from walkerlab.io.schemas.contact_sim import ContactSimArtifact
    from walkerlab.report.text import contact_text
    from walkerlab.units import Units

    c = ContactSimArtifact(tmp_path / "contact.h5", Units(), "t_final", "completed",
                           initial_rate_scale=np.array([1.41, 1.74]),
                           adjust={"objective": 1e-4})
    assert ("--adjust: kept the adjusted initial rate scale: leg1 rates × 1.41; "
            "leg2 rates × 1.74") in contact_text(c)
    # the stage writes the scaled rates by name (a kneed walker: two a leg)
    c.rate_names = ["dtheta1_thigh dtheta1_shank", "dtheta2_thigh dtheta2_shank"]
    assert ("--adjust: kept the adjusted initial rate scale: dtheta1_thigh dtheta1_shank × "
            "1.41; dtheta2_thigh dtheta2_shank × 1.74") in contact_text(c)
