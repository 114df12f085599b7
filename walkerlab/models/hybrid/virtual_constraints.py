"""The rigid view's actuators of virtual constraints: the computed torque of
:class:`walkerlab.models.virtual_constraints.VirtualConstraintController` (the controller,
below the views: the contact view and the MuJoCo export evaluate the same one) at the rigid
walker's state.  The controller's names are re-exported here.
"""

from __future__ import annotations

import numpy as np

from walkerlab.models.hybrid.actuators import Actuators
from walkerlab.models.virtual_constraints import (
    KEY,
    MAX_CONDITION,
    Design,
    VirtualConstraintController,
    annihilator,
    bezier,
    default_joints,
)

__all__ = ["MAX_CONDITION", "Design", "VirtualConstraintActuators",
           "VirtualConstraintController", "annihilator", "bezier", "default_joints"]


class VirtualConstraintActuators(Actuators):
    """:class:`~walkerlab.models.hybrid.actuators.Actuators` whose torques are the computed
    torque of a :class:`VirtualConstraintController` at its joints (no law table).

    Raises
    ------
    ValueError
        As :class:`VirtualConstraintController` (one line naming the key).
    """

    def __init__(self, spec, fns, n, total_mass, structure, params):
        from types import SimpleNamespace

        vc = spec.virtual_constraints
        shim = SimpleNamespace(torques=(), push_off=None, ankle_push_off=None)
        super().__init__(shim, fns, n, False, total_mass)
        self.controller = VirtualConstraintController(vc, fns, structure, params)
        names = self.link_angles(np.zeros(2 * n))
        from walkerlab.walker.joints import joint_links

        self.links = [joint_links(names, j, f"{KEY}.joints") for j in self.controller.joints]
        self.B = self.controller.B
        self.hip_only = False
        self.vc_spec = spec

    def torques(self, t, x) -> np.ndarray:
        """The computed torques (k,) [N m] at the state ``x`` (2n,)."""
        return self.controller.torques(x)

    def power(self, t, x) -> float:
        """Mechanical power of the computed torques [W]: ``q'^T B u`` (each joint's rate
        times its torque; the energy ledger's actuator work)."""
        x = np.asarray(x, float)
        return float(np.real(x[self.n:] @ (self.B @ self.controller.torques(x))))

    def added_acceleration(self, t, x, constraint=None, M=None):
        """``M^-1 B u`` (n,) [rad/s^2] (:meth:`Actuators.added_acceleration`; the
        controller's own ``M^-1 B``, no constraint: a free-jointed walker holds none)."""
        if constraint is not None or M is not None:
            return super().added_acceleration(t, x, constraint, M)
        return self.controller.acceleration(x)[1]
