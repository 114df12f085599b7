"""Worker processes end with their parent, locks, a private code cache, symbolic links and a
full disk (issue 19, round two: items 1, 2, 3, 7, 10 and 14).

Each test names its item (``i1`` ... ``i14``) and fails on the code before the fix
(commit 5a8281f).  Processes are checked by behaviour bounds only ("gone within 10 s"),
never by timings.
"""

from __future__ import annotations

import errno
import os
import signal
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

from tests.cli_run import IDEAL
from tests.cli_run import run_cli as _cli
from walkerlab.cli import app
from walkerlab.cli.errors import one_line as _one_line
from walkerlab.config import scene_from_dict
from walkerlab.io import runpaths
from walkerlab.io.artifacts import ArtifactError, atomic_write, write_artifact
from walkerlab.io.runpaths import RunPathError, artifact_lock
from walkerlab.stages import common
from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]
ENV = {**os.environ, "PYTHONPATH": str(ROOT)}


def _fake_compute(value: float):
    def compute():
        return (lambda f: f.create_dataset("x", data=np.array([value]))), {}
    return compute


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


def _alive(pid: int) -> bool:
    """Process ``pid`` exists and is not a zombie."""
    try:
        os.kill(pid, 0)
        with open(f"/proc/{pid}/stat") as fh:
            return fh.read().rsplit(")", 1)[1].split()[0] != "Z"
    except (ProcessLookupError, FileNotFoundError):
        return False


def _kill_and_check_orphans(main: subprocess.Popen, want: int, sig: int,
                            ready_s: float = 60) -> list[int]:
    """Wait until ``main`` has ``want`` descendants (or ``ready_s``), send ``sig``; return
    the descendants still alive 10 s later (they are then killed)."""
    kids: list[int] = []
    try:
        deadline = time.monotonic() + ready_s
        while time.monotonic() < deadline and len(kids) < want:
            time.sleep(0.05)
            kids = _descendants(main.pid)
        time.sleep(1.0)
        kids = _descendants(main.pid)
        assert kids
    finally:
        main.send_signal(sig)
        main.wait()
    deadline = time.monotonic() + 10
    while time.monotonic() < deadline and any(_alive(k) for k in kids):
        time.sleep(0.1)
    alive = [k for k in kids if _alive(k)]
    for k in alive:
        os.kill(k, signal.SIGKILL)
    return alive


# ------------------------------------------------------------------ 1: worker lifecycle
def test_stability_map_workers_end_with_their_parent_and_free_the_lock(tmp_path):
    """SIGKILL here, SIGTERM for the work-precision lane below: the same watch ends both."""
    sig = signal.SIGKILL
    script = textwrap.dedent(f"""
        from walkerlab.config import load_scene
        from walkerlab.stages import stability_map
        sc = load_scene({str(ROOT / 'configs' / 'paper.yaml')!r})
        stability_map.run(sc, {str(tmp_path)!r}, kind="friction", n=3, workers=2,
                          max_step_maps=300)
        """)
    main = subprocess.Popen([sys.executable, "-c", script], env=ENV)
    artifact = tmp_path / "paper" / "stability_map_friction.h5"
    # 2 workers, forkserver and resource tracker (a forked pool has only the 2 workers)
    alive = _kill_and_check_orphans(main, 4, sig, ready_s=20)
    assert not alive, f"workers alive 10 s after {signal.Signals(sig).name} of their parent"
    with artifact_lock(artifact, wait=False):  # a rerun is not kept waiting
        pass


def test_work_precision_lane_worker_ends_with_its_parent():
    script = textwrap.dedent("""
        import time
        from walkerlab.bench.workprecision import start_worker
        ex = start_worker(0)
        ex.submit(time.sleep, 120)
        time.sleep(120)
        """)
    main = subprocess.Popen([sys.executable, "-c", script], env=ENV)
    alive = _kill_and_check_orphans(main, 2, signal.SIGTERM)  # worker + resource tracker
    assert not alive, "spawned lane worker (or its resource tracker) outlived its parent"


