"""Run an exported MJCF walker in MuJoCo from its ``gait`` keyframe and read its heel strikes.

MuJoCo is an optional (dev/test) dependency: imported inside the functions.

A heel strike of leg i is the first contact of its foot geom (``leg<i>_foot``) with the
ground after the foot has been off the ground for at least ``min_air_s`` (shorter gaps are
bounces of the soft contact, not steps); MuJoCo is stepped :data:`LOOK_EVERY` timesteps at a time
where no stepping rule acts.  The knee latch of a kneed export (equality
constraints ``leg<i>_latch``) is switched before every step by :func:`latch_rule`.

A powered export (custom text ``walkerlab_actuation``: the scene's ``walker.actuation``) is
driven by :class:`PoweredLoop`, one loop for every walker: before every MuJoCo step each law
of ``walker.actuation.torques`` (:class:`walkerlab.models.actuation.TorqueLaws`, the rigid and
contact views' own) is evaluated at its joint's angle and rate in the present roles (leg2
stands at the keyframe; the roles swap at each heel strike), the phase variable of the rigid
view (the angle of the line from the hip to the stance foot's site from the downward
vertical) and the time since the heel strike, and its generalised forces
(:func:`walkerlab.export.joint_torques.torque_generalized_forces`: a hip, torso-leg, knee or
ankle torque on the joints' coordinates) are applied as ``data.qfrc_applied`` (the file's
motors, for a user's own controller, are left at 0).  At each heel strike the push-off
(:func:`walkerlab.models.actuation.push_off_impulse` at the hip's speed) acts as a force
``P / T`` along the trailing leg at its foot for ``T = push_off_duration_s`` (the pulse's
last MuJoCo step carries only its share of the force, so the impulse is ``P`` exactly)
(``data.xfrc_applied`` on the leg's body, with the moment of the force about its centre of
mass).  An ankle push-off (flat feet: motors ``leg<i>_ankle_motor``) is the contact view's
(:mod:`walkerlab.models.contact.actuation`): latched on when the stance foot's heel leaves
the ground while its toe is loaded (the heel geom ``leg<i>_foot`` out of contact, the toe
geom ``leg<i>_toe`` in contact) and off at the next heel strike; meanwhile the stance
ankle's motor gives ``-stiffness (a - rest_angle_rad) - constant_n_m`` on its angle ``a``
(positive toe up), the swing ankle's 0; heel off is taken once the heel has been out
of contact :data:`HEEL_OFF_STEPS` MuJoCo steps running (the soft contact flickers).

The same loop drives a walker in 3D (:mod:`walkerlab.export.legs_3d_mjcf`, its pelvis on a
free joint or slides): the laws act on the hinges ``leg<i>_hip`` (each leg's pitch about its
own hip axis, the rigid 3D model's coordinates), the phase variable is the stance leg's
pitch (the rigid 3D model's), the push-off's law reads the pelvis' speed and its force
points from the trailing foot to that leg's own hip (the anchor of its ``leg<i>_hip``,
``hip_width / 2`` from the pelvis, as :class:`walkerlab.models.hybrid.push_off.
PushOffTransition` has it).  With hip-roll joints :class:`HipRollLoop` runs after it (it sets
the roll joints' forces only).

Virtual constraints (``walker.actuation.virtual_constraints``) are the rigid view's computed
torque (:class:`walkerlab.models.virtual_constraints.VirtualConstraintController`:
``u = (L_g L_f h)^-1 (-L_f^2 h - kp y - kd y')`` on the rigid model's ``M, C, G``;
Westervelt, Grizzle & Koditschek 2003, IEEE TAC 48(1):42-56) at MuJoCo's role state: each
rigid role's absolute link angle and rate from the export's coordinates
(:func:`walkerlab.export.joint_torques.link_angle` in the present roles), the torques
applied at their joints as the laws' (:class:`VirtualConstraintFeedback`, built from the
scene: the file carries the controller's spec, not the walker's generated model).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from walkerlab.codegen.cache import functions
from walkerlab.config.actuation import Actuation
from walkerlab.export.axes_3d import slope_axes
from walkerlab.export.joint_torques import (
    law_generalized_forces,
    link_angle,
    stance_phase,
    torque_generalized_forces,
)
from walkerlab.export.mjcf_ground import lane_tops
from walkerlab.extras import require
from walkerlab.models.actuation import TorqueLaws, push_off_impulse
from walkerlab.models.virtual_constraints import VirtualConstraintController

__all__ = ["HipRollLoop", "MujocoWalk", "PoweredLoop", "VirtualConstraintFeedback", "latch_rule",
           "powered_loop", "roll", "virtual_constraint_feedback", "walk"]

LEGS = ("leg1", "leg2")


@dataclass
class MujocoWalk:
    """Heel strikes of a MuJoCo run.

    Attributes
    ----------
    times_s : ndarray (n,)
        Heel-strike times [s].
    legs : list of str
        The striking leg of each.
    positions_m : ndarray (n,)
        Along-slope position of the striking foot's site at the strike [m].
    fell : bool
        The hip dropped below half a leg length above the ground.
    t_end_s : float
        Simulated time [s].
    """

    times_s: np.ndarray
    legs: list
    positions_m: np.ndarray
    fell: bool
    t_end_s: float

    @property
    def alternating(self) -> bool:
        """Every strike is by the other leg than the one before."""
        return all(a != b for a, b in zip(self.legs, self.legs[1:]))

    @property
    def step_periods_s(self) -> np.ndarray:
        """Times between successive heel strikes [s], (n - 1,)."""
        return np.diff(self.times_s)

    @property
    def step_lengths_m(self) -> np.ndarray:
        """Along-slope distances between successive footfalls [m], (n - 1,)."""
        return np.diff(self.positions_m)


def _numeric(model, name, default=None):
    import mujoco

    i = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_NUMERIC, name)
    if i < 0:
        return default
    return float(model.numeric_data[model.numeric_adr[i]])


def latch_rule(foot_height_m: float, knee_rad: float, release_height_m: float,
               capture_rad: float) -> bool:
    """walkerlab's knee latch as an on/off rule: hold the knee straight while the foot is
    less than ``release_height_m`` above the ground and the knee is flexed less than
    ``capture_rad`` (the contact model weights the same two conditions by cubic steps,
    :mod:`walkerlab.models.contact.generated`)."""
    return foot_height_m < release_height_m and knee_rad > -capture_rad


#: MuJoCo steps the stance heel must stay out of contact, its toe in contact, for heel off:
#: MuJoCo's soft contact flickers for 1-2 timesteps (0.18 ms) at a loaded heel during foot
#: flat and as the heel lifts (flat_feet_push_off: gaps of 1-2 steps from 0.17 to 0.50 s of
#: the first step), which must not start the push-off; 10 steps (1.8 ms) hold it back.
HEEL_OFF_STEPS = 10


class VirtualConstraintFeedback:
    """The virtual constraints' computed torque on an export's coordinates (module
    docstring).

    Parameters
    ----------
    controller : walkerlab.models.virtual_constraints.VirtualConstraintController
        The rigid view's controller of the scene's walker.
    roles : sequence of str
        The rigid model's coordinates by role (``structure.roles``: ``stance_thigh``,
        ``torso``, ...), each a link's absolute angle.
    """

    def __init__(self, controller, roles):
        self.controller = controller
        self.roles = tuple(roles)
        #: the actuated joints (``controller.joints`` order)
        self.joints = tuple(controller.joints)

    def role_state(self, q, v, stance: int) -> np.ndarray:
        """The rigid role state (2 n,) [rad, rad/s] of the export's coordinates ``q``, ``v``
        (name -> value) with leg ``stance`` (0: leg1) in stance."""
        combos = [link_angle(r, stance, q.keys()) for r in self.roles]
        return np.array([sum(k * q[c] for c, k in g.items()) for g in combos]
                        + [sum(k * v[c] for c, k in g.items()) for g in combos])

    def torques(self, q, v, stance: int) -> np.ndarray:
        """The computed torques (k,) [N m] at the joints :attr:`joints`."""
        return np.real(self.controller.torques(self.role_state(q, v, stance)))


def virtual_constraint_feedback(scene, data) -> VirtualConstraintFeedback | None:
    """:class:`VirtualConstraintFeedback` of ``scene``'s walker (None without
    ``walker.actuation.virtual_constraints``); ``data``: its description
    (:attr:`walkerlab.walker.plant.Plant.data` of the caller's plant).

    Raises
    ------
    ValueError
        As :class:`walkerlab.models.virtual_constraints.VirtualConstraintController`
        (one line naming the key).
    """
    act = scene.walker.actuation
    if act is None or act.virtual_constraints is None:
        return None

    ctrl = VirtualConstraintController(act.virtual_constraints, functions(data),
                                       data.structure, data.params)
    return VirtualConstraintFeedback(ctrl, data.structure.roles)


class PoweredLoop:
    """The controller of a powered export (module docstring).

    Parameters
    ----------
    model : mujoco.MjModel
        With the custom text ``walkerlab_actuation``.
    feedback : VirtualConstraintFeedback, optional
        The scene's virtual constraints (needed when the text carries them).

    Raises
    ------
    ValueError
        The text carries virtual constraints and no ``feedback`` is given.
    """

    def __init__(self, model, feedback: VirtualConstraintFeedback | None = None):
        import json

        import mujoco

        i = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_TEXT, "walkerlab_actuation")
        adr, size = int(model.text_adr[i]), int(model.text_size[i])
        self.spec = Actuation.model_validate(json.loads(
            bytes(model.text_data[adr:adr + size - 1]).decode()))
        self.laws = TorqueLaws(self.spec.torques)
        if self.spec.virtual_constraints is not None and feedback is None:
            raise ValueError("walkerlab_actuation: virtual constraints need the walker's "
                             "rigid model: walk the MJCF with feedback= "
                             "(virtual_constraint_feedback(scene); export --walk does)")
        self.feedback = feedback if self.spec.virtual_constraints is not None else None
        self.pulse_s = _numeric(model, "push_off_duration_s", 0.005)
        hinges = [model.joint(i) for i in range(model.njnt)
                  if model.jnt_type[i] == mujoco.mjtJoint.mjJNT_HINGE]
        coords = [j.name for j in hinges]
        joints = ([t.joint for t in self.spec.torques] if self.feedback is None
                  else self.feedback.joints)
        self.gf = [[torque_generalized_forces(j, st, coords) for j in joints]
                   for st in (0, 1)]  # per stance leg (0: leg1), per law (or joint)
        self.q_of = {j.name: int(j.qposadr[0]) for j in hinges}
        self.v_of = {j.name: int(j.dofadr[0]) for j in hinges}
        self.body = [int(model.body(g if mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, g)
                                    >= 0 else f"{g}_shank").id) for g in LEGS]
        # a planar hip on the slides hip_x, hip_z; a 3D pelvis (the legs' parent) free
        self.planar = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, "hip_x") >= 0
        self.leg_hip = [int(model.joint(f"{g}_hip").id) for g in LEGS]
        self.pelvis = int(model.body_parentid[model.jnt_bodyid[self.leg_hip[0]]])
        if self.planar:
            self.hip = int(model.joint("hip_x").dofadr[0])
            self.hip_q = int(model.joint("hip_x").qposadr[0])
        else:  # the rigid 3D model's phase: the stance leg's pitch (its hinge)
            self.stance_link = [link_angle("stance", st, coords) for st in (0, 1)]
        self.dt = float(model.opt.timestep)
        self.stance, self.t_step, self.push = 1, 0.0, None  # leg2 stands at the keyframe
        self.ankle = self.spec.ankle_push_off
        self.heel_off = False  # the stance heel has left the ground (latched to heel strike)
        self.off_steps = 0  # MuJoCo steps the stance heel has been off, its toe on
        if self.ankle is not None:
            self.ankle_motor = [int(model.actuator(f"{g}_ankle_motor").id) for g in LEGS]
            ankles = [model.joint(f"{g}_ankle") for g in LEGS]
            self.ankle_q = [int(j.qposadr[0]) for j in ankles]
            self.heel_geom = [int(model.geom(f"{g}_foot").id) for g in LEGS]
            self.toe_geom = [int(model.geom(f"{g}_toe").id) for g in LEGS]

    def ankle_torque(self, data) -> float:
        """The stance ankle's push-off torque [N m] for the coming step (module docstring);
        latches heel off."""
        st = self.stance
        if not self.heel_off:
            geoms = data.contact.geom[:data.ncon]
            heel = bool((geoms == self.heel_geom[st]).any())
            toe = bool((geoms == self.toe_geom[st]).any())
            self.off_steps = self.off_steps + 1 if toe and not heel else 0
            self.heel_off = self.off_steps >= HEEL_OFF_STEPS
        if not self.heel_off:
            return 0.0
        a = float(data.qpos[self.ankle_q[st]])
        return -self.ankle.stiffness_n_m_per_rad * (a - self.ankle.rest_angle_rad) \
            - self.ankle.constant_n_m

    def phase(self, data) -> tuple[float, float]:
        """The phase variable [rad] and its rate [rad/s]: the angle from the downward
        vertical of the line from the hip to the stance foot's site (the rigid view's,
        :func:`walkerlab.export.joint_torques.stance_phase`; MuJoCo's x-z plane); a walker
        in 3D: its stance leg's pitch (the hinge ``leg<i>_hip``) and its rate."""
        import mujoco

        if not self.planar:
            g = self.stance_link[self.stance]
            return (sum(k * float(data.qpos[self.q_of[c]]) for c, k in g.items()),
                    sum(k * float(data.qvel[self.v_of[c]]) for c, k in g.items()))
        vel = np.zeros(6)
        mujoco.mj_objectVelocity(self._model, data, mujoco.mjtObj.mjOBJ_SITE,
                                 self._site[self.stance], vel, 0)
        foot = data.site_xpos[self._site[self.stance]]
        h, dh = self.hip_q, self.hip
        return stance_phase(data.qpos[h:h + 2], data.qvel[dh:dh + 2], foot[[0, 2]],
                            vel[[3, 5]])

    def control(self, data) -> None:
        """Set the joint torques, the ankle motors and the push-off force for the coming
        step."""
        st, sw = self.stance, 1 - self.stance
        if self.feedback is not None:
            q = {c: data.qpos[a] for c, a in self.q_of.items()}
            v = {c: data.qvel[a] for c, a in self.v_of.items()}
            out: dict[str, float] = {}
            for g, tau in zip(self.gf[st], self.feedback.torques(q, v, st)):
                for c, k in g.items():
                    out[c] = out.get(c, 0.0) + k * float(tau)
            for c, a in self.v_of.items():
                data.qfrc_applied[a] = out.get(c, 0.0)
        elif self.laws:
            q = {c: data.qpos[a] for c, a in self.q_of.items()}
            v = {c: data.qvel[a] for c, a in self.v_of.items()}
            out = law_generalized_forces(self.laws, self.gf[st], q, v, self.phase(data),
                                         data.time - self.t_step)
            for c, a in self.v_of.items():
                data.qfrc_applied[a] = out.get(c, 0.0)
        if self.ankle is not None:
            data.ctrl[self.ankle_motor[sw]] = 0.0
            data.ctrl[self.ankle_motor[st]] = self.ankle_torque(data)
        data.xfrc_applied[:] = 0.0
        if self.push is not None and data.time < self.push[1]:
            # the pulse's share of this step: the last step of a pulse that is not a whole
            # number of steps carries only the rest, so the impulse is P exactly
            share = min(1.0, (self.push[1] - data.time) / self.dt)
            leg, force = self.push[0], self.push[2] * share
            foot = data.site_xpos[self._site[leg]]
            e = self.hip_point(data, leg) - foot
            F = force * e / np.sqrt(e @ e)
            data.xfrc_applied[self.body[leg], :3] = F
            data.xfrc_applied[self.body[leg], 3:] = np.cross(foot - data.xipos[self.body[leg]], F)

    def heel_strike(self, data, leg: int) -> None:
        """Leg ``leg`` (0, 1) struck: roles swap, the push-off starts at the other foot."""

        self.stance, self.t_step, self.heel_off, self.off_steps = leg, float(data.time), \
            False, 0
        if self.spec.push_off is None:
            self.push = None
            return
        P = float(push_off_impulse(self.spec.push_off, self.hip_speed(data)))
        self.push = ((1 - leg, data.time + self.pulse_s, P / self.pulse_s) if P > 0 else None)

    def hip_speed(self, data) -> float:
        """The hip's speed [m/s]: a planar walker's slides', a 3D walker's pelvis'."""
        if self.planar:
            return float(np.hypot(data.qvel[self.hip], data.qvel[self.hip + 1]))
        import mujoco

        vel = np.zeros(6)
        mujoco.mj_objectVelocity(self._model, data, mujoco.mjtObj.mjOBJ_BODY, self.pelvis,
                                 vel, 0)
        return float(np.sqrt(vel[3:] @ vel[3:]))

    def hip_point(self, data, leg: int) -> np.ndarray:
        """Leg ``leg``'s (0, 1) hip (3,) [m]: a planar walker's hip body; a 3D walker's own
        hip, the anchor of its hinge ``leg<i>_hip`` (module docstring)."""
        return data.xpos[self._hip_body] if self.planar else data.xanchor[self.leg_hip[leg]]

    def bind(self, model, site: list) -> None:
        """The foot sites and the hip body (ids)."""
        self._site = site
        self._model = model
        self._hip_body = int(model.body("hip").id) if self.planar else self.pelvis


class HipRollLoop:
    """The hip-roll law of a 3D walker's MJCF (custom text ``walkerlab_hip_roll``: the
    scene's :class:`walkerlab.config.walker.HipRollLaw`), the rigid model's
    (:func:`walkerlab.codegen.legged.derive_legged`) on MuJoCo's state: before every
    MuJoCo step each body's roll about the fall line ``s`` is read from its pitch axis
    ``a`` (the body's ``0 -1 0``, walkerlab's ``Rot(s, phi) z``):
    ``phi = atan2(-a . n, a . z_w)`` (``n`` the slope's normal, ``z_w`` walkerlab's z), its
    rate ``omega . s``; with ``phi`` the stance leg's, ``phi_p`` the pelvis', ``phi_w`` the
    swing leg's::

        tau_st = k_p phi_p + c_p dphi_p,
        tau_sw = -k_s (phi_w - g_l phi - g_r dphi) - c_s (dphi_w - dphi_p)

    applied as ``data.qfrc_applied`` at the hinges ``leg<i>_roll`` (a torque on the leg
    about the fall line, its reaction on the pelvis).  The law is odd in the rolls: the
    same on either side.  Leg2 stands at the keyframe; the roles swap at each heel strike.

    Parameters
    ----------
    model : mujoco.MjModel
        With the custom text ``walkerlab_hip_roll`` and bodies ``pelvis``, ``leg1``,
        ``leg2`` (:func:`walkerlab.export.legs_3d_mjcf.legs3d_mjcf`).
    """

    def __init__(self, model):
        import json

        import mujoco

        i = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_TEXT, "walkerlab_hip_roll")
        adr, size = int(model.text_adr[i]), int(model.text_size[i])
        law = json.loads(bytes(model.text_data[adr:adr + size - 1]).decode())
        self.k_p = law["pelvis_stiffness_n_m_per_rad"]
        self.c_p = law["pelvis_damping_n_m_s_per_rad"]
        self.k_s = law["swing_stiffness_n_m_per_rad"]
        self.c_s = law["swing_damping_n_m_s_per_rad"]
        self.g_l, self.g_r = law["lean_gain"], law["lean_rate_gain_s"]
        phi = _numeric(model, "slope_rad", 0.0)
        self.s, self.n = slope_axes(phi)    # MuJoCo axes
        self.zw = np.array([0.0, -1.0, 0.0])
        self.bodies = [int(model.body(b).id) for b in ("pelvis", *LEGS)]
        self.dof = [int(model.joint(f"{g}_roll").dofadr[0]) for g in LEGS]
        self.stance = 1
        self._model = model

    def rolls(self, data) -> tuple[np.ndarray, np.ndarray]:
        """Rolls [rad] and their rates [rad/s] of the pelvis, leg1 and leg2 (3,), (3,)."""
        import mujoco

        phi, dphi = np.zeros(3), np.zeros(3)
        vel = np.zeros(6)
        for k, b in enumerate(self.bodies):
            a = -np.asarray(data.xmat[b], float).reshape(3, 3)[:, 1]
            phi[k] = math.atan2(-(a @ self.n), a @ self.zw)
            mujoco.mj_objectVelocity(self._model, data, mujoco.mjtObj.mjOBJ_BODY, b, vel, 0)
            dphi[k] = vel[:3] @ self.s
        return phi, dphi

    def control(self, data) -> None:
        """Set the roll joints' torques for the coming step."""
        st, sw = self.stance, 1 - self.stance
        phi, dphi = self.rolls(data)
        tau_st = self.k_p * phi[0] + self.c_p * dphi[0]
        ref = self.g_l * phi[1 + st] + self.g_r * dphi[1 + st]
        tau_sw = -self.k_s * (phi[1 + sw] - ref) - self.c_s * (dphi[1 + sw] - dphi[0])
        data.qfrc_applied[self.dof[st]] = tau_st
        data.qfrc_applied[self.dof[sw]] = tau_sw

    def heel_strike(self, data, leg: int) -> None:
        """Leg ``leg`` (0, 1) struck: it is the stance leg now."""
        self.stance = leg


