"""The contact step map's Jacobian from the variational equations: the check of its
finite-difference Jacobian.

The contact periodic gait's Floquet multipliers are the eigenvalues of ``dP/dz`` at the
fixed point (:mod:`walkerlab.analysis.contact.periodic`), taken by finite differences of the
map on the compiled integrator.  Here the same Jacobian comes from the sensitivity matrix
``Phi = dx(t)/dx0`` of the flow, integrated with the state (``dPhi/dt = J(x) Phi``, ``J`` the
model's analytic Jacobian, :func:`walkerlab.models.contact.generated` ``jac``), corrected for
the moving section (Parker & Chua 1989, *Practical Numerical Algorithms for Chaotic
Systems*, Sec. 4.2.3; the saltation of a smooth section):

    dx_e/dx0 = (I - f(x_e) grad_g^T / (grad_g . f(x_e))) Phi(t_e),

``g = theta_swing - theta_stance`` of the proximal links (the section), then chained with the
derivatives of the section coordinates (:meth:`StepMap.to_state`, :meth:`StepMap.to_section`;
algebraic, by central differences of steps 1e-5 x scale and 1e-8).  The contact laws are continuous
in the state (the IMPACT force rises from zero with the penetration, the friction law is a
smooth step), so ``Phi`` needs no jump at a touchdown; patch membership is locally constant
on the orbit (the feet stay inside their patches, ``patch_margin_m``).  The knee latch's
weight is held constant in the analytic Jacobian, so this check is for walkers without a
latch.

This is a check, not the search's path: the augmented system ((2 nq)(2 nq + 1) states) runs
through scipy's odeint (LSODA) with a Python right-hand side.
"""

from __future__ import annotations

import numpy as np

from walkerlab.analysis.contact.step_map import StepMap
from walkerlab.integrate.events import odeint_grid
from walkerlab.integrate.solver import Solver

__all__ = ["variational_jacobian"]


def _fd(f, x, h):
    """Central-difference Jacobian of ``f`` at ``x`` with steps ``h`` (per column)."""
    cols = []
    for k in range(len(x)):
        e = np.zeros(len(x))
        e[k] = h[k]
        cols.append((np.asarray(f(x + e)) - np.asarray(f(x - e))) / (2 * h[k]))
    return np.array(cols).T


def variational_jacobian(step_map: StepMap, z, rtol: float = 1e-10,
                         atol: float = 1e-13) -> np.ndarray:
    """dP/dz of the contact step map at ``z`` from the variational equations.

    Parameters
    ----------
    step_map : StepMap
        The map (a grid method: its crossing time comes from :meth:`StepMap.next_section`).
    z : array_like (m,)
        Section coordinates (``step_map.names``, units ``step_map.units``).
    rtol, atol : float
        odeint's tolerances for the state and its sensitivity matrix.

    Returns
    -------
    ndarray (m, m)
        dP/dz in the section's units (rows and columns in ``step_map.names`` order).
    """
    w = step_map.walker
    kern = w.kernels
    args = (w.contact_params, w.walker_params, *w.kernel_lanes)
    z = np.asarray(z, float)
    x0 = step_map.to_state(z)
    n = x0.size
    te = step_map.next_section(x0)[0]

    def rhs(t, y):
        x, phi = y[:n], y[n:].reshape(n, n)
        return np.concatenate([kern.rhs(x, *args), (kern.jac(x, *args) @ phi).ravel()])

    def jac(t, y):  # the blocks of d/dy, the second derivative of f left out (Newton only)
        return np.kron(np.eye(n + 1), kern.jac(y[:n], *args))

    y0 = np.concatenate([x0, np.eye(n).ravel()])
    Y = odeint_grid(rhs, y0, np.array([0.0, te]), Solver("odeint", rtol, atol), jac=jac)[0]
    xe, phi = Y[-1, :n], Y[-1, n:].reshape(n, n)
    grad = np.zeros(n)  # g = theta_swing(leg1) - theta_stance(leg2), proximal links
    grad[step_map.idx[w.leg_angle_states("leg1")[0]]] += 1.0
    grad[step_map.idx[w.leg_angle_states("leg2")[0]]] -= 1.0
    fe = kern.rhs(xe, *args)
    dxe = (np.eye(n) - np.outer(fe, grad) / (grad @ fe)) @ phi
    dx0 = _fd(step_map.to_state, z, 1e-5 * step_map.scale)
    dze = _fd(lambda x: step_map.to_section(x, 0)[0], xe, np.full(n, 1e-8))
    return dze @ dxe @ dx0
