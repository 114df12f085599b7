"""The batched step map integrates every row on its own (compiled DOP853,
:mod:`walkerlab.integrate.rows_dop853`) and resets heel strikes with the generated module's
compiled reset: a row's step does not depend on the other rows of its batch, and the
compiled reset is the walker's reset bit for bit."""

from pathlib import Path

import numpy as np
import pytest

from walkerlab.analysis.gait.scene import solve_scene
from walkerlab.codegen.compiled import compiled_module
from walkerlab.config import load_scene
from walkerlab.integrate.batch_step import HEEL_STRIKE, BatchStepMap
from walkerlab.integrate.rows_dop853 import reset_rows
from walkerlab.models.registry import build_walker
from walkerlab.studies.mfpt import scene_walker_at
from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]


def _one_guard_set(sm, rows: int) -> tuple:
    """``period_rows``' guard arguments for ``rows`` rows of the phase 0 of the step map
    ``sm``: one guard set, every row's."""
    return (sm._gcols[0][None], sm._goffs[0][None], sm._dirs[0][None].astype(float),
            np.array([sm._gcols[0].size]), np.zeros(rows, np.int64))


@pytest.fixture(scope="module")
def paper_map(paper_scene):
    return BatchStepMap(build_walker(plant := Plant.from_scene(paper_scene)),
                        scene_walker_at(paper_scene, plant), 1e-9, 1e-9)


@pytest.mark.slow  # in `pytest -m slow`: the quick suite keeps to its CPU budget
def test_a_rows_step_does_not_depend_on_its_batch(paper_scene, paper_map, paper_fixed_point):
    """Each row alone gives the same numbers, bit for bit, as inside a batch of 6 (a stacked
    integrator shares step sizes among rows, so its rows differed at ~1e-10; Monte Carlo walks
    and mesh images must not depend on how rows are grouped into tasks)."""
    rng = np.random.default_rng(5)
    X = paper_fixed_point.x + 0.005 * rng.standard_normal((6, 4))
    gam = paper_scene.slope.phi_rad + 0.003 * rng.standard_normal(6)
    r = paper_map.step(X, gam)
    assert (r.outcome == HEEL_STRIKE).sum() >= 4
    for i in range(6):
        one = paper_map.step(X[i:i + 1], gam[i:i + 1])
        assert one.outcome[0] == r.outcome[i]
        np.testing.assert_array_equal(one.x_next[0], r.x_next[i])
        np.testing.assert_array_equal(one.step_time_s[0], r.step_time_s[i])


@pytest.mark.parametrize("scene", ["paper.yaml", "kneed.yaml"])
def test_compiled_reset_is_the_walkers_reset(scene):
    """``reset_flow`` of the generated compiled module (a cfunc, same expressions as the
    Python ``reset``), applied row by row by ``rows_dop853.reset_rows``, gives the walker's
    heel-strike reset bit for bit, on two slopes."""
    sc = load_scene(ROOT / "configs" / scene)
    w = build_walker(Plant.from_scene(sc))
    cf = w.phases[-1].compiled
    mod = compiled_module(cf.structure)
    n = w.layout().size
    X = 0.3 * np.random.default_rng(1).standard_normal((5, n))
    for gamma in (w.slope_rad, w.slope_rad + 0.02):
        wg = scene_walker_at(sc, plant=Plant.from_scene(sc))(gamma)
        D = np.tile(wg.phases[-1].compiled.data(), (5, 1))
        out = np.empty_like(X)
        reset_rows(mod.reset_flow(), X, D, out)
        np.testing.assert_array_equal(out, np.array([wg.reset(x) for x in X]))


