"""Runs stay inside runs/, writes are atomic, the cache is keyed on content, errors are one
line (issue 12).

Each test names the defect (D1-D12) it covers; each fails on the code before the fix.
Bad-input tests are parametrised.  Heavy computations are replaced by small fakes where the
behaviour under test (paths, cache, CLI layer, sweep plumbing) does not depend on them.
"""

from __future__ import annotations

import copy
import importlib
import inspect
import math
import os
import re
import stat
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import h5py
import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

import walkerlab
from tests.cli_run import IDEAL, PAPER
from tests.cli_run import run_cli as _cli
from walkerlab.cli import app
from walkerlab.config import SceneError, load_scene, scene_from_dict
from walkerlab.io import freshness
from walkerlab.io.artifacts import ArtifactError, atomic_write, open_artifact, write_artifact
from walkerlab.io.runpaths import ArtifactBusy, RunPathError, artifact_lock, stage_artifact
from walkerlab.io.stage_files import ARTIFACTS
from walkerlab.io.sweep_store import load_sweep, partial_path
from walkerlab.safefs import process_alive
from walkerlab.stages import common
from walkerlab.studies import runner
from walkerlab.studies.outcomes import empty_row
from walkerlab.studies.params import SweepError, parse_param
from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]


def _with(base: dict, path: str, value) -> dict:
    d = copy.deepcopy(base)
    keys = path.split(".")
    node = d
    for k in keys[:-1]:
        node = node.setdefault(k, {})
    node[keys[-1]] = value
    return d


def _write(path: Path, data: dict) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(yaml.safe_dump(data))
    return path


# ------------------------------------------------------------------ D1, D2: names and paths
@pytest.mark.parametrize("name", ["../evil", "/tmp/x", "a/b", "..", ".hidden", "a\\b", ""])
def test_scene_name_with_path_parts_rejected(name):
    with pytest.raises(SceneError, match="name"):
        scene_from_dict({**IDEAL, "name": name})


def test_scene_file_stem_that_is_not_a_name(tmp_path):
    p = _write(tmp_path / "...yaml", IDEAL)
    with pytest.raises(SceneError, match="file name gives the run-folder name '..'"):
        load_scene(p)


@pytest.mark.parametrize("name", ["../../x", "/tmp/x", "a/b", ".."])
def test_sweep_name_outside_runs_rejected(tmp_path, name):
    code, err, _ = _cli("sweep", ROOT / "configs" / "goswami1996.yaml", "--param",
                        "slope.angle_deg=3", "--name", name, "--runs-dir", tmp_path / "runs")
    assert code == 1 and err.startswith("error: --name") and "\n" not in err
    assert not any(tmp_path.rglob("*.h5*"))


def test_symlinked_run_folder_leaving_runs_rejected(tmp_path):
    (tmp_path / "runs").mkdir()
    (tmp_path / "elsewhere").mkdir()
    (tmp_path / "runs" / "paper").symlink_to(tmp_path / "elsewhere")
    sc = scene_from_dict({**IDEAL, "name": "paper"})
    with pytest.raises(RunPathError, match="outside the runs folder"):
        stage_artifact(sc, tmp_path / "runs", "fixedpoint")


@pytest.mark.parametrize("name", ["fixedpoint", "simulate.h5", "contact_sim", "compare",
                                  "bifurcation", "workprecision", "basin",
                                  "stability_map_stiffness"])
def test_sweep_cannot_take_a_stage_artifact_name(tmp_path, name):
    sc = scene_from_dict({**IDEAL, "name": "paper"})
    from walkerlab.stages.sweep import sweep_path

    with pytest.raises(RunPathError, match="stage's artifact"):
        sweep_path(sc, [parse_param("slope.angle_deg=1")], "fixedpoint", tmp_path, name)


