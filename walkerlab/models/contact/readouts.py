"""What a contact run's states show: the contact table per point and per leg, the knee
stops, points, energies and the fall test of a
:class:`~walkerlab.models.contact.model.ContactWalker` (the mix-in :class:`ContactReadouts`)."""

from __future__ import annotations

import math

import numpy as np

from .parts import contact_part
from .states import FOOT_NAMES

__all__ = ["ContactReadouts"]


class ContactReadouts:
    """Post-processing of a :class:`~walkerlab.models.contact.model.ContactWalker`'s states
    (a mix-in: it reads the walker's compiled ``kernels``, ``walker_params``, its contact
    points ``_contacts`` and ``_point_legs``, and ``nq``)."""

    @property
    def normal(self) -> np.ndarray:
        """Outward ground normal n = (sin phi, cos phi) (3D: (sin phi, cos phi, 0)), shape
        (d,), unit vector [-]."""
        return np.array([np.sin(self.phi), np.cos(self.phi), 0.0][:self.dim])

    @property
    def tangent(self) -> np.ndarray:
        """Down-slope tangent t = (cos phi, -sin phi) (3D: (cos phi, -sin phi, 0)), shape
        (d,), unit vector [-]."""
        return np.array([np.cos(self.phi), -np.sin(self.phi), 0.0][:self.dim])

    @property
    def tangents(self) -> np.ndarray:
        """The ground's tangent basis, shape (d - 1, d), unit rows [-]: the down-slope
        :attr:`tangent`, then (in 3D) the lateral axis ``z`` (across the slope, to the
        walker's left).  With :attr:`normal` it spans the world; a contact walker's dynamics
        are invariant under translation along it (the patches are strips across the
        slope)."""
        return np.array([self.tangent] + [np.eye(self.dim)[k] for k in range(2, self.dim)])

    @property
    def steps_per_map(self) -> int:
        """Steps in the contact periodic gait's Poincaré map
        (:mod:`walkerlab.analysis.contact.step_map`): 1 where a step's end, the legs'
        roles swapped, is the same state as its start (planar walkers), 2 where the two
        steps of a stride mirror each other across the sagittal plane and the section is
        leg2's mid-stance (a walker in 3D, whose floating base is leg2's foot:
        :attr:`walkerlab.models.contact.parts.ContactPart.steps_per_map`) or differ (legs
        that differ: the rigid view's map is a stride too)."""
        return 2 if self.structure.asymmetric else contact_part(self.structure).steps_per_map

    def _rows(self, X) -> np.ndarray:
        return np.ascontiguousarray(np.atleast_2d(X), dtype=float)

    def contact_names(self) -> tuple[str, ...]:
        """Names of the contact points, in the order of the generated kernels (module
        docstring): ``leg1``, ``leg2``; flat feet ``leg1_heel``, ``leg1_toe``, ..."""
        return self._contacts

    def contact_leg(self, name: str) -> str:
        """The leg (``leg1``/``leg2``) of contact point ``name``."""
        return FOOT_NAMES[self._point_legs[self._contacts.index(name)]]

    def lane(self, name: str) -> np.ndarray:
        """Patch centres [m] of the lane of contact point (or leg) ``name``: ``lane1`` or
        ``lane2``, shape (number of patches,).

        Raises
        ------
        ValueError
            ``name`` is neither a leg nor one of :meth:`contact_names`.
        """
        leg = name if name in FOOT_NAMES else self.contact_leg(name)
        return self.lane1 if leg == "leg1" else self.lane2

    def lane_heights(self, name: str) -> np.ndarray:
        """Heights [m] (along the slope's outward normal) of the patches of the lane of
        contact point (or leg) ``name``, one per :meth:`lane` centre (zeros: the flat
        checkerboard)."""
        leg = self.contact_leg(name) if name in self._contacts else name
        return self._kernel_lane1[self.lane1.size:2 * self.lane1.size] if leg == "leg1" \
            else self._kernel_lane2[self.lane2.size:2 * self.lane2.size]

    def foot_state(self, x, i: int) -> tuple[np.ndarray, np.ndarray]:
        """Reference contact point of leg ``i`` (0/1) (its only point; a flat foot's heel)
        and the velocity of the material point there, for the state ``x`` (2 nq,).

        Returns
        -------
        p, v : ndarray, shape (d,)
            Position [m] and velocity [m/s] in the world frame (x, y, and in 3D z).
        """
        n, nf, d = self.nq, len(self._contacts), self.dim
        P, V, J = np.empty((nf, d)), np.empty((nf, d)), np.empty((nf, d, n))
        self.kernels.feet(np.asarray(x, float), self.walker_params, P, V, J)
        i = self._point_legs.index(i)
        return P[i].copy(), V[i].copy()

    def foot_positions(self, X) -> np.ndarray:
        """Reference contact point of each leg (n, 2, d) [m] (leg, xy (z)) for states X
        (n, 2 nq), or (2, d) for one: the foot point, an arc's lowest point, a flat foot's
        heel."""
        X = self._rows(X)
        pts = self.kernels.points(X.T, self.walker_params)
        key = contact_part(self.structure).foot_point(self.structure)
        out = np.stack([np.stack([pts[f"{leg}_{key}"][k] for k in range(self.dim)], axis=-1)
                        for leg in FOOT_NAMES], axis=1)
        return out if len(out) > 1 else out[0]

    def points(self, X) -> dict:
        """Named points (2, n) [m]: hip, each body (``leg1_<body>``), feet, knees."""
        return self.kernels.points(self._rows(X).T, self.walker_params)

    def hip_positions(self, X) -> np.ndarray:
        """The hip's position (n, d) [m] in world axes for states X (n, 2 nq): a planar
        walker's floating base (its first two coordinates), a 3D walker's pelvis (its
        base is a foot: from the kinematics)."""
        X = self._rows(X)
        if self.dim == 2:
            return X[:, :2].copy()
        return np.atleast_2d(self.points(X)["hip"].T)

    def hip_height(self, X) -> np.ndarray:
        """Hip height above the ground line, hip . n [m], for X (n, 2 nq) -> (n,) (numpy: a
        dot product is not worth a compiled kernel per walker structure, compiled anew in
        a fresh user cache; the same operations as that kernel had).  On a polyline ground
        (:attr:`~walkerlab.models.contact.model.ContactWalker.ground_line`: stairs, a
        profile on continuous ground) above the ground under the hip: less that point's
        ``g . n``, ``g = (x_hip, y(x_hip))`` on the polyline (stairs: the tread under the
        hip), so a walker many risers down has not fallen."""
        X = self._rows(X)
        phi = float(self.contact_params[self.kernels.I_PHI])
        if self.dim == 3:  # the base is the stance foot: the hip from the kinematics
            hip = np.atleast_2d(self.points(X)["hip"].T)
            h = hip[:, 0] * math.sin(phi) + hip[:, 1] * math.cos(phi)
            return self._above_line(h, hip[:, 0], phi)
        h = X[:, 0] * math.sin(phi) + X[:, 1] * math.cos(phi)
        return self._above_line(h, X[:, 0], phi)

    def _above_line(self, h, x, phi: float) -> np.ndarray:
        """``h`` (n,) [m] less the polyline ground's height along the slope's normal at
        ``x`` (n,) [m]; ``h`` itself without a polyline ground."""
        line = getattr(self, "ground_line", None)
        if line is None:
            return h
        y = np.interp(x, line[:, 0], line[:, 1])
        return h - (x * math.sin(phi) + y * math.cos(phi))

    def hip_height_rate(self, X) -> np.ndarray:
        """Rate of :meth:`hip_height` [m/s] for X (n, 2 nq) -> (n,): the hip's velocity
        along the slope's normal (a planar walker's hip rates; in 3D, where the base is
        the stance foot, the central difference of the height along the flow,
        ``(h(x + e f) - h(x - e f)) / 2 e`` with ``e`` 1e-6 s: exact to ~1e-12 m/s)."""
        X = self._rows(X)
        if self.dim == 2:
            ix = [self.state_names().index(n) for n in ("vhip_x", "vhip_y")]
            return X[:, ix] @ self.normal
        e = 1e-6
        F = np.array([self.rhs(0.0, x) for x in X])
        return (self.hip_height(X + e * F) - self.hip_height(X - e * F)) / (2 * e)

    def fall_how(self, x) -> str:
        """How a walker in 3D went down, from its last state ``x`` (2 nq,): capsized
        sideways (its hip farther from the stance foot across the slope than along it) or
        fell along the slope, with the hip's (a wheel's hub's) offset [m] and its lean from
        the normal [deg]; the stance foot the contact point pressed deepest (a leg's foot
        point or its arc's lowest point, a wheel's spoke tip).  ``""`` for a planar walker
        (its falls have one plane)."""
        if self.dim == 2:
            return ""
        X = self._rows(x)[-1:]
        hip = np.asarray(self.points(X)["hip"], float).reshape(3, -1)[:, -1]
        nf, n = len(self._contacts), self.nq
        P, V, J = np.empty((nf, 3)), np.empty((nf, 3)), np.empty((nf, 3, n))
        self.kernels.feet(X[0], self.walker_params, P, V, J)
        pen = [float(self.contact_quantities(X)[c]["penetration"][0])
               for c in self.contact_names()]
        rel = hip - P[int(np.argmax(pen))]
        # a wheel's (its contact points are its feet) hip is its hub, its stance foot a tip
        hub = contact_part(self.structure).per_point_feet
        hip_word, foot_word = ("hub", "stance spoke's tip") if hub else ("hip", "stance foot")
        side, along = float(rel[2]), float(rel @ self.tangent)
        lean = math.degrees(math.atan2(math.hypot(side, along), float(rel @ self.normal)))
        if abs(side) > abs(along):
            return (f"capsized sideways: the {hip_word} {abs(side):.3f} m to the "
                    f"{'right' if side > 0 else 'left'} of the {foot_word}, {lean:.0f} deg "
                    "from the slope's normal")
        return (f"fell {'forward' if along > 0 else 'backward'}: the {hip_word} "
                f"{abs(along):.3f} m {'ahead of' if along > 0 else 'behind'} the {foot_word}, "
                f"{lean:.0f} deg from the slope's normal")

    def fall_margin(self, x, threshold: float) -> float:
        """The one fall test: hip height of state ``x`` minus ``threshold`` [m]
        (negative = fallen).  Used as the fall event of every integration.

        Parameters
        ----------
        x : array_like, shape (2 nq,)
            State (:meth:`state_names`).
        threshold : float
            Hip height [m] below which the walker has fallen.
        """
        return float(self.hip_height(x)[0]) - threshold

    def contact_quantities(self, X) -> dict[str, dict[str, np.ndarray]]:
        """Per-contact-point quantities for states X (n, 2 nq) (the contact table).

        Returns
        -------
        dict
            Keyed by :meth:`contact_names` (``{"leg1": {...}, "leg2": {...}}`` for point
            and arc feet), each with arrays (n,): ``penetration`` [m] (signed; negative =
            height above ground), ``penetration_rate`` [m/s], ``slip_velocity`` [m/s]
            (down-slope, of the material point), ``s`` [m] along-slope position,
            ``normal_force`` [N], ``friction_force`` [N] (along t), ``power`` [W] (F . v),
            ``on_ground`` (1.0 where the point's lane has ground); a walker in 3D also
            ``lateral_slip_velocity`` [m/s] and ``lateral_friction_force`` [N] (along the
            slope's level direction ``z``), ``spin_rate`` [rad/s] (its body's about the
            slope's normal) and ``twist_moment`` [N m] (the torsional friction's).
        """
        tab = self.kernels.contact_table(self._rows(X), *self._args())
        names = ("penetration", "penetration_rate", "slip_velocity", "s", "normal_force",
                 "friction_force", "power", "on_ground", "lateral_slip_velocity",
                 "lateral_friction_force", "spin_rate", "twist_moment")[:tab.shape[2]]
        return {foot: {nm: tab[:, i, k].copy() for k, nm in enumerate(names)}
                for i, foot in enumerate(self._contacts)}

    def foot_quantities(self, X) -> dict[str, dict[str, np.ndarray]]:
        """Per-leg contact quantities (``leg1``, ``leg2``) for states X (n, 2 nq) [m, rad, m/s,
        rad/s] (or one state (2 nq,)): the
        contact table itself for one point per leg; a flat foot's points combined: forces
        and power summed, the deepest point's penetration, its rate, slip velocity, ``s``
        and ``on_ground`` (the point that touches down first and lifts off last).

        Returns
        -------
        dict
            ``{"leg1": {...}, "leg2": {...}}``, arrays (n,) as :meth:`contact_quantities`.
        """
        cq = self.contact_quantities(X)
        if self._contacts == FOOT_NAMES or contact_part(self.structure).per_point_feet:
            return cq
        out = {}
        for leg in FOOT_NAMES:
            pts = [cq[c] for c in self._contacts if self.contact_leg(c) == leg]
            pen = np.stack([q["penetration"] for q in pts])
            # the deepest point on ground (a point over a gap does not count)
            on = np.stack([q["on_ground"] for q in pts]) > 0.5
            deep = np.argmax(np.where(on, pen, pen - 1e3), axis=0)
            d = {k: np.take_along_axis(np.stack([q[k] for q in pts]), deep[None], 0)[0]
                 for k in pts[0]}
            for k in ("normal_force", "friction_force", "power"):
                d[k] = np.sum([q[k] for q in pts], axis=0)
            out[leg] = d
        return out

    def knee_stop_quantities(self, X) -> dict[str, dict[str, np.ndarray]]:
        """Per-knee stop quantities for states X (n, 2 nq); empty for straight legs.

        Returns
        -------
        dict
            ``{"leg1": {...}, "leg2": {...}}`` each with arrays (n,): ``extension`` [rad]
            (shank - thigh angle, > 0 hyperextended), ``extension_rate`` [rad/s],
            ``torque`` [N m] (> 0: pushes the knee straight from hyperextension; < 0: the
            latch holds a loaded leg's knee against flexion), ``power`` [W] (of the stop on
            the walker).  Empty for straight legs and free knees (no stop).
        """
        if not self.kernels.KNEE:  # straight legs, free knees (no stop)
            return {}
        tab = self.kernels.knee_table(self._rows(X), *self._args())
        names = ("extension", "extension_rate", "torque", "power")
        return {leg: {nm: tab[:, i, k].copy() for k, nm in enumerate(names)}
                for i, leg in enumerate(FOOT_NAMES)}

    def energies(self, X) -> dict[str, np.ndarray]:
        """Kinetic, potential (relative to y = 0) and total energy [J] for X (n, 2 nq).

        ``T = 1/2 dq^T M(q) dq`` and ``V = g sum(m_i y_i)`` of the generated mechanics
        (:mod:`walkerlab.codegen.floating`), the contact and knee-stop springs' energy not
        included.

        Parameters
        ----------
        X : array_like, shape (n, 2 nq) or (2 nq,)
            States (:meth:`state_names`).

        Returns
        -------
        dict[str, ndarray]
            ``kinetic``, ``potential``, ``total``, each of shape (n,) [J].
        """
        T, V = self.kernels.energies(self._rows(X).T, self.walker_params)
        return {"kinetic": T, "potential": V, "total": T + V}
