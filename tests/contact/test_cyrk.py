"""The cyrk_bdf route (CyRK's BDF with the compiled RHS) against scipy's odeint."""

import numpy as np
import pytest

from tests.contact.test_numbalsoda import _bench_case
from walkerlab.analysis.contact.sim import simulate_contact
from walkerlab.bench.contact import leg_angle_columns
from walkerlab.config import SolverSettings
from walkerlab.integrate import _cyrk
from walkerlab.integrate.contact import sample_grid as _grid


def test_cyrk_bdf_five_strides_match_odeint():
    """Same run, rtol 1e-10: both integrators are within ~6e-9 rad of the rtol-1e-12
    reference (bench: odeint 5.8e-9, cyrk_bdf 1.4e-9), so they must agree to 1e-7 rad in
    the leg angles (margin ~10x for the machine-dependent step sequence) and to 1e-6 s in
    every heel-strike time (measured 4.5e-9 s)."""
    w, x0, tf = _bench_case()
    a = simulate_contact(w, x0, tf,
                         SolverSettings.for_contact(method="odeint", rtol=1e-10, atol=1e-13))
    b = simulate_contact(w, x0, tf,
                         SolverSettings.for_contact(method="cyrk_bdf", rtol=1e-10, atol=1e-13))
    assert b.method == "cyrk_bdf" and b.termination == a.termination == "t_final"
    assert b.nfev > 0 and b.njev == 0  # no odeint fallback on this run
    assert b.walked_steps == a.walked_steps == 10
    assert b.heel_strike_legs == a.heel_strike_legs
    np.testing.assert_allclose(b.heel_strike_times, a.heel_strike_times, atol=1e-6)
    assert np.array_equal(a.t, b.t)
    assert np.abs(b.x[:, leg_angle_columns(w)] - a.x[:, leg_angle_columns(w)]).max() < 1e-7


# the quick suite's CPU budget (README): a longer run, in `pytest -m slow`
@pytest.mark.slow
def test_cyrk_bdf_failure_is_finished_by_odeint(monkeypatch):
    """When BDF stops inside a chunk (as at a force jump it cannot step over), odeint
    finishes that chunk from the last sample reached: same uniform samples, odeint's RHS
    and Jacobian calls counted, and the state agrees with a plain odeint run to the same
    1e-7 rad as above (measured 3e-10 over this 0.5 s)."""
    w, x0, _ = _bench_case()
    real = _cyrk.solve_chunk
    nbdf = []

    def stops_halfway(method, x, tg, *args, **kw):
        X, ok, nf, _ = real(method, x, tg[: len(tg) // 2], *args, **kw)
        nbdf.append(nf)
        return X, False, nf, "stopped (test)"

    monkeypatch.setattr(_cyrk, "solve_chunk", stops_halfway)
    b = simulate_contact(w, x0, 0.5,
                         SolverSettings.for_contact(method="cyrk_bdf", rtol=1e-10, atol=1e-13))
    a = simulate_contact(w, x0, 0.5,
                         SolverSettings.for_contact(method="odeint", rtol=1e-10, atol=1e-13))
    assert b.termination == "t_final"
    np.testing.assert_array_equal(b.t, _grid(0.0, 0.5, 1000.0))
    assert b.njev > 0 and b.nfev > sum(nbdf) > 0
    assert np.abs(b.x[:, leg_angle_columns(w)] - a.x[:, leg_angle_columns(w)]).max() < 1e-7


def test_chunk_solver_reads_cyrks_states_calls_and_messages():
    """The chunk solver's reading of CyRK's result (its solution copied through its
    address into a kept buffer, the call counter from the argument copy, the message per
    status code) against CyRK's own other paths: each sample equals CyRK's dense output
    at its time bit for bit, an answer is not overwritten by the next call, the call
    count is positive and a call stopped by its step limit says so with CyRK's message
    for its status code (read through the bridge's status-to-message function)."""
    import ctypes

    w, x0, _ = _bench_case()
    solve = _cyrk.ChunkSolver("cyrk_bdf", 1e-8, 1e-10, kernels=w.kernels)
    tg = np.linspace(0.0, 0.02, 11)
    X, ok, nfev, msg, dense = solve(x0, tg, w.pack(), dense=True)
    try:
        assert ok and X.shape == (11, len(x0)) and nfev > 0
        for k in (0, 3, 10):
            np.testing.assert_array_equal(X[k], dense(tg[k]))
    finally:
        dense.free()
    first = X.copy()
    X2, ok2, _, msg2 = solve(x0 + 1e-3, tg, w.pack())  # the same buffer, other numbers
    assert ok2 and msg2 == msg and not np.array_equal(X2, first)
    np.testing.assert_array_equal(X, first)

    ns = _cyrk._api()[0]
    stopped = _cyrk.ChunkSolver("cyrk_bdf", 1e-8, 1e-10, max_num_steps=2, kernels=w.kernels)
    Xs, oks, _, msgs = stopped(x0, tg, w.pack())
    assert not oks and len(Xs) < len(tg) and msgs != msg
    code = next(c for c, m in stopped._messages.items() if m == msgs)
    buf = ctypes.create_string_buffer(256)
    ns.c_get_status_msg_buf(code, ctypes.addressof(buf), 256)
    assert buf.value.decode() == msgs


def test_a_chunk_run_without_its_dense_output_takes_the_steps_of_one_with_it():
    """A compiled segment asks CyRK for its dense output only where an event is to be
    located, by running the segment again with it (:mod:`walkerlab.integrate.
    compiled_segments`); that is the first run's interpolant only if keeping a dense output
    leaves CyRK's steps alone: the samples and the call count of a run without it equal a
    run's with it bit for bit, and two runs with it give the same interpolant everywhere."""
    w, x0, _ = _bench_case()
    solve = _cyrk.ChunkSolver("cyrk_bdf", 1e-8, 1e-10, kernels=w.kernels)
    tg = np.linspace(0.0, 0.02, 11)
    X1, ok1, n1, _ = solve(x0, tg, w.pack())
    X2, ok2, n2, _, dense = solve(x0, tg, w.pack(), dense=True)
    again = solve(x0, tg, w.pack(), dense=True)[4]
    try:
        assert ok1 and ok2 and n1 == n2 > 0
        np.testing.assert_array_equal(X1, X2)
        for t in np.linspace(0.0, 0.02, 37):
            np.testing.assert_array_equal(dense(t), again(t))
    finally:
        dense.free()
        again.free()
