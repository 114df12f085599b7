"""Issue 26, "Reliability, round three": each test reproduces one probe finding through the
CLI or the API and failed on the code before the fix (branch point f894f40).

Dask clusters are ``distributed.LocalCluster`` on 127.0.0.1 in a child process of the test
(so that its scheduler can be SIGKILLed); every process is killed at teardown.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]
PAPER = ROOT / "configs" / "paper.yaml"


def _env(tmp_path: Path, **extra) -> dict:
    env = {**os.environ, "PYTHONPATH": str(ROOT), **extra}
    env.pop("WALKERLAB_DEBUG", None)
    if "WALKERLAB_CACHE_DIR" in extra:  # an earlier test in this process may have set numba's
        env.pop("NUMBA_CACHE_DIR", None)  # folder: the child derives it from the cache given
    return env


def _run(args, env, timeout=120, cwd=None):
    return subprocess.run([sys.executable, "-m", "walkerlab.cli", *map(str, args)], env=env,
                          capture_output=True, text=True, timeout=timeout, cwd=cwd)


# ----------------------------------------------------------------------------- Dask (High)
_CLUSTER = textwrap.dedent("""
    import os, time
    from distributed import Client, LocalCluster

    if __name__ == "__main__":
        cluster = LocalCluster(n_workers=1, threads_per_worker=1, host="127.0.0.1",
                               dashboard_address=None, processes=True)

        async def _no_restart():
            return None

        for nanny in cluster.workers.values():
            nanny.instantiate = _no_restart  # a SIGKILLed worker stays dead
        client = Client(cluster)
        (wpid,) = client.run(os.getpid).values()
        print(cluster.scheduler_address, wpid, flush=True)
        while True:
            time.sleep(1)