def test_two_scene_files_with_one_name_do_not_share_a_run_folder(tmp_path):
    a = load_scene(_write(tmp_path / "a" / "paper.yaml", IDEAL))
    b = load_scene(_write(tmp_path / "b" / "paper.yaml", IDEAL))
    runs = tmp_path / "runs"
    common.run_cached("fixedpoint", a, runs, ("walker",), (), _fake_compute(1.0))
    with pytest.raises(RunPathError, match="run folder of .*a/paper.yaml"):
        common.run_cached("fixedpoint", b, runs, ("walker",), (), _fake_compute(2.0))
    (tmp_path / "a" / "paper.yaml").unlink()  # the owner was moved away: b may take over
    common.run_cached("fixedpoint", b, runs, ("walker",), (), _fake_compute(2.0))
    assert (runs / "paper" / ".scene").read_text().strip() == str(b.origin)


# ------------------------------------------------------------------ D9, D10: strict config
@pytest.mark.parametrize("path,value,field", [
    ("walker.leg_mass_kg", True, "walker.leg_mass_kg"),
    ("walker.leg_mass_kg", "5", "walker.leg_mass_kg"),
    ("walker.leg_length_m", float("nan"), "walker.leg_length_m"),
    ("slope.angle_deg", float("inf"), "slope.angle_deg"),
    ("fixedpoint.initial_guess.swing_rate_rad_per_s", float("nan"),
     "fixedpoint.initial_guess.swing_rate_rad_per_s"),
    ("simulate.initial_state", {"swing_angle_rad": float("nan"), "stance_angle_rad": 0.1,
                                "swing_rate_rad_per_s": -0.6, "stance_rate_rad_per_s": -0.8},
     "simulate.initial_state.swing_angle_rad"),
    ("simulate.strides", 10_000, "simulate.strides"),
    ("contact.stiffness_n_per_mm_pow_e", float("inf"), "contact.stiffness_n_per_mm_pow_e"),
    ("contact.max_damping_n_s_per_mm", float("inf"), "contact.max_damping_n_s_per_mm"),
    ("contact.mu_static", float("inf"), "contact.mu_static"),
    ("contact.mu_static", True, "contact.mu_static"),
    ("terrain.patch_width_m", float("inf"), "terrain.patch_width_m"),
    ("contact_sim.initial_rate_scale", [float("nan"), 1.0], "contact_sim.initial_rate_scale"),
    ("contact_sim.initial_rate_scale", [float("inf"), 1.0], "contact_sim.initial_rate_scale"),
    ("contact_sim.n_strides", 10_000_000, "contact_sim.n_strides"),
    ("contact_solver.rtol", 1e-14, "contact_solver.rtol"),
])
def test_strict_finite_numbers_name_the_field(tmp_path, path, value, field):
    p = _write(tmp_path / "s.yaml", _with(PAPER, path, value))
    with pytest.raises(SceneError) as exc:
        load_scene(p)
    msg = str(exc.value)
    named = r"(\.|: )".join(re.escape(k) for k in field.split("."))  # a.b.c or a.b: c
    assert re.match(re.escape(f"{p}: ") + named, msg) and "\n" not in msg, msg


def test_strict_still_accepts_yaml_ints_and_nested_mappings(tmp_path):
    d = _with(_with(PAPER, "walker.leg_length_m", 1), "walker.hip_mass_kg", 10)
    d = _with(d, "contact_sim.initial_rate_scale", [1, 1.1])
    sc = load_scene(_write(tmp_path / "s.yaml", _with(d, "contact.max_damping_n_s_per_mm", 90)))
    assert isinstance(sc.walker.leg_length_m, float) and sc.walker.leg_length_m == 1.0
    assert sc.contact_sim.initial_rate_scale == (1.0, 1.1)  # a YAML list -> tuple
    assert sc.fixedpoint.initial_guess.stance_rate_rad_per_s == -0.84  # nested from a dict
    again = scene_from_dict(sc.model_dump(mode="json"))  # sweeps validate dumped scenes
    assert again.model_dump() == sc.model_dump()


@pytest.mark.parametrize("kind,match", [("binary", "not a text"), ("dir", "is a directory"),
                                        ("missing", "not found")])
