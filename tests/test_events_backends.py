"""``run_to_event`` on its two libraries: scipy's ``solve_ivp`` and CyRK's ``pysolve_ivp``
(``Solver.backend == "cyrk"``, what the drop test integrates on) end at the same event."""

import math

import numpy as np

from walkerlab.integrate.ends import RunEnd
from walkerlab.integrate.events import Event, run_to_event
from walkerlab.integrate.solver import Solver


def _oscillator(t, y):
    return np.array((y[1], -y[0]))


def test_cyrk_and_scipy_stop_at_the_same_event():
    """x'' = -x from (0, 1): x falls through zero at t = pi with x' = -1; both libraries'
    Radau find it to their tolerance (rtol 1e-10: 1e-8 is a hundred times looser)."""
    down = Event("down", lambda t, y: y[0] if t > 0 else 1.0, -1)
    runs = {b: run_to_event(_oscillator, [0.0, 1.0], 10.0,
                            Solver("Radau", 1e-10, 1e-12, 0.1, backend=b), [down])
            for b in ("scipy", "cyrk")}
    for b, r in runs.items():
        assert (r.end, r.event) == (RunEnd.T_FINAL, "down"), b
        assert abs(r.t_event - math.pi) < 1e-8, (b, r.t_event - math.pi)
        np.testing.assert_allclose(r.y_event, [0.0, -1.0], atol=1e-8)
        assert r.y.shape == (2, r.t.size) and r.nfev > 0
    assert abs(runs["cyrk"].t_event - runs["scipy"].t_event) < 1e-9
    assert runs["cyrk"].message != runs["scipy"].message  # two libraries ran, not one twice


def test_cyrk_without_an_event_runs_to_the_end_time():
    never = Event("never", lambda t, y: 2.0 + y[0], -1)
    r = run_to_event(_oscillator, [0.0, 1.0], 1.0, Solver("Radau", 1e-8, 1e-10, backend="cyrk"),
                     [never], dense=True)
    assert (r.end, r.event, r.y_event) == (RunEnd.T_FINAL, "", None)
    assert math.isnan(r.t_event) and r.t[-1] == 1.0
    np.testing.assert_allclose(r.dense(0.5), [math.sin(0.5), math.cos(0.5)], atol=1e-7)
