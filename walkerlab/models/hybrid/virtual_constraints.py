"""The rigid view's actuators of virtual constraints: the computed torque of
:class:`walkerlab.models.virtual_constraints.VirtualConstraintController` (the controller,
below the views: the contact view and the MuJoCo export evaluate the same one) at the rigid
walker's state.  The controller's names are re-exported here.
"""

from __future__ import annotations

import numpy as np

from walkerlab.models.hybrid.actuators import Actuators
from walkerlab.models.hybrid.base import Guard
from walkerlab.models.virtual_constraints import (
    KEY,
    MAX_CONDITION,
    Design,
    VirtualConstraintController,
    annihilator,
    bezier,
    default_joints,
)
from walkerlab.walker.joints import joint_links

#: the normalised phase's range of a step (:meth:`VirtualConstraintActuators.phase_guards`):
#: a quarter of a step beyond either end of the Bezier polynomials' [0, 1]
S_MIN, S_MAX = -0.25, 1.25

__all__ = ["MAX_CONDITION", "S_MAX", "S_MIN", "Design", "VirtualConstraintActuators",
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

        self.links = [joint_links(names, j, f"{KEY}.joints") for j in self.controller.joints]
        self.B = self.controller.B
        self.hip_only = False
        self.vc_spec = spec

    def phase_guards(self) -> tuple:
        """Fall guards (:class:`~walkerlab.models.hybrid.base.Guard`) on the normalised
        phase ``s = (theta - theta+) / (theta- - theta+)`` (0 at the step's start, 1 at its
        heel strike): a step whose phase leaves ``[S_MIN, S_MAX]`` without a heel strike has
        run off the Bezier polynomials' interval (stalled and rolled back, or passed the
        end with the swing foot off the ground), where the computed torque, extrapolating
        them, drives the walker to rates the integrator crawls through; it ends there as a
        fall instead (Westervelt et al. 2003 define the controller on one step's phase)."""
        d = self.controller.design
        th_p, dth = d.theta_plus, d.theta_minus - d.theta_plus
        pieces = self.controller.pieces

        def s(x):
            return (pieces(x)[3] - th_p) / dth
        return (Guard("phase_past_step_end", lambda t, x: s(x) - S_MAX, +1, "fall"),
                Guard("phase_before_step_start", lambda t, x: S_MIN - s(x), +1, "fall"))

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