def test_lock_kept_by_a_dead_holders_child_is_taken_over(tmp_path):
    """The holder records its pid, forks a child that keeps the lock file open and is
    killed: the lock is taken over at once, not waited on."""
    target = tmp_path / "a.h5"
    holder = subprocess.Popen([sys.executable, "-c", textwrap.dedent(f"""
        import os, time
        from pathlib import Path
        from walkerlab.io.runpaths import artifact_lock
        with artifact_lock(Path({str(target)!r})):
            if os.fork() == 0:
                time.sleep(60); os._exit(0)
            print('locked', flush=True); time.sleep(60)
        """)], stdout=subprocess.PIPE, text=True, env=ENV)
    try:
        assert holder.stdout.readline().strip() == "locked"
        child = [k for k in _descendants(holder.pid)]
        holder.kill()
        holder.wait()
        with artifact_lock(target, wait=False):  # before: ArtifactBusy (pid of the dead)
            assert (tmp_path / ".a.h5.lock").read_text().split()[0] == str(os.getpid())
    finally:
        holder.stdout.close()
        for k in child:
            if _alive(k):
                os.kill(k, signal.SIGKILL)
    assert not (tmp_path / ".a.h5.lock").exists()  # removed on release


def test_lock_of_a_live_holder_is_not_taken_over(tmp_path):
    target = tmp_path / "a.h5"
    holder = subprocess.Popen([sys.executable, "-c", textwrap.dedent(f"""
        import time
        from pathlib import Path
        from walkerlab.io.runpaths import artifact_lock
        with artifact_lock(Path({str(target)!r})):
            print('locked', flush=True); time.sleep(60)
        """)], stdout=subprocess.PIPE, text=True, env=ENV)
    try:
        assert holder.stdout.readline().strip() == "locked"
        with pytest.raises(runpaths.ArtifactBusy, match=f"pid {holder.pid}"):
            with artifact_lock(target, wait=False):
                pass
    finally:
        holder.kill()
        holder.wait()
        holder.stdout.close()


@pytest.mark.parametrize("host,taken_over", [("this", True), ("elsewhere.example", False)])
def test_only_a_dead_holder_of_this_host_is_taken_over(tmp_path, host, taken_over):
    """A pid recorded by another machine sharing the folder cannot be checked here: its
    lock is waited on, never taken over."""
    import socket

    target = tmp_path / "a.h5"
    holder = subprocess.Popen([sys.executable, "-c", textwrap.dedent(f"""
        import time
        from pathlib import Path
        from walkerlab.io.runpaths import artifact_lock
        with artifact_lock(Path({str(target)!r})):
            print('locked', flush=True); time.sleep(60)
        """)], stdout=subprocess.PIPE, text=True, env=ENV)
    gone = subprocess.Popen([sys.executable, "-c", "pass"])
    gone.wait()
    try:
        assert holder.stdout.readline().strip() == "locked"
        name = socket.gethostname() if host == "this" else host
        (tmp_path / ".a.h5.lock").write_text(f"{gone.pid} {name}\n")  # a dead pid
        if taken_over:
            with artifact_lock(target, wait=False):
                pass
        else:
            with pytest.raises(runpaths.ArtifactBusy):
                with artifact_lock(target, wait=False):
                    pass
    finally:
        holder.kill()
        holder.wait()
        holder.stdout.close()


# ------------------------------------------------------------------ 2: the user cache
def _simple_structure():
    from walkerlab.walker.description import BodySpec, Structure

    return Structure("absolute", (BodySpec("mass", "point_mass"),))


@pytest.fixture
def user_cache(tmp_path, monkeypatch):
    from walkerlab.codegen import cache

    monkeypatch.setenv("WALKERLAB_CACHE_DIR", str(tmp_path / "uc"))
    cache.clear_memo()
    yield tmp_path / "uc"
    cache.clear_memo()


def test_generated_code_lives_in_a_private_user_cache(user_cache, tmp_path):
    from walkerlab.codegen import cache

    cache.generated_module(_simple_structure())
    folder = user_cache / "models"
    files = list(folder.glob("*.py"))
    assert len(files) == 1
    assert stat.S_IMODE(folder.stat().st_mode) == 0o700
    assert stat.S_IMODE(files[0].stat().st_mode) == 0o600


