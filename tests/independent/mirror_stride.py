"""The symmetric period-2 gait of an independent 3D walker reference, found and linearised
by scipy alone: shared by the references of tests/test_walker_3d.py,
tests/test_hip_roll_3d.py and tests/test_round_feet_3d.py (each model its own;
this is only the step's two event searches, the root finding and the central differences
on its stride)."""

from __future__ import annotations

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import root


def stride_against(ref, w: float, res, keep) -> tuple[float, float, float]:
    """The reference ``ref``'s stride (a step with swing-hip offset ``w``, then its mirror
    ``-w``; ``ref.step(w, x) -> (x after, period)``, ``ref.on_surface(w, z)`` the state
    just after a heel strike of section coordinates ``z``), its fixed point found by
    scipy's ``hybr`` from the generated one ``res.x`` (the section keeps the state entries
    ``keep``), and its Jacobian by central differences (h = 1e-6).

    Returns
    -------
    (fixed point, period, multipliers)
        The largest differences from ``res``: ``max |x_ref - res.x|``, ``|T_ref -
        res.period_s|`` [s] and ``max |mu - mu_ref| / max(1, |mu_ref|)`` over the sorted
        multipliers (``res.multipliers_variational``).
    """
    def stride(x):
        x1, t1 = ref.step(w, x)
        x2, t2 = ref.step(-w, x1)
        return x2, t1 + t2

    def F(z):
        return stride(ref.on_surface(w, z))[0][keep] - z

    sol = root(F, np.asarray(res.x)[keep], method="hybr", options={"xtol": 1e-13})
    x_ref = ref.on_surface(w, sol.x)
    n, h = x_ref.size, 1e-6
    J = np.zeros((n, n))
    for j in range(n):
        e = np.zeros(n)
        e[j] = h
        J[:, j] = (stride(x_ref + e)[0] - stride(x_ref - e)[0]) / (2 * h)
    theirs = np.sort_complex(np.linalg.eigvals(J))
    ours = np.sort_complex(np.asarray(res.multipliers_variational))
    return (float(np.max(np.abs(x_ref - np.asarray(res.x)))),
            abs(stride(x_ref)[1] - res.period_s),
            float(np.max(np.abs(ours - theirs) / np.maximum(1.0, np.abs(theirs)))))


def to_heel_strike(f, x, swing: int, stance: int, foot_height, span: float):
    """A reference's step from just after a heel strike to just before the next, by scipy's
    DOP853 (rtol = atol = 1e-13) on its flow ``f(t, y)``: to mid-stance (state entries
    ``swing`` and ``stance``, the legs' pitch angles, crossing upwards), then to the swing
    foot's ground contact (``foot_height(y)`` through zero downwards), each within ``span``
    [s].  Returns ``(state before the impact, its time [s])``."""
    def crossing(t, y):
        return y[swing] - y[stance]
    crossing.terminal, crossing.direction = True, 1

    def strike(t, y):
        return foot_height(y)
    strike.terminal, strike.direction = True, -1
    a = solve_ivp(f, (0, span), x, method="DOP853", rtol=1e-13, atol=1e-13, events=crossing)
    t1, y1 = a.t_events[0][0], a.y_events[0][0]
    b = solve_ivp(f, (t1, t1 + span), y1, method="DOP853", rtol=1e-13, atol=1e-13,
                  events=strike)
    return b.y_events[0][0], b.t_events[0][0]