def test_scene_file_errors_are_one_line(tmp_path, kind, match):
    p = tmp_path / "s.yaml"
    if kind == "binary":
        p.write_bytes(bytes(range(256)) * 4)
    elif kind == "dir":
        p.mkdir()
    code, err, _ = _cli("fixedpoint", p, "--runs-dir", tmp_path / "runs")
    assert code == 1 and match in err and "\n" not in err, err


# ------------------------------------------------------------------ D3, D9, D11: CLI layer
@pytest.mark.parametrize("args,match", [
    (["bench", "nonsense"], "unknown benchmark"),
    (["bench", "ideal", "{scene}"], "apply to 'bench contact' only"),
    (["bench", "contact", "no_such_scene.yaml"], "no_such_scene.yaml"),
    (["simulate", "{scene}", "--strides", "10000000"], "--strides 10000000"),
    (["sweep", "{scene}", "--param", "slope.angle_deg=0:99999:1", "--param",
      "walker.hip_mass_kg=0:99999:1"], "at most 1,000,000"),
    (["sweep", "{scene}", "--param", "slope.angle_deg=1", "--name", "fixedpoint"],
     "stage's artifact"),
])
def test_bad_arguments_give_one_line(tmp_path, args, match):
    args = [a.replace("{scene}", str(ROOT / "configs" / "goswami1996.yaml")) for a in args]
    code, err, _ = _cli(*args, "--runs-dir" if args[0] != "bench" else "--out", tmp_path / "r")
    assert code == 1 and match in err and "\n" not in err and "Traceback" not in err, err


def test_unexpected_exception_is_one_line_with_debug_hint(tmp_path, monkeypatch):
    from walkerlab.stages import fixedpoint

    def boom(*a, **k):
        raise ZeroDivisionError("float division by zero")

    monkeypatch.setattr(fixedpoint, "run", boom)
    scene = ROOT / "configs" / "goswami1996.yaml"
    code, err, _ = _cli("fixedpoint", scene, "--runs-dir", tmp_path)
    assert code == 1 and "\n" not in err
    assert "internal error (ZeroDivisionError)" in err and "WALKERLAB_DEBUG=1" in err
    r = CliRunner().invoke(app, ["fixedpoint", str(scene)], env={"WALKERLAB_DEBUG": "1"})
    assert isinstance(r.exception, ZeroDivisionError)  # the traceback is there on request


def test_read_only_runs_folder_is_one_line(tmp_path, monkeypatch):
    import tempfile

    def denied(*a, **k):  # root ignores file modes: simulate EACCES where it would occur
        raise PermissionError(13, "Permission denied")

    monkeypatch.setattr(tempfile, "mkstemp", denied)
    sc = scene_from_dict({**IDEAL, "name": "paper"})
    with pytest.raises(ArtifactError, match="Permission denied"):
        common.run_cached("fixedpoint", sc, tmp_path, ("walker",), (), _fake_compute(1.0))
    monkeypatch.setattr("walkerlab.stages.fixedpoint.run",
                        lambda *a, **k: common.run_cached("fixedpoint", sc, tmp_path,
                                                          ("walker",), (), _fake_compute(1.0)))
    code, err, _ = _cli("fixedpoint", ROOT / "configs" / "goswami1996.yaml", "--runs-dir",
                        tmp_path)
    assert code == 1 and "Permission denied" in err and "\n" not in err, err


def _read_only(monkeypatch):
    """What a read-only runs folder does to walkerlab's writes (root ignores file modes, so
    the failures are raised where the kernel would raise them): no lock file, no temporary
    file."""
    import errno
    import tempfile

    from walkerlab.io import locks

    def no_lock(lock):
        raise RunPathError(f"{lock.parent}: cannot write the run folder (Read-only file "
                           "system)")

    def no_temp(suffix=None, prefix=None, dir=None, text=False):
        raise OSError(errno.EROFS, "Read-only file system", f"{dir}/{prefix}x1y2{suffix}")

    monkeypatch.setattr(locks, "_open_lock", no_lock)
    monkeypatch.setattr(tempfile, "mkstemp", no_temp)


