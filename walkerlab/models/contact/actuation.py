"""Actuators in the compliant-contact view of a walker: the same ``walker.actuation`` as the
rigid model (:mod:`walkerlab.models.hybrid.actuated`), as forces.

Hip torques
-----------
A hip actuator's torque ``tau`` (:class:`walkerlab.models.actuation.TorqueLaws`, the rigid
view's laws) acts ``+tau`` on the swing leg and ``-tau`` on the stance leg: on the floating
coordinates (``hip_x, hip_y, leg1_angle, leg2_angle``, absolute leg angles) its generalised
force is ``tau (e_swing - e_stance)`` and its power ``tau (dtheta_swing - dtheta_stance)``.
Which leg is the stance leg is a discrete state of the run, as in the rigid model: leg2 at
the start, then the leg whose foot touched down last (the integrator switches it at each
touchdown, :mod:`walkerlab.integrate.contact_powered`).

On a kneed walker (floating coordinates ``hip_x, hip_y, leg1_thigh_angle,
leg1_shank_angle, leg2_thigh_angle, leg2_shank_angle``) the hip torque acts between the two
thighs: ``+tau`` on the swing thigh's absolute angle, ``-tau`` on the stance thigh's, the
shanks and knees get nothing; its power is ``tau (dtheta_swing_thigh -
dtheta_stance_thigh)`` and its phase variable the stance thigh's angle (the rigid view's
stance angle while the stance knee is straight).  The knee stops' power is a term of the
ledger of its own (:data:`KNEE_WORK_NAMES`).

On a flat-footed walker (floating coordinates ``hip_x, hip_y, leg1_angle, leg2_angle,
leg1_foot_angle, leg2_foot_angle``) the hip torque acts between the two legs as on point
feet: ``+tau`` on the swing leg's absolute angle, ``-tau`` on the stance leg's, the feet
(hinged at the ankles, on their springs) get nothing; its power is ``tau (dtheta_swing -
dtheta_stance)``.  The ledger (:data:`FLAT_HIP_WORK_NAMES`) carries the torque's positive
and negative work, the ankle dampers' and the contact forces' (the ankle springs' energy is
the walker's potential energy).  An ankle push-off and a push-off may come with them.

Any joint
---------
Every coordinate of the floating view but the hip's position is a link's absolute angle
(a bisecting torso's angle is the legs' mean, of the thighs' on knees), so a torque at any
joint of :data:`walkerlab.config.actuation.JOINTS` (the hip; ``stance_hip`` / ``swing_hip``
torso to leg; ``stance_knee`` / ``swing_knee``; ``stance_ankle`` / ``swing_ankle``) has the
constant generalised force ``B tau``: ``+1`` on its second link's coordinate, ``-1`` on its
first's (``1/2`` on each leg for a bisecting torso), read per stance leg; its joint angle
``B^T q`` and the phase variable (the stance leg's angle, a kneed walker's stance thigh's:
the rigid view's) go into the same laws
(:meth:`walkerlab.models.actuation.TorqueLaws.each`); its power is ``tau . B^T dq``.

Push-off
--------
The rigid model's push-off is an impulse ``P`` at the trailing foot's contact point (a point
foot; an arc foot's material point at its rolling contact; a flat foot's toe, the ankle
held: :meth:`PushOffPulse.push_off_force`) along the line from it to the hip
(from the foot towards the hip) immediately before heel strike, the trailing foot free for it
(Kuo 2002; its work is the kinetic energy it adds).  Here it is a pulse: a constant force
``(P / T) e`` at the trailing foot for ``T = contact.push_off_duration_s``, ending at the
leading foot's touchdown (started when the swing foot's height extrapolated at its rate
predicts the touchdown ``T`` ahead: :mod:`walkerlab.integrate.contact_powered`), with ``e``
the unit vector from that foot to the hip, recomputed as the leg turns; its generalised force
is ``J_foot^T F`` and its power ``F . v_foot``.  ``T = 0`` applies the impulse at once at the
touchdown, before any collision force (``M dq+ = M dq- + J_foot^T P e``).  The order
matters: after the heel strike the hip moves across the new stance leg and has a component
along the trailing leg, so a push-off after it does more work than one before (Kuo 2002's
argument for the pre-emptive push-off); a pulse that started at the touchdown worked inside
the compliant collision, 3.5x the rigid push-off's work per step at 5 ms.  Ending at the
touchdown the pulse converges to the impulse as ``T -> 0`` (first order in ``T``: while it
lasts it takes over the stance foot's weight support).  ``P`` follows the same law as in
the rigid view (:func:`walkerlab.models.actuation.push_off_impulse`) at the hip speed where
the pulse starts.

Ankle push-off on flat feet
---------------------------
The rigid view's ankle push-off (:mod:`walkerlab.models.hybrid.ankle_push_off`) acts on the
stance ankle from heel off (the stance heel's normal force reaches 0 in foot flat) until
heel strike: ``tau(a) = -k_po (a - r_po) - tau_0`` on the ankle angle ``a = psi_foot -
psi_leg`` (toe up > 0).  Here it is the same torque as a force pair at the stance ankle:
``+tau`` on the stance foot, ``-tau`` on the stance leg (generalised force ``tau (e_foot -
e_leg)``, power ``tau da/dt``), switched on when the stance heel leaves the ground while
its toe is loaded (the heel's penetration crossing 0 downwards with the toe's above 0: the
contact terms of heel off, an event of the integrator) and off at the swing foot's
touchdown (the rigid view's heel strike).  The ledger of such a walker
(:attr:`ContactActuators.work_names`: :data:`ANKLE_WORK_NAMES`) carries the torque's
positive and negative work apart, the ankle (and hip) dampers' work and the contact forces'.

Source: Kuo (2002), J. Biomech. Eng. 124:113-120 (push-off, swing-hip torque); Westervelt,
Grizzle & Koditschek (2003), IEEE TAC 48(1):42-56 (phase-variable references); Mizani et al.
(2018; the paper's ref. [32]) for the ankle push-off of a flat-footed walker.
"""

