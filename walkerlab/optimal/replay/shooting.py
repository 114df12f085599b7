"""The periodic orbit that a five-link biped's optimised torques actually drive, by shooting:
how an open-loop replay of an unstable optimal gait is closed.

The collocated step (:mod:`walkerlab.optimal.transcription.free_joints`) satisfies the
dynamics only to the transcription's error (Hermite-Simpson, ``O(h^4)``: ~1e-6 rad/s at 50
intervals); the walker under open-loop torques is unstable (the error grows ~e^11-fold over
a 0.7 s step of RABBIT), so a replay from the collocated start ends ~1e-2 away from it and
never closes to 1e-6.  The torques ``u(t)`` (:func:`walkerlab.optimal.transcription.free_joints.
torques_of_time`, time since the heel strike) are kept and the start state ``x_0`` and the
step's end time ``T`` are solved so that the step closes exactly::

    reset(Phi(x_0, T)) - x_0 = 0,   clearance(Phi(x_0, T)) = 0

(``Phi`` the flow under ``u(t)``: CasADi's CVODES through each collocation interval,
rtol = atol = 1e-13, forward sensitivities for the Jacobian; MINPACK's hybrj by
``scipy.optimize.root``).  The shift ``|x_0 - x_col|`` is the transcription's error; the
closed step is then replayed on the rigid model's generated code, whose return error is the
one stored.  Its Floquet multipliers are the eigenvalues of the step map's Jacobian with the
event-time correction (the saltation of the heel-strike surface):
``DP = DR (Phi_x - f (grad c . Phi_x) / (grad c . f))``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from walkerlab.optimal.transcription.free_joints import torques_of_time

__all__ = ["ClosedStep", "close_step", "open_loop_error"]


@dataclass
class ClosedStep:
    """The closed (exactly periodic) step under the optimised torques.

    Attributes
    ----------
    x0 : ndarray (2n,)
        Its start (just after the heel strike).
    period_s : float
        Its step period [s].
    residual : float
        Max-norm of the shooting residual [rad, rad/s, m].
    shift : float
        ``max |x0 - x_col[0]|``: how far the collocated start was [rad, rad/s].
    multipliers : ndarray (2n,) complex
        Floquet multipliers of the open-loop step map (one ~0: the heel-strike surface).
    open_loop_error : float
        ``max |reset(Phi(x_col[0], t_2N)) - x_col[0]|``: the return error of the collocated
        start itself under the same torques [rad, rad/s].
    converged : bool
    message : str
    """

    x0: np.ndarray
    period_s: float
    residual: float
    shift: float
    multipliers: np.ndarray
    open_loop_error: float
    converged: bool
    message: str


def _interval_integrator(fns, n2: int, nu: int, nparam: int):
    """CVODES over one collocation interval: ``x(s)``, ``s`` in [0, 1], with parameters
    ``[H, frac, u_i, u_m, u_j, p]``; the interval's time ``tau = s frac`` (in units of its
    length ``H``), the torque the quadratic through ``u_i, u_m, u_j`` at ``tau = 0, 1/2, 1``
    (extrapolated past 1 when ``frac > 1``)."""
    import casadi as ca

    x, s = ca.SX.sym("x", n2), ca.SX.sym("s")
    par = ca.SX.sym("par", 2 + 3 * nu + nparam)
    H, frac = par[0], par[1]
    ui, um, uj = (par[2 + k * nu: 2 + (k + 1) * nu] for k in range(3))
    p = par[2 + 3 * nu:]
    tau = s * frac
    u = (2 * (tau - 0.5) * (tau - 1) * ui - 4 * tau * (tau - 1) * um
         + 2 * tau * (tau - 0.5) * uj)
    rhs = frac * H * fns["flow"](x, u, p)
    return ca.integrator("interval", "cvodes", {"t": s, "x": x, "p": par, "ode": rhs}, 0.0,
                         1.0, {"abstol": 1e-13, "reltol": 1e-13, "max_num_steps": 100000})


def _shooting(fns, params, t, u):
    """``G(z)``, ``z = [x_0, T]``: ``[reset(x_T) - x_0, clearance(x_T)]`` and ``x_T``."""
    import casadi as ca

    n2 = 2 * fns["n"]
    nu = u.shape[1]
    F = _interval_integrator(fns, n2, nu, len(params))
    z = ca.MX.sym("z", n2 + 1)
    x = z[:n2]
    nint = (len(t) - 1) // 2
    p = ca.DM(params)
    for k in range(nint):
        i = 2 * k
        H = float(t[i + 2] - t[i])
        frac = 1.0 if k < nint - 1 else (z[n2] - float(t[i])) / H
        par = ca.vertcat(H, frac, ca.DM(u[i]), ca.DM(u[i + 1]), ca.DM(u[i + 2]), p)
        x = F(x0=x, p=par)["xf"]
    res = ca.vertcat(fns["reset"](x, p) - z[:n2], fns["feet"](x, p)[0])
    return ca.Function("G", [z], [res, x]), z


def close_step(fns, params, t: np.ndarray, x: np.ndarray, u: np.ndarray) -> ClosedStep:
    """Solve the exactly periodic step under the torques ``u(t)`` (module docstring).

    Parameters
    ----------
    fns : dict
        :func:`walkerlab.optimal.transcription.free_joint_functions.five_link_functions`.
    params : sequence of float
        The walker's parameters (``WalkerData.params``).
    t : ndarray (2N + 1,)
        Collocation times [s].
    x : ndarray (2N + 1, 2n)
        Collocated states (the start of the search: the first row and ``t[-1]``).
    u : ndarray (2N + 1, k)
        Collocated torques [N m].

    Returns
    -------
    ClosedStep
    """
    from scipy.optimize import root

    n2 = 2 * fns["n"]
    G, z = _shooting(fns, list(params), np.asarray(t, float), np.asarray(u, float))

    def fun(v):
        return np.asarray(G(v)[0]).ravel()

    z0 = np.concatenate([np.asarray(x, float)[0, :], [float(t[-1])]])
    open_loop = float(np.max(np.abs(fun(z0)[:n2])))
    # hybrd: its own finite-difference Jacobian, then Broyden updates (one G costs a small
    # part of its Jacobian by CVODES' sensitivities)
    sol = root(fun, z0, method="hybr", options={"xtol": 1e-12})
    zs = sol.x
    resid = float(np.max(np.abs(fun(zs))))
    mu = _multipliers(fns, params, G, z, zs, t, u)
    return ClosedStep(x0=zs[:n2], period_s=float(zs[n2]), residual=resid,
                      shift=float(np.max(np.abs(zs[:n2] - z0[:n2]))), multipliers=mu,
                      open_loop_error=open_loop,
                      converged=bool(sol.success and resid < 1e-9), message=str(sol.message))


def _multipliers(fns, params, G, z, zs, t, u) -> np.ndarray:
    """Eigenvalues of ``DP = DR (Phi_x - f (grad c . Phi_x) / (grad c . f))`` at the closed
    step (module docstring)."""
    import casadi as ca

    n2 = 2 * fns["n"]
    xT_sym = G(z)[1]
    Phi_x = np.asarray(ca.Function("Px", [z], [ca.jacobian(xT_sym, z)])(zs))[:, :n2]
    xT = np.asarray(ca.Function("xT", [z], [xT_sym])(zs)).ravel()
    p = np.asarray(params, float)
    xs = ca.SX.sym("x", n2)
    f = np.asarray(fns["flow"](xT, torques_of_time(t, u)(zs[n2]), p)).ravel()
    grad_c = np.asarray(ca.Function("gc", [xs], [ca.jacobian(fns["feet"](xs, p)[0], xs)])(xT))
    DR = np.asarray(ca.Function("DR", [xs], [ca.jacobian(fns["reset"](xs, p), xs)])(xT))
    gx = (grad_c @ Phi_x).ravel()
    DP = DR @ (Phi_x - np.outer(f, gx) / float((grad_c @ f)[0]))
    return np.linalg.eigvals(DP)


def open_loop_error(fns, params, t: np.ndarray, x: np.ndarray, u: np.ndarray) -> float:
    """``max |reset(Phi(x_0, t_2N)) - x_0|`` (``x_0`` the first row) [rad, rad/s]: the
    return error of a collocated step from its own start under its torques (CVODES, as
    :func:`close_step`; arguments as there)."""
    G, _ = _shooting(fns, list(params), np.asarray(t, float), np.asarray(u, float))
    z0 = np.concatenate([np.asarray(x, float)[0, :], [float(t[-1])]])
    return float(np.max(np.abs(np.asarray(G(z0)[0]).ravel()[:2 * fns["n"]])))
