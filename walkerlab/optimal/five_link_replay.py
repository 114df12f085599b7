"""A five-link biped's optimised step replayed as virtual constraints: the torques as a
function of the phase variable, with PD feedback on the collocated joint trajectory.

Phase variable ``s``: the virtual stance leg's absolute angle (hip to stance foot, the
generated ``leg_angles``' ``stance``; Westervelt, Grizzle & Koditschek 2003, IEEE TAC
48(1):42-56, Sec. IV), strictly monotonic over an optimised step (it decreases: checked,
else refused).  On the collocated step ``(t_i, x_i, u_i)`` each actuator's joint angle
``delta_k`` (:data:`walkerlab.optimal.five_link.JOINTS`) becomes a reference of ``s``: the
cubic Hermite spline ``h_k`` through ``(s_i, delta_k(x_i))`` with the slopes
``ddelta_k(x_i) / ds(x_i)`` (so ``delta = h(s)`` and ``ddelta = h'(s) ds`` hold at every
collocation point), the torque the transcription's own control (the quadratic in time of
each Hermite-Simpson interval, :func:`walkerlab.optimal.five_link_collocation.
torques_of_time`) at the time ``T(s)`` the collocated step passes ``s`` (``T`` the cubic
Hermite spline through ``(s_i, t_i)`` with slopes ``1 / ds(x_i)``; a cubic spline of ``u``
over ``s`` smooths the control's kinks at the interval ends, and a replay from the
collocated start returns 6.6 times farther); the law::

    tau_k = u_k(s) - K_k (delta_k - h_k(s)) - D_k (ddelta_k - h_k'(s) ds)

(feed-forward plus PD, the PD term zero on the collocated step; ``K = D = 0``: the pure
phase-variable feed-forward).  Gains: RABBIT's (``configs/rabbit.yaml``: 2000 N m/rad;
120 N m s/rad at the hips, 60 at the knees).  The splines extrapolate past the table's
ends (a replayed step may end slightly after the collocated one; their cubic there is the
end interval's).

Complex-safe to first order (``f(a + i e) = f(a) + i e f'(a)``): the rigid model's
variational equations differentiate the law by the complex step.

The same object drives both views: the rigid model's
:class:`~walkerlab.models.hybrid.actuated_five_link.FiveLinkActuators` and the contact
model's :class:`~walkerlab.models.contact.joint_torques.JointTorqueActuators` call its
``each(deltas, ddeltas, s, ds, t_step)`` as they call
:meth:`walkerlab.models.actuation.TorqueLaws.each`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from walkerlab.numerics import sort_multipliers

__all__ = ["RABBIT_GAINS", "PhaseLaw", "PhaseReplay", "control_of_time", "phase_law",
           "phase_replays", "phased_walker", "replay_phase_law", "replay_solver",
           "rigid_actuators"]

#: PD gains ``(K [N m/rad], D [N m s/rad])`` per joint (:data:`walkerlab.optimal.five_link.
#: JOINTS` order), RABBIT's virtual-constraint controller of configs/rabbit.yaml
RABBIT_GAINS = ((2000.0, 2000.0, 2000.0, 2000.0), (120.0, 120.0, 60.0, 60.0))


def _at(f, df, u):
    """``f(u)`` of a real spline, complex-safe to first order."""
    r = np.real(u)
    out = f(r)
    if np.iscomplexobj(u):
        out = out + 1j * np.imag(u) * df(r)
    return out


class PhaseLaw:
    """The law of the module docstring (the interface of
    :meth:`walkerlab.models.actuation.TorqueLaws.each`).

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
        self._stack = _stacked((self.h, self.dh, spline if t is None else T))

    def __bool__(self) -> bool:
        return True

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


