"""The report's side process: the contact kernels compiled beside the rigid stages, the
figures shared between two processes (behaviour, not timing)."""

import math
import multiprocessing
import os
import subprocess
import sys
from pathlib import Path

import pytest

from tests.test_stages import _fake_trajectory, ideal_scene  # noqa: F401 (fixture)
from walkerlab.config import load_scene
from walkerlab.execution.side import SideWorker
from walkerlab.io.trajectory import write_samples
from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]


def test_side_share_does_each_item_once_in_order():
    """Items are shared (the side process from the back, this one from the front), each
    done once, results in the items' order; closing leaves no process behind."""
    here: list[int] = []
    with SideWorker() as side:
        out = side.share(list(range(8)), lambda k: here.append(k) or 2 ** k, pow, 2)
    assert out == [2 ** k for k in range(8)]
    assert here == sorted(here)  # this process goes from the front
    assert multiprocessing.active_children() == []


def test_without_a_side_process_everything_is_done_here():
    side = SideWorker(enabled=False)
    assert side.submit(pow, 2, 3) is None and not side.started
    assert side.wait(None) is False
    assert side.share([1, 2], lambda k: -k, pow, 2) == [-1, -2]


def test_side_errors_reach_this_process():
    with SideWorker() as side:
        if not side.enabled:
            pytest.skip("one core: no side process")
        # the side process's error is raised here; a failed warm-up only means "not done"
        with pytest.raises(ValueError):
            side.share([-1.0, -4.0], lambda x: 0.0 if x == -4.0 else math.sqrt(x),
                       math.sqrt)
        assert side.wait(side.submit(math.sqrt, -1.0)) is False
        assert side.wait(side.submit(math.sqrt, 4.0)) is True
    assert multiprocessing.active_children() == []


def test_cancel_stops_the_task_under_way():
    """After an error or Ctrl-C here, the side process's task is stopped, not waited for."""
    import time

    with SideWorker() as side:
        fut = side.submit(time.sleep, 20.0)
        if fut is None:
            pytest.skip("one core: no side process")
        time.sleep(0.5)  # let it start (either way it must not run to its end)
        side.close(cancel=True)
    assert fut.cancelled() or fut.exception() is not None
    assert multiprocessing.active_children() == []


def test_an_interrupted_numba_cache_write_leaves_no_temporary_file(tmp_path):
    from walkerlab.usercache import guard_numba_cache

    guard_numba_cache()
    from numba.core import caching

    target = tmp_path / "kernel.nbi"
    with pytest.raises(KeyboardInterrupt):
        with caching.IndexDataCacheFile._open_for_write(None, str(target)) as f:
            f.write(b"half")
            raise KeyboardInterrupt
    assert list(tmp_path.iterdir()) == []
    with caching.IndexDataCacheFile._open_for_write(None, str(target)) as f:
        f.write(b"whole")
    assert [p.name for p in tmp_path.iterdir()] == ["kernel.nbi"]


class _Recorder:
    """A side worker that records what it is given and runs nothing."""

    enabled = True

    def __init__(self):
        self.submitted = []

    def submit(self, fn, *args):
        self.submitted.append(fn)
        return object()


