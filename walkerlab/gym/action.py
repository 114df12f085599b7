"""The action of the Gymnasium environment: one torque per actuated joint of the scene,
added to the scene's own actuation, bounded by the actuators' limits.

Which joints
------------
The joints of the scene's ``walker.actuation.torques`` (in their order, each joint once); a
scene without torques (passive, or powered by a push-off alone) gets one torque at the
``hip`` between the legs (:data:`walkerlab.config.actuation.JOINTS`: ``+tau`` on the swing
leg, ``-tau`` on the stance leg; in 3D about the legs' pitch axes).  A walker with hip-roll
joints (a 3D walker's ``walker.hip_roll``) adds a torque at each of them, after those
(:data:`walkerlab.walker.joints.ROLL_JOINTS`: ``stance_hip_roll``, ``swing_hip_roll``,
``+tau`` on the leg about its roll joint, ``-tau`` on the pelvis), beside the scene's own
hip-roll law: the joints are read from the walker's links (its generated ``leg_angles``),
not from its dimension.

Bounds
------
``|tau_k| <= max_torque_n_m`` of the scene's actuator at that joint, when it has one;
otherwise :data:`DEFAULT_TORQUE_FRACTION` times ``M g l`` (total mass, gravity, leg length:
the torque that holds the whole walker's weight at a leg's length, 196 N m for the paper's
20 kg, 1 m walker), unless the environment is given its own bounds.  A feedback controller
(``walker.actuation.virtual_constraints``) bounds each joint at its ``max_torque_n_m``, or
without one at ``M g l`` itself (its computed torque is the policy's action, and it exceeds
a tenth of ``M g l``: configs/threelink_hzd.yaml's gait peaks at 53 N m, 0.15 ``M g l``).

In the rigid view the torques act through the generic actuators of the hybrid model
(:class:`walkerlab.models.hybrid.actuators.Actuators`, ``M^-1 B tau`` in the flow; in a phase
holding a lock through it): :class:`ActionTorques` is that class with the torque read from
the action instead of a law.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from walkerlab.codegen.cache import functions
from walkerlab.config.actuation import JointTorque, TorqueLaw
from walkerlab.models.hybrid.actuators import Actuators
from walkerlab.walker.joints import ROLL_JOINTS, link_angles, roll_joints

__all__ = ["DEFAULT_TORQUE_FRACTION", "GL_W", "GL_X", "ActionTorques", "action_joints",
           "action_limits", "action_torques", "walker_links"]

#: the 4-point Gauss-Legendre rule on [-1, 1] (nodes, weights) of the action's work over an
#: integrated piece (the rigid view's ledger: :mod:`walkerlab.gym.rigid_view`, and the
#: native vector environment's rows, :mod:`walkerlab.gym.rigid_rows`)
GL_X, GL_W = np.polynomial.legendre.leggauss(4)

#: Default bound of an action torque whose joint has no ``max_torque_n_m`` [-], a fraction
#: of ``M g l`` (a tenth of the weight's moment at a leg's length).
DEFAULT_TORQUE_FRACTION = 0.1


def action_joints(scene, controller=None, links=()) -> list[str]:
    """The joints the action drives: a feedback controller's (``controller.joints``, of
    ``walker.actuation.virtual_constraints``), else those of ``walker.actuation.torques``
    (each once, in order), else ``["hip"]``; then the hip-roll joints among the walker's
    ``links`` (keys of :func:`walkerlab.walker.joints.link_angles`: :func:`walker_links`),
    if it has them."""
    if controller is not None:
        return list(controller.joints)
    act = scene.walker.actuation
    joints: list[str] = []
    for t in (act.torques if act is not None else ()):
        if t.joint not in joints:
            joints.append(t.joint)
    return (joints or ["hip"]) + [j for j in roll_joints(links) if j not in joints]


def walker_links(data, n: int) -> list[str]:
    """The links of the walker ``data`` (``n`` generalised coordinates): the keys of
    :func:`walkerlab.walker.joints.link_angles` of its generated ``leg_angles`` (none for a
    walker without them: a spoked wheel)."""

    angles = functions(data).get("leg_angles")
    return [] if angles is None else list(link_angles(angles(np.zeros(2 * n))))


def _joint_torque(joint: str):
    """A constant-torque actuator at ``joint`` (its law the action's); a hip-roll joint
    (:data:`walkerlab.walker.joints.ROLL_JOINTS`), not a scene's torque joint, is built
    without the scene's joint check (the walker's links are checked when the actuators
    are made: :func:`walkerlab.walker.joints.joint_links`)."""

    if joint in ROLL_JOINTS:
        return JointTorque.model_construct(joint=joint, law=TorqueLaw())
    return JointTorque(joint=joint, law=TorqueLaw())


def action_limits(scene, joints: list[str], total_mass_kg: float, gravity: float,
                  leg_length_m: float, max_torque_n_m=None) -> np.ndarray:
    """The bound of each action torque (k,) [N m].

    Parameters
    ----------
    scene : walkerlab.config.Scene
    joints : list of str
        :func:`action_joints`.
    total_mass_kg, gravity, leg_length_m : float
        ``M`` [kg], ``g`` [m/s^2], ``l`` [m] of the walker.
    max_torque_n_m : float or sequence of float, optional
        The environment's own bounds (one for all joints, or one per joint) [N m].

    Returns
    -------
    ndarray, shape (k,)

    Raises
    ------
    ValueError
        ``max_torque_n_m`` not positive finite numbers, or of the wrong length (one line).
    """
    k = len(joints)
    if max_torque_n_m is not None:
        arr = np.atleast_1d(np.asarray(max_torque_n_m, dtype=float))
        if arr.size == 1:
            arr = np.full(k, float(arr[0]))
        if arr.shape != (k,) or not np.all(np.isfinite(arr)) or np.any(arr <= 0):
            raise ValueError(f"max_torque_n_m={max_torque_n_m!r}: give one positive number, "
                             f"or {k} (one per joint: {', '.join(joints)}) [N m]")
        return arr
    default = DEFAULT_TORQUE_FRACTION * total_mass_kg * gravity * leg_length_m
    act = scene.walker.actuation
    vc = act.virtual_constraints if act is not None else None
    if vc is not None:  # a controller's joints: its own bound, else the weight's moment
        cap = vc.max_torque_n_m
        return np.full(k, float(cap) if cap is not None
                       else total_mass_kg * gravity * leg_length_m)
    out = np.full(k, default)
    for i, j in enumerate(joints):
        caps = [t.max_torque_n_m for t in (act.torques if act is not None else ())
                if t.joint == j and t.max_torque_n_m is not None]
        if caps:
            out[i] = max(caps)
    return out


@dataclass
class ActionTorques(Actuators):
    """The generic joint actuators of a rigid walker whose torques are the action's
    (:attr:`u`, (k,) [N m], set before each control period) instead of laws: the flow gains
    :meth:`~walkerlab.models.hybrid.actuators.Actuators.added_acceleration` ``M^-1 B u``,
    their power is :meth:`~walkerlab.models.hybrid.actuators.Actuators.power`.

    ``first``: the spec's torques before this index are the scene's own laws, acting as
    they are; the action's ``u`` drives the rest (0: the action alone)."""

    first: int = 0

    def __post_init__(self):
        super().__post_init__()
        self.u = np.zeros(len(self.spec.torques) - self.first)
        #: ``(Bt (k, n), c (k,))`` of the joints' affine map
        #: (:meth:`~walkerlab.models.hybrid.actuators.Actuators.affine_joint_map`; the hip's
        #: for hip actuators), or None: the generated ``leg_angles`` at every call
        self.affine = (self.affine_joint_map(self._generated_joint_state) if self.spec.torques
                       and not self.limit else None)

    def joint_state(self, x) -> tuple[np.ndarray, np.ndarray]:
        """``(delta, ddelta)`` (k,) of the action's joints at the real state ``x`` (2n,)
        [rad, rad/s] (the hip's for every actuator when all act at the hip): the affine
        map :attr:`affine` where there is one, else the generated ``leg_angles``."""
        if self.affine is not None:
            return self.affine_joint_state(x, self.affine)
        return self._generated_joint_state(x)

    def rate_power(self, X) -> np.ndarray:
        """The held action's power ``u . ddelta`` [W] at the real states ``X`` (2n, m),
        one per column (the action alone: :attr:`first` 0, :attr:`affine` set)."""
        return self.u @ self.affine_joint_rates(X, self.affine)

    def _generated_joint_state(self, x) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`joint_state` from the generated ``leg_angles``."""
        if self.hip_only:
            d, dd = self.hip_angles(x)[:2]
            k = len(self.spec.torques)
            return np.full(k, float(np.real(d))), np.full(k, float(np.real(dd)))
        d, dd = self.joint_angles(x)[:2]
        return np.array(d, dtype=float), np.array(dd, dtype=float)

    def held_work(self, xa, xb) -> float:
        """The work of the held action :attr:`u` from the state ``xa`` to ``xb`` (2n,)
        [J]: ``sum_k u_k (delta_k(xb) - delta_k(xa))``, exact for torques held constant (the
        integral of :meth:`power` over any path between them).  The action alone
        (:attr:`first` 0); 0 for torques scaled by a massless foot's mass."""
        if self.limit or not self.spec.torques:
            return 0.0
        return float(self.u @ (self.joint_state(xb)[0] - self.joint_state(xa)[0]))

    def torques(self, t, x) -> np.ndarray:
        """The scene's laws' torques (the first :attr:`first`), then the action's (k,)
        [N m] (whatever the state)."""
        if not self.first:
            return self.u
        out = np.array(super().torques(t, x))
        return np.concatenate([out[:self.first], out[self.first:] + self.u])


