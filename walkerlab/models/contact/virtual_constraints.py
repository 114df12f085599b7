"""Virtual constraints as feedback in the compliant-contact view: the rigid view's
computed torque
(:class:`walkerlab.models.virtual_constraints.VirtualConstraintController`) evaluated at
the contact walker's role state.

The same controller, evaluated by the same code
-----------------------------------------------
A floating state with leg ``stance`` in stance is a rigid state in role order
(:meth:`walkerlab.models.contact.joint_torques.JointTorqueActuators.role_state`: the link
angles and their rates; the hip's translation left out).  At that role state the torques
are the rigid closed loop's (Westervelt, Grizzle & Koditschek 2003, IEEE TAC 48(1):42-56,
Sec. IV; Isidori 1995)::

    u = (L_g L_f h)^-1 (-L_f^2 h - kp y - kd y'),   saturated at max_torque_n_m,

with the rigid model's ``M, C, G`` at the role state: the outputs ``y = h0(q) - hd(s)`` on
the floating model's link angles, the phase ``theta`` (the virtual stance leg's angle, or the
scene's combination of the coordinates) of the stance foot in contact (the run's discrete
state, switched at each heel strike by :mod:`walkerlab.integrate.contact_powered`).  The
rigid model pins the stance foot; the contact model's foot is held by a stiff spring, so the
computed torque linearises the contact walker's outputs up to the foot's compliance.  The
torques act as :class:`~walkerlab.models.contact.joint_torques.JointTorqueActuators`' (``+tau``
on a joint's second link, ``-tau`` on its first; the same ``B``).

The law is no data of the compiled right-hand side (:meth:`VirtualConstraintLaw.packed`
is None): the run stays on :func:`scipy.integrate.solve_ivp` (the scene's
``contact_solver``; LSODA for RABBIT's).
"""

from __future__ import annotations

import numpy as np

from walkerlab.models.contact.joint_torques import JointTorqueActuators
from walkerlab.models.virtual_constraints import VirtualConstraintController

__all__ = ["VirtualConstraintJointTorques", "VirtualConstraintLaw"]


class VirtualConstraintLaw:
    """The law block of the virtual constraints: none (the controller needs the whole role
    state, not the joints' angles; the run evaluates it in Python).

    Parameters
    ----------
    controller : VirtualConstraintController
    """

    def __init__(self, controller: VirtualConstraintController):
        self.controller = controller

    def __len__(self) -> int:
        return len(self.controller.joints)

    def packed(self):
        """None: no law block of the compiled right-hand side (the run stays on
        solve_ivp, :func:`walkerlab.models.contact.powered_data.powered_data`)."""
        return None

    def each(self, deltas, ddeltas, s, ds, t_step):
        """Not defined on the joints' angles alone.

        Raises
        ------
        TypeError
            Always: the computed torque needs the role state
            (:meth:`VirtualConstraintJointTorques.torques`).
        """
        raise TypeError("the virtual constraints' computed torque needs the whole role "
                        "state (VirtualConstraintJointTorques.torques)")


class VirtualConstraintJointTorques(JointTorqueActuators):
    """The virtual-constraint controller of one free-jointed contact walker (module
    docstring; the interface of :class:`JointTorqueActuators`).

    Parameters
    ----------
    data : WalkerData
        A free-jointed walker (a hinged torso on straight legs or free knees), point feet.
    spec : walkerlab.config.actuation.Actuation
        With ``virtual_constraints`` (no other actuators: the config refuses them).
    coordinates : tuple of str
        The floating coordinates (:func:`walkerlab.codegen.floating.coordinate_names`).
    pulse_s : float
        Unused (no push-off with virtual constraints); :class:`JointTorqueActuators`'.

    Raises
    ------
    ValueError
        As :class:`VirtualConstraintController` (one line naming the key).
    """

    def __init__(self, data, spec, coordinates, pulse_s: float = 0.0):
        from walkerlab.codegen.cache import functions
        from walkerlab.config.actuation import Actuation

        vc = spec.virtual_constraints
        ctrl = VirtualConstraintController(vc, functions(data), data.structure, data.params)
        # the joints' columns and roles as the rigid view's (one zero law per joint: the
        # laws are replaced by the controller below)
        joints = Actuation(torques=[{"joint": j, "law": {}} for j in ctrl.joints])
        super().__init__(data, joints, coordinates, pulse_s)
        self.spec = spec
        #: the rigid view's controller (:class:`VirtualConstraintController`)
        self.controller = ctrl
        self.joints.laws = VirtualConstraintLaw(ctrl)
        if not np.allclose(self.joints.B, ctrl.B, rtol=0.0, atol=1e-12):
            raise ValueError("walker.actuation.virtual_constraints.joints: the contact view's "
                             "joint columns differ from the controller's B")

    def torques(self, x, stance: int, t_step: float = 0.0) -> np.ndarray:
        """The computed torques (k,) [N m] (``controller.joints`` order) at the floating
        state ``x`` (2 nq,) with leg ``stance`` (0: leg1, 1: leg2) in stance: the rigid
        closed loop's at the role state; ``t_step`` unused (the law is of the state)."""
        return np.real(self.controller.torques(self.role_state(np.asarray(x, float), stance)))
