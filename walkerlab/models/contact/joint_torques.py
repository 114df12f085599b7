"""Joint torques of a free-jointed biped (``knee.lock: free``; with a hinged torso the
five-link biped of Westervelt, Grizzle & Koditschek 2003, IEEE TAC 48(1):42-56, RABBIT) in
the compliant-contact view: the rigid view's laws, as forces.

The same laws, evaluated by the same code
-----------------------------------------
Every coordinate of both views is a link's absolute angle (the floating view adds the hip's
position), so a floating state with leg ``stance`` in stance is a rigid state in role order
(:data:`walkerlab.walker.description.FREE_KNEE_ROLES` + ``torso``): ``stance_shank`` is
``leg{stance}_shank_angle``, ``swing_thigh`` the other leg's thigh, ``torso`` the torso's
angle, and so on.  The torques are those of the rigid view's
:class:`~walkerlab.models.actuation.JointMap` at that role state (the joints, ``B`` and
laws the rigid view's actuators evaluate):

- each joint's angle ``delta = q[second] - q[first]`` and its rate
  (:data:`walkerlab.config.actuation.FIVE_LINK_JOINTS`; ``stance_hip`` = stance thigh minus
  torso, ``swing_knee`` = swing shank minus swing thigh, ...);
- the phase variable ``s``: the virtual stance leg's angle, of the line from the hip to the
  stance foot, from the downward vertical (the generated rigid ``leg_angles``' ``stance``,
  ``atan(-(hip - foot)_x / (hip - foot)_y)``, a function of the link angles only: the same
  number in both views), and its rate;
- the laws (:class:`walkerlab.models.actuation.TorqueLaws`: PD tracking of phase references,
  saturation).

Each torque acts ``+tau`` on its second link's coordinate and ``-tau`` on its first's (the
hip's translations get none: a joint torque is internal), and its power is ``tau ddelta``.

Which leg is in stance
----------------------
A discrete state of the contact run, as in the rigid model: leg2 at the start (the rigid
gait's post-impact state, leg1 swinging), then the leg whose foot touched down last, ahead
of the other by ``min_step_m`` on a patch (:mod:`walkerlab.integrate.contact_powered`
switches it at that touchdown: the heel strike; the joints' roles swap with it, so
``swing_knee`` is the knee of the leg that swings now).  The time-based laws count from that
touchdown.

A push-off is the pulse of :class:`~walkerlab.models.contact.actuation.PushOffPulse` at the
trailing foot, along the line from it to the hip (the rigid view's impulse, Kuo 2002).
"""

from __future__ import annotations

import numpy as np

from walkerlab.codegen.cache import functions
from walkerlab.models.actuation import JointMap
from walkerlab.models.contact.actuation import WORK_NAMES, ContactRows, PushOffPulse

__all__ = ["JointTorqueActuators"]


class JointTorqueActuators(PushOffPulse, ContactRows):
    """The joint torques of one free-jointed contact walker (the interface of
    :class:`walkerlab.models.contact.actuation.ContactActuators` that
    :func:`~walkerlab.models.contact.actuation.powered_rhs` and
    :mod:`walkerlab.integrate.contact_powered` use).

    Parameters
    ----------
    data : WalkerData
        ``data.structure.free_knees`` set, point feet.
    spec : walkerlab.config.actuation.Actuation
        Joint torques only.
    coordinates : tuple of str
        The floating coordinates (:func:`walkerlab.codegen.floating.coordinate_names`).
    pulse_s : float
        Push-off pulse duration [s] (0: an impulse; :class:`~walkerlab.models.contact.
        actuation.PushOffPulse`, at the trailing foot along the line to the hip).

    Raises
    ------
    ValueError
        A joint the walker lacks or a torque per foot mass (one line, naming the field;
        :class:`walkerlab.models.actuation.JointMap`, as in the rigid view).
    """

    #: A touchdown is a heel strike only this far [m] ahead of the stance foot (as
    #: :attr:`ContactActuators.min_step_m`).
    min_step_m = 0.05
    #: No ankle push-off (point feet).
    ankle = None
    #: Free knees: no knee stop, no knee-stop term in the ledger.
    knee = False
    #: Point feet: no flat feet's ankle dampers in the ledger.
    foot = None
    #: The work integrals a run carries (:data:`~walkerlab.models.contact.actuation.WORK_NAMES`:
    #: the hip-torque names carry every joint torque's work).
    work_names = WORK_NAMES
    #: ... named for what they are in the ledger (:mod:`walkerlab.io.schemas.contact_sim`)
    work_labels = {"hip_torque_positive": "positive work of the joint torques (hips and knees)",
                   "hip_torque_negative": "negative work of the joint torques (hips and knees)"}

    def __init__(self, data, spec, coordinates, pulse_s: float = 0.0):
        self.spec = spec
        roles = tuple(data.structure.roles)
        #: the joints, their ``B`` and laws in the rigid view's role order (what the rigid
        #: view's actuators evaluate, :class:`walkerlab.models.actuation.JointMap`)
        self.joints = JointMap(spec, functions(data)["leg_angles"], len(roles))
        names = tuple(coordinates)
        self.nq = len(names)
        self.pulse_s = float(pulse_s)
        #: the hip's position columns (the floating base: the hip point itself)
        self.hip = (names.index("hip_x"), names.index("hip_y"))
        # floating index of each role, per stance leg (0: leg1, 1: leg2)
        self.index = []
        for stance in (0, 1):
            leg = {"stance": f"leg{stance + 1}", "swing": f"leg{2 - stance}"}
            self.index.append(np.array([
                names.index("torso_angle") if r == "torso"
                else names.index("_".join([leg[r.split("_")[0]], *r.split("_")[1:], "angle"]))
                for r in roles]))

    @property
    def rigid(self) -> JointMap:
        """:attr:`joints` (the name its users know: the rigid view's joint torques)."""
        return self.joints

    def role_state(self, x, stance: int) -> np.ndarray:
        """The rigid view's role state (2 n,) [rad, rad/s] of the floating state ``x``
        (2 nq,) with leg ``stance`` (0: leg1, 1: leg2) in stance."""
        i = self.index[stance]
        return np.concatenate([x[i], x[self.nq + i]])

    def torques(self, x, stance: int, t_step: float = 0.0) -> np.ndarray:
        """Each actuator's torque (k,) [N m] (``walker.actuation.torques`` order); ``t_step``
        the time since the step's heel strike [s]."""
        xr = self.role_state(np.asarray(x, float), stance)
        return self.joints.laws.each(*self.joints.joint_angles(xr), t_step)

    def hip_torque(self, x, stance: int, t_step: float = 0.0) -> tuple[np.ndarray, float]:
        """Generalised force of the joint torques (nq,) [N, N m] and their power [W] (the
        name is :class:`ContactActuators`'; here every joint: hips and knees)."""
        x = np.asarray(x, float)
        tau = self.torques(x, stance, t_step)
        Qr = self.joints.B @ tau
        Q = np.zeros(self.nq)
        Q[self.index[stance]] = Qr
        i = self.index[stance]
        return Q, float(Qr @ x[self.nq + i])