def test_warm_up_only_for_a_contact_run_the_report_computes(ideal_scene,  # noqa: F811
                                                            tmp_path, monkeypatch):
    from walkerlab.execution import pending
    from walkerlab.io.runpaths import stage_artifact
    from walkerlab.models.contact import generated
    from walkerlab.stages import contact_sim
    from walkerlab.stages.pipeline import report_plan
    from walkerlab.stages.report_dag import _warm_up

    side = _Recorder()  # a scene without a contact section: nothing to compile
    assert _warm_up(ideal_scene, tmp_path, True, report_plan(ideal_scene), side) is None
    assert side.submitted == []
    paper = load_scene(ROOT / "configs" / "paper.yaml")
    # the walker's generated module in the user cache: the side process loads every kernel
    # (cheap) and the run waits for it
    monkeypatch.setattr(generated, "contact_module_state", lambda st, held=False: ("m_warm", True))
    fut, module = _warm_up(paper, tmp_path, False, report_plan(paper), side)
    assert side.submitted[0] is contact_sim.warm_up and module is None
    # its first contact run: the side process compiles the right-hand side only, and the
    # run (not waiting for it first) waits for it just before its walk
    monkeypatch.setattr(generated, "contact_module_state", lambda st, held=False: ("m_cold", False))
    side = _Recorder()
    fut, module = _warm_up(paper, tmp_path, False, report_plan(paper), side)
    assert side.submitted[0] is contact_sim.warm_rhs
    # the hand-off the report passes to the contact-sim stage (no module-level registry)
    assert isinstance(module, pending.CompiledElsewhere) and module.expected
    assert (module.module_name, module.kernel) == ("m_cold", "build_cyrk")
    side = _Recorder()
    art = stage_artifact(paper, tmp_path, "contact-sim")  # reused unless forced
    art.parent.mkdir(parents=True, exist_ok=True)
    art.write_bytes(b"")
    side = _Recorder()
    assert _warm_up(paper, tmp_path, False, report_plan(paper), side) is None
    assert side.submitted == []
    assert _warm_up(paper, tmp_path, True, report_plan(paper), side) is not None


def test_warm_up_without_numba_compiles_nothing(monkeypatch):
    import importlib.util

    from walkerlab.analysis.contact.warm import compile_run_kernels
    from walkerlab.models.contact.scene import contact_setup

    find = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec",
                        lambda name, *a: None if name == "numba" else find(name, *a))
    sc = load_scene(ROOT / "configs" / "paper.yaml")
    setup = contact_setup(sc, plant=Plant.from_scene(sc))
    assert compile_run_kernels(setup) is False


def test_figures_drawn_ahead_and_shared_make_the_whole_group(ideal_scene, tmp_path):  # noqa: F811
    """The ideal figures drawn ahead plus the rest shared with the side process: every
    figure of the group once, in the group's order, its stamp written; a figure drawn in
    the side process is byte for byte (PNG) the one drawn here."""
    import walkerlab.io.artifacts as A
    from walkerlab.plotting.scene_figures import scene_figure_plan
    from walkerlab.stages import plot

    A.write_artifact(tmp_path / "ideal_only" / "simulate.h5", "simulate", ideal_scene, "x",
                     lambda f: write_samples(f, _fake_trajectory()), 0.0)
    ahead = plot.draw_ideal_ahead(ideal_scene, tmp_path, False)
    assert [p.name for p in ahead] == ["fig2_stick_ideal.png", "fig2_stick_ideal.svg"]
    with SideWorker() as side:
        figs = plot.run(ideal_scene, tmp_path, side=side, ahead=ahead)
        sim = plot.load_simulate(tmp_path / "ideal_only" / "simulate.h5")
        (tmp_path / "there").mkdir()
        there = side.submit(plot.draw_figure, ideal_scene, (sim, None, None, None),
                            tmp_path / "there", "fig2_stick_ideal")
        there = there.result() if there is not None else plot.draw_figure(
            ideal_scene, (sim, None, None, None), tmp_path / "there", "fig2_stick_ideal")
    stems = [s for s, _ in scene_figure_plan(ideal_scene, sim, None, None, None)]
    assert [p.name for p in figs] == [f"{s}.{e}" for s in stems for e in ("png", "svg")]
    assert there[0].read_bytes() == ahead[0].read_bytes()
    # the group is drawn and stamped: nothing is drawn ahead of a group that may be reused
    assert plot.draw_ideal_ahead(ideal_scene, tmp_path, False) == []