from __future__ import annotations

import numpy as np

from walkerlab.models.actuation import TorqueLaws, push_off_impulse
from walkerlab.walker.joints import joint_links

__all__ = ["ANKLE_WORK_NAMES", "FLAT_HIP_WORK_NAMES", "FLOW_LAW_WORK_NAMES", "KNEE_WORK_NAMES",
           "WORK_NAMES",
           "ContactActuators", "ContactRows", "PushOffPulse", "powered_rhs"]


class ContactRows:
    """Readers of a contact walker's contact table at one state, shared by every kind of
    contact actuators (the powered run's touchdown and heel-off events read them)."""

    _points = None  # each leg's rows of the table, filled on first use
    _last = None  # (walker, state bytes, rows) of the last call (the events share one state)

    def contact_rows(self, walker, x) -> np.ndarray:
        """The contact table (points, 8) at one state ``x`` (points as
        ``walker.contact_names()``; columns as :meth:`leg_contacts`)."""
        return walker.kernels.contact_table(np.ascontiguousarray(np.atleast_2d(x), float),
                                            *walker._args())[0]

    def leg_contacts(self, walker, x) -> list[np.ndarray]:
        """Per leg (leg1, leg2) the contact-table row (8,) of its deepest point on ground
        (its only point for point feet; as :meth:`ContactWalker.foot_quantities` picks a
        flat foot's, without building its dictionaries: the event functions' fast path):
        ``penetration`` [m], its rate [m/s], slip velocity [m/s], ``s`` [m], normal and
        friction force [N], power [W], ``on_ground``."""
        x = np.asarray(x, float)
        key = x.tobytes()
        last = self._last
        if last is not None and last[0] is walker and last[1] == key:  # the events of one
            return last[2]  # step ask at the same state: the table once
        tab = self.contact_rows(walker, x)
        if self._points is None:  # each leg's rows of the table, once
            names = walker.contact_names()
            self._points = [[k for k, c in enumerate(names) if walker.contact_leg(c) == leg]
                            for leg in ("leg1", "leg2")]
        if all(len(idx) == 1 for idx in self._points):  # point feet: each leg's one row
            out = [tab[idx[0]].copy() for idx in self._points]
            self._last = (walker, key, out)
            return out
        out = []
        for idx in self._points:
            rows = tab[idx]
            on = rows[:, 7] > 0.5
            out.append(rows[int(np.argmax(np.where(on, rows[:, 0], rows[:, 0] - 1e3)))])
        self._last = (walker, key, out)
        return out


