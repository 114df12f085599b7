"""``walkerlab.integrate.rigid_phase.solve_on``, the one phase integration of the rigid
view, on every integrator a scene can name: per-row tolerance floors for the variational
rows of a numerical Jacobian, and fall guards that are zero as their phase begins."""

from __future__ import annotations

import numpy as np
import pytest

from walkerlab.integrate.solver import Solver


@pytest.mark.parametrize("method,backend", [("DOP853", "cyrk"), ("DOP853", "scipy"),
                                            ("Radau", "scipy"), ("BDF", "scipy"),
                                            ("LSODA", "scipy")])
def test_variational_rows_with_a_tolerance_floor_run_on_every_method(method, backend):
    """``solve_on``'s per-row floor (``rows_rtol``) on every integrator a scene can name:
    scipy's Radau and BDF take one ``rtol`` (the floor goes on ``atol`` there); the linear
    test system ``x' = -2 x`` with ``Phi' = -2 Phi`` ends at ``exp(-2)`` in both, the state
    to the solver's tolerance and ``Phi`` to the floor."""
    from walkerlab.integrate.rigid_phase import solve_on

    def rhs(t, y):
        return -2.0 * y

    y0 = np.array([1.0, 1.0])
    run = solve_on(rhs, 0.0, 1.0, y0, (), 1, Solver(method, 1e-10, 1e-10), backend,
                   rows_rtol=1e-6)
    assert not run.failed
    assert run.t_last == 1.0
    assert abs(run.y_last[0] - np.exp(-2.0)) < 1e-8
    assert abs(run.y_last[1] - np.exp(-2.0)) < 1e-4


@pytest.mark.parametrize("method,backend", [("LSODA", "scipy"), ("BDF", "scipy"),
                                            ("DOP853", "cyrk")])
def test_a_fall_guard_that_is_zero_as_its_phase_begins_is_not_crossed_there(method, backend):
    """A fall guard exactly 0 at the phase's start (heel off begins with the foot flat) whose
    first motion is away from its firing side does not fire there: scipy counted ``g <= 0
    <= g_new`` at an implicit method's first step as a crossing (a false fall at the start
    of heel off).  One that starts at 0 toward its firing side fires at the start, where
    it crosses.  ``x = -t^3`` (heel off's ``phi``: zero angle, rate and acceleration),
    read as ``(0.3 + x) - 0.3`` as ``phi`` is a sum of angles: a first step's ``-h^3``
    below their round-off reads exactly 0 (without the rule LSODA and BDF fire at t = 0)."""
    from walkerlab.integrate.rigid_phase import ENTRY_ZERO, solve_on
    from walkerlab.models.hybrid.base import Guard

    def rhs(t, y):  # y = (x, v, a): x''' = -6
        return np.array([y[1], y[2], -6.0])

    away = Guard("touches_down", lambda t, y: (0.3 + y[0]) - 0.3, +1, "fall")
    run = solve_on(rhs, 0.0, 1.0, np.zeros(3), (away,), 3, Solver(method, 1e-12, 1e-12),
                   backend)
    assert run.event is None and run.t_last == 1.0
    assert abs(run.y_last[0] + 1.0) < 1e-8
    toward = Guard("lifts", lambda t, y: (0.3 + y[0]) - 0.3, -1, "fall")
    run = solve_on(rhs, 0.0, 1.0, np.zeros(3), (toward,), 3, Solver(method, 1e-12, 1e-12),
                   backend)
    assert run.event == 0
    assert 0.0 <= run.t_last <= 1.1 * ENTRY_ZERO ** (1 / 3)