@pytest.mark.slow  # ~10-15 s: a cold compile of the contact kernels, then a contact run
def test_a_contact_run_after_the_warm_up_compiles_nothing(tmp_path):
    """The warm-up (another process, empty user cache) leaves numba's cache complete for
    the scene's contact run: the run's process compiles nothing (no cache file written)."""
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    env.update(WALKERLAB_CACHE_DIR=str(tmp_path / "cache"), PYTHONPATH=str(ROOT))
    scene = str(ROOT / "configs" / "paper.yaml")
    code = ("import sys; from walkerlab.config import load_scene; "
            "from walkerlab.stages.contact_sim import warm_up; "
            "assert warm_up(load_scene(sys.argv[1]))")
    subprocess.run([sys.executable, "-c", code, scene], env=env, check=True, cwd=ROOT)
    numba_dir = tmp_path / "cache" / "numba"

    def files():
        return {(p, p.stat().st_size, p.stat().st_mtime_ns) for p in numba_dir.rglob("*")
                if p.is_file()}

    before = files()
    assert any(p.suffix == ".nbc" for p, *_ in before)
    runs = str(tmp_path / "runs")
    subprocess.run([sys.executable, "-m", "walkerlab.cli", "-q", "fixedpoint", scene,
                    "--runs-dir", runs], env=env, check=True, cwd=ROOT,
                   stdout=subprocess.DEVNULL)
    subprocess.run([sys.executable, "-m", "walkerlab.cli", "-q", "contact-sim", scene,
                    "--runs-dir", runs], env=env, check=True, cwd=ROOT,
                   stdout=subprocess.DEVNULL)
    assert files() == before


def test_no_side_process_on_a_busy_machine(monkeypatch):
    """``idle_only``: a load average of at least the number of cores starts nothing (the
    side process would only take turns with this one)."""
    from walkerlab.execution import side as S

    monkeypatch.setattr(S.os, "getloadavg", lambda: (2.5, 2.0, 2.0))
    monkeypatch.setattr(S, "_running_now", lambda: 3)  # this process and two others
    monkeypatch.setattr(S, "_cores", lambda: 2)
    busy = SideWorker(idle_only=True)
    assert not busy.enabled and busy.submit(pow, 2, 3) is None
    monkeypatch.setattr(S, "_running_now", lambda: 2)  # one other task: no core to spare
    assert not SideWorker(idle_only=True).enabled
    monkeypatch.setattr(S, "_running_now", lambda: None)  # no instant count: the average
    assert not SideWorker(idle_only=True).enabled
    # a burst that has ended: the minute's average still lags it, only this process runs
    monkeypatch.setattr(S, "_running_now", lambda: 1)
    assert SideWorker(idle_only=True).enabled
    monkeypatch.setattr(S.os, "getloadavg", lambda: (1.2, 1.0, 1.0))
    monkeypatch.setattr(S, "_running_now", lambda: 3)
    assert SideWorker(idle_only=True).enabled  # below the cores on average
    assert SideWorker().enabled  # without idle_only, the load is not asked


def test_the_tasks_running_now_include_this_one():
    from walkerlab.execution import side as S

    now = S._running_now()
    assert now is None or now >= 1


SIDE_CPU_CHILD = r"""
import resource, time
from walkerlab.execution.side import SideWorker
BURN = "import time\nt = time.process_time()\nwhile time.process_time() - t < 0.3: pass"
with SideWorker() as side:
    fut = side.submit(exec, BURN)
    done = fut is not None and fut.result() is None
    there = side.submit(time.process_time).result() if done else 0.0
r = resource.getrusage(resource.RUSAGE_SELF)
print(r.ru_utime + r.ru_stime + there)
"""


@pytest.mark.slow  # in `pytest -m slow`: the quick suite keeps to its CPU budget
def test_the_main_job_benchmark_counts_the_side_process_cpu():
    """A command's side process ends after the command's own process has been waited for:
    the benchmark still counts its CPU (an accounting identity, not a timing)."""
    from walkerlab.bench.process_env import code_env, timed_run

    _, cpu, out = timed_run([sys.executable, "-c", SIDE_CPU_CHILD], code_env(ROOT), ROOT)
    assert cpu >= 0.95 * float(out.strip().splitlines()[-1])