# the quick suite's CPU budget (README): a longer run, in `pytest -m slow`
@pytest.mark.slow
def test_compiled_walks_equal_step_after_step(paper_scene, paper_map, paper_fixed_point):
    """A whole walk in compiled code (``BatchStepMap.walk``) gives the same heel strikes,
    falls and last states, bit for bit, as ``step`` called step after step on the same
    slopes (sigma 0.01 rad: most walks fall within 12 steps, so both branches are met)."""
    rng = np.random.default_rng(11)
    W, S = 40, 12
    gam = paper_scene.slope.phi_rad + 0.01 * rng.standard_normal((W, S))
    assert paper_map.can_walk
    steps, fell, X_end = paper_map.walk(np.tile(paper_fixed_point.x, (W, 1)), gam)
    X = np.tile(paper_fixed_point.x, (W, 1))
    alive = np.arange(W)
    ref = np.zeros(W, int)
    for s in range(S):
        r = paper_map.step(X[alive], gam[alive, s])
        ok = r.outcome == HEEL_STRIKE
        ref[alive[ok]] += 1
        X[alive[ok]] = r.x_next[ok]
        alive = alive[ok]
    np.testing.assert_array_equal(steps, ref)
    np.testing.assert_array_equal(fell, ~np.isin(np.arange(W), alive))
    np.testing.assert_array_equal(X_end, X)
    assert 0 < fell.sum() < W


@pytest.mark.slow  # in `pytest -m slow`: the quick suite keeps to its CPU budget
def test_kneed_walker_keeps_the_step_by_step_walks():
    """A kneed walker (two flows, the knee strike's reset between phases) is not walked in
    one compiled call: ``can_walk`` is False and ``walk`` says why in one line."""
    sc = load_scene(ROOT / "configs" / "kneed.yaml")
    sm = BatchStepMap(build_walker(Plant.from_scene(sc)), scene_walker_at(sc,
            plant=Plant.from_scene(sc)), 1e-9, 1e-9)
    assert not sm.can_walk
    with pytest.raises(ValueError, match="compiled walks need"):
        sm.walk(np.zeros((1, sm.n)), np.zeros((1, 1)))


@pytest.mark.parametrize("scene", ["paper.yaml", "kneed.yaml"])
def test_stage_and_guard_cfuncs_are_the_flows_values(scene):
    """The generated ``plain_flow(name)`` (a DOP853 step's inner stages) writes the flow's 2n
    values and ``guard_one()`` each guard's value (a crossing's location), bit for bit those
    the flow cfunc writes with its guard outputs, for every flow of the module."""
    from ctypes import POINTER, c_double

    from walkerlab.integrate.rows_dop853 import cfuncs

    def ptr(v):
        return v.ctypes.data_as(POINTER(c_double))

    sc = load_scene(ROOT / "configs" / scene)
    w = build_walker(Plant.from_scene(sc))
    cf = w.phases[0].compiled
    mod = compiled_module(cf.structure)
    n, ng = w.layout().size, len(mod.GUARDS)
    d = cf.data()
    X = 0.4 * np.random.default_rng(2).standard_normal((20, n))
    names = {p.compiled.name for p in w.phases}
    for name in names:
        full, plain, guard, sel = cfuncs(mod, name, getattr(mod, name))
        assert sel
        for x in X:
            a, b, g = np.empty(n + ng), np.empty(n), np.empty(1)
            full.ctypes(ptr(a), 0.0, ptr(x), ptr(d))
            plain.ctypes(ptr(b), 0.0, ptr(x), ptr(d))
            np.testing.assert_array_equal(b, a[:n])
            for j in range(ng):
                g[0] = j
                guard.ctypes(ptr(g), 0.0, ptr(x), ptr(d))
                assert g[0] == a[n + j] or (np.isnan(g[0]) and np.isnan(a[n + j]))