#: MuJoCo steps a walk takes without looking (``mj_step``'s ``nstep``) when no stepping rule
#: acts (no latch, no motor): heel-strike times are then known to 5 timesteps (an export's
#: timestep is tau/4 of its contact, at most 1 ms; 0.18-0.25 ms for the shipped SI scenes),
#: a mean step period over 10 steps to 5 dt / (10 T), ~1e-4; the latch and PoweredLoop act
#: every step.
LOOK_EVERY = 5


def powered_loop(model, feedback: VirtualConstraintFeedback | None = None) -> PoweredLoop:
    """The controller of a powered export (module docstring): :class:`PoweredLoop`."""
    return PoweredLoop(model, feedback)


def _at_gait_keyframe(xml_path, doing: str):
    """``(mujoco, model, data)``: the MJCF at ``xml_path`` loaded and reset to its ``gait``
    keyframe (:func:`walk` and :func:`roll`; their ``ValueError`` without one, their
    ``MissingExtra`` without MuJoCo, ``doing`` naming the use in its line)."""
    mujoco = require("mujoco", "engines", doing)
    model = mujoco.MjModel.from_xml_path(str(xml_path))
    data = mujoco.MjData(model)
    key = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_KEY, "gait")
    if key < 0:
        raise ValueError(f"{xml_path}: no 'gait' keyframe")
    mujoco.mj_resetDataKeyframe(model, data, key)
    return mujoco, model, data


