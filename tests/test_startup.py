"""Start-up: each command imports only what it needs (issue 10, part 4).

Structural facts checked in fresh interpreters (``sys.modules`` after the command), never
timings: ``walkerlab fixedpoint`` integrates with CyRK but loads neither numba (CyRK's numba
solvers, see :mod:`walkerlab.integrate.cyrk_loader`) nor sympy nor matplotlib, and a later
plain ``import CyRK`` still gets the whole package.
"""

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from walkerlab.cli.process import BLAS_THREADS_ENV
from walkerlab.cli.process import single_threaded_blas as _single_threaded_blas

ROOT = Path(__file__).resolve().parents[1]
HEAVY = ("numba", "llvmlite", "sympy", "matplotlib", "CyRK.nb", "dask", "scipy.integrate")


def _run(code: str, *args: str) -> dict:
    """Run ``code`` in a fresh interpreter (the tests' environment and package, no
    ``OPENBLAS_NUM_THREADS``) and return the JSON it prints on its last line."""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(
        [str(ROOT)] + [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p]))
    env.pop(BLAS_THREADS_ENV, None)
    out = subprocess.run([sys.executable, "-c", code, *args], capture_output=True, text=True,
                         env=env, cwd=ROOT, timeout=300)
    assert out.returncode == 0, out.stderr[-2000:]
    return json.loads(out.stdout.strip().splitlines()[-1])


def _loaded(names, extra: str = "{}") -> str:
    """Code that prints which of ``names`` are in ``sys.modules``, merged with the dict
    expression ``extra`` (JSON)."""
    have = f"{{m: m in sys.modules for m in {tuple(names)!r}}}"
    return f"import json, sys\nprint(json.dumps({{**{have}, **{extra}}}))"


def test_cli_import_loads_no_numeric_library():
    """``walkerlab --help`` and every command's argument parsing need only typer."""
    got = _run("import walkerlab.cli\n"
               + _loaded(HEAVY + ("CyRK", "numpy", "scipy", "h5py", "pydantic")))
    assert not any(got.values()), got


@pytest.mark.usefixtures("paper_walker")  # generated model code in the shared cache
def test_fixedpoint_command_loads_cyrk_without_numba(tmp_path):
    """The whole ``walkerlab fixedpoint --force``: CyRK integrates, numba is not loaded, no
    process-pool machinery (``multiprocessing``) is loaded, and OpenBLAS started no thread
    pool (one OS thread in the process besides the threads Python started: the collector's
    start-up timer, :func:`walkerlab.cli.process.pause_collection`)."""
    code = ("import os, sys, threading\n"
            "from walkerlab.cli import app\n"
            "try:\n"
            "    app(['fixedpoint', 'configs/paper.yaml', '--force', '--runs-dir', sys.argv[1]])\n"
            "except SystemExit as exc:\n"
            "    assert not exc.code, exc.code\n"
            "tasks = '/proc/self/task'\n"
            "threads = (len(os.listdir(tasks)) - threading.active_count() + 1\n"
            "           if os.path.isdir(tasks) else 1)\n"
            + _loaded(HEAVY + ("CyRK", "multiprocessing"),
                      f"{{'blas': os.environ.get({BLAS_THREADS_ENV!r}), 'threads': threads}}"))
    # a first run fills the shared cache (the rigid module AND the compiled flow: a cold
    # cache compiles with sympy/numba, which is not what this test is about); the second is
    # the one measured
    _run(code, str(tmp_path / "warm"))
    got = _run(code, str(tmp_path / "runs"))
    assert (tmp_path / "runs" / "paper" / "fixedpoint.h5").is_file()
    assert got.pop("blas") == "1" and got.pop("threads") == 1
    assert got.pop("CyRK"), "the paper scene integrates with CyRK (solver.backend auto)"
    assert not any(got.values()), got


def test_blas_threads_default_keeps_the_users_choice(monkeypatch):
    monkeypatch.delenv(BLAS_THREADS_ENV, raising=False)
    _single_threaded_blas()
    assert os.environ[BLAS_THREADS_ENV] == "1"
    monkeypatch.setenv(BLAS_THREADS_ENV, "2")
    _single_threaded_blas()
    assert os.environ[BLAS_THREADS_ENV] == "2"


