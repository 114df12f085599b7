"""The symmetric period-2 gait of an independent 3D walker reference, found and linearised
by scipy alone: shared by the references of tests/test_spatial_walker.py,
tests/test_spatial_hip_roll.py and tests/test_spatial_round_feet.py (each model its own;
this is only the root finding and the central differences on its stride)."""

from __future__ import annotations

import numpy as np
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