def test_a_read_only_runs_folder_reuses_an_up_to_date_artifact_and_names_its_folder(
        tmp_path, monkeypatch):
    """Issue 56 item 16: a read-only runs folder could not even reuse an up-to-date
    artifact (the lock file was created first), and a write there named the temporary
    file (".walker.xml.<pid>.<random>.tmp") and said "walker.xml kept as they were"."""
    from walkerlab.io.artifacts import atomic_write_all

    sc = scene_from_dict({**IDEAL, "name": "paper"})
    common.run_cached("fixedpoint", sc, tmp_path, ("walker",), (), _fake_compute(-0.8))
    _read_only(monkeypatch)
    again = common.run_cached("fixedpoint", sc, tmp_path, ("walker",), (), _fake_compute(-0.8))
    assert again.reused
    with pytest.raises(RunPathError, match="cannot write the run folder"):  # a write: one line
        common.run_cached("fixedpoint", sc, tmp_path, ("walker",), (), _fake_compute(-0.8),
                          force=True)
    folder = tmp_path / "paper"
    with pytest.raises(ArtifactError) as exc:
        atomic_write_all([(folder / "walker.xml", lambda fh: fh.write(b"<mujoco/>"))])
    msg = str(exc.value)
    assert msg.startswith(f"{folder}: cannot write there (Read-only file system)"), msg
    assert ".tmp" not in msg and "(walker.xml kept as it was)" in msg


def test_plot_after_a_dataset_was_removed_is_one_line(tmp_path):
    sc = scene_from_dict({**IDEAL, "name": "paper"})
    path = stage_artifact(sc, tmp_path, "simulate")
    write_artifact(path, "simulate", sc, "k", lambda f: None, 0.0)  # no samples/ inside
    from walkerlab.stages import plot

    with pytest.raises(ArtifactError, match="doesn't exist .the artifact is damaged"):
        plot.run(sc, tmp_path)


@pytest.mark.parametrize("termination,code", [("fall", 1), ("solver_failure", 1),
                                              ("t_final", 0)])
def test_contact_sim_fall_exits_non_zero(tmp_path, monkeypatch, termination, code):
    sc = scene_from_dict({**PAPER, "name": "paper"})
    path = stage_artifact(sc, tmp_path, "contact-sim")

    def fake_run_cached(stage, scene, runs_root, *a, **k):  # the run, not its physics
        write_artifact(path, "contact-sim", sc, "k",
                       lambda f: f.attrs.__setitem__("termination", termination), 0.0)
        return common.StageOutcome("contact-sim", path, False, 0.0, {})

    # the stage decides the exit from how the run ended; the CLI opens no artifact for it
    monkeypatch.setattr("walkerlab.stages.contact_sim.run_cached", fake_run_cached)
    monkeypatch.setattr("walkerlab.stages.pipeline.run_upstream", lambda *a, **k: None)
    monkeypatch.setattr("walkerlab.io.schemas.contact_sim.load_contact_sim", lambda p: None)
    monkeypatch.setattr("walkerlab.report.text.contact_text", lambda c: "summary")
    got, err, _ = _cli("contact-sim", ROOT / "configs" / "paper.yaml", "--runs-dir", tmp_path)
    assert got == code
    assert (termination in err and "\n" not in err) if code else err == ""


def test_version_lists_the_numeric_libraries():
    code, _, out = _cli("--version")
    assert code == 0
    for name in ("walkerlab", "python", "numpy", "scipy", "numba", "h5py"):
        assert name in out


# ------------------------------------------------------------------ D6: cache on content
def _fake_compute(value: float):
    def compute():
        def writer(f):
            f.create_dataset("fixed_point/stance_rate", data=value)
        return writer, {}
    return compute


