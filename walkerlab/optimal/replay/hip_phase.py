"""A straight-legged or kneed walker's optimised step replayed with its hip torque as a
function of the phase variable (:mod:`walkerlab.optimal.replay.phase`'s law and replay).

Phase variable ``s``: the stance leg's absolute angle (the actuators' ``hip_angles``: the
stance thigh's on a kneed walker, whose stance knee is locked), strictly monotonic over the
optimised step (it decreases; checked, else refused in one line).  The one actuated
coordinate is the hip angle ``delta`` (swing minus stance leg, thighs on a kneed walker);
the law::

    tau = u(s) - K (delta - h(s)) - D (ddelta - h'(s) ds)

with ``u(s)`` the optimised torque at the time the collocated step passes ``s`` and
``h(s)`` the collocated hip angle (:class:`~walkerlab.optimal.replay.phase.PhaseLaw`).
A step of phases (a kneed walker's unlocked and locked swing) gets one such law per phase,
each from that phase's collocation points, monotonic in each (the phase variable's rate
jumps at the knee strike); the law in force is the phase whose stretch of ``s`` holds the
present value (the breaks at the collocated phase changes): still a function of ``s``
alone.

Gains: the hip angle's error obeys ``e'' + 2 w e' + w^2 e = 0`` in the linearised flow
(critical damping) at ``w = BANDWIDTH sqrt(g / l)``: ``K = w^2 / b``, ``D = 2 w / b`` with
``b = d(ddelta)/dt per unit torque`` (``dd/dq . M^-1 B``, the hip's mobility at the
collocated start; on massless legs the torque per foot mass, Kuo 2002).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from walkerlab import progress
from walkerlab.config.actuation import Actuation, JointTorque, PushOff, TorqueLaw
from walkerlab.integrate.solver import CYRK_METHODS, available_backends
from walkerlab.models.hybrid.actuated import actuate
from walkerlab.models.hybrid.rigid import make_rigid_walker
from walkerlab.optimal.replay.phase import (
    LIMIT_N_M,
    PhaseLaw,
    driven_by,
    law_of_rows,
    replay_law,
)

__all__ = ["BANDWIDTH", "CLOSED", "LIMIT_N_M", "PiecewisePhaseLaw", "hip_gains",
           "hip_phase_law", "hip_phase_replays", "hip_walker",
           "replay_solver"]

#: the PD law's closed-loop frequency in units of the leg's pendulum frequency sqrt(g / l)
BANDWIDTH = 4.0
#: largest return error of a closed start [rad, rad/s]: above the step map's round-off
#: (flat feet's four phases, the ankle's fast start: the root finder's best 2.3e-10)
CLOSED = 1e-9


class PiecewisePhaseLaw:
    """One :class:`~walkerlab.optimal.replay.phase.PhaseLaw` per phase of a step, chosen by
    the phase variable ``s`` (the interface of :meth:`walkerlab.models.actuation.
    TorqueLaws.__call__`).

    Parameters
    ----------
    laws : list of PhaseLaw
        One per phase, in the step's order.
    breaks : sequence of float
        ``s`` [rad] where each phase after the first begins (len(laws) - 1).
    sign : float
        The sign of the phase variable's rate over the step (-1: it decreases).
    """

    def __init__(self, laws, breaks, sign: float):
        self.laws, self.breaks, self.sign = list(laws), np.asarray(breaks, float), sign
        self.K, self.D = self.laws[0].K, self.laws[0].D
        self.torques = self.laws[0].torques

    def __bool__(self) -> bool:
        return True

    def law_at(self, s) -> PhaseLaw:
        """The law in force at the phase variable ``s`` [rad] (complex: its real part)."""
        passed = int(np.sum(self.sign * (float(np.real(s)) - self.breaks) >= 0.0))
        return self.laws[passed]

    def packed(self, limit: float | None = None) -> np.ndarray:
        """The law block of compiled flows (:func:`walkerlab.codegen.torque_law.pack_laws`,
        kind PIECEWISE: each piece :meth:`PhaseLaw.table`, chosen by ``s`` as
        :meth:`law_at`), each torque saturated at ``limit`` [N m] (None: not).

        Returns
        -------
        ndarray (L,)
        """
        from walkerlab.codegen.torque_law import PIECEWISE, pack_laws  # light

        rows = []
        for k in range(len(self.K)):
            pieces = [np.concatenate([[len(law.h.x)], law.table(k)]) for law in self.laws]
            head = 1 + len(self.breaks) + len(pieces)
            offsets = head + np.cumsum([0] + [p.size for p in pieces[:-1]])
            table = np.concatenate([[self.sign], self.breaks, offsets, *pieces])
            rows.append((PIECEWISE, 0.0, float(self.K[k]), float(self.D[k]), 0.0, limit,
                         len(pieces), None, table))
        return pack_laws(rows)

    def each(self, deltas, ddeltas, s, ds, t_step=0.0) -> np.ndarray:
        """:meth:`PhaseLaw.each` of the law in force at ``s``."""
        return self.law_at(s).each(deltas, ddeltas, s, ds, t_step)

    def __call__(self, delta, ddelta, s, ds, t_step=0.0) -> np.ndarray:
        """:meth:`PhaseLaw.__call__` of the law in force at ``s``."""
        return self.law_at(s)(delta, ddelta, s, ds, t_step)


def hip_walker(data, law, push_off_n_s: float = 0.0):
    """The rigid walker of ``data`` (its generated code, phases, guards and reset) with a hip
    actuator driven by ``law`` and the push-off ``push_off_n_s`` [N s] (0: none): its flow
    in Python (``law`` called) and, where the walker has compiled actuated flows (massive
    legs: straight or kneed, point feet), compiled with the law's block (``law.packed``,
    the same splines); without a law (None) no compiled flow."""

    st = data.structure
    massless = bool(st.bodies) and all(b.massless for b in st.bodies)
    push = PushOff(impulse_n_s=max(push_off_n_s, 0.0)) if push_off_n_s > 0.0 else None
    spec = Actuation(push_off=push,
                     torques=[JointTorque(joint="hip", law=TorqueLaw(),
                                          max_torque_n_m=LIMIT_N_M,
                                          scaled_by="foot_mass" if massless else "none")])
    return driven_by(actuate(make_rigid_walker(data, "biped", "derived"), data, spec), law,
                     LIMIT_N_M)


def replay_solver(walker, solver):
    """The solver of the replays: ``solver`` on CyRK's compiled flows (``cyrk_compiled``)
    when every phase of ``walker`` has one and CyRK integrates ``solver``'s method, else
    ``solver`` itself (the law then a Python callback)."""
    if (all(ph.compiled is not None for ph in walker.phases) and solver.method in CYRK_METHODS
            and "cyrk" in available_backends()):
        return replace(solver, backend="cyrk_compiled")
    return solver


def hip_gains(data, acts, x0, walker=None) -> tuple[float, float]:
    """``(K, D)`` of the module docstring at the state ``x0`` (2n,) [N m/rad, N m s/rad;
    per foot mass on massless legs]: the mobility ``b`` from the generated mass matrix, or
    (flat feet: a mass matrix per contact mode) from ``walker``'s first phase's flow under
    a unit torque and under none (``walker``: :func:`hip_walker`'s)."""
    x0 = np.asarray(x0, float)
    if "matrices" in acts.fns:
        M = np.asarray(acts.fns["matrices"](x0)[0], float)
        col = np.eye(acts.n)[0] if acts.limit else acts.ddelta_dq
        b = float(acts.ddelta_dq @ np.linalg.solve(M, col))
    else:
        flow, saved = walker.phases[0].flow, walker.actuators.laws
        acc = []
        for v in (1.0, 0.0):
            walker.actuators.laws = lambda *_a, v=v: np.array([v])
            acc.append(np.asarray(flow(0.0, x0), float)[acts.n:])
        walker.actuators.laws = saved
        b = float(acts.ddelta_dq @ (acc[0] - acc[1]))
    w = BANDWIDTH * np.sqrt(data.gravity_m_per_s2 / data.leg_length_m)
    return w * w / b, 2.0 * w / b


def hip_phase_law(acts, t, x, u, gains, phase_start=None, phase_names=()):
    """The law of the module docstring for a collocated step.

    Parameters
    ----------
    acts : walkerlab.models.hybrid.actuated.Actuators
        The rigid walker's actuators (their ``hip_angles``).
    t : ndarray (m,)
        Collocation times since the heel strike [s].
    x : ndarray (m, 2n)
        Collocated states [rad, rad/s].
    u : ndarray (m,)
        Collocated hip torque [N m; N m/kg on massless legs].
    gains : (float, float)
        ``(K, D)`` (zeros: the feed-forward alone).
    phase_start : ndarray (P,) of int, optional
        Index of each phase's first point (a step of phases; None: one).
    phase_names : tuple of str
        The phases' names (for the error).

    Returns
    -------
    PhaseLaw or PiecewisePhaseLaw

    Raises
    ------
    ValueError
        The phase variable is not strictly monotonic over the step or one of its phases
        (one line).
    """
    x, u = np.asarray(x, float), np.asarray(u, float).reshape(len(t), -1)
    rows = [([d], [dd], s, ds) for d, dd, s, ds in (acts.hip_angles(xi) for xi in x)]
    K, D = (gains[0],), (gains[1],)
    if phase_start is None or len(phase_start) < 2:
        return law_of_rows(rows, u, K, D, t=np.asarray(t, float))
    ends = list(phase_start[1:]) + [len(t)]
    rates = np.array([float(r[3]) for r in rows])
    if not (np.all(rates < 0.0) or np.all(rates > 0.0)):
        law_of_rows(rows, u, K, D)  # raises: the whole step's line
    laws = [law_of_rows(rows[a:b], u[a:b], K, D, t=np.asarray(t[a:b], float),
                        where=f"the optimised step's phase {name}")
            for a, b, name in zip(phase_start, ends, phase_names)]
    breaks = [float(rows[a][2]) for a in phase_start[1:]]
    return PiecewisePhaseLaw(laws, breaks, float(np.sign(rates[0])))


def hip_phase_replays(data, res, tau, solver) -> dict:
    """Both phase-variable replays of an optimised step: ``feedback`` (the PD gains of
    :func:`hip_gains`, closed to its fixed point by scipy's root finder) and ``feedforward``
    (no PD, reported from the collocated start, its multipliers those of the step map
    there) (:func:`walkerlab.optimal.replay.phase.replay_law`).

    Parameters
    ----------
    data : WalkerData
    res : CollocationResult or PhasedResult
        The optimised step (``t``, ``x``, ``u``; a step of phases: ``phase_start``,
        ``phase_names``; the push-off ``push_off_n_s`` when it has one).
    tau : callable
        The optimised torque as a function of the time since the heel strike [s] -> [N m].
    solver : walkerlab.integrate.solver.Solver

    Returns
    -------
    dict
        ``{"feedback": PhaseReplay, "feedforward": PhaseReplay}``.

    Raises
    ------
    ValueError
        The phase variable is not monotonic over the step or a phase of it (one line).
    """
    names = tuple(getattr(res, "phase_names", ()) or ())
    start = getattr(res, "phase_start", None)
    push = float(getattr(res, "push_off_n_s", 0.0))
    walker = hip_walker(data, None, push)
    probe = walker.actuators
    gains = {"feedback": hip_gains(data, probe, res.x[0], walker), "feedforward": (0.0, 0.0)}
    out = {}
    with progress.task("optimize: phase-variable replays (feedback closed, feed-forward)",
                       len(gains)) as bar:
        for name, g in gains.items():
            law = hip_phase_law(probe, res.t, res.x, res.u, g, start, names)
            driven = hip_walker(data, law, push)
            out[name] = replay_law(driven, replay_solver(driven, solver), res.t, res.x, tau,
                                   close=name == "feedback", tol=CLOSED, phases=names or None)
            bar.advance(info=name)
    return out
