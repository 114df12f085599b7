"""The ground's force on a rigid hybrid walker's stance foot, and the impulses of its
step-to-step transition, from the walker's generated floating view.

The rigid model pins the stance foot; a real foot stays on the ground only while the
ground pushes (a unilateral contact).  Its force follows from the floating view of the same
walker (:mod:`walkerlab.codegen.floating`: coordinates ``[hip_x, hip_y, link angles]``, no
foot pinned), whose equations ``M(q) qdd + h(q, dq) = sum_i J_i^T F_i + Q`` have, in the
rows of the hip's position, the whole walker's linear momentum: every point of the walker
moves with the hip, so ``J_i`` has the identity there, and a joint torque ``Q`` (an
actuator, a spring, a damper between links) does no work on a translation of the whole
walker.  With the stance foot the only contact,

    F = (M qdd_f + h)[hip_x, hip_y]      (= total mass x (CoM acceleration + g), Newton)

where ``qdd_f`` is the rigid flow's acceleration in the floating coordinates: the link
angles' accelerations from the rigid ones, and the hip's from the stance foot's
kinematics, ``v_hip = -J_s,links dq_links`` (the stance foot's material point at rest; an
arc foot rolls), differentiated: ``a_hip = -(J_s,links qdd_links + (dV_s/dq) dq)``.

At the end of a step the same rows give the total impulse of the ground,
``Lambda = (M (dq_f+ - dq_f-))[hip rows]``: the push-off's (an impulse ``P`` along the
trailing leg, :mod:`walkerlab.models.hybrid.actuated`) plus the heel strike's at the leading
foot (the trailing foot leaves the ground with no impulse in the rigid model).  A
unilateral contact needs the normal component of each >= 0, and the trailing foot must move
away from the ground after the transition.

A walker whose legs are massless (the simplest walker, Garcia et al. 1998; Kuo 2002) has no
floating view; all its mass is the hip's, so the same rows read ``F = M_hip (a_hip + g)``,
with the hip's acceleration ``d^2/dt^2 hip(q(t))`` from the rigid model's own ``points``
(central differences along ``q + h dq + h^2 qdd / 2``), and the impulses
``M_hip (v_hip+ - v_hip-)``.

A walker in 3D (a straight-legged walker of :mod:`walkerlab.codegen.derive_3d`) has the
floating view of its body tree set free at the stance foot
(:func:`walkerlab.walker.tree.free_root`: three slides along the world's axes and a heading,
a turn about the slope's normal, before the tree's own joints, which keep the rigid model's
coordinates; :func:`walkerlab.codegen.floating_equations.derive_floating`).  Along the
rigid flow the free coordinates rest, so the slides' rows of ``M qdd + h`` are the force
(3,) and the heading's row the moment about the normal through the root's origin, moved to
the contact point: the **twist** the rigid stance joint carries (it lets the foot roll and
pitch, never turn), which a point foot on real ground cannot hold.  At a heel strike the
post-impact rates are the rigid reset's, relabelled back by its permutation (the reset's
configuration block).  A wheel in 3D turns on a spherical joint: no twist, and all its mass
is its hub's (the force from the hub's acceleration, in 3D).

Nothing here knows the number of states: the rigid state is read by role name
(``walker.leg_angles`` or the roles) and mapped to the floating view's link coordinates by
:func:`walkerlab.walker.layout.floating_links_from_rigid`.  Leg angles are affine in the
rigid coordinates (every generated walker's are), so the same map takes the rates'
derivatives to the angles' accelerations.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from walkerlab.codegen.floating import FREE_3D, ROLES_3D, floating_plain
from walkerlab.models.hybrid.floating_view import FloatingView
from walkerlab.walker import parts as P
from walkerlab.walker.layout import StateLayout, floating_links_from_rigid

__all__ = ["StanceReaction", "TransitionImpulses"]

#: the floating view's contact point of each role's foot (leg1 swings, leg2 stands)
_FOOT_OF_ROLE = {"swing": "leg1", "stance": "leg2"}


@dataclass(frozen=True)
class _Part:
    """What :class:`StanceReaction` needs of a walker's kind.

    Attributes
    ----------
    hub : bool
        All the mass is at the hip (a spoked wheel's hub): the force from the hip's
        acceleration, whatever the bodies (a legged walker: only when its legs are
        massless).
    trailing_point : str
        The rigid model's point that is the old stance foot after the transition (a
        biped's new swing foot, a wheel's spoke behind).
    refusal : str or None
        Why the kind is not checked here (one line), or None.
    """

    hub: bool = False
    trailing_point: str = "swing_foot"
    refusal: str | None = None


# each kind's reaction part (:attr:`walkerlab.walker.kinds.Kind.reaction`) given what the
# stance reaction needs of it, planar or 3D ("{title}": the kind's title)
P.REACTION_LEG_END.provide(_Part())
P.REACTION_FLAT_FEET.provide(_Part(refusal="flat feet: the rigid model's own guards check "
                                           "the heel's and toe's normal forces"))
P.REACTION_HUB.provide(_Part(hub=True, trailing_point="trailing_foot"))
P.REACTION_NONE.provide(_Part(refusal="{title}: its floating view has a stance knee the "
                                      "rigid state leaves straight and a heel strike whose "
                                      "reset is no relabelling, which this reaction does not "
                                      "map, so the stance foot's reaction is not computed"))


@dataclass(frozen=True)
class TransitionImpulses:
    """The ground's impulses across one step-to-step transition (push-off, heel strike).

    Attributes
    ----------
    heel_strike : ndarray (d,)
        Impulse on the leading foot [N s], world axes (x downhill, y up; in 3D z lateral).
    push_off : ndarray (d,)
        Impulse on the trailing foot [N s] (zeros without a push-off).
    trailing_foot_velocity : ndarray (d,)
        The trailing foot's velocity just after the transition [m/s].
    normal : ndarray (d,)
        The ground's outward unit normal ``(sin phi, cos phi[, 0])``.
    """

    heel_strike: np.ndarray
    push_off: np.ndarray
    trailing_foot_velocity: np.ndarray
    normal: np.ndarray

    @property
    def heel_strike_normal(self) -> float:
        """Normal component of the heel strike's impulse [N s] (>= 0: the ground pushes)."""
        return float(self.heel_strike @ self.normal)

    @property
    def push_off_normal(self) -> float:
        """Normal component of the push-off's impulse [N s] (>= 0)."""
        return float(self.push_off @ self.normal)

    @property
    def trailing_foot_normal_velocity(self) -> float:
        """The trailing foot's velocity along the normal after the transition [m/s] (>= 0:
        it leaves the ground, as the rigid model takes it to)."""
        return float(self.trailing_foot_velocity @ self.normal)