def flat_action_walker(walker, data, joints: list[str], actuation):
    """The flat-footed rigid walker of one step with the action's torques at ``joints``
    acting in every stance-foot mode
    (:func:`walkerlab.models.hybrid.mode_torques.actuate_flat_hips`: each mode's own mass
    matrix, the foot-flat lock, the guards' ground forces and the double support carrying
    them), besides the scene's own torque laws and
    ankle push-off (its heel-off numbers).  Its guards are the walker's, in the same order:
    the heel strike's reset (a push-off impulse's) is read from the scene's walker
    (:class:`walkerlab.gym.rigid_view.RigidView`).

    Parameters
    ----------
    walker : walkerlab.models.hybrid.HybridWalker
        The scene's walker of that step (its name, variant and double support kept).
    data : walkerlab.walker.description.WalkerData
        That step's walker data (without ``mirror_params``).
    joints : list of str
    actuation : walkerlab.config.actuation.Actuation or None
        The scene's.

    Returns
    -------
    (HybridWalker, ActionTorques)
        The walker and its actuators (set :attr:`ActionTorques.u` before each period).
    """
    from dataclasses import replace

    from walkerlab.codegen.cache import functions
    from walkerlab.config.actuation import Actuation, JointTorque, TorqueLaw
    from walkerlab.models.hybrid.ankle_push_off import heel_off_data
    from walkerlab.models.hybrid.mode_torques import actuate_flat_hips

    own = list(actuation.torques) if actuation is not None else []
    spec = Actuation(torques=own + [JointTorque(joint=j, law=TorqueLaw()) for j in joints])
    off = (heel_off_data(data, actuation) if actuation is not None
           and actuation.ankle_push_off is not None else None)
    acts = ActionTorques(spec, functions(data), len(walker.roles), False,
                         float(walker.total_mass_kg), torso_mean=bool(data.structure.torso),
                         first=len(own))
    twin = actuate_flat_hips(replace(walker, mirror=None), data, spec, off, actuators=acts)
    return twin, acts