def test_edited_artifact_and_edited_upstream_are_detected(tmp_path):
    sc = scene_from_dict({**IDEAL, "name": "paper"})
    first = common.run_cached("fixedpoint", sc, tmp_path, ("walker",), (), _fake_compute(-0.8))
    assert not first.reused
    assert common.run_cached("fixedpoint", sc, tmp_path, ("walker",), (),
                             _fake_compute(-0.8)).reused
    up = (first.path,)
    key_before = freshness.input_hash("simulate", sc, ("walker",), up)
    with h5py.File(first.path, "a") as f:  # a user edits the output by hand
        f["fixed_point/stance_rate"][()] = -3.0
    assert freshness.input_hash("simulate", sc, ("walker",), up) != key_before  # downstream
    again = common.run_cached("fixedpoint", sc, tmp_path, ("walker",), (), _fake_compute(-0.8))
    assert not again.reused  # the edited output is not trusted
    with open_artifact(again.path, "fixedpoint") as f:
        assert f["fixed_point/stance_rate"][()] == -0.8


# ------------------------------------------------------------------ D5, permissions
def test_interrupted_figure_save_leaves_the_old_file(tmp_path):
    import matplotlib.pyplot as plt

    from walkerlab.plotting.figures import save

    fig = plt.figure()
    save(fig, tmp_path, "f")
    old = (tmp_path / "f.png").read_bytes()
    fig = plt.figure()

    def killed(fh, **kw):
        fh.write(b"\x89PNG half")
        raise KeyboardInterrupt

    fig.savefig = killed
    with pytest.raises(KeyboardInterrupt):
        save(fig, tmp_path, "f")
    assert (tmp_path / "f.png").read_bytes() == old
    assert sorted(p.name for p in tmp_path.iterdir()) == ["f.png", "f.svg"]  # no temp left


def test_report_is_written_atomically(tmp_path, monkeypatch):
    """The report writer goes through atomic_write (a kill cannot leave a 0-byte file)."""
    from walkerlab.stages import report

    calls = []
    real = atomic_write

    def spy(path, write, mode=0o644):
        calls.append(Path(path).name)
        return real(path, write, mode)

    monkeypatch.setattr("walkerlab.io.artifacts.atomic_write", spy)
    monkeypatch.setattr(report, "run_report", lambda *a, **k: ([], []))
    sc = scene_from_dict({**IDEAL, "name": "paper"})
    out = report.run(sc, tmp_path, echo=lambda s: None)
    assert out.is_file() and {"report.md", "report.html"} <= set(calls)


def test_every_output_is_0644(tmp_path, monkeypatch, fake_points):
    old = os.umask(0o077)  # even under a strict umask the files are the same mode
    try:
        sc = scene_from_dict({**IDEAL, "name": "paper"})
        a = common.run_cached("fixedpoint", sc, tmp_path, ("walker",), (), _fake_compute(1.0))
        t = atomic_write(tmp_path / "r.txt", lambda fh: fh.write(b"x"))
        s = _fake_sweep(tmp_path, "perm", n=2)
    finally:
        os.umask(old)
    for p in (a.path, t, s):
        assert stat.S_IMODE(p.stat().st_mode) == 0o644, p


# ------------------------------------------------------------------ D4, D12, D3: sweeps
@pytest.fixture
def fake_points(monkeypatch):
    """Instantaneous sweep points: the sweep plumbing is under test, not the physics."""
    monkeypatch.setattr(runner, "evaluate", _fake_evaluate)
    monkeypatch.setattr(runner, "warm_up", lambda: None)


def _fake_evaluate(stage, base, paths, values, index, guess, options, origin, *, plant):
    row = empty_row(stage, index)
    row.update(outcome="ok", wall_time_s=0.0, residual=float(values[0]))
    return row, np.array([values[0]])


def _fake_sweep(tmp_path, name, n=9, **kw):
    """A sweep whose points are instantaneous (runner.evaluate patched by the caller)."""
    from walkerlab.stages import sweep as sweep_stage

    sc = scene_from_dict({**IDEAL, "name": "paper"})
    return sweep_stage.run(sc, [f"slope.angle_deg=1:{n}:1"], "fixedpoint", workers=1,
                           runs_root=tmp_path, name=name, progress=False, **kw)