def phase_law(acts, x, u, stiffness, damping, t=None) -> PhaseLaw:
    """The law of the collocated step ``x``, ``u`` (module docstring).

    Parameters
    ----------
    acts : FiveLinkActuators
        The rigid walker's actuators on :data:`walkerlab.optimal.five_link.JOINTS` (their
        ``joint_angles``).
    x : ndarray (m, 2n)
        Collocated states (``state_names()`` order) [rad, rad/s].
    u : ndarray (m, k)
        Collocated torques [N m].
    stiffness, damping : sequence of float (k,)
        PD gains [N m/rad], [N m s/rad] (zeros: the feed-forward alone).
    t : ndarray (m,), optional
        Collocation times [s] (the feed-forward: the control at ``T(s)``; without: a
        spline of ``u`` over ``s``).

    Returns
    -------
    PhaseLaw

    Raises
    ------
    ValueError
        The phase variable is not strictly monotonic over the step (one line).
    """
    rows = [acts.joint_angles(xi) for xi in np.asarray(x, float)]
    s = np.array([float(r[2]) for r in rows])
    ds = np.array([float(r[3]) for r in rows])
    if not (np.all(ds < 0.0) or np.all(ds > 0.0)) or np.any(np.diff(s) == 0.0):
        raise ValueError("optimize: the stance leg's angle (the phase variable) is not "
                         f"monotonic over the optimised step (its rate spans "
                         f"[{ds.min():.3g}, {ds.max():.3g}] rad/s): no phase-variable replay")
    delta = np.array([[float(v) for v in r[0]] for r in rows])
    ddelta = np.array([[float(v) for v in r[1]] for r in rows])
    return PhaseLaw(s, delta, ddelta / ds[:, None], u, stiffness, damping, t=t, ds=ds)