# the quick suite's CPU budget (README): a longer run, in `pytest -m slow`
@pytest.mark.slow
def test_phase_rows_with_stage_cfuncs_equal_the_flow_alone(paper_map, paper_fixed_point):
    """One phase of rows by ``phase_rows`` with the stage and guard cfuncs gives the same
    crossings, times, states and next step sizes, bit for bit, as with the flow (and its
    guard outputs) in every role."""
    from walkerlab.integrate.rows_dop853 import phase_rows

    rng = np.random.default_rng(7)
    X = paper_fixed_point.x + 0.01 * rng.standard_normal((8, 4))
    D = paper_map.data(paper_map.slope_rad + 0.003 * rng.standard_normal(8))
    fns = paper_map._cfuncs(0)
    assert fns[3]
    res = []
    for f in (fns, (fns[0], fns[0], fns[0], False)):
        which, te, Yev, H = np.empty(8, np.int64), np.empty(8), np.empty((8, 4)), np.zeros(8)
        phase_rows(*f, X.copy(), D.copy(), np.full(8, 5.0), paper_map._gcols[0],
                   paper_map._goffs[0], paper_map._dirs[0], 1e-9, 1e-9, 4 + paper_map.phases[0][2],
                   which, te, Yev, H, -1, np.zeros(1))
        res.append((which, te, Yev, H))
    for a, b in zip(*res):
        np.testing.assert_array_equal(a, b)


def test_cfuncs_called_by_address_give_the_first_class_calls_numbers(paper_map,
                                                                     paper_fixed_point):
    """``period_rows`` given the flow's cfuncs as process addresses (``int``: the native
    vector environment's call, :func:`walkerlab.integrate.rows_dop853._call_address`)
    crosses the same guards at the same times and states with the same next step sizes,
    bit for bit, as given the cfuncs themselves (numba's first-class functions); rows that
    end on a guard and rows that reach their cap are both met."""
    from walkerlab.integrate.rows_dop853 import TIMEOUT, period_rows

    rng = np.random.default_rng(11)
    X = paper_fixed_point.x + 0.01 * rng.standard_normal((8, 4))
    D = paper_map.data(paper_map.slope_rad + 0.003 * rng.standard_normal(8))
    fns = paper_map._cfuncs(0)
    cap = np.where(np.arange(8) % 2 == 0, 5.0, 0.05)  # half the rows stop at 50 ms
    res = []
    for f in (fns, (fns[0].address, fns[1].address, fns[2].address, fns[3])):
        which, te, Yev, H = np.empty(8, np.int64), np.empty(8), np.empty((8, 4)), np.zeros(8)
        period_rows(*f, X.copy(), D.copy(), cap, *_one_guard_set(paper_map, 8), 1e-9, 1e-9,
                    4 + paper_map.phases[0][2], which, te, Yev, H, np.full((8, 0), np.nan),
                    np.empty((8, 0, 4)))
        res.append((which, te, Yev, H))
    assert (res[0][0] == TIMEOUT).any() and (res[0][0] >= 0).any()
    for a, b in zip(*res):
        np.testing.assert_array_equal(a, b)


def test_period_rows_give_each_row_its_own_guard_set(paper_map, paper_fixed_point):
    """Rows of one flow in different phases (the same cfunc, guards of their own: the
    native vector environment's walkers out of step) integrated in one ``period_rows``
    call, each by its guard set (``gi``), give bit for bit what each set's rows give in a
    call of their own; a set without the paper walker's midstance guard (its first
    phase's end) walks its rows on past it."""
    from walkerlab.integrate.rows_dop853 import TIMEOUT, period_rows

    rng = np.random.default_rng(3)
    N = 6
    X = paper_fixed_point.x + 0.01 * rng.standard_normal((N, 4))
    D = paper_map.data(np.full(N, paper_map.slope_rad))
    fns = paper_map._cfuncs(0)
    cap = np.full(N, 2.0)
    gc, go, gd = paper_map._gcols[0], paper_map._goffs[0], paper_map._dirs[0].astype(float)
    g = gc.size
    mid = [k.outcome for k in paper_map.phases[0][0].guards].index("next_phase")
    keep = np.arange(g) != mid  # set 1: every guard but midstance's
    tables = (np.zeros((2, g), np.int64), np.zeros((2, g)), np.zeros((2, g)))
    for table, full in zip(tables, (gc, go, gd)):
        table[0] = full
        table[1, :keep.sum()] = full[keep]
    ng = np.array([g, keep.sum()])
    gi = np.array([0, 1, 1, 0, 1, 0])

    def call(Xr, Dr, capr, *guards):
        r = len(Xr)
        out = np.empty(r, np.int64), np.empty(r), np.empty((r, 4)), np.zeros(r)
        period_rows(*fns, Xr.copy(), Dr.copy(), capr, *guards, 1e-9, 1e-9,
                    4 + paper_map.phases[0][2], *out, np.full((r, 0), np.nan),
                    np.empty((r, 0, 4)))
        return out

    mixed = call(X, D, cap, *tables, ng, gi)
    for s in (0, 1):
        rows = gi == s
        alone = call(X[rows], D[rows], cap[rows], tables[0][s:s + 1], tables[1][s:s + 1],
                     tables[2][s:s + 1], ng[s:s + 1], np.zeros(rows.sum(), np.int64))
        for a, b in zip(alone, mixed):
            np.testing.assert_array_equal(a, b[rows])
    which = mixed[0]
    assert (which[gi == 0] == mid).all()  # set 0: midstance
    past = which[gi == 1]  # set 1: on past it, to a fall (its guards' own index) or the cap
    assert all(w == TIMEOUT or np.flatnonzero(keep)[w] != mid for w in past)
    assert (mixed[1][gi == 1] > mixed[1][gi == 0].max()).all()


