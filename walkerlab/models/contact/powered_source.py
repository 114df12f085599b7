"""The compiled right-hand side of a powered contact walker: the actuation as data.

Every actuated contact walker (straight or kneed legs; point, arc or flat feet; a torso; a
free-jointed biped) runs on one compiled right-hand side, ``powered_packed``, in its
generated contact module (:mod:`walkerlab.models.contact.generated`; a few lines of glue,
:func:`powered_source`, that hand the structure's kinematics to the kernels of
:mod:`walkerlab.models.contact.powered_kernels`): the walker's own straight-line dynamics
with a generalised force added (``rhs_q``) and, in the same call, the forces of its
actuators computed from an *actuation block* of numbers in the data vector.  The block says
everything a run's discrete state changes (which leg is in stance, when the step began,
whether a push-off pulse or an ankle push-off is on), so the event loop
(:mod:`walkerlab.integrate.contact_powered`) changes numbers between its events and never
calls Python inside a step.

The forces are those of :func:`walkerlab.models.contact.actuation.powered_rhs` (the
reference arithmetic; a test holds the two equal on every kind of walker):

- joint torques ``tau_k`` of the laws of :mod:`walkerlab.codegen.torque_law` (plain
  spring-dampers, phase and time tables, the replays' feed-forward laws; saturation), at
  the joint angles ``delta = B^T q`` (``B`` (nq, k) the stance's joint columns: ``+1`` on a
  joint's second link, ``-1`` on its first, ``1/2`` on each leg for a bisecting torso) and
  the phase variable ``s``: a coordinate (the stance leg's or stance thigh's angle), or the
  virtual stance leg's angle ``atan(-(hip - foot)_x / (hip - foot)_y)`` of a free-jointed
  biped (Westervelt, Grizzle & Koditschek 2003); ``Q += B tau``, power ``tau . d delta/dt``;
- a flat foot's ankle push-off ``tau_a = -K (a - a_0) - c`` on ``(foot, leg)`` while on;
- the push-off pulse: a force ``F e`` at the trailing foot's push point along the line to
  its leg's hip (the generated ``hips``: a 3D walker's own end of the hip axis),
  ``Q += J^T F e`` (on a flat foot with the ankle torque ``lam`` that holds the ankle:
  ``a M^-1 (J^T F e + a lam) = 0``);
- a generalised force held from outside (a Gymnasium action's torques, per stance leg),
  power ``E . dq``;
- the ledger's powers: ``W = [tau+, tau-, ankle+, ankle-, push, damper, contact, joint
  law (the knee stops'; a 3D walker's hip-roll law's), action+, action-]``, of which
  the block's work map picks the run's work integrals in order.

The actuation block ``A`` (after the passive data ``[n1, n2, PC, p, c1, c2]``; then the call
counter):

=============  =============================================================================
``A[0]``       the block's length
``A[1]``       nq
``A[2]``       k, the number of joint torques
``A[3]``       phase mode: 0 a coordinate, 1 the virtual stance leg
``A[4]``       the phase's coordinate (mode 0) or the stance foot's contact point (mode 1)
               with leg1 in stance (``A[31]`` with leg2)
``A[5]``       the push-off pulse's contact point (-1: no pulse on)
``A[6]``       the pulse's force [N]
``A[7:9]``     the hip's position coordinates
``A[9]``       the ankle push-off is on (0/1)
``A[10:12]``   the stance ankle's foot and leg coordinates with leg1 in stance (``A[32:34]``
               with leg2)
``A[12:15]``   the ankle push-off's stiffness [N m/rad], rest angle [rad], constant [N m]
``A[15]``      the pulse holds a flat foot's ankle (1), ``A[16:18]`` its foot and leg; a
               3D walker's trailing foot's spin about the normal (2); neither (0)
``A[18:20]``   the ankle dampers' and the leg springs' damping [N m s/rad]
``A[20:26]``   feet (2), ankle legs (2), legs (2) coordinates of the dampers' power
``A[26]``      the ledger has the dampers' term (0/1)
``A[27]``      m, the number of work integrals; ``A[34:34 + m]`` their indices in ``W``
``A[28]``      the stance leg (0: leg1, 1: leg2) before the switch time
``A[29]``      the switch time [s] (inf: none): from it the other leg is in stance, its step
               begun then, the ankle push-off off (a heel strike located in advance, so the
               solver meets it warm: :mod:`walkerlab.integrate.compiled_segments`)
``A[30]``      the time [s] the present step began (before the switch)
``A[34]``      a held generalised force is on (0/1)
``A[35]``      the ghost swing foot: its points at least ``A[35]`` [m] ahead of the stance
               foot's carry no contact force (< 0: none; :func:`rhs_q`'s ``G``), the swing
               leg's once the heel strike in the data has passed, or with none pending
then           ``B`` with leg1 in stance, then with leg2 (nq * k each, row-major), the held
               force ``E`` with leg1 in stance, then with leg2 (nq each), then the law block
               (its ``b[2]``, the time the step began, written by each call)
=============  =============================================================================

After the block, ``nq + 14`` numbers of scratch (the force, the powers, the ghost swing
foot and the joint law's power split in its positive and negative parts of one call: the
right-hand side allocates nothing), then the call counter.
"""

from __future__ import annotations

from walkerlab.codegen.contact_glue import CYRK_POWERED_SOURCE, powered_glue
from walkerlab.models.contact.powered_kernels import A_HEAD

__all__ = ["A_HEAD", "CYRK_POWERED_SOURCE", "W_INDEX", "powered_source"]

#: Index in the powers ``W`` of each work integral's name.
W_INDEX = {"hip_torque_positive": 0, "hip_torque_negative": 1, "ankle_torque_positive": 2,
           "ankle_torque_negative": 3, "push_off": 4, "damper": 5, "contact": 6,
           "knee_stop": 7, "action_positive": 8, "action_negative": 9,
           "hip_roll_positive": 12, "hip_roll_negative": 13}


def powered_source() -> str:
    """The source appended to every generated contact module: ``actuate`` (the actuators'
    forces and powers from the actuation block, the kernels of
    :mod:`walkerlab.models.contact.powered_kernels` on the structure's kinematics),
    ``powered_packed`` (the powered right-hand side from the data vector) and
    ``build_cyrk_powered`` (its CyRK cfunc's address):
    :func:`walkerlab.codegen.contact_glue.powered_glue`."""
    return powered_glue()
