"""An optimised step replayed with its torques as a function of the phase variable (virtual
constraints): the law, and its replay on the rigid model closed to the law's fixed point.

Phase variable ``s``: a quantity that is strictly monotonic over the optimised step, the
stance leg's absolute angle (Westervelt, Grizzle & Koditschek 2003, IEEE TAC 48(1):42-56,
Sec. IV; checked by the caller, else refused).  On the collocated step ``(t_i, x_i, u_i)``
each actuator's joint angle ``delta_k`` becomes a reference of ``s``: the cubic Hermite
spline ``h_k`` through ``(s_i, delta_k(x_i))`` with the slopes ``ddelta_k(x_i) / ds(x_i)``
(so ``delta = h(s)`` and ``ddelta = h'(s) ds`` hold at every collocation point), the torque
the transcription's own control (the quadratic in time of each Hermite-Simpson interval,
:func:`control_of_time`) at the time ``T(s)`` the collocated step passes ``s`` (``T`` the
cubic Hermite spline through ``(s_i, t_i)`` with slopes ``1 / ds(x_i)``); the law::

    tau_k = u_k(s) - K_k (delta_k - h_k(s)) - D_k (ddelta_k - h_k'(s) ds)

(feed-forward plus PD, the PD term zero on the collocated step; ``K = D = 0``: the pure
phase-variable feed-forward).  The splines extrapolate past the table's ends (a replayed
step may end slightly after the collocated one; their cubic there is the end interval's).

Complex-safe to first order (``f(a + i e) = f(a) + i e f'(a)``): the rigid model's
variational equations differentiate the law by the complex step.

Used by the five-link biped (:mod:`walkerlab.optimal.replay.virtual_constraints`) and the
straight-legged and kneed walkers (:mod:`walkerlab.optimal.replay.hip_phase`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from walkerlab.integrate.rigid import integrate_step
from walkerlab.models.compiled_flows import ActuatedFlow
from walkerlab.numerics import fd_jacobian, sort_multipliers

__all__ = ["LIMIT_N_M", "PhaseLaw", "PhaseReplay", "control_of_time", "driven_by",
           "law_of_rows", "replay_law", "torque_error"]

#: the replays' torque limit [N m]: none in effect (the optimised torques are bounded by the
#: transcription's own ``max_torque_n_m``)
LIMIT_N_M = 1e6


def _at(f, df, u):
    """``f(u)`` of a real spline, complex-safe to first order."""
    r = np.real(u)
    out = f(r)
    if np.iscomplexobj(u):
        out = out + 1j * np.imag(u) * df(r)
    return out


class PhaseLaw:
    """The law of the module docstring (the interface of
    :meth:`walkerlab.models.actuation.TorqueLaws.each` and ``__call__``).

    Parameters
    ----------
    s : ndarray (m,)
        Phase variable at the collocation points, strictly monotonic [rad].
    delta, ddelta_ds : ndarray (m, k)
        Each actuator's joint angle there [rad] and its slope in ``s`` [rad/rad].
    u : ndarray (m, k)
        The optimised torques there [N m].
    stiffness, damping : sequence of float (k,)
        ``K`` [N m/rad] and ``D`` [N m s/rad] per actuator.
    t, ds : ndarray (m,), optional
        The collocation times [s] and the phase variable's rate there [rad/s]: the
        feed-forward is then the transcription's control at ``T(s)`` (module docstring);
        without them the not-a-knot cubic spline of ``u`` over ``s``.
    """

    def __init__(self, s, delta, ddelta_ds, u, stiffness, damping, t=None, ds=None):
        from scipy.interpolate import CubicHermiteSpline, CubicSpline

        s = np.asarray(s, float)
        order = np.argsort(s)
        so = s[order]
        self.h = CubicHermiteSpline(so, np.asarray(delta, float)[order],
                                    np.asarray(ddelta_ds, float)[order], extrapolate=True)
        self.dh, self.d2h = self.h.derivative(), self.h.derivative(2)
        if t is None:
            spline = CubicSpline(so, np.asarray(u, float)[order], bc_type="not-a-knot",
                                 extrapolate=True)
            self.ff, self.dff = spline, spline.derivative()
        else:
            T = CubicHermiteSpline(so, np.asarray(t, float)[order],
                                   1.0 / np.asarray(ds, float)[order], extrapolate=True)
            U = control_of_time(t, u)
            dT, dU = T.derivative(), U.derivative()
            self.ff = lambda r: U(T(r))
            self.dff = lambda r: dU(T(r)) * np.expand_dims(dT(r), -1)
        self.K = np.asarray(stiffness, float)
        self.D = np.asarray(damping, float)
        self.torques = [None] * len(self.K)  # as TorqueLaws (its length: the actuators)
        # h, h' and T (or the spline of u) share their knots: one PPoly evaluates them all
        # at a real s (the padded zero coefficient adds an exact 0: the same numbers)
        self._outer = None if t is None else U
        self._time = None if t is None else T
        self._stack = _stacked((self.h, self.dh, spline if t is None else T))

    def __bool__(self) -> bool:
        return True

    def table(self, k: int) -> np.ndarray:
        """Actuator ``k``'s law as a kind-3 table (FEEDFORWARD, :mod:`walkerlab.codegen.
        torque_law`): the knots, ``h``'s and ``T``'s coefficients (the feed-forward of ``s``
        alone as ``T(s) = s``), ``U``'s knot count, knots and coefficients (1-D)."""
        knots = self.h.x
        if self._outer is None:  # the feed-forward a spline of s: T(s) = s on s's knots
            T = np.zeros((4, len(knots) - 1))
            T[2], T[3] = 1.0, knots[:-1]
            U = self.ff
        else:
            T, U = self._time.c, self._outer
        uc = U.c.reshape(U.c.shape[0], U.c.shape[1], -1)
        uc = np.concatenate([np.zeros((4 - uc.shape[0],) + uc.shape[1:]), uc])
        return np.concatenate([knots, self.h.c[:, :, k].T.ravel(), T.T.ravel(), [len(U.x)],
                               U.x, uc[:, :, k].T.ravel()])

    def packed(self, limit: float | None = None) -> np.ndarray:
        """The law as the law block of compiled flows (:func:`walkerlab.codegen.torque_law.
        pack_laws`, kind FEEDFORWARD: the same splines' coefficients, :meth:`table`), each
        torque saturated at ``limit`` [N m] (None: not).

        Returns
        -------
        ndarray (L,)
        """
        from walkerlab.codegen.torque_law import FEEDFORWARD, pack_laws  # light

        n = len(self.h.x)
        return pack_laws([(FEEDFORWARD, 0.0, float(self.K[k]), float(self.D[k]), 0.0, limit,
                           n, None, self.table(k)) for k in range(len(self.K))])

    def __call__(self, delta, ddelta, s, ds, t_step=0.0) -> np.ndarray:
        """Torque (k,) [N m] of every actuator on the one joint angle ``delta`` [rad] and
        its rate ``ddelta`` [rad/s] (a straight-legged or kneed walker's hip: the interface
        of :meth:`walkerlab.models.actuation.TorqueLaws.__call__`)."""
        k = len(self.K)
        return self.each([delta] * k, [ddelta] * k, s, ds, t_step)

    def each(self, deltas, ddeltas, s, ds, t_step=0.0) -> np.ndarray:
        """Torque of each actuator (k,) [N m] at the joint angles ``deltas`` (k,) [rad],
        their rates ``ddeltas`` (k,) [rad/s], the phase variable ``s`` [rad] and its rate
        ``ds`` [rad/s] (``t_step`` unused: the law reads no time)."""
        if np.iscomplexobj(s):  # first order in the imaginary part (the complex step)
            h = _at(self.h, self.dh, s)
            dh = _at(self.dh, self.d2h, s)
            ff = _at(self.ff, self.dff, s)
        else:
            k = len(self.K)
            v = self._stack(s)
            h, dh = v[..., :k], v[..., k:2 * k]
            ff = v[..., 2 * k:] if self._outer is None else self._outer(v[..., 2 * k])
        err = np.asarray(deltas) - h
        derr = np.asarray(ddeltas) - dh * ds
        return ff - self.K * err - self.D * derr


def _stacked(polys):
    """One :class:`scipy.interpolate.PPoly` of the columns of ``polys`` (PPolys on the same
    breakpoints, degree <= 3, each of shape (k_i,) or scalar), lower degrees padded with
    leading zero coefficients."""
    from scipy.interpolate import PPoly

    order = max(p.c.shape[0] for p in polys)
    cs = []
    for p in polys:
        c = p.c.reshape(p.c.shape[0], p.c.shape[1], -1)
        pad = np.zeros((order - c.shape[0],) + c.shape[1:])
        cs.append(np.concatenate([pad, c]))
    return PPoly(np.concatenate(cs, axis=2), polys[0].x, extrapolate=True)


def driven_by(walker, law, limit: float):
    """``walker`` (actuated, its actuators' laws set to ``law``) with each phase's compiled
    actuated flow (:class:`walkerlab.models.compiled_flows.ActuatedFlow`) carrying ``law``'s
    block (``law.packed(limit)``, the same splines, saturated at ``limit`` [N m]) and every
    other compiled flow dropped (it would run without the law); ``law`` None: none kept."""
    from dataclasses import replace

    walker.actuators.laws = law
    block = None if law is None else law.packed(limit)
    return replace(walker, phases=tuple(
        replace(ph, compiled=replace(ph.compiled, laws=block)
                if isinstance(ph.compiled, ActuatedFlow) and block is not None else None)
        for ph in walker.phases))


def law_of_rows(rows, u, stiffness, damping, t=None,
                where: str = "the optimised step") -> PhaseLaw:
    """The law (module docstring) of a collocated step given by its joint angles.

    Parameters
    ----------
    rows : sequence of (deltas, ddeltas, s, ds)
        At each collocation point (m,): each actuator's joint angle [rad] and rate [rad/s]
        (sequences, length k), the phase variable [rad] and its rate [rad/s] (the
        actuators' ``joint_angles``).
    u, stiffness, damping, t
        As :func:`walkerlab.optimal.replay.virtual_constraints.phase_law`'s: the collocated
        torques (m, k) [N m], the PD gains (k,) and the collocation times (m,) [s].
    where : str
        The stretch of the step, for the error ("the optimised step", a phase).

    Returns
    -------
    PhaseLaw

    Raises
    ------
    ValueError
        The phase variable is not strictly monotonic there (one line).
    """
    s = np.array([float(r[2]) for r in rows])
    ds = np.array([float(r[3]) for r in rows])
    if not (np.all(ds < 0.0) or np.all(ds > 0.0)) or np.any(np.diff(s) == 0.0):
        raise ValueError("optimize: the stance leg's angle (the phase variable) is not "
                         f"monotonic over {where} (its rate spans "
                         f"[{ds.min():.3g}, {ds.max():.3g}] rad/s): no phase-variable replay")
    delta = np.array([[float(v) for v in r[0]] for r in rows])
    ddelta = np.array([[float(v) for v in r[1]] for r in rows])
    return PhaseLaw(s, delta, ddelta / ds[:, None], u, stiffness, damping, t=t, ds=ds)


def control_of_time(t, u):
    """The Hermite-Simpson control as a :class:`scipy.interpolate.PPoly` of the time since
    the heel strike [s] -> (k,) [N m]: each interval's quadratic through its three points
    (the transcriptions' own, e.g. :func:`walkerlab.optimal.transcription.free_joints.
    torques_of_time`, with derivatives),
    the last one extrapolated.

    Parameters
    ----------
    t : ndarray (2N + 1,)
        Collocation times [s].
    u : ndarray (2N + 1, k)
        Torques there [N m].
    """
    from scipy.interpolate import PPoly

    t, u = np.asarray(t, float), np.asarray(u, float).reshape(len(t), -1)
    ti, tm, tj = t[0:-1:2], t[1::2], t[2::2]
    ui, um, uj = u[0:-1:2], u[1::2], u[2::2]
    # Newton's form about t_i: u_i + a (t - t_i) + b (t - t_i)(t - t_m)
    a = ((um - ui) / (tm - ti)[:, None])
    b = ((uj - um) / (tj - tm)[:, None] - a) / (tj - ti)[:, None]
    c = np.stack([b, a - b * (tm - ti)[:, None], ui])  # (3, N, k): powers of (t - t_i)
    return PPoly(c, np.append(ti, tj[-1]), extrapolate=True)


@dataclass
class PhaseReplay:
    """A phase-variable law's replay of the optimised step on the rigid model.

    Attributes
    ----------
    collocated_start_error : float
        ``max |P(x_col) - x_col|``: one step from the collocated start [rad, rad/s].
    x0 : ndarray (2n,)
        The closed (periodic) start, or the collocated one when the law was not closed.
    start_shift : float
        ``max |x0 - x_col|`` [rad, rad/s] (0: not closed).
    return_error : float
        ``max |P(x0) - x0|`` of the rigid replay from ``x0`` [rad, rad/s] (inf: the step
        did not end in a heel strike).
    step_period_s : float
        The replayed step's period [s].
    multipliers : ndarray (2n,) complex
        Eigenvalues of the step map's Jacobian at ``x0`` (forward differences, sorted by
        modulus; the Floquet multipliers when ``x0`` is closed; one ~0: the heel-strike
        surface).
    torque_error : float
        ``max_t |tau(t) - u*(t)|`` over the replayed step from ``x0`` [N m]: the law's
        torques against the optimised ones (the transcription's control of time) at the
        same time since the heel strike.
    closed : bool
        ``x0`` is the law's fixed point (``return_error`` below the closure's tolerance).
    """

    collocated_start_error: float
    x0: np.ndarray
    start_shift: float
    return_error: float
    step_period_s: float
    multipliers: np.ndarray
    torque_error: float
    closed: bool


def replay_law(walker, solver, t, x, tau, close: bool = True, tol: float = 1e-10,
               phases: tuple | None = None) -> PhaseReplay:
    """Replay the collocated step ``(t, x)`` on ``walker`` (driven by a phase-variable law),
    closed to the law's fixed point when ``close``.

    The step map ``P`` (one step of ``walker`` by ``solver``) is differentiated by forward
    differences (``h`` = 1e-6 rad, rad/s; the map's round-off ~1e-12), its fixed point
    solved by MINPACK's hybrj (``scipy.optimize.root``) from the collocated start with that
    Jacobian; the multipliers are the eigenvalues of the forward differences at the closed
    start (at the collocated one when not closed): ``2n + 1`` step maps not closed,
    ``2 (2n + 1)`` + the root finder's closed.

    Parameters
    ----------
    walker : HybridWalker
        The rigid walker, its actuators driven by the law (their ``torques(t, x)``).
    solver : walkerlab.integrate.solver.Solver
    t : ndarray (m,)
        Collocation times since the heel strike [s].
    x : ndarray (m, 2n)
        Collocated states [rad, rad/s].
    tau : callable
        The optimised torques as a function of the time since the heel strike [s] ->
        (k,) or scalar [N m] (for ``torque_error``).
    close : bool
        Close the step (else the replay from the collocated start is the one reported).
    tol : float
        Largest return error [rad, rad/s] of a closed start.
    phases : tuple of str, optional
        The phases a step must cross in this order (a step of phases; None: any).

    Returns
    -------
    PhaseReplay
        ``return_error`` inf, NaN multipliers when a step does not end in a heel strike
        (or crosses other phases).
    """
    x_col = np.asarray(x, float)[0]
    horizon = 3.0 * float(t[-1])

    def step(z):
        seg = integrate_step(walker, np.asarray(z, float), solver, max_step_time=horizon)
        if seg.termination != "heel_strike":
            raise ValueError(f"the replayed step ended in {seg.termination}")
        if phases is not None and tuple(ph.name for ph, _s, _ab in seg.pieces) != phases:
            raise ValueError("the replayed step crossed other phases than the optimised ones")
        return seg

    try:
        p_col = step(x_col).x_next
        J = fd_jacobian(lambda z: step(z).x_next, x_col, 1e-6, central=False, f0=p_col)
    except ValueError:
        return PhaseReplay(float("inf"), x_col, 0.0, float("inf"), float("nan"),
                           np.full(x_col.size, np.nan + 0j), float("nan"), False)
    e_col = float(np.max(np.abs(p_col - x_col)))
    x0, seg = _closed_start(step, x_col, J, close and e_col > tol)
    err = float(np.max(np.abs(seg.x_next - x0)))
    closed = bool(close and err <= tol)
    if x0 is not x_col:
        J = fd_jacobian(lambda z: step(z).x_next, x0, 1e-6, central=False, f0=seg.x_next)
    return PhaseReplay(e_col, np.asarray(x0, float), float(np.max(np.abs(x0 - x_col))), err,
                       float(seg.t_end), sort_multipliers(np.linalg.eigvals(J)),
                       torque_error(walker, seg, t, tau), closed)


def _closed_start(step, x_col, J, close: bool):
    """The start of the replayed step and its step: the fixed point of the step map from the
    collocated start ``x_col`` by MINPACK's hybrj (``scipy.optimize.root``, Jacobian ``J``
    of the map minus the identity) when ``close``, else (or where the root finder's iterate
    falls or does not step) ``x_col``.  ``step(z)`` is one step from ``z``; returns ``(x0,
    seg)``."""
    from scipy.optimize import root

    x0 = x_col
    if close:
        eye = np.eye(x_col.size)
        try:
            sol = root(lambda z: step(z).x_next - z, x_col, jac=lambda z: J - eye,
                       method="hybr", options={"xtol": 1e-13})
            x0 = sol.x
        except ValueError:  # a fall on the way
            x0 = x_col
    try:
        seg = step(x0)
    except ValueError:  # the root finder's last iterate does not step: the collocated start
        x0 = x_col
        seg = step(x0)
    return x0, seg


def torque_error(walker, seg, t, tau) -> float:
    """``max |tau(t) - u*(t)|`` [N m] over the replayed step ``seg`` (4 samples per
    collocation point ``t`` (m,)): the law's torques (``walker.actuators.torques``) against
    ``tau``, the optimised ones as a function of the time since the heel strike [s]."""
    ts = np.linspace(seg.t_start, seg.t_end, 4 * len(t))
    xs = seg.sample(ts).T
    return max(float(np.max(np.abs(walker.actuators.torques(ti, xi) - tau(ti - seg.t_start))))
               for ti, xi in zip(ts, xs))