class StanceReaction:
    """The ground reaction on the stance foot of one rigid walker's steps.

    Parameters
    ----------
    walker : HybridWalker
        The rigid walker of the steps (for legs that differ, the walker of one stance leg:
        ``walker.for_stance(leg)``).
    data : WalkerData
        Its structure and numbers (for legs that differ, the matching ``data`` or
        ``data.mirror``: leg1 swinging).

    Raises
    ------
    ValueError
        A walker this cannot check: massless bodies beside massive ones other than the hip
        (no floating view, :data:`walkerlab.codegen.floating.MASSLESS_MESSAGE`) or flat
        feet (whose rigid model checks its own contact forces,
        :mod:`walkerlab.models.hybrid.rigid_foot_modes`).
    """

    def __init__(self, walker, data):
        st = data.structure
        self.part = st.kind.reaction.behaviour
        if self.part.refusal is not None:
            raise ValueError(self.part.refusal.format(title=st.kind.title))
        self.walker = walker
        phi = float(walker.slope_rad)
        self.normal = np.array([np.sin(phi), np.cos(phi)])
        self.tangent = np.array([np.cos(phi), -np.sin(phi)])
        self.view, self._roles, self._heading = None, None, None
        if self.part.hub or any(b.massless for b in st.bodies):  # all the mass at the hub
            if not st.hip_mass or any(not b.massless for b in (*st.bodies, *st.torso)):
                floating_plain(st)  # raises: a massless body beside massive ones
            # massless legs, all the mass at the hip (module docstring)
            self.hip_mass_kg = float(data.total_mass_kg)
            self.g = float(data.gravity_m_per_s2)
            self._up_g = np.array([0.0, self.g])
            if st.in_3d:  # a wheel in 3D: its hub's acceleration in 3D
                self.normal, self.tangent = np.append(self.normal, 0.0), None
                self._up_g = np.array([0.0, self.g, 0.0])
            return
        self.view = FloatingView(data)
        coords = tuple(self.view.coordinates)
        self._feet = {r: self.view.names.index(f) for r, f in _FOOT_OF_ROLE.items()}
        if self.view.dim == 3:  # free at the stance foot: its slides, its heading, the roles
            self.normal, self.tangent = np.append(self.normal, 0.0), None
            self._hip, self._heading = list(range(3)), coords.index(FREE_3D[3])
            self._roles = [coords.index(ROLES_3D[r]) for r in walker.roles]
            self._links = [i for i in range(len(coords)) if i not in self._hip]
            return
        self._layout = StateLayout.floating(coords, coords + tuple(f"d_{c}" for c in coords),
                                            ("",) * (2 * len(coords)))
        self._hip = [coords.index("hip_x"), coords.index("hip_y")]
        self._links = [i for i in range(len(coords)) if i not in self._hip]

    # ------------------------------------------------------------------ state maps
    def _values(self, x) -> dict:
        """The rigid state's absolute link angles and rates by role name."""
        w = self.walker
        x = np.asarray(x, float)
        if w.leg_angles is not None:
            vals = {k: float(np.asarray(v)) for k, v in w.leg_angles(x).items()}
        else:
            vals = {}
        n = w.n_coordinates
        for i, r in enumerate(w.roles):  # a coordinate on no leg (a torso) by its own name
            vals.setdefault(f"{r}_angle", float(x[i]))
            vals.setdefault(f"{r}_rate", float(x[n + i]))
        return vals

    def floating_state(self, x, swapped: bool = False) -> tuple[np.ndarray, np.ndarray]:
        """``(q, dq)`` of the floating view (nq,) for the rigid state ``x`` (2n,) with the
        stance foot's material point at rest (``swapped``: ``x`` is a post-impact state,
        roles swapped, and is expressed in the pre-impact labels: its stance leg in the
        swing leg's place).  The hip's position is 0 (nothing here depends on it)."""
        idx, z = self._links_of(x, swapped)
        m = z.size // 2
        q, dq = np.zeros(self.view.nq), np.zeros(self.view.nq)
        q[idx], dq[idx] = z[:m], z[m:]
        _, V, _ = self.view.contact_points(q, dq)
        dq[self._hip] = -V[self._feet["swing" if swapped else "stance"]]
        return q, dq

    def _links_of(self, x, swapped: bool = False) -> tuple[list, np.ndarray]:
        """The floating view's indices of the rigid state's coordinates and their values
        then rates (2m,): a 3D walker's are its roles' (:data:`ROLES_3D`, ``x`` in this
        step's labels); a planar walker's absolute link angles by role name
        (:func:`walkerlab.walker.layout.floating_links_from_rigid`; ``swapped`` as in
        :meth:`floating_state`)."""
        if self._roles is not None:
            return self._roles, np.asarray(x, float)
        vals = self._values(x)
        if swapped:
            flip = {"swing": "stance", "stance": "swing"}
            vals = {(flip[k.split("_", 1)[0]] + "_" + k.split("_", 1)[1]
                     if k.split("_", 1)[0] in flip else k): v for k, v in vals.items()}
        return self._links, floating_links_from_rigid(vals, self._layout)

    def _link_acceleration(self, x, xdot) -> tuple[list, np.ndarray]:
        """The floating view's indices of the rigid coordinates and their accelerations
        from the rigid rates' derivatives (the leg-angle map is affine: its rate part is
        linear)."""
        n = self.walker.n_coordinates
        xa = np.concatenate([np.asarray(x, float)[:n], np.asarray(xdot, float)[n:]])
        idx, z = self._links_of(xa)
        return idx, z[z.size // 2:]

    # ------------------------------------------------------------------ a point hip
    def _point(self, name: str, q) -> np.ndarray:
        """The rigid model's point ``name`` (2,) [m] (from the stance foot) at ``q`` (n,)."""
        n = self.walker.n_coordinates
        return np.asarray(self.walker.points(np.concatenate([q, np.zeros(n)]))[name], float)

    def _point_velocity(self, name: str, x, h: float = 1e-6) -> np.ndarray:
        """Velocity (2,) [m/s] of the rigid model's point ``name`` at state ``x`` (the
        stance foot at rest), by central differences along ``dq``."""
        n = self.walker.n_coordinates
        q, dq = np.asarray(x, float)[:n], np.asarray(x, float)[n:]
        return (self._point(name, q + h * dq) - self._point(name, q - h * dq)) / (2 * h)

    def _hip_acceleration(self, x, xdot, h: float = 1e-4) -> np.ndarray:
        """``d^2 hip / dt^2`` (2,) [m/s^2] along the flow: the second difference of the hip
        along ``q + s dq + s^2 qdd / 2`` (error O(h^2))."""
        n = self.walker.n_coordinates
        q, dq, qdd = np.asarray(x, float)[:n], np.asarray(x, float)[n:], xdot[n:]
        mid = q + 0.5 * h * h * qdd
        return (self._point("hip", mid + h * dq) + self._point("hip", mid - h * dq)
                - 2.0 * self._point("hip", q)) / (h * h)

    # ------------------------------------------------------------------ forces
    def force(self, t: float, x, flow) -> np.ndarray:
        """The ground's force on the stance foot (d,) [N], world axes (``d`` 2 in the plane,
        3 in 3D: ``z`` lateral), at state ``x`` (2n,) of a phase whose flow is
        ``flow(t, x) -> xdot (2n,)``."""
        return self.force_and_twist(t, x, flow)[0]

    def force_and_twist(self, t: float, x, flow) -> tuple[np.ndarray, float]:
        """The ground's force on the stance foot (d,) [N] (:meth:`force`) and, in 3D, its
        moment about the slope's normal through the foot [N m] (the twist the rigid
        model's stance joint carries: it lets the foot roll and pitch, never turn); NaN in
        the plane, where no moment can turn the foot.

        The force and the moment are the rows of the free slides and of the heading of
        ``M qdd + h`` in the floating view (module docstring): a slide of the whole walker
        is worked on by the ground's force alone, a turn about the normal through the
        stance foot by its moment alone (joint torques are between the walker's bodies)."""
        xdot = np.asarray(flow(t, np.asarray(x, float)), float)
        if self.view is None:  # all the mass at the hip
            # a wheel in 3D turns on a spherical joint at its stance foot: no twist
            return (self.hip_mass_kg * (self._hip_acceleration(x, xdot) + self._up_g),
                    np.nan if self.tangent is not None else 0.0)
        q, dq = self.floating_state(x)
        qdd = np.zeros(self.view.nq)
        idx, acc = self._link_acceleration(x, xdot)
        qdd[idx] = acc
        i = self._feet["stance"]
        P, _, J = self.view.contact_points(q, dq)
        dV = self.view.velocity_gradient(q, dq)
        qdd[self._hip] = -(J[i][:, self._links] @ qdd[self._links] + dV[i] @ dq)
        M, h = self.view.dynamics(q, dq)
        rows = M @ qdd + h
        F = rows[self._hip]
        if self._heading is None:
            return F, np.nan
        # the heading's row is the moment about the normal through the root's origin (a
        # point foot's contact; a round foot's rolls along the fall line from it)
        return F, float(rows[self._heading] - self.normal @ np.cross(P[i], F))

    def normal_and_tangential(self, F) -> tuple[float, float]:
        """``(F . n, F . t)`` [N] of a force (2,) (n outward, t down the slope); in 3D, of a
        force (3,), ``(F . n, |F - (F . n) n|)`` (the tangential force's magnitude)."""
        F = np.asarray(F, float)
        fn = float(F @ self.normal)
        if self.tangent is None:
            return fn, float(np.linalg.norm(F - fn * self.normal))
        return fn, float(F @ self.tangent)

    def transition(self, x_minus, x_plus=None) -> TransitionImpulses:
        """The impulses of the transition from the pre-impact state ``x_minus`` (2n,) to
        ``x_plus`` (default ``walker.reset(x_minus)``, roles swapped).

        The total impulse of the ground is the hip rows of ``M (dq_f+ - dq_f-)``; the
        push-off's is ``P e`` (``walker.actuators.impulse``, ``e`` from the trailing foot to
        the hip), the heel strike's the rest.

        Raises
        ------
        ValueError
            ``x_plus`` is not the configuration of ``x_minus`` (it is not a transition).
        """
        w = self.walker
        x_minus = np.asarray(x_minus, float)
        x_plus = w.reset(x_minus) if x_plus is None else np.asarray(x_plus, float)
        if self.view is None:  # all the mass at the hip
            total = self.hip_mass_kg * (self._point_velocity("hip", x_plus)
                                        - self._point_velocity("hip", x_minus))
            e = self._point("hip", x_minus[:w.n_coordinates])  # from the trailing foot
            # the old stance foot: a biped's new swing foot, a wheel's spoke behind
            trail = self._point_velocity(self.part.trailing_point, x_plus)
            push = self._push_off(x_minus, e)
            return TransitionImpulses(total - push, push, trail, self.normal.copy())
        q0, v0 = self.floating_state(x_minus)
        if self._roles is not None:  # 3D: x_plus in this step's labels (a relabelling)
            x_plus = self._before_relabel(x_minus, x_plus)
        q1, v1 = self.floating_state(x_plus, swapped=True)
        if not np.allclose(q0[self._links], q1[self._links], atol=1e-8):
            raise ValueError("the post-impact state is not the pre-impact configuration "
                             "with the roles swapped")
        total = (self.view.dynamics(q0, v0)[0] @ (v1 - v0))[self._hip]
        P, _, _ = self.view.contact_points(q0)
        if self._roles is None:  # the hip is at 0
            push = self._push_off(x_minus, -P[self._feet["stance"]])
        else:  # 3D: the root is the stance foot; the trailing leg ends at its own hip
            pts = w.points(x_minus)
            push = self._push_off(x_minus, np.asarray(pts["stance_hip"], float)
                                  - np.asarray(pts["stance_foot"], float))
        _, V, _ = self.view.contact_points(q1, v1)
        return TransitionImpulses(total - push, push, V[self._feet["stance"]].copy(),
                                  self.normal.copy())

    def _before_relabel(self, x_minus, x_plus) -> np.ndarray:
        """A 3D walker's post-impact state ``x_plus`` in the pre-impact labels: its reset's
        configuration block (``walker.reset_jacobian``) is the roles' permutation ``R``
        (``q+ = R q-``), so ``x = [R^T q+, R^T dq+]``.

        Raises
        ------
        ValueError
            The block is not a permutation."""
        n = self.walker.n_coordinates
        R = np.asarray(self.walker.reset_jacobian(np.asarray(x_minus, float)), float)[:n, :n]
        P = np.rint(R)
        if not (np.allclose(R, P, atol=1e-12) and np.all(P.sum(0) == 1)
                and np.all(P.sum(1) == 1)):
            raise ValueError("the heel strike's reset does not relabel the coordinates by a "
                             "permutation")
        x_plus = np.asarray(x_plus, float)
        return np.concatenate([P.T @ x_plus[:n], P.T @ x_plus[n:]])

    def _push_off(self, x_minus, e) -> np.ndarray:
        """The push-off's impulse (d,) [N s]: ``P`` (``walker.actuators.impulse``) along
        ``e`` (d,) (from the trailing foot to its hip); zeros without a push-off."""
        acts = getattr(self.walker, "actuators", None)
        if acts is None or getattr(acts.spec, "push_off", None) is None:
            return np.zeros(self.normal.size)
        e = np.asarray(e, float)
        return float(acts.impulse(x_minus)) * e / np.sqrt(e @ e)
