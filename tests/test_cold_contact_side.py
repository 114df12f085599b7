"""A cold ``walkerlab contact-sim`` (the walker structure's first contact run in this user
cache): a side process compiles the compiled solvers' right-hand side while the run's own
process generates the model and compiles the other kernels; the run waits for it before its
walk and loads it (behaviour, not timing: the timing is ``walkerlab bench main-job``)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest

from walkerlab.config import load_scene
from walkerlab.execution import pending
from walkerlab.models.contact.scene import contact_setup
from walkerlab.stages import contact_sim
from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]


def test_a_pending_kernel_is_waited_for_once_and_only_for_itself():
    """The hand-off is an object the caller passes down, no module-level registry."""
    seen: list[str] = []
    a = pending.CompiledElsewhere("mod_a", "build_cyrk", lambda: seen.append("a"))
    a.before_first_use("mod_a", "other_kernel")
    a.before_first_use("mod_b", "build_cyrk")
    assert seen == [] and a.expected
    a.before_first_use("mod_a", "build_cyrk")
    a.before_first_use("mod_a", "build_cyrk")  # once
    assert seen == ["a"] and not a.expected
    assert not [k for k, v in vars(pending).items()
                if isinstance(v, (dict, list, set)) and not k.startswith("__")]


class _FakeSide:
    """Records what the stage asks of its side process (no process)."""

    made: list[_FakeSide] = []

    def __init__(self, enabled=True, idle_only=False):
        self.idle_only, self.submitted, self.closed = idle_only, [], []
        _FakeSide.made.append(self)

    def submit(self, fn, *args):
        from concurrent.futures import Future

        self.submitted.append((fn, args))
        self.fut = Future()
        self.fut.set_result(True)
        return self.fut

    @staticmethod
    def wait(fut):
        return bool(fut.result())

    def close(self, cancel=False):
        self.closed.append(cancel)


@pytest.fixture()
def fake_side(monkeypatch):
    from walkerlab.execution import side

    _FakeSide.made.clear()
    monkeypatch.setattr(side, "SideWorker", _FakeSide)
    return _FakeSide


@pytest.mark.parametrize("cached", [True, None, False])  # None: no user cache folder
def test_the_right_hand_side_is_compiled_beside_only_on_a_cold_run(cached, fake_side,
                                                                   monkeypatch):
    from walkerlab.models.contact import generated

    sc = load_scene(ROOT / "configs" / "paper.yaml")
    setup = contact_setup(sc, plant=Plant.from_scene(sc))
    monkeypatch.setattr(generated, "contact_module_state", lambda s, held=False: ("mod_x", cached))
    used: list[bool] = []
    with contact_sim._rhs_beside(setup, None) as run_setup:
        # the walk's first use of the compiled right-hand side (the hand-off it was given)
        ready = run_setup.rhs_ready
        used.append(ready is not None)
        if ready is not None:
            ready.before_first_use("mod_x", "build_cyrk")
            assert not ready.expected
            assert run_setup.build(np.array([0.2, -0.2, -1.0, -1.0]), 2)[0].rhs_ready is ready
    assert setup.rhs_ready is None  # the caller's setup untouched
    if cached is not False:  # warm, or nothing to share through: no side process
        assert fake_side.made == [] and used == [False]
        return
    (side,) = fake_side.made
    assert side.idle_only  # never on a busy machine
    assert side.submitted == [(contact_sim.warm_rhs, (setup,))]
    assert used == [True] and side.closed == [False]


def test_a_run_whose_kernel_a_caller_compiles_beside_starts_nothing(fake_side, monkeypatch):
    """In ``walkerlab report`` the report's own side process compiles the right-hand side
    (:func:`walkerlab.stages.report_dag._warm_up`): the run starts no second one and its
    walk waits for the report's."""
    from walkerlab.models.contact import generated

    sc = load_scene(ROOT / "configs" / "paper.yaml")
    setup = contact_setup(sc, plant=Plant.from_scene(sc))
    monkeypatch.setattr(generated, "contact_module_state", lambda s, held=False: ("mod_r", False))
    seen: list[str] = []
    ready = pending.CompiledElsewhere("mod_r", "build_cyrk", lambda: seen.append("report's"))
    with contact_sim._rhs_beside(setup, ready) as run_setup:
        assert run_setup.rhs_ready is ready
        run_setup.rhs_ready.before_first_use("mod_r", "build_cyrk")
    assert fake_side.made == [] and seen == ["report's"]


def test_a_side_process_that_was_never_needed_is_stopped(fake_side, monkeypatch):
    """A run that ends before its walk (or an up-to-date artifact) does not wait for the
    side process's compile: it is cancelled."""
    from concurrent.futures import Future

    from walkerlab.models.contact import generated

    sc = load_scene(ROOT / "configs" / "paper.yaml")
    setup = contact_setup(sc, plant=Plant.from_scene(sc))
    monkeypatch.setattr(generated, "contact_module_state", lambda s, held=False: ("mod_y", False))
    monkeypatch.setattr(_FakeSide, "submit", lambda self, fn, *a: Future())  # still running
    with contact_sim._rhs_beside(setup, None):
        pass
    assert fake_side.made[0].closed == [True]
    with pytest.raises(KeyError), contact_sim._rhs_beside(setup, None):
        raise KeyError("an error in the run")
    assert fake_side.made[1].closed == [True]