def action_torques(data, n: int, joints: list[str]) -> ActionTorques:
    """:class:`ActionTorques` at ``joints`` of the walker ``data``.

    Parameters
    ----------
    data : walkerlab.walker.description.WalkerData
    n : int
        Number of generalised coordinates of the rigid walker.
    joints : list of str

    Raises
    ------
    ValueError
        A joint the walker does not have (naming those it has), a walker whose legs are
        massless (a torque there has no inertia to act on: the limit of Kuo's simplest
        walker) or one the capability table's ``walk`` x ``gym`` cell refuses (a rimless
        wheel), one line each.  (Flat feet: these actuators' generic ``M^-1 B u`` is not
        their modes'; the rigid view drives them through :func:`flat_action_walker`.)
    """
    from walkerlab.codegen.cache import functions
    from walkerlab.config.actuation import Actuation

    st = data.structure
    st.kind.require("walk", "gym", "walkerlab.gym")  # a wheel: the table's
    if st.bodies and all(b.massless for b in st.bodies):
        raise ValueError("walkerlab.gym: the legs are massless (Kuo's simplest walker): a "
                         "joint torque has no inertia to act on; give the legs mass")
    spec = Actuation(torques=[_joint_torque(j) for j in joints])
    return ActionTorques(spec, functions(data), n, False, float(data.total_mass_kg),
                         some_massless=any(b.massless for b in st.bodies))
