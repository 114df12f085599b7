"""A five-link biped's optimised step replayed as virtual constraints: the torques as a
function of the phase variable, with PD feedback on the collocated joint trajectory.

Phase variable ``s``: the virtual stance leg's absolute angle (hip to stance foot, the
generated ``leg_angles``' ``stance``; Westervelt, Grizzle & Koditschek 2003, IEEE TAC
48(1):42-56, Sec. IV), strictly monotonic over an optimised step (it decreases: checked,
else refused).  On the collocated step ``(t_i, x_i, u_i)`` each actuator's joint angle
``delta_k`` (:data:`walkerlab.optimal.transcription.free_joint_functions.JOINTS`) becomes a
reference of ``s``: the
cubic Hermite spline ``h_k`` through ``(s_i, delta_k(x_i))`` with the slopes
``ddelta_k(x_i) / ds(x_i)`` (so ``delta = h(s)`` and ``ddelta = h'(s) ds`` hold at every
collocation point), the torque the transcription's own control (the quadratic in time of
each Hermite-Simpson interval, :func:`walkerlab.optimal.transcription.free_joints.
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
:class:`~walkerlab.models.hybrid.free_joint_actuators.FiveLinkActuators` and the contact
model's :class:`~walkerlab.models.contact.joint_torques.JointTorqueActuators` call its
``each(deltas, ddeltas, s, ds, t_step)`` as they call
:meth:`walkerlab.models.actuation.TorqueLaws.each`.
"""

from __future__ import annotations

import numpy as np

from walkerlab.config.actuation import Actuation, JointTorque, TorqueLaw
from walkerlab.models.hybrid.actuated import actuate
from walkerlab.models.hybrid.free_joint_actuators import five_link_actuators
from walkerlab.optimal.replay.phase import (
    LIMIT_N_M,
    PhaseLaw,
    PhaseReplay,
    driven_by,
    law_of_rows,
    replay_law,
)

__all__ = ["RABBIT_GAINS", "phase_law", "phase_replays", "phased_walker", "replay_phase_law",
           "replay_solver", "rigid_actuators"]

#: PD gains ``(K [N m/rad], D [N m s/rad])`` per joint
#: (:data:`walkerlab.optimal.transcription.free_joint_functions.
#: JOINTS` order), RABBIT's virtual-constraint controller of configs/rabbit.yaml
RABBIT_GAINS = ((2000.0, 2000.0, 2000.0, 2000.0), (120.0, 120.0, 60.0, 60.0))


def phase_law(acts, x, u, stiffness, damping, t=None) -> PhaseLaw:
    """The law of the collocated step ``x``, ``u`` (module docstring).

    Parameters
    ----------
    acts : FiveLinkActuators
        The rigid walker's actuators on
        :data:`walkerlab.optimal.transcription.free_joint_functions.JOINTS` (their
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
    return law_of_rows(rows, u, stiffness, damping, t=t)


def phased_walker(data, law: PhaseLaw):
    """The rigid five-link walker (its generated code, phases, guards and reset) driven by
    ``law`` on :data:`walkerlab.optimal.transcription.free_joint_functions.JOINTS`: in Python
    (``law`` called) and
    compiled (its flows' law block :meth:`PhaseLaw.packed`, the same splines: the
    ``cyrk_compiled`` backend of :func:`replay_solver` runs it without a Python callback)."""
    from walkerlab.models.hybrid.rigid import make_rigid_walker
    from walkerlab.optimal.transcription.free_joint_functions import JOINTS

    spec = Actuation(torques=[JointTorque(joint=j, law=TorqueLaw(), max_torque_n_m=LIMIT_N_M)
                              for j in JOINTS])
    return driven_by(actuate(make_rigid_walker(data, "biped", "derived"), data, spec), law,
                     LIMIT_N_M)


def rigid_actuators(data):
    """The rigid walker's actuators on
    :data:`walkerlab.optimal.transcription.free_joint_functions.JOINTS` (for
    :func:`phase_law`)."""
    from walkerlab.optimal.transcription.free_joint_functions import JOINTS

    spec = Actuation(torques=[JointTorque(joint=j, law=TorqueLaw()) for j in JOINTS])
    return five_link_actuators(data, spec, tuple(data.structure.roles))


def replay_solver():
    """The replay's integrator: DOP853 at rtol = atol = 1e-12 on CyRK with the compiled
    flows of :func:`phased_walker` (the law in the cfunc, not a Python callback of
    scipy's LSODA)."""
    from walkerlab.integrate.solver import Solver

    return Solver(method="DOP853", rtol=1e-12, atol=1e-12, backend="cyrk_compiled")


def replay_phase_law(data, t, x, u, law: PhaseLaw, close: bool = True,
                     tol: float = 1e-10) -> PhaseReplay:
    """Replay the collocated step ``(t, x, u)`` under ``law`` on the rigid model, closed
    to the law's fixed point when ``close``.

    The step map ``P`` (one step of :func:`phased_walker`, :func:`replay_solver`) is
    differentiated by forward differences (``h`` = 1e-6 rad, rad/s; the map's round-off
    ~1e-12), its fixed point solved by MINPACK's hybrj (``scipy.optimize.root``) from the
    collocated start with that Jacobian; the multipliers are the eigenvalues of the forward
    differences at the closed start (at the collocated one when not closed).  ~25 step
    maps closed (on the compiled flows), 11 not.

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
    from walkerlab.optimal.transcription.free_joints import torques_of_time

    return replay_law(phased_walker(data, law), replay_solver(), t, x, torques_of_time(t, u),
                      close=close, tol=tol)


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
    from walkerlab import progress

    replays = {}
    with progress.task("optimize: phase-variable replays (feedback closed, feed-forward; "
                       "~35 rigid step maps on compiled flows)", len(laws)) as bar:
        for name, law in laws.items():
            replays[name] = replay_phase_law(data, t, x, u, law, close=name == "feedback")
            bar.advance(info=name)
    return replays, laws