def test_period_rows_write_their_dense_output_at_sample_times_without_changing_the_steps(
        paper_map, paper_fixed_point):
    """``period_rows`` given sample times (the native vector environment's Gauss-Legendre
    nodes) writes each row's states there from its steps' dense output: scipy's DOP853
    at 1e-12 gives the same states within the run's tolerance (1e-9 on a state of order
    1: 1e-8), a time left NaN is not written, and the steps' outcomes (guards, times,
    end states, next step sizes) are bit for bit those without samples."""
    from ctypes import POINTER, c_double

    from scipy.integrate import solve_ivp

    from walkerlab.integrate.rows_dop853 import TIMEOUT, period_rows

    rng = np.random.default_rng(5)
    X = paper_fixed_point.x + 0.01 * rng.standard_normal((4, 4))
    D = paper_map.data(paper_map.slope_rad + 0.003 * rng.standard_normal(4))
    fns = paper_map._cfuncs(0)
    cap = np.array([0.05, 0.2, 0.05, 0.3])
    nodes = 0.5 * cap[:, None] * (1 + np.polynomial.legendre.leggauss(4)[0])
    nodes[2] = np.nan  # row 2: no samples
    out = []
    for Tn, Yn in ((np.full((4, 0), np.nan), np.empty((4, 0, 4))),
                   (nodes, np.full((4, 4, 4), -7.0))):
        which, te, Yev, H = np.empty(4, np.int64), np.empty(4), np.empty((4, 4)), np.zeros(4)
        period_rows(*fns, X.copy(), D.copy(), cap, *_one_guard_set(paper_map, 4), 1e-9,
                    1e-9, 4 + paper_map.phases[0][2], which, te, Yev, H, Tn, Yn)
        out.append((which, te, Yev, H, Yn))
    for a, b in zip(out[0][:4], out[1][:4]):
        np.testing.assert_array_equal(a, b)
    which, Yn = out[1][0], out[1][4]
    assert (which == TIMEOUT).all()  # every row reached its cap: all its nodes were passed
    assert (Yn[2] == -7.0).all()
    f = fns[0]  # the flow's cfunc (dy, t, y, d): its 4 rates, then its guard outputs
    dy = np.empty(4 + paper_map.phases[0][2])

    def ptr(v):
        return v.ctypes.data_as(POINTER(c_double))

    for i in (0, 1, 3):
        d = np.ascontiguousarray(D[i])

        def rhs(t, y, d=d):
            y = np.ascontiguousarray(y, dtype=float)
            f.ctypes(ptr(dy), t, ptr(y), ptr(d))
            return dy[:4].copy()

        ref = solve_ivp(rhs, (0.0, cap[i]), X[i], method="DOP853", rtol=1e-12, atol=1e-12,
                        t_eval=nodes[i]).y.T
        np.testing.assert_allclose(Yn[i], ref, rtol=0, atol=1e-8)