def walk(xml_path, t_final_s: float, min_air_s: float = 0.1,
         feedback: VirtualConstraintFeedback | None = None, each=None) -> MujocoWalk:
    """Run the MJCF at ``xml_path`` from its ``gait`` keyframe for ``t_final_s`` [s]
    (``feedback``: the scene's virtual constraints, :func:`virtual_constraint_feedback`,
    needed when the file carries them; ``each``: a callable ``(model, data)`` called after
    every look, e.g. to record a 3D walker's lean).  The hip is the slide joints
    ``hip_x``, ``hip_z`` of a planar walker or the free joint ``free`` of a walker in 3D
    (:mod:`walkerlab.export.legs_3d_mjcf`).

    Returns
    -------
    MujocoWalk

    Raises
    ------
    ValueError
        The file has no ``gait`` keyframe (exported without a scene).
    walkerlab.extras.MissingExtra
        MuJoCo is not installed (one line naming the ``engines`` extra).
    """
    mujoco, model, data = _at_gait_keyframe(xml_path, "walking an exported MJCF in MuJoCo")
    phi = _numeric(model, "slope_rad", 0.0)
    off = _numeric(model, "foot_height_offset_m", 0.0)
    h_rel = _numeric(model, "latch_release_height_m")
    cap = _numeric(model, "latch_capture_rad")
    t, n = slope_axes(phi)  # slope tangent and normal, (x, y, z)
    foot_geom = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, f"{g}_foot") for g in LEGS]
    site = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, f"{g}_foot") for g in LEGS]
    latch = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_EQUALITY, f"{g}_latch") for g in LEGS]
    latched = latch[0] >= 0 and h_rel is not None
    knee = [model.jnt_qposadr[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, f"{g}_knee")]
            if latch[0] >= 0 else -1 for g in LEGS]
    slide = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, "hip_x")
    # a walker in 3D: the pelvis on a free joint, its position the first three of qpos
    free = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, "free")
    if free < 0:  # a 3D walker with hip-roll joints: its pelvis on three slides
        free = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, "pelvis_x")
    hip = model.jnt_qposadr[slide if slide >= 0 else free]
    up = hip + (1 if slide >= 0 else 2)  # the hip's height (world z)
    loops = []  # in order: PoweredLoop sets every hinge's force, HipRollLoop the rolls'
    if mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_TEXT, "walkerlab_actuation") >= 0:
        loops.append(powered_loop(model, feedback))
        loops[-1].bind(model, site)
    if mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_TEXT, "walkerlab_hip_roll") >= 0:
        loops.append(HipRollLoop(model))  # a 3D walker's hip-roll law
    nstep = 1 if latched or loops else LOOK_EVERY
    mujoco.mj_forward(model, data)
    tops = lane_tops(mujoco, model, data, t, n, LEGS) if latched else None
    L = float(np.hypot(*(data.site_xpos[site[1]][[0, 2]] - data.qpos[[hip, up]])))
    last_contact = [data.time, data.time]  # both feet at the ground at the keyframe
    times, legs, pos = [], [], []
    fell = False
    while data.time < t_final_s:
        if latched:
            for i in range(2):
                up_i = float(data.site_xpos[site[i]] @ n) - off  # stairs, footholds: from
                if tops is not None:  # the nearest patch's top (lane_tops)
                    up_i -= tops[i][1][np.argmin(abs(tops[i][0] - data.site_xpos[site[i]] @ t))]
                data.eq_active[latch[i]] = latch_rule(up_i, float(data.qpos[knee[i]]), h_rel, cap)
        for loop in loops:
            loop.control(data)
        mujoco.mj_step(model, data, nstep)
        if data.ncon:
            geoms = data.contact.geom[:data.ncon]
            for i in range(2):
                if (geoms == foot_geom[i]).any():
                    if data.time - last_contact[i] > min_air_s:
                        times.append(data.time)
                        legs.append(LEGS[i])
                        pos.append(float(data.site_xpos[site[i]] @ t))
                        for loop in loops:
                            loop.heel_strike(data, i)
                    last_contact[i] = data.time
        if each is not None:
            each(model, data)
        if data.qpos[hip] * n[0] + data.qpos[up] * n[2] < 0.5 * L:
            fell = True
            break
    return MujocoWalk(np.array(times), legs, np.array(pos), fell, float(data.time))