@pytest.mark.parametrize("how", ["group_writable", "other_owner", "symlink"])
def test_untrusted_cache_file_is_regenerated_never_executed(user_cache, tmp_path, how):
    import hashlib

    from walkerlab.codegen import cache

    s = _simple_structure()
    cache.generated_module(s)
    path = next((user_cache / "models").glob("*.py"))
    good = path.read_text()
    flag = tmp_path / "EXECUTED"
    body = f"open({str(flag)!r}, 'w').write('x')\n" + good.split("\n", 1)[1]
    evil = f"# sha256 {hashlib.sha256(body.encode()).hexdigest()}\n{body}"  # self-checksum
    if how == "symlink":
        other = tmp_path / "evil.py"
        other.write_text(evil)
        path.unlink()
        path.symlink_to(other)
    else:
        path.write_text(evil)
        if how == "group_writable":
            os.chmod(path, 0o664)
        else:
            if os.geteuid() != 0:
                pytest.skip("changing a file's owner needs root")
            os.chown(path, 12345, -1)
    cache.clear_memo()
    cache.generated_module(s)
    assert not flag.exists(), "code from an untrusted cache file was executed"
    assert not path.is_symlink() and path.read_text() == good  # regenerated
    assert stat.S_IMODE(path.stat().st_mode) == 0o600 and path.stat().st_uid == os.geteuid()


def test_nothing_from_a_runs_folder_is_executed(user_cache, tmp_path):
    """A runs folder unpacked from someone else carries ``.cache/models``: never read."""
    from walkerlab.codegen import cache

    s = _simple_structure()
    key = cache.cache_key(s)
    flag = tmp_path / "EXECUTED"
    planted = tmp_path / "runs" / ".cache" / "models" / f"{key}.py"
    planted.parent.mkdir(parents=True)
    body = f"open({str(flag)!r}, 'w').write('x')\ndef make(p):\n    return {{}}\n"
    import hashlib

    planted.write_text(f"# sha256 {hashlib.sha256(body.encode()).hexdigest()}\n{body}")
    sc = scene_from_dict({**IDEAL, "name": "paper"})
    common.run_cached("fixedpoint", sc, tmp_path / "runs", ("walker",), (), _fake_compute(1.0))
    cache.generated_module(s)
    assert not flag.exists()