def test_a_compiled_walk_is_what_the_side_process_serves():
    scene = load_scene(ROOT / "configs" / "paper.yaml")
    assert contact_sim._compiled_walk(contact_setup(scene,
                                                    plant=Plant.from_scene(scene)))  # cyrk_bdf
    odeint = scene.model_copy(update={"contact_solver": scene.contact_solver.model_copy(
        update={"method": "odeint"})})
    assert not contact_sim._compiled_walk(contact_setup(odeint, plant=Plant.from_scene(odeint)))


_COLD = r"""
import json, sys, time
from pathlib import Path
from walkerlab.execution import pending

waits = []
register = pending.CompiledElsewhere.__init__
numba_dir = Path(sys.argv[2]) / "numba"

def rhs_files():
    return sorted((str(p), p.stat().st_mtime_ns) for p in numba_dir.rglob("*rhs*")
                  if p.is_file())

def spy(self, name, kernel, wait):
    def timed():
        ok = wait()
        waits.append([kernel, bool(ok), rhs_files()])
    register(self, name, kernel, timed)

pending.CompiledElsewhere.__init__ = spy
if __name__ == "__main__":
    from walkerlab.cli import app
    try:
        app(["-q", "contact-sim", "configs/paper.yaml", "--force", "--runs-dir", sys.argv[1]])
    except SystemExit as exc:
        assert not exc.code, exc.code
    print(json.dumps({"waits": waits, "after": rhs_files()}))
"""


@pytest.mark.slow  # a cold compile of the contact kernels (~5 s), then a warm run
def test_a_cold_contact_run_loads_the_right_hand_side_the_side_process_compiled(tmp_path):
    """In a fresh user cache: the run waits for the side process once, the side process
    has compiled the right-hand side by then (its cache files exist and the run's process
    rewrites none of them: it loaded them), and the artifact's numbers equal those of a
    warm run of the same cache."""
    cache, runs = tmp_path / "cache", tmp_path / "runs"
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    env.update(WALKERLAB_CACHE_DIR=str(cache), PYTHONPATH=str(ROOT))
    subprocess.run([sys.executable, "-m", "walkerlab.cli", "-q", "fixedpoint",
                    "configs/paper.yaml", "--runs-dir", str(runs)], env=env, check=True,
                   cwd=ROOT, stdout=subprocess.DEVNULL)
    script = tmp_path / "cold.py"
    script.write_text(_COLD)
    r = subprocess.run([sys.executable, str(script), str(runs), str(cache)], env=env,
                       cwd=ROOT, capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr[-2000:]
    got = json.loads(r.stdout.strip().splitlines()[-1])
    if not got["waits"]:
        pytest.skip("no side process here (one core, or a busy machine)")
    (kernel, ok, files), = got["waits"]
    assert kernel == "build_cyrk" and ok
    assert any(f.endswith(".nbi") and "rhs_c" in f for f, _ in files)
    assert got["after"] == files  # loaded, not compiled again here
    path = runs / "paper" / "contact_sim.h5"

    def numbers():
        with h5py.File(path, "r") as f:
            out = {}
            f.visititems(lambda n, o: out.__setitem__(n, o[()]) if isinstance(
                o, h5py.Dataset) and o.dtype.kind == "f" and "time" not in n else None)
            return out

    cold = numbers()
    subprocess.run([sys.executable, "-m", "walkerlab.cli", "-q", "contact-sim",
                    "configs/paper.yaml", "--force", "--runs-dir", str(runs)], env=env,
                   check=True, cwd=ROOT, stdout=subprocess.DEVNULL)
    warm = numbers()
    assert cold.keys() == warm.keys() and len(cold) > 10
    for k in cold:
        np.testing.assert_array_equal(cold[k], warm[k], err_msg=k)


@pytest.mark.parametrize("held", [False, True])
def test_the_side_process_compiles_the_module_the_run_will_load(monkeypatch, held):
    """The side process compiles the right-hand side of the generated module the run loads:
    with ``contact.hold_heading`` the held floating view's (its own module), not the
    free-heading one's (stand-ins record which module is built and compiled)."""
    from types import SimpleNamespace

    from walkerlab.analysis.contact import warm
    from walkerlab.models.contact import generated

    built, compiled = [], []
    monkeypatch.setattr(generated, "contact_module",
                        lambda s, held=False: built.append((s, held)) or f"mod_{held}")
    monkeypatch.setattr(warm, "compile_rhs", compiled.append)
    setup = SimpleNamespace(walker=SimpleNamespace(structure="st"),
                            law=SimpleNamespace(hold_heading=held))
    assert warm.compile_rhs_kernels(setup)
    assert built == [("st", held)] and compiled == [f"mod_{held}"]