def test_cyrk_loader_then_plain_import_gets_the_whole_package():
    """pysolve_ivp without numba solves y' = -y; a later ``import CyRK`` elsewhere (the
    contact code's numba solver) completes the same module: numba solvers, version."""
    code = (
        "import json, sys, importlib.metadata\n"
        "import numpy as np\n"
        "from walkerlab.integrate.cyrk_loader import pysolve_ivp\n"
        "solve = pysolve_ivp()\n"
        "before = 'numba' in sys.modules\n"
        "r = solve(lambda t, y: -y, (0.0, 1.0), np.array([1.0]), method='DOP853', rtol=1e-12,"
        " atol=1e-12)\n"
        "err = abs(float(r.y[0, -1]) - float(np.exp(-1.0)))\n"
        "import CyRK\n"
        "from CyRK import nbsolve2_ivp\n"
        "print(json.dumps({'numba_before': before, 'err': err,\n"
        "    'same': CyRK.pysolve_ivp is solve and CyRK.cy.pysolver.pysolve_ivp is solve,\n"
        "    'numba_after': 'numba' in sys.modules, 'nb': callable(nbsolve2_ivp),\n"
        "    'version': CyRK.__version__ == importlib.metadata.version('CyRK'),\n"
        "    'again': pysolve_ivp() is solve}))")
    got = _run(code)
    assert got["numba_before"] is False
    assert got["err"] < 1e-11  # DOP853 at rtol 1e-12 on exp(-t): error ~1e-13
    assert got["same"] and got["again"] and got["version"]
    assert got["numba_after"] and got["nb"]


def test_cyrk_loader_runs_cyrk_cpu_check_before_any_compiled_module():
    """A CPU without AVX2 (CyRK's check fails) gets CyRK's ImportError, and no compiled
    CyRK module has been loaded (it would fault with an illegal instruction)."""
    code = (
        "import json, sys, types\n"
        "fake = types.ModuleType('CyRK._cpu_check')\n"
        "def check_cpu():\n"
        "    raise ImportError('This build of CyRK is compiled for AVX2 (test)')\n"
        "fake.check_cpu = check_cpu\n"
        "sys.modules['CyRK._cpu_check'] = fake\n"
        "from walkerlab.integrate.cyrk_loader import pysolve_ivp\n"
        "try:\n"
        "    pysolve_ivp()\n"
        "    msg = ''\n"
        "except ImportError as exc:\n"
        "    msg = str(exc)\n"
        "print(json.dumps({'msg': msg, 'cy': sorted(m for m in sys.modules"
        " if m.startswith('CyRK.cy')), 'pkg': 'CyRK' in sys.modules}))")
    got = _run(code)
    assert "AVX2" in got["msg"]
    assert got["cy"] == [] and got["pkg"] is False


def test_sweep_figure_loads_no_root_finder():
    """``walkerlab sweep`` draws its figure in the main process after its points ran in
    worker processes: the sweep stage and the figure module load neither scipy's root
    finders nor an integrator (issue 27: ``scipy.optimize`` alone cost that process ~0.3 s)."""
    got = _run("import walkerlab.stages.sweep, walkerlab.plotting.sweep_figures\n"
               + _loaded(("scipy.optimize", "scipy.integrate", "CyRK", "numba")))
    assert not any(got.values()), got


def test_a_command_process_ends_without_walking_its_objects_again():
    """The interpreter's shutdown collected the garbage of every object a command had
    loaded (numba's, scipy's, sympy's, matplotlib's): ~0.4 s of a warm ``walkerlab
    contact-sim``, ~0.8 s of a cold first report, measured.  A command's exit function
    (registered once, by the process settings every command applies, before the libraries
    it imports register theirs) freezes them all and turns the collector off, last: an
    exit function registered before the command's runs after it and sees that.  During
    the command's start-up (``START_UP_S``, here shortened) the collector is off: the
    libraries' long-lived objects are imported then, and every collection walked them
    again; after it they are frozen and the collector runs again."""
    code = ("import atexit, gc, json, sys, time\n"
            "atexit.register(lambda: print(json.dumps({'at_exit': [gc.isenabled(), "
            "gc.get_freeze_count() > 0]})))\n"
            "from walkerlab.cli import process\n"
            "process.START_UP_S = 0.2\n"
            "process.process_settings(); process.process_settings()\n"
            "print(json.dumps({'start_up': [gc.isenabled(), gc.get_freeze_count()]}))\n"
            "time.sleep(1.0)\n"
            "print(json.dumps({'after': [gc.isenabled(), gc.get_freeze_count() > 0]}))\n")
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         env=env, cwd=ROOT, timeout=120)
    assert out.returncode == 0, out.stderr[-2000:]
    lines = [json.loads(line) for line in out.stdout.strip().splitlines()]
    assert lines == [{"start_up": [False, 0]}, {"after": [True, True]},
                     {"at_exit": [False, True]}]