def test_numba_cache_is_written_to_the_user_cache(tmp_path):
    env = {k: v for k, v in ENV.items() if k != "NUMBA_CACHE_DIR"}
    env["WALKERLAB_CACHE_DIR"] = str(tmp_path / "uc")
    out = subprocess.run([sys.executable, "-c", textwrap.dedent("""
        import os
        from walkerlab.models.contact import _kernels as K
        K.friction_mu(0.1, 0.9, 0.7, 0.01, 0.02)
        print(os.environ.get("NUMBA_CACHE_DIR"))
        """)], env=env, capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    from walkerlab.usercache import numba_sources_key

    # keyed on the numba modules' sources: machine code that inlined another module's
    # kernel never outlives that kernel's change
    assert out.stdout.strip() == str(tmp_path / "uc" / "numba" / numba_sources_key())
    assert list((tmp_path / "uc" / "numba").rglob("*.nbi")), "numba cached nothing there"


def test_other_numba_cache_keys_are_pruned_after_a_day_never_through_a_link(tmp_path):
    """The numba cache's key folder is created private; the folders of other keys (another
    version's sources, the old flat layout) are removed once unused for a day, a fresh one
    is kept, and a symbolic link is left alone (its target untouched)."""
    from walkerlab.usercache import _keyed

    d = tmp_path / "numba"
    d.mkdir(mode=0o700)
    old, fresh = d / "0123456789abcdef", d / "contact_feedface"
    for f in (old, fresh):
        f.mkdir()
        (f / "x.nbi").write_bytes(b"")
    os.utime(old, (time.time() - 2 * 86400,) * 2)
    target = tmp_path / "elsewhere"
    target.mkdir()
    (target / "keep").write_text("precious\n")
    os.utime(target, (time.time() - 2 * 86400,) * 2)
    (d / "link").symlink_to(target)
    sub = _keyed(d, "fedcba9876543210")
    assert sub == d / "fedcba9876543210" and stat.S_IMODE(sub.stat().st_mode) == 0o700
    assert not old.exists() and fresh.exists() and (d / "link").is_symlink()
    assert (target / "keep").read_text() == "precious\n"


# ------------------------------------------------------------------ 3: symbolic links
def test_lock_file_symlink_is_refused_and_its_target_untouched(tmp_path):
    sc = scene_from_dict({**IDEAL, "name": "paper"})
    runs = tmp_path / "runs"
    (runs / "paper").mkdir(parents=True)
    victim = tmp_path / "victim.txt"
    victim.write_text("precious\n")
    (runs / "paper" / ".fixedpoint.h5.lock").symlink_to(victim)
    with pytest.raises(RunPathError, match="symbolic link"):
        common.run_cached("fixedpoint", sc, runs, ("walker",), (), _fake_compute(1.0))
    assert victim.read_text() == "precious\n"


@pytest.mark.parametrize("name", ["fixedpoint.h5", "report.md", "basin.h5.partial"])
def test_writers_refuse_a_symlink_in_place(tmp_path, name):
    victim = tmp_path / "victim.txt"
    victim.write_text("precious\n")
    link = tmp_path / "paper" / name
    link.parent.mkdir()
    link.symlink_to(victim)
    sc = scene_from_dict({**IDEAL, "name": "paper"})
    with pytest.raises(RunPathError, match="symbolic link"):
        if name.endswith(".partial"):
            from walkerlab.studies import basin

            monkey_fp = np.zeros(4)
            basin.compute_basin(sc, monkey_fp, "k", link.with_name("basin.h5"), grid=(2, 2),
                                workers=1, plant=Plant.from_scene(sc))
        elif name.endswith(".h5"):
            write_artifact(link, "fixedpoint", sc, "k", lambda f: None, 0.0)
        else:
            atomic_write(link, lambda fh: fh.write(b"x"))
    assert victim.read_text() == "precious\n" and link.is_symlink()


def test_basin_partial_symlink_is_one_line_error(tmp_path):
    runs = tmp_path / "runs"
    (runs / "paper").mkdir(parents=True)
    victim = tmp_path / "victim.txt"
    victim.write_text("precious\n")
    # --grid 2x2 (not the scene's grid) writes basin_2x2.h5 (issue 26, item 6)
    (runs / "paper" / "basin_2x2.h5.partial").symlink_to(victim)
    code, err, _ = _cli("basin", ROOT / "configs" / "paper.yaml", "--grid", "2x2",
                        "--workers", "1", "--runs-dir", runs)
    assert code == 1 and "symbolic link" in err and "\n" not in err, err
    assert victim.read_text() == "precious\n"


def test_report_folder_symlink_leaving_runs_is_refused(tmp_path):
    runs = tmp_path / "runs"
    (runs / "paper").mkdir(parents=True)
    outside = tmp_path / "outside"
    outside.mkdir()
    (runs / "paper" / "report").symlink_to(outside)
    sc = scene_from_dict({**IDEAL, "name": "paper"})
    for fn in (runpaths.report_dir, runpaths.figures_dir):
        with pytest.raises(RunPathError, match="outside the runs folder"):
            fn(sc, runs, claim=True)
    assert not any(outside.iterdir())


# ------------------------------------------------------------------ 7: disk full
def _limited(script: str, limit_bytes: int, cwd: Path, env=None) -> subprocess.CompletedProcess:
    pre = (f"import resource\nresource.setrlimit(resource.RLIMIT_FSIZE, "
           f"({limit_bytes}, {limit_bytes}))\n")
    return subprocess.run([sys.executable, "-c", pre + textwrap.dedent(script)], cwd=cwd,
                          env={**ENV, **(env or {})}, capture_output=True, text=True,
                          timeout=300)


def test_full_disk_is_one_line_and_keeps_the_old_artifact(tmp_path):
    scene = tmp_path / "paper.yaml"
    scene.write_text(yaml.safe_dump(IDEAL))
    code, err, _ = _cli("simulate", scene, "--strides", "1", "--runs-dir", tmp_path / "runs")
    assert code == 0, err
    old = (tmp_path / "runs" / "paper" / "simulate.h5").read_bytes()
    limit = 2 * len(old)  # room for the 1-stride file, not for 40 strides (~40x the samples)
    r = _limited(f"""
        import sys
        from walkerlab.cli import app
        sys.argv = ["walkerlab", "simulate", {str(scene)!r}, "--strides", "40",
                    "--runs-dir", {str(tmp_path / 'runs')!r}]
        app()
        """, limit, tmp_path)
    # the error is one line (a 'recomputing ... (scene changed ...)' note may precede it)
    err = [ln for ln in r.stderr.strip().splitlines() if not ln.startswith("simulate: ")]
    assert r.returncode == 1 and len(err) == 1 and err[0].startswith("error: disk full"), err
    assert (tmp_path / "runs" / "paper" / "simulate.h5").read_bytes() == old
    assert not [p for p in (tmp_path / "runs").rglob("*") if p.name.endswith(".tmp")]


def test_cache_write_on_a_full_disk_leaves_nothing(tmp_path):
    r = _limited("""
        from walkerlab.codegen import cache
        from walkerlab.walker.description import BodySpec, Structure
        ns = cache.generated_module(Structure("absolute", (BodySpec("mass", "point_mass"),)))
        assert callable(ns["make"])  # the code is still usable (kept in memory)
        """, 2048, tmp_path, env={"WALKERLAB_CACHE_DIR": str(tmp_path / "uc")})
    assert r.returncode == 0, r.stderr
    assert not [p for p in (tmp_path / "uc").rglob("*") if p.is_file()]


def test_disk_full_errors_map_to_one_line(tmp_path):
    def boom(fh):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
    (tmp_path / "x.json").write_text("old")
    with pytest.raises(ArtifactError, match="^disk full: cannot write .*x.json"):
        atomic_write(tmp_path / "x.json", boom)
    assert (tmp_path / "x.json").read_text() == "old"
    assert [p.name for p in tmp_path.iterdir()] == ["x.json"]


# ------------------------------------------------------------------ 10: damaged cache entry
@pytest.mark.parametrize("damage", ["{}", "[]", "not json",
                                    '{"vec": null, "nfev": 3, "times": [], "cpu_times": []}',
                                    '{"vec": ["a"], "nfev": 3, "times": [0.1], '
                                    '"cpu_times": [0.1]}',
                                    # measured before the integration's CPU time was timed
                                    '{"vec": [1.0], "nfev": 3, "times": [0.1], '
                                    '"cpu_times": [0.1]}'])
def test_damaged_work_precision_case_is_measured_again(tmp_path, monkeypatch, damage):
    from walkerlab.bench import workprecision as W

    good = {"vec": [1.0, 2.0], "nfev": 10, "times": [0.01], "cpu_times": [0.01],
            "clock": "thread_cpu_integration"}
    monkeypatch.setattr(W, "_run_case", lambda t: (t.key, dict(good)))
    case = W.Case("k1", "ideal", "{}", 1.0, (0.0,), 1, "RK45", 1e-3, 1e-6, 1, ())
    (tmp_path / "k1.json").write_text(damage)
    out = W.run_cases([case], tmp_path, workers=1)
    assert out["k1"]["cached"] is False and out["k1"]["vec"] == good["vec"]
    assert W.read_cached_case(tmp_path / "k1.json")["vec"] == good["vec"]  # repaired
    assert W.run_cases([case], tmp_path, workers=1)["k1"]["cached"] is True


# ------------------------------------------------------------------ 14: messages
def test_one_line_keeps_a_wrapped_sentence_and_breaks_a_long_one_at_a_boundary():
    short = _one_line("the error is larger than allowed, as measured by the\nreference run.")
    assert short == "the error is larger than allowed, as measured by the reference run."
    text = "first field: bad value. " + "second sentence goes on " * 30 + "end."
    first, second = _one_line(text).splitlines()  # never cut: a second line
    assert first.startswith("first field: bad value.") and len(first) <= 300  # at a word
    assert second.startswith("  ") and second.rstrip().endswith("end.")
    assert f"{first} {second.strip()}" == text.strip()
    assert "WALKERLAB_DEBUG=1" not in second and "more lines" not in second


@pytest.mark.parametrize("value,traceback", [("false", False), ("0", False), ("no", False),
                                             ("", False), ("1", True), ("true", True),
                                             ("YES", True)])
def test_debug_switch_accepts_1_true_yes_only(tmp_path, value, traceback):
    r = CliRunner().invoke(app, ["fixedpoint", str(tmp_path / "missing.yaml")],
                           env={"WALKERLAB_DEBUG": value})
    assert r.exit_code == 1
    assert (r.exception is not None and not isinstance(r.exception, SystemExit)) == traceback
    if not traceback:
        assert r.stderr.strip().startswith("error: ") and "scene file not found" in r.stderr


def test_empty_runs_dir_is_refused(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    code, err, _ = _cli("fixedpoint", ROOT / "configs" / "paper.yaml", "--runs-dir", "")
    assert code == 2 and "empty folder name" in err
    assert list(tmp_path.iterdir()) == []


def test_report_markdown_escapes_the_scene_source():
    from walkerlab.report.build import _header
    from walkerlab.report.markdown import to_html

    sc = scene_from_dict({**IDEAL, "name": "x", "source": "Smith <script>alert(1)</script>\n& co"})
    md = "\n".join(_header(sc))
    assert "<script>" not in md and "&lt;script&gt;alert(1)&lt;/script&gt; &amp; co" in md
    html = to_html(md, Path("."))
    assert "<script>" not in html and "&lt;script&gt;" in html and "&amp;lt;" not in html


def test_device_as_scene_is_not_a_regular_file():
    code, err, _ = _cli("fixedpoint", "/dev/zero")
    assert code == 1 and err == "error: /dev/zero: not a regular file; give a YAML scene file"


def test_bench_out_naming_a_file_says_what_to_do(tmp_path):
    f = tmp_path / "FILE"
    f.write_text("keep")
    code, err, _ = _cli("bench", "ideal", "--out", f)
    assert code == 1 and "is a file; --out names a folder" in err and "\n" not in err
    assert f.read_text() == "keep"


# -------------------- one-line advice kept whole; SIGTERM as Ctrl-C; a full disk
def test_a_long_error_is_never_cut_its_detail_takes_a_second_line():
    """A message longer than the limit loses nothing ("rerun with WALKERLAB_DEBUG=1" is
    never needed to read it): the advice stays whole on the first line, the search's
    ``[detail]`` goes on a second; a long message without one breaks at a clause."""
    from walkerlab.cli.errors import MAX_ERROR_CHARS, one_line

    advice = "no gait; " + "advice " * 60  # longer than the limit on its own
    assert len(advice) > MAX_ERROR_CHARS
    detail = "[tried a; last: " + "word " * 60 + "]"
    lines = one_line(advice + detail).splitlines()
    assert lines == [advice.rstrip(), "  " + detail.replace("  ", " ").rstrip()] or \
        (len(lines) == 2 and lines[0] == advice.rstrip() and lines[1].strip() ==
         detail.strip())
    short = "no gait; advice [tried a and b]"
    assert one_line(short) == short  # short: one line as it is
    long = "first clause; " + "word " * 80
    two = one_line(long).splitlines()
    assert len(two) == 2 and " ".join(t.strip() for t in two) == long.strip()
    assert "WALKERLAB_DEBUG" not in one_line(long)


# ------------------------------------------------------------- 15: SIGTERM as Ctrl-C
def test_sigterm_during_a_write_leaves_no_lock_nor_temporary_file(tmp_path):
    script = textwrap.dedent(f"""
        import sys, time
        from walkerlab.cli.process import terminate_as_interrupt
        terminate_as_interrupt()
        from walkerlab.config import load_scene
        from walkerlab.io.freshness import write_if_stale
        sc = load_scene({str(ROOT / 'configs' / 'paper.yaml')!r})
        def writer(f):
            f.create_dataset('x', data=[1.0])
            print('ready', flush=True)
            time.sleep(60)
        try:
            write_if_stale('fixedpoint', sc, {str(tmp_path)!r}, ('walker',), (),
                           lambda: (writer, dict()))
        except KeyboardInterrupt:
            sys.exit(130)
        """)
    with subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE,
                          text=True) as p:
        try:
            assert p.stdout.readline().strip() == "ready"
            p.send_signal(signal.SIGTERM)
            assert p.wait(timeout=30) == 130
        finally:
            p.kill()
    left = sorted(q.name for q in (tmp_path / "paper").iterdir())
    assert left == [".scene"], left  # no .fixedpoint.h5.lock, no temporary file


# ------------------------------------------ 15: a full disk while the model is written
def test_a_file_size_limit_while_the_generated_module_is_written_says_disk_full(monkeypatch):
    import walkerlab.safefs as safefs
    import walkerlab.usercache as usercache
    from walkerlab import codestore
    from walkerlab.cli.errors import _disk_full_line
    from walkerlab.io.artifacts import is_disk_full

    def full(path, fill, **kw):
        raise OSError(errno.EFBIG, "File too large", str(path))

    monkeypatch.setattr(safefs, "atomic_replace", full)
    monkeypatch.setattr(usercache, "atomic_replace", full)  # the name the cache writes by
    with pytest.raises(OSError) as exc:
        codestore.import_generated("zz_never_written_nb.py", "walkerlab_zz_never", lambda: "X = 1")
    assert is_disk_full(exc.value) and "cannot write the generated module" in str(exc.value)
    line = _disk_full_line(exc.value)
    assert line.startswith("error: disk full: cannot write ") and "zz_never_written" in line


# -------------------- a full disk while a study writes its partial file
def _scene(tmp_path: Path, name: str = "paper", **sections) -> Path:
    path = tmp_path / f"{name}.yaml"
    path.write_text(yaml.safe_dump({**IDEAL, **sections}))
    return path


STUDIES = {
    "mfpt": (["mfpt", "--method", "montecarlo"],
             {"mfpt": {"sigma_rad": [0.008], "walks": 12, "max_steps": 8}}),
    "sweep": (["sweep", "--param", "slope.angle_rad=0.012:0.02:0.001"], {}),
    "basin": (["basin", "--grid", "8x8"], {"basin": {"max_steps": 5}}),
}


@pytest.mark.slow
@pytest.mark.parametrize("study", sorted(STUDIES))
def test_full_disk_while_a_study_writes_its_partial_file_is_one_line(tmp_path, study):
    args, sections = STUDIES[study]
    scene = _scene(tmp_path, **sections)
    runs = tmp_path / "runs"
    code, err, _ = _cli("fixedpoint", scene, "--runs-dir", runs)
    assert code == 0, err
    limit = 4096  # an HDF5 file of a few pieces is larger: the partial file's writes fail
    script = f"""
        import resource, sys
        resource.setrlimit(resource.RLIMIT_FSIZE, ({limit}, {limit}))
        from walkerlab.cli import app
        sys.argv = ["walkerlab", *{args!r}, {str(scene)!r}, "--workers", "1",
                    "--runs-dir", {str(runs)!r}]
        app()
        """
    r = subprocess.run([sys.executable, "-c", textwrap.dedent(script)], cwd=tmp_path,
                       env=ENV, capture_output=True, text=True, timeout=300)
    err = r.stderr.strip().splitlines()
    assert r.returncode == 1 and len(err) == 1 and err[0].startswith("error: disk full"), \
        (r.returncode, err[:5])
    left = [p for p in runs.rglob("*") if p.is_file() and p.name != ".scene"
            and p.name != "fixedpoint.h5"]
    assert not [p for p in left if p.name.endswith(".tmp")]
    for p in left:  # what is left is a whole file (the work saved before the disk filled)
        assert p.name.endswith(".partial"), p
        with h5py.File(p, "r") as f:
            assert "input_hash" in f.attrs