def test_rows_saved_every_few_points_and_kept_on_resume(tmp_path, monkeypatch, fake_points):
    seen = []

    def stop(done, total):
        seen.append(done)
        if len(seen) == 2:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        _fake_sweep(tmp_path, "prog", n=40, on_chunk=stop)
    assert seen[0] <= runner.PIECE_POINTS  # the first rows were saved after a few points
    part = partial_path(tmp_path / "paper" / "prog.h5")
    kept = load_sweep(part)["points"]["index"]
    assert kept.size == seen[-1] > 0
    done = load_sweep(_fake_sweep(tmp_path, "prog", n=40, resume=True))["points"]
    assert list(done["index"]) == list(range(40))


def test_second_identical_sweep_fails_in_one_line_while_the_first_runs(tmp_path,
                                                                           fake_points):
    target = tmp_path / "paper" / "same.h5"
    target.parent.mkdir(parents=True)
    holder = subprocess.Popen([sys.executable, "-c", textwrap.dedent(f"""
        import sys, time
        from walkerlab.io.runpaths import artifact_lock
        with artifact_lock(__import__('pathlib').Path({str(target)!r})):
            print('locked', flush=True); time.sleep(30)
        """)], stdout=subprocess.PIPE, text=True, env={**os.environ,
                                                        "PYTHONPATH": str(ROOT)})
    try:
        assert holder.stdout.readline().strip() == "locked"
        with pytest.raises(ArtifactBusy, match=f"pid {holder.pid}"):
            _fake_sweep(tmp_path, "same", n=3)
        with pytest.raises(ArtifactBusy):
            with artifact_lock(target, wait=False):
                pass
    finally:
        holder.kill()
        holder.wait()
        holder.stdout.close()
    assert not target.exists() and not partial_path(target).exists()
    assert load_sweep(_fake_sweep(tmp_path, "same", n=3))["points"]["index"].size == 3


def test_half_done_sweep_is_never_finalized(tmp_path, monkeypatch, fake_points):
    def lossy(chains, *a, **k):  # an executor that loses a piece
        for ci, chain in enumerate(chains[1:], 1):
            guess = None
            for j, t in enumerate(chain):
                rows, guess = runner.run_piece(t, guess)
                yield ci, j, rows, guess

    monkeypatch.setattr(runner, "iter_piece_results", lossy)
    with pytest.raises(SweepError, match="grid points have a row"):
        _fake_sweep(tmp_path, "half", n=9, chunk_size=3)
    assert not (tmp_path / "paper" / "half.h5").exists()


def test_grid_cap_is_on_the_product_of_the_axes():
    sc = scene_from_dict({**IDEAL, "name": "paper"})
    axes = [parse_param("slope.angle_deg=0:99999:1"), parse_param("walker.hip_mass_kg=0:99:1")]
    assert math.prod(len(a) for a in axes) > runner.MAX_GRID_POINTS
    with pytest.raises(SweepError, match="at most 1,000,000"):
        runner.run_sweep(sc, axes, "fixedpoint", Path("/nonexistent/x.h5"), workers=1,
                         plant=Plant.from_scene(sc))


# ------------------------------------------------------------------ D7: orphans
def _descendants(pid: int) -> list[int]:
    out = subprocess.run(["ps", "-e", "-o", "pid=,ppid="], capture_output=True,
                         text=True).stdout
    kids: dict[int, list[int]] = {}
    for ln in out.splitlines():
        a, b = map(int, ln.split())
        kids.setdefault(b, []).append(a)
    res, todo = [], [pid]
    while todo:
        for c in kids.get(todo.pop(), []):
            res.append(c)
            todo.append(c)
    return res