class PushOffPulse:
    """The push-off pulse of a contact walker's actuators, shared by every kind (a mixin:
    the owner sets ``spec``, ``nq``, ``hip``, ``pulse_s``).

    The pulse acts at the trailing foot's contact point (:meth:`push_row`): a point foot's
    point, an arc foot's material point at its rolling contact (the generated ``feet``
    gives that point's velocity and Jacobian), a flat foot's toe; along the line from that
    point to the hip."""

    _push_rows = None  # the contact-table row of each leg's push-off point, on first use
    #: the generated flow carries a joint law that does work (a 3D walker's hip-roll law,
    #: set by :class:`ContactActuators`): the ledger's :data:`FLOW_LAW_WORK_NAMES` terms
    flow_law = False

    def push_row(self, walker, leg: int) -> int:
        """Row of ``walker.contact_names()`` where leg ``leg`` (0: leg1, 1: leg2) pushes off:
        ``leg{i}`` (point and arc feet) or ``leg{i}_toe`` (flat feet)."""
        if self._push_rows is None:
            names = tuple(walker.contact_names())
            self._push_rows = tuple(
                names.index(f"leg{i}_toe") if f"leg{i}_toe" in names else names.index(f"leg{i}")
                for i in (1, 2))
        return self._push_rows[leg]

    @staticmethod
    def hips(walker, x) -> tuple[np.ndarray, np.ndarray]:
        """``(H, HV)``: the hip, leg1's and leg2's own hips (3, d) [m] and their velocities
        [m/s] at the state ``x`` (the generated ``hips``: a planar walker's legs share the
        hip, its floating base; a 3D walker's hips are the ends of its hip axis, the pelvis
        between them)."""
        d = walker.dim
        H, HV = np.empty((3, d)), np.empty((3, d))
        walker.kernels.hips(np.ascontiguousarray(x, dtype=float), walker.walker_params, H, HV)
        return H, HV

    def impulse(self, walker, x) -> float:
        """Push-off impulse ``P`` [N s] for the state ``x`` where the pulse starts (its hip
        speed: the pelvis' in 3D, as the rigid view's)."""
        v = self.hips(walker, x)[1][0]
        speed = v[0]
        for c in v[1:]:  # np.hypot over the components (a planar walker's two: one call)
            speed = np.hypot(speed, c)
        return float(push_off_impulse(self.spec.push_off, speed))

    def push_direction(self, walker, x, trailing: int):
        """``(e, J, v)``: the unit vector (d,) from leg ``trailing``'s push-off point
        (:meth:`push_row`) towards its leg's hip (the push-off's direction), that point's
        Jacobian (d, nq) and velocity (d,) [m/s]."""
        n, d = self.nq, walker.dim
        nf = len(walker.contact_names())
        P, V, J = np.empty((nf, d)), np.empty((nf, d)), np.empty((nf, d, n))
        x = np.asarray(x, float)
        walker.kernels.feet(x, walker.walker_params, P, V, J)
        k = self.push_row(walker, trailing)
        r = self.hips(walker, x)[0][1 + trailing] - P[k]
        return r / np.sqrt(r @ r), J[k], V[k]

    def push_off_force(self, walker, x, trailing: int, force: float):
        """Generalised force (nq,) of a force ``force`` [N] at leg ``trailing``'s push-off
        point along the line to the hip, and its power [W].

        On a flat foot the ankle holds through the push-off, as in the rigid view
        (:class:`walkerlab.models.hybrid.toe_push_off.FlatPushOff`: a massless foot passes a
        push off its ankle's line only with an ankle torque; the joint holds): the force at
        the toe comes with the ankle torque ``lam`` (``+lam`` on the foot, ``-lam`` on the
        leg) that leaves the ankle's angular acceleration from them at 0, ``a M^-1 (J^T F +
        a lam) = 0`` with ``a = d(ankle)/dq``; the power is ``F . v_toe + lam d(ankle)/dt``
        (``Q . dq``).  Without it the pulse would spin the light (regularising) foot about
        its ankle and reach the legs only through the toe's lift-off.

        A walker in 3D: the trailing foot holds its turn about the ground's normal through
        the push-off, as in the rigid view (whose extended impact frees the stance foot's
        three translations, not its yaw): the pulse comes with the moment ``lam`` about the
        normal on the foot's leg that leaves the foot's spin acceleration from them at 0,
        ``a M^-1 (J^T F + a lam) = 0`` with ``a = Jn`` (the spin's Jacobian, the generated
        ``spins``); the power is ``F . v_foot + lam w_n``.  The pulse's ground reaction
        grips in yaw as the rigid foot does; without it the walker, whose yaw inertia about
        the trailing foot is small, turns under the pulse (measured on
        configs/hip_width_powered.yaml: the pulse's work 0.0529 J a step against the
        rigid push-off's 0.0297 J)."""
        e, J, v = self.push_direction(walker, x, trailing)
        F = force * e
        Q = J.T @ F
        foot = getattr(self, "foot", None)
        n = self.nq
        x = np.asarray(x, float)
        if foot is None:
            if walker.dim == 2:
                return Q, float(F @ v)
            k = self.push_row(walker, trailing)
            nf = len(walker.contact_names())
            S, Jn = np.empty(nf), np.empty((nf, n))
            walker.kernels.spins(x, walker.walker_params, S, Jn)
            a, rate = Jn[k].copy(), float(S[k])
        else:
            a = np.zeros(n)
            a[foot[trailing]], a[self.ankle_leg[trailing]] = 1.0, -1.0
            rate = None
        M = walker.mass_matrix(x)
        Ma = np.linalg.solve(M, a)
        lam = -float(Ma @ Q) / float(a @ Ma)  # a M^-1 Q = Ma . Q (M symmetric)
        Q = Q + lam * a
        if rate is None:
            rate = float(a @ x[n:])
        return Q, float(F @ v) + lam * rate


