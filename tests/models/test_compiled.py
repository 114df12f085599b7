"""The ``cyrk_compiled`` backend (numba cfuncs in CyRK's C++ solvers) against ``cyrk``.

Both backends integrate the same equations with the same DOP853 pair; the compiled one only
restarts the solver at chunk boundaries (``walkerlab.integrate._compiled``), so results agree
to a few rtol, far below the tolerances asserted here (fixed point 1e-10: the root finder's
xtol is 1e-12; multipliers 1e-8: eigenvalues of DP, whose entries are O(1) and agree to
~1e-14 in ``scripts/bench_compiled.py``).
"""

import ctypes

import numpy as np
import pytest

from tests.conftest import ROOT
from walkerlab.analysis.gait.poincare import find_fixed_point
from walkerlab.codegen.compiled import compiled_module
from walkerlab.config import load_scene
from walkerlab.integrate.rigid import simulate_steps
from walkerlab.integrate.solver import Solver
from walkerlab.models.registry import build_walker
from walkerlab.published import paper
from walkerlab.walker.plant import Plant

pytest.importorskip("numba")
pytest.importorskip("CyRK")

A = Solver("DOP853", 1e-12, 1e-12, None, "cyrk")
B = Solver("DOP853", 1e-12, 1e-12, None, "cyrk_compiled")


def test_fixed_point_and_multipliers_agree(paper_walker):
    a = find_fixed_point(paper_walker, np.array(paper.EQ11_STATE), A, fd_check=False)
    b = find_fixed_point(paper_walker, np.array(paper.EQ11_STATE), B, fd_check=False)
    assert np.max(np.abs(a.x - b.x)) < 1e-10
    assert abs(a.period_s - b.period_s) < 1e-10
    assert np.max(np.abs(a.multipliers_variational - b.multipliers_variational)) < 1e-8


def _cfunc_outputs(phase, x):
    """Outputs of the phase's compiled flow at ``x``: flow (2n,) and guard values."""
    c = phase.compiled
    fn = getattr(compiled_module(c.structure), c.name).ctypes
    n_extra, cols, offs = c.guard_columns()
    dy = np.empty(x.size + n_extra)
    y, d = np.ascontiguousarray(x, float), c.data()
    P = ctypes.POINTER(ctypes.c_double)
    fn(dy.ctypes.data_as(P), 0.0, y.ctypes.data_as(P), d.ctypes.data_as(P))
    return dy[:x.size], dy[x.size + cols] + offs


@pytest.mark.parametrize("scene", ["paper.yaml", "kneed.yaml"])
@pytest.mark.slow  # in `pytest -m slow`: the quick suite keeps to its CPU budget
def test_compiled_flow_and_guards_match_python(scene):
    """Each phase's cfunc equals its Python flow, and its guard columns the phase's guards
    (which generated guard, which offset: the mapping written in the model layer)."""
    sc = load_scene(ROOT / "configs" / scene)
    w = build_walker(Plant.from_scene(sc))
    rng = np.random.default_rng(1)
    for phase in w.phases:
        for _ in range(3):
            x = rng.uniform(-0.5, 0.5, 2 * w.n_coordinates)
            f, g = _cfunc_outputs(phase, x)
            assert np.allclose(f, phase.flow(0.0, x), rtol=1e-13, atol=1e-13)
            assert np.allclose(g, [gd.function(0.0, x) for gd in phase.guards], rtol=1e-13,
                               atol=1e-15)


def test_kneed_steps_agree():
    """Knee strike (an intra-step reset) and heel strike: same events, same states."""
    sc = load_scene(ROOT / "configs" / "kneed.yaml")
    w = build_walker(Plant.from_scene(sc))
    x0 = sc.fixedpoint.initial_guess.as_array(w.state_names())
    ta = simulate_steps(w, x0, 2, A)
    tb = simulate_steps(w, x0, 2, B)
    assert [s.termination for s in ta.segments] == [s.termination for s in tb.segments]
    for sa, sb in zip(ta.segments, tb.segments):
        assert sa.phase_times.keys() == sb.phase_times.keys()
        assert abs(sa.t_end - sb.t_end) < 1e-9
        assert np.max(np.abs(sa.x_end - sb.x_end)) < 1e-9
        ts = np.linspace(sa.t_start, sa.t_end, 9)
        assert np.max(np.abs(sa.sample(ts) - sb.sample(ts))) < 1e-9


def test_a_fall_is_found_like_cyrk(paper_walker, paper_fixed_point):
    """A start far off the gait falls within the first chunk of steps: the compiled backend
    re-runs the crossing step with dense output and must find the same fall at the same
    time. For this start (cell (0, 2) of an 80 x 80 basin of the paper walker) the re-run's
    span rounded below twice its first step, CyRK refused the step, and the cell came out
    ``stalled`` instead of ``fell_backward``."""
    from walkerlab.integrate.rigid import integrate_step
    from walkerlab.studies.basin import slice_state

    x_star = np.asarray(paper_fixed_point.x, dtype=float)
    x = slice_state(paper_walker, x_star, ("stance_angle", "stance_rate"),
                    (-0.11185039149661627, -2.046040719984428))
    a = integrate_step(paper_walker, x, Solver("DOP853", 1e-8, 1e-8, None, "cyrk"))
    b = integrate_step(paper_walker, x, Solver("DOP853", 1e-8, 1e-8, None, "cyrk_compiled"))
    assert a.termination == "fall"
    assert b.termination == "fall", b.message
    assert abs(a.t_end - b.t_end) < 1e-9