def test_sigkill_of_the_main_process_leaves_no_workers(tmp_path):
    # the forkserver's preload (model derivation) is skipped to keep the test short: the
    # workers then derive in their initializer, which the parent watch covers the same way
    script = textwrap.dedent(f"""
        import multiprocessing as mp
        from walkerlab.config import load_scene
        from walkerlab.stages import sweep
        from walkerlab.studies import runner
        runner._mp_context = lambda: mp.get_context("forkserver")
        sc = load_scene({str(ROOT / 'configs' / 'goswami1996.yaml')!r})
        sweep.run(sc, ["slope.angle_deg=1:4:0.02"], "fixedpoint", workers=2,
                  runs_root={str(tmp_path)!r}, name="orphans", progress=False)
        """)
    main = subprocess.Popen([sys.executable, "-c", script],
                            env={**os.environ, "PYTHONPATH": str(ROOT)})
    kids: list[int] = []
    try:
        for _ in range(1200):  # wait until the pool's workers run
            kids = _descendants(main.pid)
            if len(kids) >= 3:
                break
            time.sleep(0.05)
        time.sleep(1.0)
        kids = _descendants(main.pid)
        assert len(kids) >= 3, kids  # forkserver + 2 workers (+ resource tracker)
    finally:
        main.kill()
        main.wait()
    deadline = time.monotonic() + 10
    while time.monotonic() < deadline and any(process_alive(k) for k in kids):
        time.sleep(0.1)
    alive = [k for k in kids if process_alive(k)]
    names = {}
    for k in alive:
        try:
            names[k] = Path(f"/proc/{k}/cmdline").read_bytes().replace(b"\0", b" ")[:120]
        except OSError:
            names[k] = "?"
        os.kill(k, 9)
    assert not alive, f"still running after SIGKILL of the main process: {names}"


def test_a_second_stage_run_waits_for_the_first_writer(tmp_path, capfd):
    sc = scene_from_dict({**IDEAL, "name": "paper"})
    target = stage_artifact(sc, tmp_path, "fixedpoint")
    target.parent.mkdir(parents=True)
    holder = subprocess.Popen([sys.executable, "-c", textwrap.dedent(f"""
        import time
        from pathlib import Path
        from walkerlab.io.runpaths import artifact_lock
        with artifact_lock(Path({str(target)!r})):
            print('locked', flush=True); time.sleep(1.5)
            Path({str(tmp_path / "released")!r}).touch()
        """)], stdout=subprocess.PIPE, text=True, env={**os.environ,
                                                        "PYTHONPATH": str(ROOT)})
    try:
        assert holder.stdout.readline().strip() == "locked"
        out = common.run_cached("fixedpoint", sc, tmp_path, ("walker",), (), _fake_compute(1.0))
        assert (tmp_path / "released").exists()  # it ran only after the first one let go
    finally:
        holder.wait()
        holder.stdout.close()
    assert not out.reused and f"pid {holder.pid}" in capfd.readouterr().err


def test_memoised_content_hash_sees_an_edit(tmp_path, monkeypatch):
    """The per-process memo of content hashes (a report checks each upstream file several
    times) is keyed by the file's stamp: an edit after memoisation is still detected."""
    from walkerlab.io import artifacts as A

    scene = scene_from_dict({"name": "memo", "walker": {"leg_length_m": 1.0, "leg_mass_kg": 5.0,
                             "hip_mass_kg": 10.0, "leg_mass_from_foot_m": 0.5},
                             "slope": {"angle_rad": 0.0174}})
    path = tmp_path / "memo" / "x.h5"
    write_artifact(path, "simulate", scene, "k",
                   lambda f: f.create_dataset("a", data=np.arange(3.0)), 0.0)
    now = time.time_ns()
    monkeypatch.setattr(A.time, "time_ns", lambda: now + 10_000_000_000)  # the file is "old"
    first = A.content_hash(path)
    assert A.verified_hash(path) == "k" and A.content_hash(path) == first
    time.sleep(0.02)
    with h5py.File(path, "r+") as f:  # same size, new value
        f["a"][1] = 7.0
    monkeypatch.setattr(A.time, "time_ns", lambda: now + 20_000_000_000)
    assert A.content_hash(path) != first
    assert A.verified_hash(path) is None