class ContactActuators(PushOffPulse, ContactRows):
    """The actuators of one contact walker whose floating coordinates are its links'
    absolute angles (straight or kneed legs; point, arc or flat feet; a bisecting torso):
    joint torques at any of its joints, a push-off pulse, a flat foot's ankle push-off
    (module docstring).  A free-jointed biped has
    :class:`walkerlab.models.contact.joint_torques.JointTorqueActuators`.

    Parameters
    ----------
    spec : walkerlab.config.actuation.Actuation
    coordinates : tuple of str
        The floating coordinates (``hip_x, hip_y, leg1_angle, leg2_angle``; flat feet then
        ``leg1_foot_angle, leg2_foot_angle``; knees: ``leg{i}_thigh_angle,
        leg{i}_shank_angle`` in place of ``leg{i}_angle``).
    pulse_s : float
        Push-off pulse duration [s] (0: an impulse).
    kind : walkerlab.walker.kinds.Kind
        The walker's kind (its refusals: :data:`walkerlab.walker.kinds.CAPABILITIES`).
    torso : bool
        The walker has a torso bisecting the legs (its angle the mean of the legs', of the
        thighs' on knees: the rigid view's).
    flow_law : bool
        The walker's generated flow carries a joint law that does work (a 3D walker's
        hip-roll law, Kuo 1999): its positive and negative work are terms of the ledger
        (:data:`FLOW_LAW_WORK_NAMES`).

    Raises
    ------
    ValueError
        An ankle push-off on feet that are not flat, a joint the walker does not have
        (naming ``walker.actuation.torques.<i>.joint`` and the joints it has), a torque per
        foot mass (one line).
    """

    #: A touchdown is a heel strike only this far [m] ahead of the stance foot (a scuff
    #: near mid-stance is not one; the contact gait analysis' ``min_step_m`` default).
    min_step_m = 0.05

    #: the ledger's words for this walker's work terms where they differ from the generic
    #: ones (:mod:`walkerlab.io.schemas.contact_sim`): none
    work_labels: dict = {}

    def __init__(self, spec, coordinates, pulse_s: float, kind, torso: bool = False,
                 flow_law: bool = False):
        names = tuple(coordinates)
        #: a kneed walker: the hip torque acts on the thighs (module docstring)
        self.knee = "leg1_thigh_angle" in names
        leg = ("leg1_thigh_angle", "leg2_thigh_angle") if self.knee else ("leg1_angle",
                                                                            "leg2_angle")
        if leg[0] not in names or leg[1] not in names:
            raise ValueError("walker.actuation: the contact view carries these actuators on "
                             "walkers whose coordinates are their links' angles (a "
                             "free-jointed biped has its own)")
        flat = "leg1_foot_angle" in names
        ankle = getattr(spec, "ankle_push_off", None)
        if ankle is not None:  # the table's: a flat foot's ankle only
            kind.require("ankle_push_off", "contact", "walker.actuation.ankle_push_off")
        for i, t in enumerate(spec.torques):
            if t.scaled_by != "none":
                raise ValueError(f"walker.actuation.torques.{i}.scaled_by: foot_mass is for "
                                 "walkers whose legs are massless (the contact view has "
                                 "massive legs)")
        self.ankle = ankle
        #: the walker's own joint law in its generated flow does work (a 3D walker's
        #: hip-roll law): the ledger's :data:`FLOW_LAW_WORK_NAMES` terms
        self.flow_law = bool(flow_law)
        self._dampers = None  # the walker's dampers, looked up on first use
        self.foot = ((names.index("leg1_foot_angle"), names.index("leg2_foot_angle"))
                     if flat else None)
        self.spec = spec
        self.nq = len(names)
        self.pulse_s = float(pulse_s)
        #: each leg's angle column (a kneed walker's: its thigh's)
        self.leg = (names.index(leg[0]), names.index(leg[1]))
        #: the link an ankle joins to its foot (a kneed walker's shank)
        self.ankle_leg = ((names.index("leg1_shank_angle"), names.index("leg2_shank_angle"))
                          if self.knee else self.leg)
        #: the hip's position columns where the floating base is the hip point (a walker
        #: in 3D is set free at a foot: (-1, -1))
        self.hip = ((names.index("hip_x"), names.index("hip_y")) if "hip_x" in names
                    else (-1, -1))
        self.laws = TorqueLaws(spec.torques)
        #: every torque at the hip between the legs (the arithmetic of a single hip torque)
        self.hip_only = all(t.joint == "hip" for t in spec.torques)
        # per stance leg (0: leg1, 1: leg2): B (nq, k), +1 on each torque's second link's
        # column, -1 on its first's (a bisecting torso: 1/2 on each leg)
        self.B = []
        for stance in (0, 1):
            links = self._links(names, stance, torso)
            pairs = [joint_links(links, t.joint, f"walker.actuation.torques.{i}.joint")
                     for i, t in enumerate(spec.torques)]
            B = np.zeros((self.nq, len(pairs)))
            for k, (first, second) in enumerate(pairs):
                for col, w in links[second]:
                    B[col, k] += w
                for col, w in links[first]:
                    B[col, k] -= w
            self.B.append(B)

    def _links(self, names, stance: int, torso: bool) -> dict:
        """``{link role: [(column, weight), ...]}`` with leg ``stance`` in stance: the
        link's absolute angle as a weighted sum of coordinates."""
        legs = {"stance": f"leg{stance + 1}", "swing": f"leg{2 - stance}"}
        out = {}
        for role, lg in legs.items():
            if self.knee:
                out[f"{role}_thigh"] = [(names.index(f"{lg}_thigh_angle"), 1.0)]
                out[f"{role}_shank"] = [(names.index(f"{lg}_shank_angle"), 1.0)]
            else:
                out[role] = [(names.index(f"{lg}_angle"), 1.0)]
            if self.foot is not None:
                out[f"{role}_foot"] = [(names.index(f"{lg}_foot_angle"), 1.0)]
        if torso:
            out["torso"] = [(self.leg[0], 0.5), (self.leg[1], 0.5)]
        return out

    def hip_angles(self, x, stance: int):
        """``(delta, ddelta, s, ds)`` with leg ``stance`` (0: leg1, 1: leg2) in stance:
        hip angle (swing minus stance) [rad], its rate [rad/s], the phase variable (the
        stance leg's angle) [rad] and its rate [rad/s]."""
        n = self.nq
        i_sw, i_st = self.leg[1 - stance], self.leg[stance]
        return (x[i_sw] - x[i_st], x[n + i_sw] - x[n + i_st], x[i_st], x[n + i_st])

    def joint_angles(self, x, stance: int):
        """``(deltas (k,), ddeltas (k,), s, ds)``: each torque's joint angle [rad] and rate
        [rad/s], ``angle(second) - angle(first)``, and the phase variable (the stance leg's
        angle; a kneed walker's stance thigh's: the rigid view's) and its rate."""
        n = self.nq
        B, i_st = self.B[stance], self.leg[stance]
        return B.T @ x[:n], B.T @ x[n:], x[i_st], x[n + i_st]

    def torques(self, x, stance: int, t_step: float = 0.0) -> np.ndarray:
        """Each actuator's torque (k,) [N m] (``walker.actuation.torques`` order)."""
        x = np.asarray(x, float)
        if self.hip_only:
            return self.laws(*self.hip_angles(x, stance), t_step)
        return self.laws.each(*self.joint_angles(x, stance), t_step)

    def hip_torque(self, x, stance: int, t_step: float = 0.0) -> tuple[np.ndarray, float]:
        """Generalised force of the joint torques (nq,) [N, N m] and their power [W];
        ``t_step`` the time since the step's heel strike [s] (``time_reference`` laws).
        (The name is historical: every joint's torque is here.)"""
        Q = np.zeros(self.nq)
        if not self.laws:
            return Q, 0.0
        if not self.hip_only:
            deltas, ddeltas, s, ds = self.joint_angles(x, stance)
            tau = self.laws.each(deltas, ddeltas, s, ds, t_step)
            return self.B[stance] @ tau, float(tau @ ddeltas)
        delta, ddelta, s, ds = self.hip_angles(x, stance)
        tau = float(np.sum(self.laws(delta, ddelta, s, ds, t_step)))
        Q[self.leg[1 - stance]] += tau
        Q[self.leg[stance]] -= tau
        return Q, tau * ddelta

    @property
    def work_names(self) -> tuple[str, ...]:
        """Names of the work integrals this walker's run carries: point and arc feet
        :data:`WORK_NAMES` (knees: :data:`KNEE_WORK_NAMES`); flat feet the ankle push-off's
        positive and negative work (with one), the joint torques' (with some, or neither),
        the push-off's (with one), the dampers', the contact forces' (an ankle push-off
        alone: :data:`ANKLE_WORK_NAMES`; hip torques alone :data:`FLAT_HIP_WORK_NAMES`),
        the knee stops' last on knees."""
        knee = ("knee_stop",) if self.knee else ()
        if self.foot is None:
            return WORK_NAMES + knee + (FLOW_LAW_WORK_NAMES if self.flow_law else ())
        names = ()
        if self.ankle is not None:
            names += ANKLE_WORK_NAMES[:2]
        if self.spec.torques or self.ankle is None:
            names += WORK_NAMES[:2]
        if self.spec.push_off is not None:
            names += ("push_off",)
        return names + ("damper", "contact") + knee

    def ankle_torque(self, x, stance: int) -> tuple[np.ndarray, float]:
        """Generalised force (nq,) of the ankle push-off at leg ``stance``'s ankle (0: leg1,
        1: leg2) and its power [W] (module docstring)."""
        n = self.nq
        i_f, i_l = self.foot[stance], self.ankle_leg[stance]
        po = self.ankle
        a = x[i_f] - x[i_l]
        tau = -po.stiffness_n_m_per_rad * (a - po.rest_angle_rad) - po.constant_n_m
        Q = np.zeros(n)
        Q[i_f] += tau
        Q[i_l] -= tau
        return Q, float(tau * (x[n + i_f] - x[n + i_l]))

    def damper_power(self, walker, x) -> float:
        """Power [W] (<= 0) of the ankle spring-dampers, ``-c (d delta/dt)^2`` at each
        ankle (``delta`` = foot angle - leg angle), and of the springs' dampers between the
        legs (on the legs' angle difference); the ledger's ``damper`` term."""
        n = self.nq
        if self._dampers is None:  # (ankle c, sum of the leg springs' c), once
            p = dict(zip(walker.data.structure.param_names, walker.data.params))
            self._dampers = (float(p.get("c_ankle", 0.0)),
                             sum(float(p[f"c_s{i}"])
                                 for i in range(len(walker.data.structure.springs))))
        c_a, c_s = self._dampers
        r1 = x[n + self.foot[0]] - x[n + self.ankle_leg[0]]
        r2 = x[n + self.foot[1]] - x[n + self.ankle_leg[1]]
        hip = x[n + self.leg[1]] - x[n + self.leg[0]]
        return float(-c_a * (r1 * r1 + r2 * r2) - c_s * hip * hip)

    def compiled_rhs(self, walker):
        """The compiled right-hand side of :func:`powered_rhs` for this walker, or None
        where it has none (knees, flat feet, torques at joints other than the hip: those
        run on :func:`powered_rhs`).

        Returns
        -------
        callable or None
            ``f(y, stance, push, t_step) -> ndarray (2 nq + 4,)``: ``[dx, powers]`` as
            :func:`powered_rhs` returns them concatenated, the same numbers (its arithmetic
            in the generated module's ``powered_rhs`` kernel, one call; the torque laws
            evaluated here when there are any: they may be any callable).
        """
        kern = getattr(walker.kernels, "powered_rhs", None)
        if (kern is None or self.knee or self.foot is not None or self.ankle is not None
                or not self.hip_only or self.flow_law):
            return None
        args = walker._args()
        nx = 2 * self.nq

        def f(y, stance: int, push, t_step: float):
            x = np.ascontiguousarray(y[:nx], dtype=float)
            laws = self.laws
            tau = 0.0
            if laws:
                delta, ddelta, s, ds = self.hip_angles(x, stance)
                tau = float(np.sum(laws(delta, ddelta, s, ds, t_step)))
            out = np.empty(nx + 4)
            kern(x, *args, bool(laws), self.leg[1 - stance], self.leg[stance], tau,
                 -1 if push is None else self.push_row(walker, int(push[0])),
                 0.0 if push is None else float(push[1]), out)
            return out
        return f


