"""A flat foot's compiled flows (``cyrk_compiled``): each mode's numba cfunc gives the
generated Python flow and, as extra outputs, the values of the phase's Python guards (state
guards and ground reactions); a walk and the fixed point on them agree with the Python path
to the integrator's tolerance, through the same sequence of modes."""

from __future__ import annotations

import ctypes

import numpy as np
import pytest

from walkerlab.analysis.gait.poincare import find_fixed_point
from walkerlab.codegen.compiled import compiled_module
from walkerlab.config import load_scene
from walkerlab.integrate.python_step import needs_python_path
from walkerlab.integrate.rigid import simulate_steps
from walkerlab.integrate.solver import Solver
from walkerlab.models.registry import build_walker
from walkerlab.walker.plant import Plant

pytest.importorskip("numba")
pytest.importorskip("CyRK")


@pytest.fixture(scope="module")
def scene():
    return load_scene("configs/flat_feet.yaml")


@pytest.fixture(scope="module")
def walker(scene):
    return build_walker(Plant.from_scene(scene))


def _call(cfunc, x: np.ndarray, data: np.ndarray, m: int) -> np.ndarray:
    dy = np.zeros(m)
    ptr = ctypes.POINTER(ctypes.c_double)
    cfunc.ctypes(dy.ctypes.data_as(ptr), 0.0, np.ascontiguousarray(x).ctypes.data_as(ptr),
                 data.ctypes.data_as(ptr))
    return dy


def _single_support(walker):
    """The phases with a compiled flow: all but the double support's, whose closed chain is
    a Python flow (a numeric linear solve in generated code, run by CyRK's own loop on
    cyrk_compiled, its guards called in Python); checked to have none."""
    ds = [ph for ph in walker.phases if ph.name.startswith("double_support:")]
    assert len(ds) == 2 and all(ph.compiled is None for ph in ds)
    return [ph for ph in walker.phases if ph not in ds]


@pytest.mark.slow  # in `pytest -m slow`: the quick suite keeps to its CPU budget
def test_every_phase_is_compiled_with_its_guards_as_outputs(walker):
    """The cfunc of each phase at states around the gait: the flow to round-off of the
    Python flow (the same generated lines; 1e-12 relative allows a libm difference), each
    guard's output to round-off of the Python guard (the ground reactions are ~100 N)."""
    rng = np.random.default_rng(3)
    base = np.array([-0.3, 0.25, -0.05, -1.3, -1.2, -5.0])
    for ph in _single_support(walker):
        cf = ph.compiled
        assert cf is not None, ph.name
        mod = compiled_module(cf.structure)
        n_extra, cols, offs = cf.guard_columns()
        for _ in range(5):
            x = base + rng.normal(0.0, [0.05, 0.05, 0.02, 0.2, 0.2, 2.0])
            out = _call(getattr(mod, cf.name), x, cf.data(), 6 + n_extra)
            want = np.asarray(ph.flow(0.0, x))
            np.testing.assert_allclose(out[:6], want, rtol=1e-12, atol=1e-12 * np.abs(want).max())
            for g, c, o in zip(ph.guards, cols, offs):
                py = float(g.function(0.0, x))
                assert abs(out[6 + c] + o - py) <= 1e-12 * max(1.0, abs(py)), (ph.name, g.name)


# the quick suite's CPU budget (README): a longer run, in `pytest -m slow`
@pytest.mark.slow
def test_the_variational_cfunc_is_the_flow_jacobian_times_phi(walker):
    rng = np.random.default_rng(4)
    x = np.array([-0.3, 0.25, -0.05, -1.3, -1.2, -5.0])
    phi = rng.normal(size=(6, 6))
    for ph in walker.phases[:3]:
        cf = ph.compiled
        mod = compiled_module(cf.structure)
        n_extra = cf.guard_columns()[0]
        out = _call(getattr(mod, f"{cf.name}_variational"), np.concatenate([x, phi.ravel()]),
                    cf.data(), 42 + n_extra)
        want = np.asarray(ph.jacobian(0.0, x)) @ phi
        np.testing.assert_allclose(out[6:42].reshape(6, 6), want, rtol=1e-11,
                                   atol=1e-11 * np.abs(want).max())


