"""The plain-library yardsticks of the main-job benchmark find what walkerlab finds: the
bare scipy script the paper walker's fixed point, and the Monte Carlo walks on CyRK's
DOP853 (``scripts/bench_mc_cyrk.py``) the same walks and falls as the minimal numba loop
and the library (issue 51, items 16 and 17)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from tests.scripts_loader import load_file
from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.slow
def test_bare_script_finds_the_paper_walkers_fixed_point(paper_scene):
    """The bare numpy + scipy script (no walkerlab import) prints the fixed point walkerlab
    finds for configs/paper.yaml; both stop at 1e-12, so they agree to ~1e-10 rad."""
    from walkerlab.analysis.gait.scene import solve_scene

    out = subprocess.run([sys.executable, str(ROOT / "walkerlab" / "bench" /
                                              "bare_fixedpoint.py")],
                         capture_output=True, text=True, timeout=120, cwd="/")
    assert out.returncode == 0, out.stderr[-2000:]
    words = out.stdout.split()
    bare = np.array([float(w) for w in words[2:6]])
    _, search = solve_scene(paper_scene, fd_check=False, plant=Plant.from_scene(paper_scene))
    np.testing.assert_allclose(bare, search.gait.result.x, rtol=0, atol=1e-9)
    assert "walkerlab" not in out.stderr


@pytest.mark.slow
def test_cyrk_monte_carlo_walks_as_the_minimal_loop():
    """CyRK's DOP853 driven from a numba loop makes the same heel strikes and falls as the
    minimal loop and the library on the same slopes (what makes its timing comparable; at
    the benchmark's sigma 0.002 rad none of 500 walks of 100 steps differed; at 0.004 rad a
    walk at the edge of a fall may go either way on another integrator)."""
    mod = load_file("scripts/bench_mc_cyrk.py")
    out = mod.measure(str(ROOT / "configs" / "paper.yaml"), walks=20, steps=10, sigma=0.002,
                      repeats=1)
    assert out["walks_differing_from_minimal"] == {"library": 0, "cyrk": 0, "minimal": 0}
    assert len(set(out["heel_strikes"].values())) == 1
    assert out["heel_strikes"]["minimal"] > 20  # the walks took steps


@pytest.mark.slow
def test_minimal_casadi_script_finds_compass_optimal_gait():
    """The minimal CasADi + IPOPT script (no walkerlab import) collocates the least-effort
    step of configs/compass_optimal.yaml: the passive gait (u = 0), as walkerlab optimize
    finds; its start and step period equal the rigid fixed point to Hermite-Simpson's error
    on 40 intervals (measured 5e-8; bound 1e-6)."""
    import walkerlab as wl

    out = subprocess.run([sys.executable, str(ROOT / "walkerlab" / "bench" /
                                              "minimal_casadi.py")],
                         capture_output=True, text=True, timeout=120, cwd="/")
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stdout.startswith("Solve_Succeeded"), out.stdout
    words = out.stdout.split()
    period = float(words[words.index("period") + 1])
    objective = float(words[words.index("objective") + 1])
    start = np.array([float(w) for w in words[words.index("start") + 1:][:4]])
    gait = wl.Walker.from_scene(ROOT / "configs" / "compass_optimal.yaml").fixed_point()
    assert objective < 1e-12  # int u^2 dt [N^2 m^2 s]: zero torque
    assert abs(period - gait.step_period) < 1e-6
    np.testing.assert_allclose(start, gait.x, rtol=0, atol=1e-6)


@pytest.mark.slow
def test_minimal_casadi_hzd_script_finds_walkerlabs_design():
    """The minimal CasADi script of the three-link design (the book's closed forms, no
    walkerlab import) reaches walkerlab's optimum from the same start: the same objective,
    delta^2 at its bound and period (both IPOPT at tol 1e-10 on the same formulation:
    agreement to ~1e-8 relative; bound 1e-6), so the benchmark's times compare the same
    work."""
    from walkerlab.bench.hzd import bench_design

    r = bench_design(repeats=1)
    w, s = r["walkerlab"], r["script"]
    assert w["status"] == s["status"] == "Solve_Succeeded"
    assert abs(w["objective"] / s["objective"] - 1) < 1e-6
    assert abs(w["period_s"] - s["period_s"]) < 1e-6
    assert abs(w["delta2"] - 0.6) < 1e-8 and abs(s["delta2"] - 0.6) < 1e-8


def test_the_bench_commands_help_names_every_benchmark():
    """``walkerlab bench --help`` lists each benchmark the command runs (its help is a
    literal kept apart from :data:`walkerlab.cli.bench.BENCHMARKS`, which the CLI does not
    import at start-up)."""
    from typer.testing import CliRunner

    from walkerlab.cli import app
    from walkerlab.cli.bench import BENCHMARKS

    out = CliRunner().invoke(app, ["bench", "--help"], terminal_width=400).output
    missing = [b for b in BENCHMARKS if b not in out.replace("\n", " ")]
    assert not missing, missing


@pytest.mark.slow
def test_the_monte_carlo_benchmarks_yardstick_caches_its_numba_code_in_the_user_cache(
        tmp_path):
    """The main-job benchmark's Monte Carlo child loads the numba yardstick by its file; its
    ``cache=True`` functions go to walkerlab's private user cache, never beside the source
    (an installed package's folder: nothing is written outside the runs folder and the user
    cache).  A copy of the yardstick in a fresh folder (numba keys its cache by the source's
    path) is run for 2 walks of 3 steps; the copy's folder holds no numba cache file after,
    the user cache's numba folder does (the copy's entries)."""
    import shutil

    from walkerlab.bench.main_job import MC_CHILD, child
    from walkerlab.bench.process_env import TREE
    from walkerlab.usercache import private_dir

    src = tmp_path / "yardstick"
    src.mkdir()
    copy = src / "monte_carlo_yardstick.py"
    shutil.copy(ROOT / "walkerlab" / "bench" / "monte_carlo_yardstick.py", copy)
    out = child(TREE, MC_CHILD, str(ROOT / "configs" / "paper.yaml"), 0.002, 2, 3, 1, copy)
    assert out["steps"] > 0
    beside = [p.name for p in src.rglob("*") if p.suffix in (".nbi", ".nbc")]
    assert beside == []
    cache = private_dir("numba")
    assert cache is not None
    assert any(p.name.startswith("monte_carlo_yardstick") for p in cache.rglob("*.nbi"))