def test_force_replaces_an_artifact_without_hashing_it(tmp_path, monkeypatch):
    """``--force`` recomputes whatever the existing artifact holds, so its content is not
    hashed first (issue 27: that hash was ~10 % of ``walkerlab fixedpoint --force``); without
    ``--force`` the same artifact is verified and reused."""
    sc = scene_from_dict({**IDEAL, "name": "paper"})
    common.run_cached("fixedpoint", sc, tmp_path, ("walker",), (), _fake_compute(1.0))
    verified = []
    real = freshness.verified_hash
    monkeypatch.setattr(freshness, "verified_hash", lambda p: verified.append(p) or real(p))
    out = common.run_cached("fixedpoint", sc, tmp_path, ("walker",), (), _fake_compute(2.0),
                            force=True)
    assert verified == [] and not out.reused and out.note == "--force"
    with h5py.File(out.path, "r") as f:
        assert float(f["fixed_point/stance_rate"][()]) == 2.0
    again = common.run_cached("fixedpoint", sc, tmp_path, ("walker",), (), _fake_compute(3.0))
    assert verified == [out.path] and again.reused


# -------------------- an initial guess from a FIFO


def _one_line(*args) -> str:
    code, err, _ = _cli(*args)
    assert code == 1, (code, err)
    assert len(err.splitlines()) == 1, err
    return err


def test_an_initial_guess_from_a_fifo_is_not_a_regular_file(tmp_path):
    import os

    fifo = tmp_path / "branch.h5"
    os.mkfifo(fifo)
    data = yaml.safe_load((ROOT / "configs" / "simplest.yaml").read_text())
    data["fixedpoint"]["initial_guess"] = {"from": str(fifo), "at": 0.5}
    scene = tmp_path / "s.yaml"
    scene.write_text(yaml.safe_dump(data))
    err = _one_line("fixedpoint", scene, "--runs-dir", tmp_path / "runs")
    assert err.endswith(f"{fifo}: not a regular file; give an HDF5 artifact")


# -------------------- a link in an artifact's place, before computing
# ------------------------------------------------------------------ 5: a link, before computing
@pytest.mark.parametrize("stage", ["continuation", "robustness"])
def test_link_in_place_of_an_artifact_is_refused_before_computing(tmp_path, monkeypatch,
                                                                     stage):
    from walkerlab.io.artifacts import write_artifact
    from walkerlab.io.freshness import write_if_stale
    from walkerlab.io.runpaths import RunPathError

    sc = scene_from_dict({**IDEAL, "name": "paper"})
    runs = tmp_path / "runs"
    elsewhere = tmp_path / "elsewhere.h5"  # a valid artifact of another run
    write_artifact(elsewhere, stage, sc, "other inputs", lambda f: None, 0.0)
    link = runs / "paper" / f"{stage}.h5"
    link.parent.mkdir(parents=True)
    link.symlink_to(elsewhere)
    computed, told = [], []

    def compute():
        computed.append(1)
        return (lambda f: None), {}

    with pytest.raises(RunPathError, match="symbolic link"):
        write_if_stale(stage, sc, runs, ("walker",), (), compute, tell=told.append)
    assert not computed and not told  # before: "recomputing ... changed" and the computation


@pytest.mark.parametrize("stage", sorted(ARTIFACTS))
def test_every_stage_loader_refuses_an_absent_or_foreign_artifact_in_one_line(tmp_path, stage):
    """Each stage's loader (made by walkerlab.io.artifacts.artifact_loader) takes the path,
    documents its ArtifactError and refuses in one line naming the file: an absent file,
    and an empty file written as another stage's (a stage-bound loader refuses the stage; the
    stability map's, bound to none, finds nothing it reads)."""
    art = ARTIFACTS[stage]
    loader = getattr(importlib.import_module(f"walkerlab.io.schemas.{art.schema}"), art.loader)
    assert next(iter(inspect.signature(loader).parameters)) == "path"
    assert "Raises\n------\nwalkerlab.io.artifacts.ArtifactError" in inspect.getdoc(loader)
    absent = tmp_path / "absent.h5"
    foreign = tmp_path / "foreign.h5"
    with h5py.File(foreign, "w") as f:
        f.attrs["stage"] = "another-stage"
        f.attrs["walkerlab_version"] = walkerlab.__version__
    for path in (absent, foreign):
        with pytest.raises(ArtifactError) as err:
            art.load(path)
        assert str(path) in str(err.value) and "\n" not in str(err.value)