def control_of_time(t, u):
    """The Hermite-Simpson control as a :class:`scipy.interpolate.PPoly` of the time since
    the heel strike [s] -> (k,) [N m]: each interval's quadratic through its three points
    (:func:`walkerlab.optimal.five_link_collocation.torques_of_time`'s, with derivatives),
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


def phased_walker(data, law: PhaseLaw):
    """The rigid five-link walker (its generated code, phases, guards and reset) driven by
    ``law`` on :data:`walkerlab.optimal.five_link.JOINTS`: its flow in Python (the law is
    a Python callable; the compiled flows, which carry only tabled laws, are dropped so
    that no backend runs them)."""
    from dataclasses import replace

    from walkerlab.config.actuation import Actuation, JointTorque, TorqueLaw
    from walkerlab.models.hybrid.actuated import actuate
    from walkerlab.models.hybrid.rigid import make_rigid_walker
    from walkerlab.optimal.five_link import JOINTS

    spec = Actuation(torques=[JointTorque(joint=j, law=TorqueLaw(), max_torque_n_m=1e6)
                              for j in JOINTS])
    walker = actuate(make_rigid_walker(data, "biped", "derived"), data, spec)
    walker.actuators.laws = law
    return replace(walker, phases=tuple(replace(ph, compiled=None) for ph in walker.phases))


def rigid_actuators(data):
    """The rigid walker's actuators on :data:`walkerlab.optimal.five_link.JOINTS` (for
    :func:`phase_law`)."""
    from walkerlab.config.actuation import Actuation, JointTorque, TorqueLaw
    from walkerlab.models.hybrid.actuated_five_link import five_link_actuators
    from walkerlab.optimal.five_link import JOINTS

    spec = Actuation(torques=[JointTorque(joint=j, law=TorqueLaw()) for j in JOINTS])
    return five_link_actuators(data, spec, tuple(data.structure.roles))


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
        torques against the optimised ones (:func:`walkerlab.optimal.five_link_collocation.
        torques_of_time`) at the same time since the heel strike.
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


def replay_solver():
    """The replay's integrator: LSODA at rtol = atol = 1e-12, scipy's (the law is a Python
    callback; at RABBIT's gains the flow is stiff and LSODA switches to BDF, ~2.5x fewer
    evaluations than DOP853)."""
    from walkerlab.integrate.solver import Solver

    return Solver(method="LSODA", rtol=1e-12, atol=1e-12, backend="scipy")


def replay_phase_law(data, t, x, u, law: PhaseLaw, close: bool = True,
                     tol: float = 1e-10) -> PhaseReplay:
    """Replay the collocated step ``(t, x, u)`` under ``law`` on the rigid model, closed
    to the law's fixed point when ``close``.

    The step map ``P`` (one step of :func:`phased_walker`, :func:`replay_solver`) is
    differentiated by forward differences (``h`` = 1e-6 rad, rad/s; the map's round-off
    ~1e-12), its fixed point solved by MINPACK's hybrj (``scipy.optimize.root``) from the
    collocated start with that Jacobian; the multipliers are the eigenvalues of the forward
    differences at the closed start (at the collocated one when not closed).  ~25 step
    maps closed (~2.5 s CPU each: the PD gains make the flow stiff), 11 not.

    Parameters
    ----------
    data : WalkerData
    t : ndarray (m,)
        Collocation times [s].
    x : ndarray (m, 2n)
        Collocated states [rad, rad/s].
    u : ndarray (m, k)
        Collocated torques [N m].
    law : PhaseLaw
    close : bool
        Close the step (else the replay from the collocated start is the one reported).
    tol : float
        Largest return error [rad, rad/s] of a closed start.

    Returns
    -------
    PhaseReplay
        ``return_error`` inf, NaN multipliers when a step does not end in a heel strike.
    """
    from scipy.optimize import root

    from walkerlab.integrate.rigid import integrate_step
    from walkerlab.numerics import fd_jacobian

    walker, solver = phased_walker(data, law), replay_solver()
    x_col = np.asarray(x, float)[0]
    horizon = 3.0 * float(t[-1])

    def step(z):
        seg = integrate_step(walker, np.asarray(z, float), solver, max_step_time=horizon)
        if seg.termination != "heel_strike":
            raise ValueError(f"the replayed step ended in {seg.termination}")
        return seg

    try:
        p_col = step(x_col).x_next
        J = fd_jacobian(lambda z: step(z).x_next, x_col, 1e-6, central=False, f0=p_col)
    except ValueError:
        return PhaseReplay(float("inf"), x_col, 0.0, float("inf"), float("nan"),
                           np.full(x_col.size, np.nan + 0j), float("nan"), False)
    e_col = float(np.max(np.abs(p_col - x_col)))
    x0 = x_col
    if close and e_col > tol:
        eye = np.eye(x_col.size)
        try:
            sol = root(lambda z: step(z).x_next - z, x_col, jac=lambda z: J - eye,
                       method="hybr", options={"xtol": 1e-13})
            x0 = sol.x
        except ValueError:  # a fall on the way
            x0 = x_col
    seg = step(x0)
    err = float(np.max(np.abs(seg.x_next - x0)))
    closed = bool(close and err <= tol)
    if x0 is not x_col:
        J = fd_jacobian(lambda z: step(z).x_next, x0, 1e-6, central=False, f0=seg.x_next)
    return PhaseReplay(e_col, np.asarray(x0, float), float(np.max(np.abs(x0 - x_col))), err,
                       float(seg.t_end), sort_multipliers(np.linalg.eigvals(J)),
                       _torque_error(walker, seg, t, u), closed)


def _torque_error(walker, seg, t, u) -> float:
    """``max |tau(t) - u*(t)|`` [N m] over the replayed step ``seg`` (4 samples per
    collocation point)."""
    from walkerlab.optimal.five_link_collocation import torques_of_time

    tau = torques_of_time(t, u)
    ts = np.linspace(seg.t_start, seg.t_end, 4 * len(t))
    xs = seg.sample(ts).T
    return max(float(np.max(np.abs(walker.actuators.torques(ti, xi) - tau(ti - seg.t_start))))
               for ti, xi in zip(ts, xs))


def phase_replays(data, t, x, u) -> tuple[dict, dict]:
    """Both phase-variable replays of a collocated step: ``feedback`` (RABBIT's gains,
    closed to its fixed point) and ``feedforward`` (no PD: unstable, reported from the
    collocated start, its multipliers those of the step map there).

    Parameters
    ----------
    data : WalkerData
    t, x, u : ndarray
        As :func:`replay_phase_law`.

    Returns
    -------
    replays : dict
        ``{"feedback": PhaseReplay, "feedforward": PhaseReplay}``.
    laws : dict
        The two :class:`PhaseLaw` by the same names.

    Raises
    ------
    ValueError
        The phase variable is not monotonic over the step (one line).
    """
    acts = rigid_actuators(data)
    zero = (0.0,) * len(RABBIT_GAINS[0])
    laws = {"feedback": phase_law(acts, x, u, *RABBIT_GAINS, t=t),
            "feedforward": phase_law(acts, x, u, zero, zero, t=t)}
    replays = {name: replay_phase_law(data, t, x, u, law, close=name == "feedback")
               for name, law in laws.items()}
    return replays, laws