""")


@pytest.fixture
def one_worker_cluster(tmp_path):
    """``(address, worker pid, cluster process)``: a scheduler and one worker process."""
    pytest.importorskip("distributed")
    script = tmp_path / "cluster.py"
    script.write_text(_CLUSTER)
    proc = subprocess.Popen([sys.executable, str(script)], env=_env(tmp_path),
                            stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True,
                            start_new_session=True)
    try:
        line = proc.stdout.readline().split()
        if len(line) != 2:
            pytest.skip("LocalCluster did not start")
        yield line[0], int(line[1]), proc
    finally:
        try:
            os.killpg(proc.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
        proc.wait(timeout=30)
        proc.stdout.close()


def _sweep_files(folder: Path) -> set[str]:
    return {p.name for p in folder.iterdir()} if folder.is_dir() else set()


@pytest.mark.xdist_group("timing")  # wall-clock bound: not beside another of them
@pytest.mark.slow
def test_dask_only_worker_killed_bounded_wait_one_line_resume(tmp_path, one_worker_cluster):
    addr, wpid, _ = one_worker_cluster
    os.kill(wpid, signal.SIGKILL)  # the only worker dies; its nanny does not restart it
    env = _env(tmp_path, WALKERLAB_DASK_WORKER_WAIT_S="3")
    args = ["sweep", PAPER, "--param", "slope.angle_deg=1:1.3:0.1", "--name", "dk",
            "--runs-dir", tmp_path / "runs"]
    t0 = time.monotonic()
    r = _run([*args, "--scheduler", addr], env, timeout=90)  # before: waited for ever
    assert time.monotonic() - t0 < 60
    assert r.returncode == 1, r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and "no worker for 3 s" in lines[0] and "--resume" in lines[0], lines
    folder = tmp_path / "runs" / "paper"
    assert _sweep_files(folder) == {".scene", "dk.h5.partial"}  # lock released, rows kept
    r = _run([*args, "--resume", "--workers", "1"], env)
    assert r.returncode == 0, r.stderr
    files = _sweep_files(folder)
    assert "dk.h5" in files and not {"dk.h5.partial", ".dk.h5.lock"} & files, files


@pytest.mark.slow
def test_dask_scheduler_killed_one_line_suggests_resume(tmp_path, one_worker_cluster):
    addr, wpid, proc = one_worker_cluster
    env = _env(tmp_path)
    folder = tmp_path / "runs" / "paper"
    p = subprocess.Popen([sys.executable, "-m", "walkerlab.cli", "sweep", str(PAPER),
                          "--param", "slope.angle_deg=1:4:0.005", "--name", "dk",
                          "--runs-dir", str(tmp_path / "runs"), "--scheduler", addr],
                         env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        import psutil  # a dependency of distributed

        port = int(addr.rsplit(":", 1)[1])
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline and p.poll() is None:  # until it is connected
            if any(c.raddr and c.raddr.port == port and c.status == "ESTABLISHED"
                   for c in psutil.Process(p.pid).net_connections("tcp")):
                break
            time.sleep(0.1)
        time.sleep(2.0)  # tasks submitted, rows coming in
        assert p.poll() is None, p.communicate()
        os.killpg(proc.pid, signal.SIGKILL)  # scheduler and worker gone
        out, err = p.communicate(timeout=90)
    finally:
        if p.poll() is None:
            p.kill()
            p.wait()
    lines = err.strip().splitlines()
    assert p.returncode == 1
    assert len(lines) == 1, err  # before: ~40 lines, 2 tracebacks, internal error
    assert "internal error" not in lines[0] and "--resume" in lines[0], lines
    assert _sweep_files(folder) == {".scene", "dk.h5.partial"}


# ----------------------------------------------------------------------------- user cache
def _fifo_all(folder: Path, suffixes=None) -> int:
    n = 0
    for p in sorted(folder.rglob("*")):
        if p.is_file() and (suffixes is None or p.suffix in suffixes):
            p.unlink()
            os.mkfifo(p)
            n += 1
    return n


@pytest.mark.slow  # compiles the kernels into a fresh cache (~9 s CPU)
def test_fifos_in_the_user_cache_do_not_hang_fixedpoint(tmp_path):
    cache = tmp_path / "cache"
    env = _env(tmp_path, WALKERLAB_CACHE_DIR=str(cache), TMPDIR=str(tmp_path / "tmp"))
    (tmp_path / "tmp").mkdir()
    args = ["fixedpoint", PAPER, "--runs-dir", tmp_path / "runs", "--force"]
    assert _run(args, env).returncode == 0
    assert _fifo_all(cache) >= 1  # every generated module replaced by a FIFO
    r = _run(args, env, timeout=60)  # before: hung in open() for ever
    assert r.returncode == 0, r.stderr
    assert "step period     0.70359" in r.stdout
    assert not any(p.is_fifo() for p in (cache / "models").iterdir())  # rebuilt in place


_KERNEL = ("from walkerlab.models.contact import _kernels as k; "
           "print(k.step(0.25, 0.0, 0.0, 1.0, 1.0)[0], k.friction_mu(0.5, 0.9, 0.7, 0.1, 1.0)[0])")


def _kernel_run(env):
    return subprocess.run([sys.executable, "-c", _KERNEL], env=env, capture_output=True,
                          text=True, timeout=120)


@pytest.mark.parametrize("damage", ["garbage", "empty", "fifo"])
@pytest.mark.slow  # in `pytest -m slow`: the quick suite keeps to its CPU budget
def test_damaged_numba_cache_files_are_rebuilt(tmp_path, damage):
    cache = tmp_path / "cache"
    env = _env(tmp_path, WALKERLAB_CACHE_DIR=str(cache), TMPDIR=str(tmp_path / "tmp"))
    (tmp_path / "tmp").mkdir()
    first = _kernel_run(env)
    assert first.returncode == 0, first.stderr
    files = [p for p in (cache / "numba").rglob("*") if p.suffix in (".nbi", ".nbc")
             and ("_kernels.step-" in p.name or "_kernels.friction_mu-" in p.name)]
    assert {p.suffix for p in files} == {".nbi", ".nbc"}
    for p in files:
        p.unlink()
        if damage == "fifo":
            os.mkfifo(p)
        else:
            p.write_bytes(b"" if damage == "empty" else b"\x80\x05garbage" * 7)
    r = _kernel_run(env)  # before: UnpicklingError / EOFError for good (FIFO: a hang)
    assert r.returncode == 0, r.stderr
    assert r.stdout.split() == first.stdout.split()  # STEP(0.25) = 0.15625; mu(0.5) < 0
    assert float(r.stdout.split()[0]) == 0.25 ** 2 * (3 - 2 * 0.25)
    again = [p for p in (cache / "numba").rglob("*") if "_kernels.step-" in p.name]
    assert again and all(p.is_file() and p.stat().st_size > 0 for p in again)  # rewritten


def _package_pycache() -> set[Path]:
    return {p for p in (ROOT / "walkerlab").rglob("*.nbi")} | \
        {p for p in (ROOT / "walkerlab").rglob("*.nbc")}


@pytest.mark.slow  # each case compiles the kernels into a fresh cache (~10 s CPU)
@pytest.mark.parametrize("how", ["group_writable", "symlink", "not_creatable", "read_only"])
def test_unusable_numba_cache_never_writes_into_the_package(tmp_path, how):
    if how == "read_only" and os.geteuid() == 0:
        pytest.skip("root writes into read-only folders (not_creatable covers the fallback)")
    cache, tmp = tmp_path / "cache", tmp_path / "tmp"
    tmp.mkdir()
    env = _env(tmp_path, WALKERLAB_CACHE_DIR=str(cache), TMPDIR=str(tmp))
    env.pop("NUMBA_CACHE_DIR", None)
    cache.mkdir(mode=0o700)
    if how == "not_creatable":  # the cache root lies under a regular file
        (cache / "file").write_text("")
        env["WALKERLAB_CACHE_DIR"] = str(cache / "file" / "walkerlab")
    elif how == "group_writable":
        (cache / "numba").mkdir()
        os.chmod(cache / "numba", 0o770)
    elif how == "symlink":
        (tmp_path / "elsewhere").mkdir(mode=0o700)
        os.symlink(tmp_path / "elsewhere", cache / "numba")
    else:
        (cache / "numba").mkdir(mode=0o700)
        (cache / "models").mkdir(mode=0o700)
        os.chmod(cache / "numba", 0o500)
        os.chmod(cache / "models", 0o500)
        os.chmod(cache, 0o500)
    before = _package_pycache()
    try:
        for _ in range(2):
            r = _kernel_run(env)
            assert r.returncode == 0, r.stderr
            r = _run(["fixedpoint", PAPER, "--runs-dir", tmp_path / "runs", "--force"], env)
            assert r.returncode == 0, r.stderr
    finally:
        os.chmod(cache, 0o700)
        for p in cache.iterdir():
            if not p.is_symlink():
                os.chmod(p, 0o700)
    new = _package_pycache() - before
    for p in new:  # do not leave them for the next run
        p.unlink()
    assert not new, sorted(map(str, new))[:3]  # before: machine code in walkerlab/__pycache__
    assert list(tmp.iterdir()) == []  # before: a walkerlab_gen_* folder per run
    if how == "symlink":
        assert list((tmp_path / "elsewhere").iterdir()) == []


# ----------------------------------------------------------------------------- API (Medium)
def test_api_runs_dir_empty_is_refused_not_the_current_folder(tmp_path, monkeypatch):
    import walkerlab.api as wl
    from walkerlab.safefs import RunPathError

    monkeypatch.chdir(tmp_path)
    scene = wl.load_scene(PAPER)
    for bad in ("", "  ", None, 5):
        with pytest.raises(RunPathError, match="runs_dir"):
            wl.fixed_point(scene, runs_dir=bad)
        with pytest.raises(RunPathError, match="runs_dir"):
            wl.sweep(scene, "walker.hip_mass_kg", [10.0], runs_dir=bad)
    assert list(tmp_path.iterdir()) == []  # before: ./paper/fixedpoint.h5


def test_api_sweep_values_must_be_a_sequence(tmp_path):
    import walkerlab.api as wl
    from walkerlab.studies.params import SweepError

    scene = wl.load_scene(PAPER)
    for bad in ("10", "1,2", b"10", 10):
        with pytest.raises(SweepError, match="give a sequence"):  # before: swept "1" and "0"
            wl.sweep(scene, "walker.hip_mass_kg", bad, runs_dir=tmp_path)
    assert list(tmp_path.iterdir()) == []


def test_api_load_scene_name_is_validated():
    import walkerlab.api as wl
    from walkerlab.config import SceneError

    for bad in (5, "", "a/b", "..", ".hidden", 1.5):
        with pytest.raises(SceneError, match="name"):
            wl.load_scene(PAPER, name=bad)
    assert wl.load_scene(PAPER, name="steep_1").name == "steep_1"


def test_a_5000_digit_integer_is_one_line_naming_the_field():
    import yaml

    import walkerlab.api as wl
    from walkerlab.config import SceneError

    d = yaml.safe_load(PAPER.read_text())
    d["walker"]["hip_mass_kg"] = 10 ** 5000
    with pytest.raises(SceneError) as err:  # before: ValueError (int-to-str digit limit)
        wl.load_scene(d)
    msg = str(err.value)
    assert "\n" not in msg and len(msg) < 200
    assert "walker.hip_mass_kg" in msg and "5001 digits" in msg


# ----------------------------------------------------------------------------- guess (Medium)
@pytest.mark.xdist_group("timing")  # wall-clock bound: not beside another of them
def test_a_spinning_initial_guess_fails_fast_in_one_line(tmp_path):
    import yaml

    d = yaml.safe_load(PAPER.read_text())
    d["fixedpoint"]["initial_guess"]["swing_rate_rad_per_s"] = 1.0e6
    scene = tmp_path / "spin.yaml"
    scene.write_text(yaml.safe_dump(d))
    t0 = time.monotonic()
    r = _run(["fixedpoint", scene, "--runs-dir", tmp_path / "runs"], _env(tmp_path), timeout=60)
    assert time.monotonic() - t0 < 30  # before: 74 s, then internal error (OverflowError)
    assert r.returncode == 1
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and "swing_rate_rad_per_s: 1e+06" in lines[0], lines
    assert "62.6 rad/s" in lines[0]  # 20 sqrt(9.81 / 1.0)


def test_every_shipped_initial_guess_is_within_the_walking_bound():
    """Each shipped guess names the walker's states and is a walking state, checked on the
    walker's description (its state names from :func:`walkerlab.models.registry.
    state_layout`, which tests/models/test_state_layout.py holds to the built walker's, and
    the numbers the check reads): no equations derived, so a cold cache (CI) derives no
    3D walker here."""
    from types import SimpleNamespace

    from walkerlab.analysis.gait.scene import initial_guess
    from walkerlab.config import load_scene
    from walkerlab.models.registry import state_layout

    n = 0
    for path in sorted((ROOT / "configs").glob("*.yaml")):
        scene = load_scene(path)
        if scene.fixedpoint is not None and scene.fixedpoint.initial_guess is not None:
            plant = Plant.from_scene(scene)
            names = state_layout(plant)[0]
            walker = SimpleNamespace(state_names=lambda names=names: names, params={
                "leg_length_m": plant.data.leg_length_m,
                "gravity_m_per_s2": plant.data.gravity_m_per_s2})
            assert initial_guess(scene, walker) is not None, path.name
            n += 1
    assert n >= 3


# ----------------------------------------------------------------------------- Low
def _dead_pid() -> int:
    p = subprocess.Popen(["true"])
    p.wait()
    return p.pid  # exited and reaped: not alive (a reuse of the pid would keep the file)


@pytest.mark.slow
def test_killed_animate_temp_files_are_removed_and_a_linked_gif_refused(tmp_path):
    env = _env(tmp_path)
    args = ["animate", PAPER, "--runs-dir", tmp_path / "runs"]
    assert _run(args, env).returncode == 0
    folder = tmp_path / "runs" / "paper"
    figs = folder / "report" / "figures"
    dead, old = _dead_pid(), time.time() - 3600
    stale = [figs / f".animation.{dead}.abcd1234.gif", folder / f".simulate.h5.{dead}.k2j4h5g6.tmp",
             figs / f".report.md.{dead}.zz99yy88.tmp"]
    kept = [figs / f".animation.{os.getpid()}.live0000.gif",  # a live writer's
            figs / f".animation.{dead}.abcd1234.png"]  # not a name walkerlab writes
    for p in stale + kept:
        p.write_bytes(b"partial")
        os.utime(p, (old, old))
    r = _run(args, env)  # before: SIGTERM/SIGKILL left-overs were never removed
    assert r.returncode == 0, r.stderr
    assert [p.name for p in stale if p.exists()] == []
    assert all(p.exists() for p in kept)
    # animation.gif replaced by a link: refused in one line, the target untouched
    target = tmp_path / "elsewhere.gif"
    target.write_bytes(b"mine")
    (figs / "animation.gif").unlink()
    os.symlink(target, figs / "animation.gif")
    r = _run(args, env)
    assert r.returncode == 1
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and "symbolic link" in lines[0] and "animation.gif" in lines[0]
    assert target.read_bytes() == b"mine" and (figs / "animation.gif").is_symlink()


def test_knee_latch_on_a_straight_leg_walker_is_an_error(tmp_path):
    import yaml

    for cfg in ("paper.yaml", "round_feet.yaml"):
        d = yaml.safe_load((ROOT / "configs" / cfg).read_text())
        d.setdefault("contact", {})["knee_stop"] = {"latch": True}
        scene = tmp_path / cfg
        scene.write_text(yaml.safe_dump(d))
        r = _run(["contact-sim", scene, "--runs-dir", tmp_path / "runs"], _env(tmp_path))
        assert r.returncode == 1  # before: accepted, the latch silently ignored
        lines = r.stderr.strip().splitlines()
        assert len(lines) == 1 and "contact.knee_stop.latch" in lines[0] and "no knee" in lines[0]
    assert not (tmp_path / "runs").exists()


def test_cache_dir_symlink_is_refused_before_anything_is_created(tmp_path):
    target = tmp_path / "target"
    target.mkdir(mode=0o700)
    link = tmp_path / "cache_link"
    os.symlink(target, link)
    (tmp_path / "tmp").mkdir()
    env = _env(tmp_path, WALKERLAB_CACHE_DIR=str(link), TMPDIR=str(tmp_path / "tmp"))
    env.pop("NUMBA_CACHE_DIR", None)
    r = _run(["fixedpoint", PAPER, "--runs-dir", tmp_path / "runs"], env)
    assert r.returncode == 0, r.stderr
    assert list(target.iterdir()) == []  # before: models/ and numba/ made inside the target
    assert list((tmp_path / "tmp").iterdir()) == []  # the private fallback removed at exit


# ----------------------------------------------------------------------------- figures (Medium)
def _rigid_scene(tmp_path: Path) -> Path:
    import yaml

    d = yaml.safe_load(PAPER.read_text())
    keep = {k: v for k, v in d.items()
            if k in ("walker", "slope", "solver", "fixedpoint", "simulate", "published")}
    p = tmp_path / "rigid.yaml"
    p.write_text(yaml.safe_dump(keep))
    return p


def _edit(path: Path, dataset: str, factor: float = 3.0) -> None:
    import h5py

    with h5py.File(path, "r+") as f:
        f[dataset][...] = f[dataset][()] * factor


def _digests(folder: Path) -> dict[str, str]:
    import hashlib

    return {p.name: hashlib.sha256(p.read_bytes()).hexdigest() for p in folder.glob("*.png")}


@pytest.mark.slow
def test_figures_and_report_key_on_the_content_they_draw(tmp_path):
    scene, env = _rigid_scene(tmp_path), _env(tmp_path)
    runs = tmp_path / "runs"
    folder, figs = runs / "rigid", runs / "rigid" / "report" / "figures"
    assert _run(["report", scene, "--runs-dir", runs], env).returncode == 0
    drawn = _digests(figs)
    assert {"fig7_angles_rates.png", "fig9_limit_cycles.png"} <= set(drawn)
    _edit(folder / "simulate.h5", "samples/coordinates/leg1_angle")
    r = _run(["plot", scene, "--runs-dir", runs], env)  # before: drew the edited numbers
    assert r.returncode == 1
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and "simulate.h5" in lines[0] and "changed after" in lines[0]
    assert _digests(figs) == drawn
    # figures drawn from other content (the edited file, as the old `plot` did) are redrawn
    import shutil

    stamp = figs / ".drawn_from_trajectories"
    assert not stamp.exists()  # removed before drawing: a refused or killed plot leaves none
    stale = '{"artifacts": {"simulate": "0"}, "code": "0"}'
    stamp.write_text(stale)
    r = _run(["report", scene, "--runs-dir", runs], env)
    assert r.returncode == 0, r.stderr
    assert "trajectories figures reused" not in r.stdout  # before: "reused"
    assert "plot: trajectories, " in " ".join(r.stdout.split())
    assert stamp.read_text() != stale
    # a bifurcation.h5 edited by hand is left out of the report, and said so
    assert _run(["bifurcation", scene, "--slopes", "1:1.1:0.1", "--runs-dir", runs],
                env).returncode == 0
    r = _run(["report", scene, "--runs-dir", runs], env)
    assert "bifurcation" in (folder / "report" / "report.md").read_text().lower()
    _edit(folder / "bifurcation.h5", _first_float_dataset(folder / "bifurcation.h5"))
    r = _run(["report", scene, "--runs-dir", runs], env)
    assert r.returncode == 0, r.stderr
    out = " ".join((r.stdout + r.stderr).split())
    assert "bifurcation.h5 (changed after it was written" in out  # before: shown as is
    shutil.rmtree(runs)


def _first_float_dataset(path: Path) -> str:
    import h5py

    names: list[str] = []
    with h5py.File(path, "r") as f:
        f.visititems(lambda n, o: names.append(n) if isinstance(o, h5py.Dataset)
                     and o.dtype.kind == "f" and o.size > 1 else None)
    return names[0]


@pytest.mark.slow
def test_animate_leaves_out_a_stale_or_edited_contact_sim(tmp_path):
    import yaml

    env, runs = _env(tmp_path), tmp_path / "runs"
    d = yaml.safe_load(PAPER.read_text())
    d["simulate"]["strides"] = 2
    d["name"] = "anim"
    scene = tmp_path / "anim.yaml"
    scene.write_text(yaml.safe_dump(d))
    assert _run(["contact-sim", scene, "--runs-dir", runs], env).returncode == 0
    r = _run(["animate", scene, "--runs-dir", runs], env)
    assert r.returncode == 0 and "rigid walker only" not in r.stdout, r.stdout + r.stderr
    d["walker"]["hip_mass_kg"] = 12.0  # the scene changes; contact_sim.h5 is the old one
    scene.write_text(yaml.safe_dump(d))
    r = _run(["animate", scene, "--runs-dir", runs], env)
    assert r.returncode == 0, r.stderr  # before: drew the old contact walker beside the new
    assert "animated the rigid walker only: contact_sim.h5 was computed for another scene" \
        in " ".join(r.stdout.split())
    d["walker"]["hip_mass_kg"] = 10.0
    scene.write_text(yaml.safe_dump(d))
    _edit(runs / "anim" / "contact_sim.h5", _first_float_dataset(runs / "anim" / "contact_sim.h5"))
    r = _run(["animate", scene, "--runs-dir", runs], env)
    assert r.returncode == 0, r.stderr  # before: drew the hand-edited one
    assert "contact_sim.h5 was changed after it was written" in " ".join(r.stdout.split())


@pytest.mark.xdist_group("timing")  # wall-clock bound: not beside another of them
def test_dask_garbage_scheduler_address_is_one_line_at_once(tmp_path):
    pytest.importorskip("distributed")
    for addr in ("not an address", "tcp://host", "inproc://x"):
        t0 = time.monotonic()
        r = _run(["sweep", PAPER, "--param", "slope.angle_deg=1,1.1", "--runs-dir",
                  tmp_path / "runs", "--scheduler", addr], _env(tmp_path), timeout=90)
        assert time.monotonic() - t0 < 30  # before: one line, then a 60 s hang and a traceback
        assert r.returncode == 1
        lines = r.stderr.strip().splitlines()
        assert len(lines) == 1 and "not a Dask scheduler address" in lines[0], lines


# -------------------- every Dask wait bounded
class _NoWorkerClient:
    """A client whose scheduler answers but has no worker (the only one was killed)."""

    status = "running"
    scheduler = type("S", (), {"address": "tcp://127.0.0.1:1", "identity": None})()

    def sync(self, fn, callback_timeout=None):
        return {"workers": {}}


class _LostDataFuture:
    """A finished future whose data died with its worker: Dask computes it again, and its
    ``result()`` waits - for ever, with no worker, unless given a timeout."""

    key = "piece-1"
    status = "finished"

    def result(self, timeout=None):
        if timeout is None:
            raise AssertionError("an unbounded wait on a Dask future")
        import time as _time

        _time.sleep(min(timeout, 0.05))
        raise TimeoutError


def test_waiting_for_a_dask_result_is_bounded_and_says_why(monkeypatch):
    """A sweep's chains wait on each finished piece's result (its continuation guess):
    with the worker that held it killed, that wait never ended (170 s+, while mfpt's wait
    for finished futures ended at 60 s).  Both waits are now one: no worker for
    $WALKERLAB_DASK_WORKER_WAIT_S seconds ends it in one line."""
    pytest.importorskip("distributed")
    from walkerlab.execution import dask as D

    monkeypatch.setattr(D, "CHECK_S", 0.05)
    monkeypatch.setenv(D.WAIT_ENV, "0.3")
    with pytest.raises(D.DaskLost, match="has had no worker for 0.3 s") as info:
        D.result(_NoWorkerClient(), _LostDataFuture())
    assert "--resume" in str(info.value) and "{rerun}" not in str(info.value)
