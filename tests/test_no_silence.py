"""No command is silent for long: a heartbeat line names the work under way when nothing
was shown for :data:`walkerlab.progress.HEARTBEAT_S`, a new walker structure's code
generation is said before it starts, and the heartbeat of a command ends with it."""

from __future__ import annotations

import io
import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

from walkerlab import progress

ROOT = Path(__file__).resolve().parents[1]


def _wait_for(pred, limit_s: float = 20.0) -> bool:
    """``pred()`` true within ``limit_s`` (polled; a loaded machine may delay a thread)."""
    end = time.monotonic() + limit_s
    while time.monotonic() < end:
        if pred():
            return True
        time.sleep(0.05)
    return pred()


def test_a_quiet_task_gets_a_heartbeat_line_naming_it_and_none_after_the_command():
    out = io.StringIO()
    sink = progress.LineSink(stream=out, label="walkerlab fixedpoint")
    assert sink.heartbeat is None  # the suite's WALKERLAB_HEARTBEAT_S=0 (conftest)
    sink.heartbeat = progress.Heartbeat(sink._print, sink._under_way, every_s=0.2)
    with progress.use(sink):
        with progress.task("deriving the equations of this walker structure"):
            assert _wait_for(lambda: "deriving the equations of this walker structure: "
                                     "working (" in out.getvalue())
        n = len(out.getvalue())
        # no task open: the command itself is named
        assert _wait_for(lambda: "walkerlab fixedpoint: working (" in out.getvalue()[n:])
    sink.heartbeat.stop()
    time.sleep(0.3)  # a beat under way ends
    n = len(out.getvalue())
    time.sleep(0.8)
    assert len(out.getvalue()) == n  # stopped: silent after the command


def test_a_line_shown_resets_the_heartbeat():
    out = io.StringIO()
    sink = progress.LineSink(stream=out, label="walkerlab sweep")
    sink.heartbeat = progress.Heartbeat(sink._print, sink._under_way, every_s=5.0)
    with progress.use(sink):
        for _ in range(4):  # a notice every 0.1 s: never 5 s of silence
            progress.note("gait search: trying the planar twin")
            time.sleep(0.1)
    sink.heartbeat.stop()
    assert "working" not in out.getvalue()


def test_the_cli_sink_has_a_heartbeat_unless_quiet(monkeypatch):
    class Tty(io.StringIO):
        def isatty(self):
            return False

    monkeypatch.delenv(progress.HEARTBEAT_ENV, raising=False)  # the default: 8 s
    assert progress.heartbeat_s() == progress.HEARTBEAT_S <= 10
    monkeypatch.setenv(progress.HEARTBEAT_ENV, "0")  # off
    assert progress.sink_for_terminal(False, Tty(), label="walkerlab report").heartbeat is None
    monkeypatch.delenv(progress.HEARTBEAT_ENV)
    loud = progress.sink_for_terminal(False, Tty(), label="walkerlab report")
    quiet = progress.sink_for_terminal(True, Tty(), label="walkerlab report")
    try:
        assert isinstance(loud, progress.LineSink) and loud.heartbeat is not None
        assert not hasattr(quiet, "heartbeat")
    finally:
        loud.heartbeat.stop()


@pytest.mark.slow
def test_a_new_structure_says_its_code_generation_before_it_starts(tmp_path):
    """An empty code cache: the first run of the paper walker says, on stderr, that it
    derives this structure's equations for the first time on this machine (and where the
    cost is documented), and the heartbeat names the derivation while it runs; the second
    run, from the cache, says nothing of it and finds the
    same gait."""
    # a heartbeat of 0.05 s (looked at every 12.5 ms): the paper walker's cold derivation
    # (sympy's import and first expressions included: 0.3 s and more) now takes under the 1 s
    # this test had, so whether a line came depended on the machine's speed
    env = {**os.environ, "WALKERLAB_CACHE_DIR": str(tmp_path / "cache"),
           "NUMBA_CACHE_DIR": str(tmp_path / "numba"), "WALKERLAB_HEARTBEAT_S": "0.05"}
    cmd = [sys.executable, "-m", "walkerlab.cli", "fixedpoint", str(ROOT / "configs/paper.yaml"),
           "--runs-dir", str(tmp_path / "runs")]
    first = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=1200)
    assert first.returncode == 0, first.stderr
    assert "deriving the equations of this walker structure: first time on this machine" \
        in first.stderr
    assert "docs/user_guide/first_run.md" in first.stderr
    # never silent: the derivation (seconds) is seen working, a line a second here
    assert "deriving the equations of this walker structure: working (" in first.stderr
    (tmp_path / "runs" / "paper" / "fixedpoint.h5").unlink()
    second = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=1200)
    assert second.returncode == 0, second.stderr
    assert "first time on this machine" not in second.stderr
    gait = [ln for ln in first.stdout.splitlines() if "step period" in ln]
    assert gait and gait == [ln for ln in second.stdout.splitlines() if "step period" in ln]