# the quick suite's CPU budget (README): a longer run, in `pytest -m slow`
@pytest.mark.slow
@pytest.mark.parametrize("scene", ["paper.yaml", "kneed.yaml"])
def test_loops_specialised_to_the_flow_give_the_cfunc_loops_numbers(scene):
    """The per-row loops compiled with the walker's flow inlined
    (:func:`walkerlab.integrate.rows_dop853.kernels`) give the heel strikes, falls, states,
    times and step sizes of the same loops calling the flow's cfuncs, bit for bit (the same
    operations in the same order: inlining changes no rounding), for whole walks (on slopes
    and on landing heights) and for single steps over every phase (the kneed walker: two
    flows, a knee strike between them)."""
    from walkerlab.models.hybrid.ground import with_clearance_guard
    from walkerlab.walker.description import walker_data

    sc = load_scene(ROOT / "configs" / scene)
    w = build_walker(Plant.from_scene(sc))
    w_hts = with_clearance_guard(w, walker_data(sc.walker, sc.slope.phi_rad))
    maps = [[BatchStepMap(wk, scene_walker_at(sc,
            plant=Plant.from_scene(sc)), 1e-9, 1e-9, specialised=s)
             for wk in (w, w_hts)] for s in (True, False)]
    assert all(maps[0][0]._kernels(k) is not None for k in range(len(w.phases)))
    assert all(maps[1][0]._kernels(k) is None for k in range(len(w.phases)))
    rng = np.random.default_rng(3)
    x0 = np.asarray(solve_scene(sc, fd_check=False,
                                plant=Plant.from_scene(sc))[1].gait.result.x, float)
    gam = maps[0][0].slope_rad + 0.006 * rng.standard_normal((30, 10))
    hts = 0.002 * rng.standard_normal((30, 10))
    X = x0 + 0.005 * rng.standard_normal((30, x0.size))
    got = []
    for sm, sm_hts in maps:
        out = [sm.step(X, gam[:, 0])]
        if sm.can_walk:
            out.append(sm.walk(np.tile(x0, (30, 1)), gam))
            out.append(sm_hts.walk(np.tile(x0, (30, 1)), gam, hts))
        got.append(out)
    a, b = got
    np.testing.assert_array_equal(a[0].outcome, b[0].outcome)
    for k in ("x_pre", "x_next", "step_time_s"):
        np.testing.assert_array_equal(getattr(a[0], k), getattr(b[0], k))
    assert (a[0].outcome == HEEL_STRIKE).sum() >= 20
    for wa, wb in zip(a[1:], b[1:]):
        for u, v in zip(wa, wb):
            np.testing.assert_array_equal(u, v)
        assert 0 < wa[1].sum() < 30  # walks that fall and walks that do not


def test_the_kernels_file_is_named_by_the_loop_it_compiles(paper_walker):
    """The specialised loops live in a generated file whose name carries the sha256 of
    ``rows_dop853.py`` (numba's cache checks only the file a function is in: a changed loop
    must be a new file, not stale machine code) and the model's cache key; the compiled
    model's own file does not (editing the loop does not re-derive the model)."""
    import hashlib

    from walkerlab.codegen import cache
    from walkerlab.integrate.rows_dop853 import kernels, source_hash

    cf = paper_walker.phases[0].compiled
    src = (ROOT / "walkerlab" / "integrate" / "rows_dop853.py").read_bytes()
    assert source_hash() == hashlib.sha256(src).hexdigest()[:12]
    walk, phase = kernels(cf.structure, cf.name)
    key = cache.cache_key(cf.structure)
    for k in (walk, phase):
        assert Path(k.py_func.__code__.co_filename).name == f"{key}_rows_{source_hash()}_nb.py"
    assert Path(compiled_module(cf.structure).__file__).name == f"{key}_nb.py"