@pytest.mark.slow  # in `pytest -m slow`: the quick suite keeps to its CPU budget
def test_a_walk_and_the_fixed_point_on_compiled_flows_match_the_python_path(scene, walker):
    """Same modes in the same order; the steps' end states and times, and the fixed point,
    within the integrator's tolerance (rtol = atol = 1e-12 per step: the two paths locate
    the guards on different step sequences, so they agree to ~1e-11, not bit for bit)."""
    guess = scene.fixedpoint.initial_guess.as_array(walker.state_names())
    runs = {}
    for backend in ("cyrk", "cyrk_compiled"):
        sv = Solver("DOP853", 1e-12, 1e-12, None, backend)
        fp = find_fixed_point(walker, guess, sv)
        runs[backend] = (fp, simulate_steps(walker, fp.x, 4, sv))
    (fa, ta), (fb, tb) = runs["cyrk"], runs["cyrk_compiled"]
    np.testing.assert_allclose(fb.x, fa.x, rtol=0, atol=1e-10)
    np.testing.assert_allclose(fb.jacobian_variational, fa.jacobian_variational, atol=1e-8)
    assert [s.termination for s in tb.segments] == ["heel_strike"] * 4
    for sa, sb in zip(ta.segments, tb.segments):
        assert [p[0] for p in sa.phase_log] == [p[0] for p in sb.phase_log]
        assert [p[3] for p in sa.phase_log] == [p[3] for p in sb.phase_log]
        np.testing.assert_allclose(sb.x_end, sa.x_end, rtol=0, atol=1e-10)
        assert abs(sb.t_end - sa.t_end) < 1e-10


def test_flat_feet_keep_the_row_by_row_step_map(walker):
    """The batched step map runs phases in order with one heel-strike map: a flat foot's
    phase graph (mode-dependent heel strikes) stays on the row-by-row map."""
    assert needs_python_path(walker)


@pytest.mark.slow  # in `pytest -m slow`: the quick suite keeps to its CPU budget
def test_a_modes_entry_check_reads_the_compiled_guards(walker):
    """``guard_values``: the phase's guards at one state from its cfunc (the entry check of
    a mode on cyrk_compiled), each to round-off of the Python guard (forces ~100 N)."""
    from walkerlab.integrate._compiled import guard_values

    x = np.array([-0.3, 0.25, -0.05, -1.3, -1.2, -5.0])
    for ph in _single_support(walker):
        got = guard_values(ph.compiled, 0.0, x)
        want = np.array([float(g.function(0.0, x)) for g in ph.guards])
        np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-12 * np.abs(want).max())


@pytest.mark.parametrize("rtol", [1e-8, 1e-10, 1e-12])
def test_each_phase_ends_in_its_first_chunk_with_few_steps_wasted(walker, scene, rtol):
    """The first chunk of each flat-foot phase (scaled with rtol) holds the step of the
    phase's guard crossing, and at most a third of the chunk's steps (and 6) lie after it
    (they are integrated and thrown away; the chunks of 64/8/24 steps wasted 45 % of heel
    contact's and 55 % of heel off's at rtol 1e-10)."""
    import walkerlab.integrate._compiled as backend

    guess = scene.fixedpoint.initial_guess.as_array(walker.state_names())
    x = find_fixed_point(walker, guess, Solver("DOP853", 1e-12, 1e-12, None,
                                               "cyrk_compiled")).x
    seen, first = [], backend._first_crossing

    def spy(G, dirs):
        out = first(G, dirs)
        seen.append((len(G) - 1, out[0]))  # (G: an array, or a few step points' rows)
        return out

    mp = pytest.MonkeyPatch()
    mp.setattr(backend, "_first_crossing", spy)
    try:
        tr = simulate_steps(walker, x, 2, Solver("DOP853", rtol, rtol, None, "cyrk_compiled"))
    finally:
        mp.undo()
    assert [s.termination for s in tr.segments] == ["heel_strike"] * 2
    # one chunk per compiled phase (the double support's flow is Python: CyRK's own loop)
    assert len(seen) == sum(1 for s in tr.segments for name, *_ in s.phase_log
                            if not name.startswith("double_support"))
    for steps, k in seen:
        assert k is not None and steps - k <= max(6, steps // 3), (rtol, steps, k)
