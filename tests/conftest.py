"""Shared fixtures: the paper walker and its fixed point (computed once per session)."""

import os
import tempfile

# the per-user cache (generated model code, numba's cache): one shared by all test sessions
# (keyed by content, so safe), not the user's own
os.environ.setdefault("WALKERLAB_CACHE_DIR",
                      os.path.join(tempfile.gettempdir(), "walkerlab-test-models"))
# no heartbeat lines ("...: working (m:ss)", walkerlab.progress.Heartbeat) nor first-run
# code-generation notices (walkerlab.progress.machine_note) in the stderr the
# tests read: how many a command prints depends on the machine's speed; the heartbeat's own
# tests (tests/test_no_silence.py) set it
os.environ.setdefault("WALKERLAB_HEARTBEAT_S", "0")

from pathlib import Path

import numpy as np
import pytest

from walkerlab.analysis.gait.poincare import find_fixed_point
from walkerlab.config import load_scene
from walkerlab.integrate.solver import Solver
from walkerlab.models.registry import build_walker
from walkerlab.published import paper
from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]
TIGHT = Solver("DOP853", 1e-12, 1e-12)


@pytest.fixture(scope="session")
def paper_scene():
    return load_scene(ROOT / "configs" / "paper.yaml")


@pytest.fixture(scope="session")
def paper_walker(paper_scene):
    return build_walker(Plant.from_scene(paper_scene))


@pytest.fixture(scope="session")
def paper_fixed_point(paper_walker):
    return find_fixed_point(paper_walker, np.array(paper.EQ11_STATE), TIGHT)


@pytest.fixture
def default_signals():
    """SIGINT and SIGTERM at Python's defaults for the test, restored after it.  A command
    installs its handlers (:func:`walkerlab.cli.process.terminate_as_interrupt`) over the
    defaults only, keeping an ignored SIGINT ignored, and a test process may inherit SIGINT
    ignored: a suite started in the background (a non-interactive shell's ``&``, ``nohup``,
    a CI runner) and its pytest-xdist workers, which inherit it.  A test of the command's
    handling of SIGINT asks for this, so it tests the handler whatever the suite inherited;
    the handler it leaves does not reach the tests after it."""
    import signal

    old = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)}
    signal.signal(signal.SIGINT, signal.default_int_handler)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    try:
        yield
    finally:
        for s, h in old.items():
            signal.signal(s, signal.SIG_DFL if h is None else h)


def _slow_by_cost() -> set[str]:
    """The quick tests moved to the slow run by their measured cost
    (``tests/slow_by_cost.txt``, written by ``scripts/slow_by_cost.py`` from a timed quick
    run: the README's test command keeps its CPU budget)."""
    path = Path(__file__).with_name("slow_by_cost.txt")
    return {line.split(maxsplit=1)[1] for line in path.read_text().splitlines()
            if line.strip() and not line.startswith("#")}


@pytest.hookimpl(tryfirst=True)
def pytest_collection_modifyitems(config, items):
    """Each test file runs on one pytest-xdist worker (``--dist loadgroup``, pyproject): a
    file's module-scoped fixtures (fixed points, compiled models) are computed once, not once
    per worker, and the two workers do not compile the same model side by side.  Tests with
    an ``xdist_group`` mark of their own keep it (the group then spans files).  The long
    runs (``slow``) are spread over both workers one by one: each is long beside its file's
    fixtures."""
    by_cost = _slow_by_cost()
    for item in items:
        if item.nodeid in by_cost:  # measured cost: the slow run's (tests/slow_by_cost.txt)
            item.add_marker(pytest.mark.slow)
        if not any(item.iter_markers("xdist_group")) and not any(item.iter_markers("slow")):
            item.add_marker(pytest.mark.xdist_group(item.nodeid.split("::")[0]))
