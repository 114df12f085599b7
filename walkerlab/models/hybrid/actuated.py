"""A rigid hybrid walker with its actuators (:func:`actuate`): the flows gain the joint
torques' acceleration ``M^-1 B tau``, the heel-strike reset a push-off impulse.

One actuator class for every walker (:class:`walkerlab.models.hybrid.actuators.Actuators`):
a torque at any joint the walker has (:data:`walkerlab.config.actuation.JOINTS`: the hip
between the legs, torso to leg, knees, flat feet's ankles), its ``B^T = d(delta)/dq`` from
the generated link angles; the push-off of Kuo (2002) in its transition.  Free knees (the
five-link biped) add one spline for laws sharing a table
(:mod:`walkerlab.models.hybrid.free_joint_actuators`); flat feet run their stance-foot modes'
own mass matrices (:mod:`walkerlab.models.hybrid.mode_torques`) or an ankle push-off
(:mod:`walkerlab.models.hybrid.ankle_push_off`).  Each kind's way is its actuators part
(:attr:`walkerlab.walker.kinds.Kind.actuators`), given its behaviour here; what a kind
cannot carry is refused by its row of
:data:`walkerlab.walker.kinds.CAPABILITIES`, what the legs' masses cannot carry by
:mod:`walkerlab.models.hybrid.leg_masses`.  Those modules import the shared actuators from
:mod:`walkerlab.models.hybrid.actuators`, never this one.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from walkerlab.models.actuation import refuse_actuators, torque_feature
from walkerlab.models.hybrid.actuators import Actuators, torque_chain_jacobian
from walkerlab.models.hybrid.base import HybridWalker, Phase
from walkerlab.models.hybrid.leg_masses import check_impact_masses, massless_limit
from walkerlab.numerics import complex_step_jacobian
from walkerlab.walker import parts as P

__all__ = ["compiled_with", "Actuators", "actuate", "refuse_actuators",
           "torque_chain_jacobian", "torque_feature"]


def _functions(data):
    from walkerlab.codegen.cache import functions

    return functions(data)


def spec_of(acts):
    """The actuation section ``acts`` drives (a virtual-constraint controller's: the scene's
    ``walker.actuation``)."""
    return getattr(acts, "vc_spec", acts.spec)


def spring_equivalent(data, spec):
    """The walker's data with its hip torques as one more generated hip spring-damper, when
    every law is linear in the hip angle and rate (no reference, no saturation, not scaled
    by a massless foot's mass): ``sum_i (c_i - K_i (delta - r_i) - D_i ddelta) = -K (delta -
    r) - D ddelta`` with ``K = sum K_i > 0``, ``r = (sum K_i r_i + sum c_i) / K``, ``D = sum
    D_i`` (or ``K = 0`` and no constant torque: a damper), on the pair (swing, stance) of
    :data:`walkerlab.walker.description.SPRING_LINKS` (its ``delta`` is stance - swing: rest
    angle ``-r``).  Its flows are then the generated, compiled ones; None otherwise (and for
    a kind whose part has no such spring, ``hip_spring``: knees, free joints, flat feet)."""
    from walkerlab.walker.description import WalkerData

    st = data.structure
    laws = [t for t in spec.torques]
    if not laws or not st.kind.actuators.hip_spring or st.knee_spring or st.torso \
            or any(b.massless for b in st.bodies) or any(
            t.joint != "hip" or t.scaled_by != "none" or t.max_torque_n_m is not None
            or t.law.reference is not None or t.law.time_reference is not None for t in laws):
        return None
    K = sum(t.law.stiffness_n_m_per_rad for t in laws)
    D = sum(t.law.damping_n_m_s_per_rad for t in laws)
    C = sum(t.law.constant_n_m for t in laws)
    if (K <= 0.0 and C != 0.0) or K == D == C == 0.0:
        return None
    r = (sum(t.law.stiffness_n_m_per_rad * t.law.rest_angle_rad for t in laws) + C) / K \
        if K > 0.0 else 0.0
    structure = replace(st, springs=st.springs + (("swing", "stance"),))
    extra = (float(K), float(-r), float(D))
    mirror = None if data.mirror_params is None else tuple(data.mirror_params) + extra
    return WalkerData(structure, tuple(data.params) + extra, data.total_mass_kg,
                      data.leg_length_m, data.gravity_m_per_s2, data.slope_rad, data.extra,
                      mirror)


def _compiled_laws(phase: Phase, data, acts, limit: bool):
    """The phase's flow with its torque laws compiled
    (:class:`walkerlab.models.compiled_flows.ActuatedFlow`: the laws evaluated in the cfunc, the
    same guards as extra outputs), or None: torques scaled by a massless foot's mass (they
    act on the swing row alone), or a phase whose guards have no compiled outputs."""
    from walkerlab.models.compiled_flows import ActuatedFlow

    # a kneed walker's phases: the free flow and the knee-locked one (``flow_locked``)
    if limit or acts.rows is not None:  # the force in the massless limit's rows: Python
        return None
    if getattr(spec_of(acts), "virtual_constraints", None) is not None:  # computed torque:
        if phase.constraint is not None:  # a held constraint's rows: the Python flow
            return None
        from walkerlab.models.compiled_flows import VirtualConstraintFlow

        # the closed loop compiled, for the cyrk_compiled backend (None where the
        # controller's law is not compiled)
        return VirtualConstraintFlow.of(acts.controller, data.structure, data.params)
    guards = phase.compiled.guards if phase.compiled is not None else None
    if guards is None:  # a passive flow run in Python: the guards' outputs from the kind
        guards = data.structure.kind.actuators.guard_outputs(phase, data)
    if guards is None:
        return None
    links = acts.links  # each actuator's (first, second) link: keys of ``leg_angles``
    name = phase.compiled.name if phase.compiled is not None else "flow"
    return ActuatedFlow(data.structure, tuple(data.params), name, guards,
                        joints=tuple(tuple(j) for j in links), laws=acts.laws.packed(),
                        actuators=acts)


def compiled_with(phase: Phase, data, acts):
    """``phase``'s flow compiled with the actuators ``acts`` acting in it (their laws
    evaluated in the cfunc: :class:`walkerlab.models.compiled_flows.ActuatedFlow`), for a phase
    of the passive walker built from ``data``; None where no compiled flow can carry them
    (a massless limit's rows, a computed-torque controller, guards without compiled
    outputs).  The Gymnasium environment's compiled control step holds its action so
    (:class:`walkerlab.gym.rigid_view.RigidView`)."""
    return _compiled_laws(phase, data, acts, False)


def actuate(walker: HybridWalker, data, spec) -> HybridWalker:
    """The walker with its actuators: every phase's flow gains ``M^-1 B tau`` (and its
    Jacobian the derivative of it, by the complex step), the heel-strike reset becomes
    push-off + heel strike (:meth:`Actuators.transition`; its Jacobian by the complex step).

    Parameters
    ----------
    walker : HybridWalker
        The passive walker built from ``data`` (legs that differ: its ``mirror`` too).
    data : walkerlab.walker.description.WalkerData
    spec : walkerlab.config.actuation.Actuation

    Returns
    -------
    HybridWalker
        With ``actuators`` set (:class:`walkerlab.models.hybrid.actuators.Actuators`);
        every phase's flow in Python (the
        actuation added to the generated flow) and compiled with its laws
        (``cyrk_compiled``: :class:`walkerlab.models.compiled_flows.ActuatedFlow`).

    Raises
    ------
    ValueError
        A joint the walker does not have (naming the joints it has), a torque across a
        link that carries no mass, a torque scaling that does not fit the legs, a push-off
        on massless arc-footed legs (one line).
    """
    if getattr(spec, "virtual_constraints", None) is not None:  # the kind's table
        data.structure.kind.require("virtual_constraints", "rigid",
                                    "walker.actuation.virtual_constraints")
    return data.structure.kind.actuators.actuate(walker, data, spec)


def _actuate_joints(part, walker: HybridWalker, data, spec) -> HybridWalker:
    """:func:`actuate` for a kind whose actuators are :class:`Actuators` on its joints
    (``part``: the kind's :class:`_Joints`)."""
    if getattr(spec, "virtual_constraints", None) is not None:  # computed torque (HZD)
        from walkerlab.models.hybrid.virtual_constraints import VirtualConstraintActuators

        acts, limit = VirtualConstraintActuators(
            spec, _functions(data), len(walker.roles), float(walker.total_mass_kg),
            data.structure, data.params), False
    else:
        acts, limit = part.actuators(walker, data, spec)
    base_jac = walker.variational
    has_torque = bool(spec.torques) or getattr(spec, "virtual_constraints", None) is not None

    def locked(constraint):  # the torque's acceleration, through a phase's lock if any
        if constraint is None:
            return acts.added_acceleration
        return lambda t, x: acts.added_acceleration(t, x, constraint)

    def flow_of(flow, constraint=None):
        if not has_torque:
            return flow
        acc = locked(constraint)

        def f(t, x):
            out = np.array(flow(t, x), dtype=complex if np.iscomplexobj(x) else float)
            out[acts.n:] += acc(t, x)
            return out
        return f

    def jac_of(jac, constraint=None):
        if not has_torque:
            return jac

        def J(t, x):
            base = np.array(jac(t, x), float)
            base[acts.n:] += acts.acceleration_jacobian(t, x, constraint)
            return base
        return J

    phases = []
    sprung = spring_equivalent(data, spec) if has_torque and not limit else None
    if sprung is not None:  # the torques as a generated (compiled) hip spring-damper
        from walkerlab.models.hybrid.rigid import make_rigid_walker

        fast = make_rigid_walker(sprung, walker.name, walker.variant)
        base_jac = fast.variational
        phases = [Phase(ph.name, ph.flow, ph.guards, jacobian=ph.jacobian,
                        variational=ph.variational, compiled=ph.compiled,
                        jacobian_rtol=ph.jacobian_rtol)
                  for ph in fast.phases]
    # virtual constraints: a step ends as a fall once its phase leaves the polynomials'
    extra = acts.phase_guards() if hasattr(acts, "phase_guards") else ()
    for ph in walker.phases if sprung is None else ():
        phases.append(Phase(ph.name, flow_of(ph.flow, ph.constraint), ph.guards + extra,
                            jacobian=jac_of(ph.jacobian or base_jac, ph.constraint),
                            variational=None if has_torque else ph.variational,
                            compiled=(_compiled_laws(ph, data, acts, limit) if has_torque
                                      else ph.compiled), constraint=ph.constraint,
                            jacobian_rtol=ph.jacobian_rtol))
    reset = walker.reset
    reset_jac = walker.reset_jacobian
    if spec.push_off is not None:
        reset = acts.reset

        def reset_jac(x):
            return complex_step_jacobian(acts.reset, x)
    mirror = walker.mirror
    if mirror is not None:
        mirror = actuate(mirror, data.mirror, spec)
    return replace(walker, phases=tuple(phases), reset=reset, reset_jacobian=reset_jac,
                   variational=base_jac if sprung is not None else jac_of(base_jac),
                   mirror=mirror, actuators=acts)


class _Joints:
    """How :func:`actuate` drives straight legs (the parts of the other kinds derive from
    it): the generic :class:`Actuators` at the joints, hip laws linear in the hip angle
    as a generated hip spring-damper (:func:`spring_equivalent`)."""

    #: hip laws may become a generated spring (:func:`spring_equivalent`)
    hip_spring = True

    def actuate(self, walker: HybridWalker, data, spec) -> HybridWalker:
        """The actuated walker (an ankle push-off refused by the kind's table)."""
        if spec.ankle_push_off is not None:
            data.structure.kind.require("ankle_push_off", "rigid",
                                        "walker.actuation.ankle_push_off")
        return _actuate_joints(self, walker, data, spec)

    def actuators(self, walker: HybridWalker, data, spec):
        """``(acts, limit)``: the actuators and whether the legs are massless (Kuo's
        limit, :func:`walkerlab.models.hybrid.leg_masses.massless_limit`)."""
        from walkerlab.codegen.cache import functions

        limit = massless_limit(data, spec)
        acts = Actuators(spec, functions(data), len(walker.roles), limit,
                         float(walker.total_mass_kg),
                         some_massless=any(b.massless for b in data.structure.bodies))
        self.hold(acts, walker)
        if spec.push_off is not None and acts.rows is not None:
            check_impact_masses(acts)
        return acts, limit

    def hold(self, acts, walker: HybridWalker) -> None:
        """The constraint the heel strike holds (none for straight legs)."""

    def guard_outputs(self, phase: Phase, data):
        """The compiled outputs of a phase's guards when the passive phase has no compiled
        flow (none here: every legged phase has one)."""
        return None


class _LockingKnees(_Joints):
    """Knees that lock: the heel strike takes place with the swing knee locked (the last
    phase's constraint); no hip spring (the generated spring acts on straight legs)."""

    hip_spring = False

    def hold(self, acts, walker: HybridWalker) -> None:
        """The locked knee of the last phase (``locked_swing``)."""
        acts.hold_lock(walker.phases[-1].constraint)


class _FreeJoints(_Joints):
    """Every joint free (five-link bipeds; a torso hinged on straight legs): hips and knees
    driven, one spline for laws that share a table (:func:`walkerlab.models.hybrid.
    free_joint_actuators.five_link_actuators`); the passive flow is not compiled, the driven
    one takes its guards' outputs from :func:`walkerlab.models.hybrid.rigid_free_joints.
    guard_outputs`."""

    hip_spring = False

    def actuators(self, walker: HybridWalker, data, spec):
        """``(acts, False)``: the free-jointed walker's actuators (its legs carry mass)."""
        from walkerlab.models.hybrid.free_joint_actuators import five_link_actuators

        return five_link_actuators(data, spec, walker.roles, push_off=True), False

    def guard_outputs(self, phase: Phase, data):
        """Each guard of ``phase`` as a generated output and offset."""
        from walkerlab.models.hybrid.rigid_free_joints import guard_outputs

        return guard_outputs(phase, data)


class _Legs3d(_Joints):
    """Straight legs in 3D (:func:`walkerlab.codegen.legged.derive_legged`): the hip
    torque between the legs' pitch joints and the push-off along the trailing leg, by the
    planar walkers' :class:`Actuators`.  Each leg's pitch ``theta`` is its rotation about
    its own (rolled) hip axis, ``R_leg = Rot(s, phi_leg) Rot(z, theta)``, from the
    pelvis, which neither pitches nor yaws: a torque ``+tau`` on the swing leg about its
    pitch axis and ``-tau`` on the stance leg about its own does the virtual work ``tau
    delta(theta_sw - theta_st)`` (the legs' rolls are not pitch: their angular rates
    about the hip axis cancel in the difference), so ``B = d(delta)/dq`` of the generated
    leg angles is the true generalised force, as the planar hip's.  The push-off's
    extended system is the generated one in world axes (``impact_matrices``: ``(n + 3)``
    extended coordinates), along the trailing leg from its foot to its own hip
    (``stance_hip``).  The heel strike's role swap carries the rolls too: its rate map is
    the generated reset's (:meth:`PushOffTransition.swap_from_reset`), not the legs'
    pitches alone."""

    hip_spring = False  # the 3D flow has no generated hip spring: the laws are compiled

    def actuators(self, walker: HybridWalker, data, spec):
        """``(acts, False)`` (legs with mass: the 3D walker has no massless limit); a disc
        foot's push-off from its rolling contact (``stance_contact``), as a planar arc's."""
        acts, limit = super().actuators(walker, data, spec)
        if limit:
            raise ValueError("walker.actuation: a 3D walker's legs carry mass")
        return acts, limit

    def hold(self, acts, walker: HybridWalker) -> None:
        """No constraint; the role swap's rate map from the generated reset (the rolls)."""
        acts.push.swap_from_reset()


class _KneedLegs3d(_Legs3d):
    """Locking knees in 3D (:func:`walkerlab.codegen.legged.derive_legged`: the 3D straight
    legs' tree with a pitch knee on the swing leg): the 3D straight legs' hip torque and
    push-off (:class:`_Legs3d`) with the planar kneed walker's knee (:class:`_LockingKnees`).
    The knee's pitch ``theta_sh - theta_sw`` is a rotation about the swing thigh's own
    (rolled) ``z`` axis, the hip's ``theta_sw - theta_st`` one about the hip axis, so each
    torque's generalised force is ``tau d(delta)/dq`` of the generated leg angles as in the
    plane; the push-off and the heel strike hold the locked swing knee (the last phase's
    constraint) in the generated 3D extended impact system, and the role swap's rate map is
    the generated reset's (the lean, the rolls and the new swing knee's shank)."""

    def hold(self, acts, walker: HybridWalker) -> None:
        """The locked knee of the last phase (``locked_swing``), with the generated reset's
        role swap."""
        acts.hold_lock(walker.phases[-1].constraint)


class _FlatFeet:
    """Flat feet: their stance-foot modes' own mass matrices or an ankle push-off
    (:func:`walkerlab.models.hybrid.ankle_push_off.actuate_flat`)."""

    hip_spring = False

    def actuate(self, walker: HybridWalker, data, spec) -> HybridWalker:
        """The actuated flat-footed walker."""
        from walkerlab.models.hybrid.ankle_push_off import actuate_flat

        return actuate_flat(walker, data, spec)


class _RollingPolygon:
    """A walker without actuators so far (a spoked wheel: one rigid body, no joint; a walker
    in 3D) - every actuator refused by the table."""

    hip_spring = False

    def actuate(self, walker: HybridWalker, data, spec) -> HybridWalker:
        """Refuse the first actuator ``spec`` asks for (one line, naming its field)."""
        refuse_actuators(data.structure.kind, spec, "rigid")
        return walker


# each kind's actuators part (:attr:`walkerlab.walker.kinds.Kind.actuators`) given how
# :func:`actuate` drives it (none: passive so far, the capability table refuses)
P.ACTUATORS_HIPS.provide(_Joints())
P.ACTUATORS_LATCHED_KNEES.provide(_LockingKnees())
P.ACTUATORS_JOINTS.provide(_FreeJoints())
P.ACTUATORS_ANKLES.provide(_FlatFeet())
P.ACTUATORS_LEGS_3D.provide(_Legs3d())
P.ACTUATORS_KNEES_3D.provide(_KneedLegs3d())
P.ACTUATORS_NONE.provide(_RollingPolygon())