#: Names of the work integrals a powered contact run carries beside the state [J].
WORK_NAMES = ("hip_torque_positive", "hip_torque_negative", "push_off", "contact")
#: ... and those of a flat-footed walker's ankle push-off run [J].
ANKLE_WORK_NAMES = ("ankle_torque_positive", "ankle_torque_negative", "damper", "contact")
#: ... and those of a flat-footed walker's hip torque run [J].
FLAT_HIP_WORK_NAMES = ("hip_torque_positive", "hip_torque_negative", "damper", "contact")
#: ... and those of a kneed walker's (the knee stops' work last) [J].
KNEE_WORK_NAMES = WORK_NAMES + ("knee_stop",)
#: ... and those a joint law in the flow adds (a 3D walker's hip-roll law: its positive and
#: negative work, as the rigid ledger counts it among the actuators') [J].
FLOW_LAW_WORK_NAMES = ("hip_roll_positive", "hip_roll_negative")


def powered_rhs(walker, x, stance: int, push: tuple[int, float] | None = None,
                t_step: float = 0.0, ankle: bool = False):
    """dx/dt of the contact walker with its actuators, and the powers of the ledger.

    Parameters
    ----------
    walker : ContactWalker
        With ``actuators`` set.
    x : ndarray, shape (2 nq,)
        State (``walker.state_names()``), SI.
    stance : int
        The stance leg (0: leg1, 1: leg2).
    push : (int, float), optional
        A push-off pulse in progress: the trailing leg and the force [N].
    t_step : float
        Time since the step's heel strike (the last touchdown, or the run's start) [s].
    ankle : bool
        The ankle push-off is on (flat feet: from the stance heel's lift-off to the next
        touchdown).

    Returns
    -------
    dx : ndarray, shape (2 nq,)
        ``[dq, ddq]`` [m/s, rad/s, m/s^2, rad/s^2].
    powers : ndarray, shape (4,) or (5,)
        [W], in the order of ``walker.actuators.work_names``: the hip torques' positive and
        negative power, the push-off's, and the contact forces' (normal + friction, all
        points; negative while they dissipate or store); flat feet: the ankle push-off's
        (or the hip torques') positive and negative power, the dampers', the contact forces';
        knees: then the knee stops' power.
    """
    acts = walker.actuators
    n = walker.nq
    dx = np.array(walker.rhs(0.0, x), float)
    p_contact = float(np.sum(walker.kernels.contact_table(
        np.ascontiguousarray(x[None], dtype=float), *walker._args())[0, :, 6]))
    if getattr(acts, "foot", None) is not None:  # flat feet: the ankle dampers' term
        return _flat_rhs(walker, acts, x, dx, p_contact, stance, push, t_step, ankle)
    Q, p_tau = acts.hip_torque(x, stance, t_step)
    p_po = 0.0
    if push is not None:
        Qp, p_po = acts.push_off_force(walker, x, push[0], push[1])
        Q = Q + Qp
    if np.any(Q):
        dx[n:] += np.linalg.solve(walker.mass_matrix(x), Q)
    if acts.knee:
        return dx, np.array([max(p_tau, 0.0), min(p_tau, 0.0), p_po, p_contact,
                             _knee_power(walker, x)])
    if acts.flow_law:
        p_law = _flow_law_power(walker, x)
        return dx, np.array([max(p_tau, 0.0), min(p_tau, 0.0), p_po, p_contact,
                             max(p_law, 0.0), min(p_law, 0.0)])
    return dx, np.array([max(p_tau, 0.0), min(p_tau, 0.0), p_po, p_contact])


