"""Joint torques on a free-jointed biped (``knee.lock: free``; with a hinged torso the
five-link biped of Westervelt, Grizzle & Koditschek 2003, IEEE TAC 48(1):42-56): its hips
and knees driven by torque laws, e.g. PD tracking of references of the phase variable
(virtual constraints).

Every coordinate is a link's absolute angle (:mod:`walkerlab.codegen.free_joints`), so a
joint's angle ``delta = q[second] - q[first]`` (:data:`walkerlab.config.actuation.
FIVE_LINK_JOINTS`) and its torque's generalised force is ``tau`` on the second link's row and
``-tau`` on the first's: ``B`` has one column ``e_second - e_first`` per actuator, and the flow
gains ``M^-1 B tau`` (:func:`walkerlab.models.hybrid.actuated.actuate` adds it, as on every
actuated walker).  The phase variable ``s`` is the virtual stance leg's angle (hip to
stance foot, from the generated ``leg_angles``), ``ds`` its rate; it decreases through a
step.  The legacy ``joint: hip`` acts between the two thighs (a walker without torso).
The push-off impulse is not offered for these walkers (refused in one line).

Everything is complex-safe (the generated ``leg_angles`` and ``matrices`` are), so the flow's
Jacobian is taken by the complex step as on the straight-legged walkers.
"""

from __future__ import annotations

import numpy as np

from walkerlab.config.actuation import FIVE_LINK_JOINTS
from walkerlab.models.actuation import TorqueLaws
from walkerlab.numerics import complex_step_jacobian

__all__ = ["FiveLinkActuators", "five_link_actuators"]

#: the joint between the two thighs on a walker without torso (``joint: hip``)
THIGHS = ("stance_thigh", "swing_thigh")


class FiveLinkActuators:
    """The joint torques of one free-jointed walker, bound to its generated model.

    Parameters
    ----------
    spec : walkerlab.config.actuation.Actuation
    fns : dict
        The generated model's functions (``leg_angles``, ``matrices``).
    roles : tuple of str
        The walker's coordinates (:data:`walkerlab.walker.description.FREE_KNEE_ROLES`
        [+ ``torso``]).

    Attributes
    ----------
    B : ndarray, shape (n, k)
        Each actuator's generalised-force direction (``+1`` on its second link's row,
        ``-1`` on the first's).
    links : list of (str, str)
        Each actuator's (first, second) link.
    """

    limit = False  # the legs carry mass (the massless-leg scaling is the simplest walker's)

    def __init__(self, spec, fns: dict, roles):
        self.spec, self.fns, self.n = spec, fns, len(roles)
        self.links = [THIGHS if t.joint == "hip" else FIVE_LINK_JOINTS[t.joint]
                      for t in spec.torques]
        self.B = np.zeros((self.n, len(self.links)))
        for k, (a, b) in enumerate(self.links):
            self.B[roles.index(a), k] -= 1.0
            self.B[roles.index(b), k] += 1.0
        self.laws = TorqueLaws(spec.torques)
        shared = _shared_phase_table(spec.torques)
        if shared is not None:  # one spline for every law's reference: 2 calls, not 2k
            self.laws.refs = shared
        self.t_origin = 0.0
        # (t, x) -> (k, 2n) the torques' derivative by the state when known in closed form
        # (a torque of time alone: zeros); None: the complex step differentiates the torques
        self.torque_jacobian = None

    def joint_angles(self, x):
        """``(deltas, ddeltas, s, ds)``: each actuator's joint angle [rad] and rate [rad/s]
        (lists, length k), the phase variable [rad] and its rate [rad/s]."""
        d = self.fns["leg_angles"](x)
        deltas = [d[f"{b}_angle"] - d[f"{a}_angle"] for a, b in self.links]
        ddeltas = [d[f"{b}_rate"] - d[f"{a}_rate"] for a, b in self.links]
        return deltas, ddeltas, d["stance_angle"], d["stance_rate"]

    def torques(self, t, x) -> np.ndarray:
        """Torque of each actuator (k,) [N m] at the state ``x`` (2n,) (complex-safe)."""
        return self.laws.each(*self.joint_angles(x), t - self.t_origin)

    def begin_step(self, t0: float) -> None:
        """A step begins at ``t0`` [s] (the origin of ``time_reference`` laws)."""
        self.t_origin = float(t0)

    def generalised_force(self, t, x):
        """``B tau`` (n,) [N m]."""
        return self.B @ self.torques(t, x)

    def added_acceleration(self, t, x):
        """``M^-1 B tau`` (n,) [rad/s^2]."""
        M = self.fns["matrices"](x)[0]
        return np.linalg.solve(M, self.generalised_force(t, x))

    def acceleration_jacobian(self, t, x, constraint=None) -> np.ndarray:
        """``d(M^-1 B tau)/dx`` (n, 2n): :func:`walkerlab.models.hybrid.actuated.
        torque_chain_jacobian` with :attr:`torque_jacobian` set, else the complex step of
        :meth:`added_acceleration` (``constraint``: none on free joints, must be None)."""
        from walkerlab.models.hybrid.actuators import torque_chain_jacobian

        x = np.asarray(x, float)
        if self.torque_jacobian is None:
            return complex_step_jacobian(lambda z: self.added_acceleration(t, z), x)
        return torque_chain_jacobian(self.fns["matrices"], x, self.generalised_force(t, x),
                                     self.B @ np.asarray(self.torque_jacobian(t, x), float))

    def power(self, t, x) -> float:
        """Mechanical power of the joint torques [W]: ``sum tau_k ddelta_k``."""
        if not self.spec.torques:
            return 0.0
        ddeltas = self.joint_angles(x)[1]
        return float(np.real(np.sum(self.torques(t, x) * np.asarray(ddeltas))))