def roll(xml_path, t_final_s: float) -> MujocoWalk:
    """Run a spoked wheel's MJCF (:func:`walkerlab.export.spoked.wheel_mjcf_text`, spoke tips
    ``spoke<k>_tip``) at ``xml_path`` from its ``gait`` keyframe (spoke 0 in stance) for
    ``t_final_s`` [s] and read its spoke strikes: a strike is the first contact of the next
    spoke ahead (``spoke<k+1>_tip``), which then stands.

    Returns
    -------
    MujocoWalk
        ``legs`` the striking spokes' names (each the next: ``alternating`` holds while the
        wheel rolls spoke by spoke), ``positions_m`` the striking tip along the slope,
        ``fell``: the hub below half a spoke above its stance spoke's tip (along the
        slope's normal; the tip stands on the ground, a tread or a profile too).

    Raises
    ------
    ValueError
        The file has no ``gait`` keyframe.
    walkerlab.extras.MissingExtra
        MuJoCo is not installed (one line naming the ``engines`` extra).
    """
    mujoco, model, data = _at_gait_keyframe(xml_path, "rolling an exported MJCF in MuJoCo")
    tips = {}
    while (g := mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM,
                                  f"spoke{len(tips)}_tip")) >= 0:
        tips[g] = len(tips)
    n = len(tips)
    ground = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, "ground")
    qw, _, qy, _ = model.geom_quat[ground] if ground >= 0 else (1.0, 0.0, 0.0, 0.0)
    phi = 2.0 * math.atan2(float(qy), float(qw))  # the plane turned about y by phi
    tan, nrm = slope_axes(phi)
    slide = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, "hip_x")
    free = slide < 0  # a wheel in 3D: a free joint, its position the first three of qpos
    hub = int(model.jnt_qposadr[slide if not free else mujoco.mj_name2id(
        model, mujoco.mjtObj.mjOBJ_JOINT, "free")])
    mujoco.mj_forward(model, data)
    tip0 = next(g for g, k in tips.items() if k == 0)
    L = float(np.linalg.norm(data.geom_xpos[tip0] - data.xpos[model.geom_bodyid[tip0]]))
    stance, times, legs, pos, fell = 0, [], [], [], False
    while data.time < t_final_s:
        mujoco.mj_step(model, data)
        touching = {tips[g] for c in data.contact[:data.ncon] for g in (c.geom1, c.geom2)
                    if g in tips}
        if (stance + 1) % n in touching:
            stance = (stance + 1) % n
            times.append(data.time)
            legs.append(f"spoke{stance}")
            g = next(g for g, k in tips.items() if k == stance)
            pos.append(float(data.geom_xpos[g] @ tan))
        g = next(g for g, k in tips.items() if k == stance)
        hub_x = (np.array(data.qpos[hub:hub + 3]) if free
                 else np.array([data.qpos[hub], 0.0, data.qpos[hub + 1]]))
        if (hub_x - data.geom_xpos[g]) @ nrm < 0.5 * L:  # above its stance tip (stairs,
            # a profile: the ground under the hub is the stance tip's)
            fell = True
            break
    return MujocoWalk(np.array(times), legs, np.array(pos), fell, float(data.time))