def _flow_law_power(walker, x) -> float:
    """The power [W] of the joint law in the walker's generated flow (a 3D walker's
    hip-roll law) at the state ``x``: the generated ``rhs_q``'s joint-law power
    (:func:`walkerlab.models.contact.rhs_lines.rhs_source`, no force added, no ghost
    foot)."""
    n = walker.nq
    S = np.zeros(n + 12)
    S[n + 10] = -1.0
    walker.kernels.rhs_q(np.ascontiguousarray(x, dtype=float), *walker._args(), S,
                         np.empty(2 * n))
    return float(S[n + 7])


def _knee_power(walker, x) -> float:
    """The knee stops' power [W] at the state ``x``."""
    return float(np.sum(walker.kernels.knee_table(
        np.ascontiguousarray(x[None], dtype=float), *walker._args())[0, :, 3]))


def _flat_rhs(walker, acts, x, dx, p_contact, stance, push, t_step, ankle):
    """:func:`powered_rhs` of a flat-footed walker: the ankle push-off (while ``ankle``),
    the joint torques, the push-off pulse at the trailing toe; powers in the order of
    ``acts.work_names``."""
    n = walker.nq
    powers = []
    Q = None
    if acts.ankle is not None:
        p_a = 0.0
        if ankle:
            Q, p_a = acts.ankle_torque(x, stance)
        powers += [max(p_a, 0.0), min(p_a, 0.0)]
    if acts.spec.torques or acts.ankle is None:
        Qt, p_tau = acts.hip_torque(x, stance, t_step)
        if acts.spec.torques:
            Q = Qt if Q is None else Q + Qt
        powers += [max(p_tau, 0.0), min(p_tau, 0.0)]
    if acts.spec.push_off is not None:
        p_po = 0.0
        if push is not None:
            Qp, p_po = acts.push_off_force(walker, x, push[0], push[1])
            Q = Qp if Q is None else Q + Qp
        powers.append(p_po)
    if Q is not None and np.any(Q):
        dx[n:] += np.linalg.solve(walker.mass_matrix(x), Q)
    powers += [acts.damper_power(walker, x), p_contact]
    if acts.knee:
        powers.append(_knee_power(walker, x))
    return dx, np.array(powers)