def _shared_phase_table(torques):
    """The references ``[(h_i, dh_i)]`` of laws that all track cubic phase tables on the
    same abscissa, from ONE vector-valued spline (the same not-a-knot
    :class:`scipy.interpolate.CubicSpline` per column as
    :func:`walkerlab.models.actuation.phase_reference`, held at its end values outside,
    complex-step aware), evaluated once per phase value; None when the laws differ."""
    tabs = [t.law.reference for t in torques]
    if (not tabs or any(r is None or r.interpolation != "cubic" or len(r.phase_rad) < 3
                        or r.phase_rad != tabs[0].phase_rad for r in tabs)):
        return None
    from scipy.interpolate import CubicSpline

    s = np.asarray(tabs[0].phase_rad, float)
    cs = CubicSpline(s, np.array([r.values_rad for r in tabs], float).T, bc_type="not-a-knot",
                     extrapolate=False)
    d1, d2 = cs.derivative(), cs.derivative(2)
    memo: dict = {}

    def at(u):  # (h (k,), dh (k,)) at the phase u
        key = (bool(np.iscomplexobj(u)), complex(u))  # a real call never reads a complex
        if key not in memo:
            memo.clear()
            r = min(max(float(np.real(u)), s[0]), s[-1])
            inside = float(s[0] < np.real(u) < s[-1])
            h, dh = cs(r), d1(r) * inside
            if np.iscomplexobj(u):
                h = h + 1j * np.imag(u) * dh
                dh = dh + 1j * np.imag(u) * d2(r) * inside
            memo[key] = (h, dh)
        return memo[key]

    return [((lambda u, i=i: at(u)[0][i]), (lambda u, i=i: at(u)[1][i]))
            for i in range(len(tabs))]


def five_link_actuators(data, spec, roles) -> FiveLinkActuators:
    """The actuators of a free-jointed walker, after checking what it can carry.

    Parameters
    ----------
    data : walkerlab.walker.description.WalkerData
        ``data.structure.free_knees`` set.
    spec : walkerlab.config.actuation.Actuation
    roles : tuple of str
        The walker's roles.

    Returns
    -------
    FiveLinkActuators

    Raises
    ------
    ValueError
        A push-off, a torso joint without a hinged torso or ``joint: hip`` with one (one
        line, naming the field).
    """
    from walkerlab.codegen.cache import functions

    if spec.push_off is not None:
        raise ValueError("walker.actuation.push_off: not available on a walker with free "
                         "knees yet (drive its joints with torques)")
    for i, t in enumerate(spec.torques):
        where = f"walker.actuation.torques.{i}"
        if t.scaled_by != "none":
            raise ValueError(f"{where}.scaled_by: foot_mass is for walkers whose legs are "
                             "massless")
        torso = data.structure.hinged_torso
        if t.joint in ("stance_hip", "swing_hip") and not torso:
            raise ValueError(f"{where}.joint: {t.joint} joins the torso and a thigh: it needs "
                             "a hinged torso (torso.coupling: hinged)")
        if t.joint == "hip" and torso:
            raise ValueError(f"{where}.joint: with a hinged torso the hips are stance_hip and "
                             "swing_hip (torso to thigh), not hip")
    return FiveLinkActuators(spec, functions(data), tuple(roles))
