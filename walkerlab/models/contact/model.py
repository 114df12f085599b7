"""Floating walker with compliant ADAMS-style feet (:class:`ContactWalker`), for any walker
with positive leg masses (compass gait, rods, knees, arc feet).

Conventions (shared with the rigid model, :mod:`walkerlab.codegen.floating`): x downhill, y up,
gravity (0, -g); ground line y = -x tan(phi), outward normal n = (sin phi, cos phi),
down-slope tangent t = (cos phi, -sin phi).  The mechanics (mass matrix, bias, contact points,
Jacobians) are generated from the walker description; the contact forces use the laws of
:mod:`walkerlab.models.contact.laws` (numba twins in :mod:`walkerlab.models.contact._kernels`); the
knees of a kneed walker are free, each held by a compliant stop
(:class:`~walkerlab.config.contact.KneeStopSettings`).

State names
-----------
``x = [q, dq]``.  The floating coordinates are named by
:func:`walkerlab.codegen.floating.coordinate_names` (``hip_x``, ``hip_y``, ``leg1_angle``, ...);
the contact model keeps its established state vocabulary, mapped one to one
(:data:`~walkerlab.models.contact.states.STATE_OF_COORDINATE`):

============================  ===========================  ==========================
coordinate                    state                        rate state
============================  ===========================  ==========================
``hip_x``, ``hip_y``          ``hip_x``, ``hip_y``         ``vhip_x``, ``vhip_y``
``leg{i}_angle``              ``theta{i}``                 ``dtheta{i}``
``leg{i}_thigh_angle``        ``theta{i}_thigh``           ``dtheta{i}_thigh``
``leg{i}_shank_angle``        ``theta{i}_shank``           ``dtheta{i}_shank``
============================  ===========================  ==========================

so the paper walker's states are unchanged: ``[hip_x, hip_y, theta1, theta2, vhip_x, vhip_y,
dtheta1, dtheta2]``; a flat foot's absolute angle ``leg{i}_foot_angle`` is ``theta{i}_foot``,
a hinged torso's ``torso_angle`` (the five-link biped) ``theta_torso``.

Contact points
--------------
Each contact point carries the IMPACT and Coulomb laws on its leg's lane and has its own
row of the contact table (:meth:`ContactWalker.contact_quantities`), named by
:meth:`ContactWalker.contact_names`: ``leg1``, ``leg2`` for point and arc feet (the tables
of the walkers before flat feet, unchanged), ``leg1_heel``, ``leg1_toe``, ``leg2_heel``,
``leg2_toe`` for flat feet.  The gait analysis reads each *leg* as one foot
(:meth:`ContactWalker.foot_quantities`: a flat foot's points combined).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np

from walkerlab.config.contact import ContactSettings, KneeStopSettings
from walkerlab.config.terrain import TerrainSettings

from .lanes import checkerboard_lanes, flat_foot_numbers, footprint_offsets
from .laws import ContactParamsSI, KneeStopSI, contact_params_si, knee_stop_si
from .parts import contact_part
from .readouts import ContactReadouts
from .states import FOOT_NAMES, STATE_OF_COORDINATE, state_name

__all__ = ["FOOT_NAMES", "FOOT_RATE_ATOL_FACTOR", "ContactWalker", "STATE_OF_COORDINATE",
           "checkerboard_lanes", "compass_gait_data", "flat_foot_numbers", "footprint_offsets",
           "state_name"]

#: A flat foot's rotation rate is integrated to this many times the run's ``atol`` [-]
#: (:meth:`ContactWalker.atol_scale`).  The regularising foot inertia (0.1 kg, 5e-4 kg m^2)
#: makes that rate a fast variable on the contact's slow manifold (eigenvalue ~ -7e5 1/s in
#: foot flat, ~ 1 / inertia): an error e in it decays within microseconds and moves the foot
#: angle by only ~ e / 7e5, so its absolute tolerance need not be the angles'.  Held to the
#: angles' atol (1e-10 rad/s), CyRK's BDF (finite-difference Jacobian) chatters in foot flat
#: (4 us steps at mid-stance, 13x the RHS calls at rtol 1e-9) and ends farther from the
#: reference (configs/flat_feet.yaml, 5 strides: 1.8e-6 -> 2.3e-7 rad at rtol 1e-9).
FOOT_RATE_ATOL_FACTOR = 100.0


def compass_gait_data(L=1.0, m=5.0, MH=10.0, a=0.5, g=9.81, phi=0.0174):
    """:class:`~walkerlab.walker.description.WalkerData` of the paper's compass gait (Table 1):
    leg length L [m], leg mass m [kg] at ``a`` [m] from the foot, hip mass MH [kg]."""
    from walkerlab.walker.description import WalkerData, compass_gait_structure

    st = compass_gait_structure()
    vals = {"g": g, "L": L, "gamma": phi, "M_hip": MH, "m_mass": m, "d_mass": L - a}
    return WalkerData(st, tuple(float(vals[n]) for n in st.param_names), MH + 2 * m, L, g, phi,
                      {"leg_mass_kg": m, "hip_mass_kg": MH, "leg_mass_from_foot_m": a})


@dataclass(frozen=True, eq=False)
class ContactWalker(ContactReadouts):
    """A walker, slope, SI contact parameters and terrain.

    Attributes
    ----------
    L, m, MH, a, g, phi : float
        The paper compass gait's shorthand (leg length [m], leg mass [kg], hip mass [kg],
        foot-to-leg-mass distance [m], gravity [m/s^2], slope [rad]), used only when ``data``
        is None.  With ``data`` they are set from it (``L``, ``g``, ``phi``; ``m``, ``MH``,
        ``a`` NaN unless the walker is a compass gait).
    contact : ContactParamsSI
        IMPACT and friction parameters of the feet in SI.
    lane1, lane2 : ndarray
        Patch centres [m] of leg1's / leg2's lane (ignored if ``continuous``).
    heights1, heights2 : ndarray, optional
        Height [m] of each patch of leg1's / leg2's lane along the slope's outward normal
        (> 0 raised; a step-down is a patch at -h), same length as the lane; default 0
        (the flat checkerboard).  Rough ground as geometry.
    patch_half_width : float
        Half width of each patch [m].
    continuous : bool
        Ground everywhere (no lanes/gaps).
    ground_line : ndarray, optional
        A polyline ground (m, 2) [m], vertices (x, y) in the world frame, x increasing
        along the walk (stairs: treads level, risers vertical; the ground lies below it):
        both feet meet it everywhere (``continuous`` is then True and the lanes only name
        the footfalls), each point with the contact law on its penetration into the nearest
        segment, along that segment's normal (a toe caught by a riser is pushed back
        horizontally; :func:`walkerlab.models.contact._kernels.ground_line`).  None: the
        slope and its patches.
    data : WalkerData, optional
        Any walker description (:func:`walkerlab.walker.description.walker_data`).
    knee_stop : KneeStopSI, optional
        Knee-stop law (kneed walkers; default :class:`KneeStopSettings` ()).
    flat_foot : (float, float), optional
        A flat foot's regularising mass [kg] (at the ankle) and inertia about the ankle
        [kg m^2] (``contact.flat_foot_mass_kg``, ``contact.flat_foot_inertia_kg_m2``);
        required for flat feet, ignored otherwise.
    hub_inertia : float, optional
        A spoked wheel's regularising hub inertia [kg m^2] (``contact.hub_inertia_kg_m2``),
        required when its hub is a point mass, ignored otherwise
        (:func:`walkerlab.codegen.floating.floating_params`).
    actuators : ContactActuators or JointTorqueActuators, optional
        The walker's actuators (:mod:`walkerlab.models.contact.actuation`): hip torques and
        the push-off pulse; a free-jointed (five-link) biped's joint torques
        (:mod:`walkerlab.models.contact.joint_torques`); a walker with them runs on
        :mod:`walkerlab.integrate.contact_powered` (its stance leg is a discrete state).
    torsion : float
        A walker in 3D: each contact's torsional friction coefficient [m]
        (:func:`walkerlab.models.contact.assembly.twist`; ``contact.torsional_friction_m``);
        0: none (a planar walker's contact has no spin about the normal).
    hold_heading : bool
        A legged walker in 3D: its floating base on three slides, no heading
        (``contact.hold_heading``; the rigid model's assumption: its stance foot does not
        yaw), so the whole walker cannot turn about the ground's normal.
    rhs_ready : walkerlab.execution.pending.CompiledElsewhere, optional
        A side process compiling the compiled solvers' right-hand side: the first compiled
        chunk waits for it and loads the kernel from the cache (the caller's hand-off,
        passed down with the walker; None: compile it here when needed).

    Raises
    ------
    ValueError
        A body of the walker has mass 0 (a floating (contact) model needs positive leg
        masses); flat feet without ``flat_foot``
        (:data:`walkerlab.codegen.floating.FLAT_FOOT_MESSAGE`).
    """

    L: float = 1.0
    m: float = 5.0
    MH: float = 10.0
    a: float = 0.5
    g: float = 9.81
    phi: float = 0.0174
    contact: ContactParamsSI = field(default_factory=lambda: contact_params_si(ContactSettings()))
    lane1: np.ndarray = field(default_factory=lambda: np.zeros(0))
    lane2: np.ndarray = field(default_factory=lambda: np.zeros(0))
    patch_half_width: float = 0.05
    continuous: bool = True
    data: object = None
    knee_stop: KneeStopSI | None = None
    heights1: np.ndarray | None = None
    heights2: np.ndarray | None = None
    flat_foot: tuple[float, float] | None = None
    actuators: object = None
    rhs_ready: object = None
    hub_inertia: float | None = None
    ground_line: np.ndarray | None = None
    torsion: float = 0.0
    hold_heading: bool = False

    def __post_init__(self):
        from walkerlab.codegen.floating import check_masses, coordinate_names, floating_params

        from .generated import NPC, contact_module

        set_ = object.__setattr__
        if self.data is None:
            set_(self, "data", compass_gait_data(self.L, self.m, self.MH, self.a, self.g,
                                                 self.phi))
        d = self.data
        check_masses(d.structure)
        params = floating_params(d, *(self.flat_foot or (None, None)),
                                 hub_inertia_kg_m2=self.hub_inertia)
        set_(self, "L", float(d.leg_length_m))
        set_(self, "g", float(d.gravity_m_per_s2))
        set_(self, "phi", float(d.slope_rad))
        ex = d.extra or {}
        for name, key in (("m", "leg_mass_kg"), ("MH", "hip_mass_kg"),
                          ("a", "leg_mass_from_foot_m")):
            set_(self, name, float(ex.get(key, np.nan)))
        if self.knee_stop is None:
            set_(self, "knee_stop", knee_stop_si(KneeStopSettings()))
        c, ks = self.contact, self.knee_stop
        mod = contact_module(d.structure, self.hold_heading)
        PC = np.empty(NPC)
        PC[mod.I_PHI] = self.phi
        PC[mod.I_K], PC[mod.I_E], PC[mod.I_CMAX], PC[mod.I_DMAX] = c.k, c.e, c.cmax, c.dmax
        PC[mod.I_MUS], PC[mod.I_MUD], PC[mod.I_VS], PC[mod.I_VD] = c.mu_s, c.mu_d, c.v_s, c.v_d
        PC[mod.I_HW], PC[mod.I_CONT] = self.patch_half_width, 1.0 if self.continuous else 0.0
        PC[mod.I_KK], PC[mod.I_KE], PC[mod.I_KC], PC[mod.I_KD] = ks.k, ks.e, ks.cmax, ks.dmax
        PC[mod.I_KL], PC[mod.I_KF] = (1.0 if ks.latch else 0.0), ks.latch_height
        PC[mod.I_KA] = ks.latch_capture
        PC[mod.I_TOR] = self.torsion
        PC[mod.I_WEPS] = 1e-3 * d.total_mass_kg * d.gravity_m_per_s2  # load shares' floor
        set_(self, "lane1", np.ascontiguousarray(self.lane1, dtype=float))
        set_(self, "lane2", np.ascontiguousarray(self.lane2, dtype=float))
        for k in ("1", "2"):
            lane, h = getattr(self, "lane" + k), getattr(self, "heights" + k)
            if h is not None:  # (None stays None: dataclasses.replace with new lanes works)
                h = np.ascontiguousarray(h, dtype=float)
                if h.shape != lane.shape or not np.all(np.isfinite(h)):
                    raise ValueError(f"heights{k}: one finite height [m] per patch of "
                                     f"lane{k} ({lane.size}), got shape {h.shape}")
                set_(self, "heights" + k, h)
            h = np.zeros(lane.size) if h is None else h
            set_(self, "_kernel_lane" + k, np.ascontiguousarray(
                np.concatenate([lane, h, [h.max(initial=0.0)]])))
        if self.ground_line is not None:  # both feet on the polyline (the kernels' mode 2)
            g = np.ascontiguousarray(self.ground_line, dtype=float)
            if g.ndim != 2 or g.shape[1] != 2 or g.shape[0] < 2 or not np.all(np.isfinite(g)):
                raise ValueError("ground_line: finite polyline vertices (m >= 2, 2) [m], got "
                                 f"shape {g.shape}")
            set_(self, "ground_line", g)
            set_(self, "continuous", True)
            PC[mod.I_CONT] = 2.0
            flat = np.ascontiguousarray(g.ravel())
            set_(self, "_kernel_lane1", flat)
            set_(self, "_kernel_lane2", flat.copy())
        set_(self, "kernels", mod)
        set_(self, "contact_params", PC)
        set_(self, "walker_params", params)
        set_(self, "_coords", coordinate_names(d.structure, self.hold_heading))
        set_(self, "_contacts", tuple(mod.CONTACTS))
        set_(self, "_point_legs", tuple(mod.POINT_LEG))

    # ------------------------------------------------------------------ construction
    @classmethod
    def from_settings(cls, contact: ContactSettings, terrain: TerrainSettings, *,
                      step_length: float, n_steps: int, L=1.0, m=5.0, MH=10.0, a=0.5,
                      g=9.81, phi=0.0174, data=None) -> ContactWalker:
        """Build from validated settings; ``step_length`` [m] is the ideal gait's step length
        (patch spacing; each lane shifted by the leg's :func:`footprint_offsets`).  ``data``
        (a WalkerData) replaces the compass-gait shorthand."""
        from .rigid_limit import contact_si

        si, knee = contact_si(contact)  # the scene's stiffness family applied
        walker = cls(L=L, m=m, MH=MH, a=a, g=g, phi=phi, contact=si, data=data, knee_stop=knee,
                     flat_foot=contact.flat_foot())
        return walker.on_terrain(terrain, step_length=step_length, n_steps=n_steps)

    def on_terrain(self, terrain: TerrainSettings, *, step_length: float,
                   n_steps: int, step_lengths: tuple | None = None,
                   shift: float = 0.0) -> ContactWalker:
        """The same walker and contact law on ``terrain``: checkerboard patches spaced by
        ``step_length`` [m] (or by ``step_lengths`` in turn) for ``n_steps`` steps (each
        lane shifted by its leg's :func:`footprint_offsets`), or continuous ground; stairs
        and footholds as the patches' heights or a polyline ground
        (:func:`walkerlab.models.contact.terrain.terrain_ground`).

        Parameters
        ----------
        terrain : TerrainSettings
        step_length : float
            Patch spacing [m] (footfall to footfall along the slope).
        n_steps : int
            Steps the run may take.
        step_lengths : tuple of float, optional
            Each step's advance along the slope [m], in turn (a gait of several steps:
            footholds of several heights, the rigid period-n gait's steps); replaces
            ``step_length``; footfall ``k`` at
            :func:`walkerlab.models.contact.terrain.footfall_positions`.
        shift : float
            Every patch this far [m] downhill of its footfall (a disc foot's roll,
            :meth:`walkerlab.models.contact.parts.ContactPart.patch_shift`).

        Returns
        -------
        ContactWalker
            A copy (:func:`dataclasses.replace`) with lanes of ``n_steps // 2 + 2`` patch
            centres [m] each and ``patch_half_width = terrain.patch_width_m / 2`` [m].

        Raises
        ------
        ValueError
            A ground the contact model does not build
            (:func:`walkerlab.models.contact.terrain.terrain_ground`, one line naming the
            scene key); footholds of several heights without ``step_lengths``.  A walker
            already on a terrain is laid out afresh (its patch heights and polyline are
            replaced, never carried to lanes they do not fit).
        """
        from .terrain import footfall_positions, ground_drops

        if step_lengths is None:
            if not terrain.is_slope and len(ground_drops(terrain)) > 1:
                raise ValueError("terrain.foothold_heights_m: footholds of several heights "
                                 "are laid at the rigid gait's footfalls, step by step "
                                 "(walkerlab contact-sim lays them; a fixed spacing misses "
                                 "them)")
            c1, c2 = checkerboard_lanes(step_length, n_steps)
        else:
            k = n_steps // 2 + 2
            s = footfall_positions(step_lengths, 2 * k)
            c1, c2 = s[1::2], s[0::2]
        o1, o2 = footprint_offsets(self.data)
        # the ground laid afresh: a previous terrain's patch heights or polyline go with it
        # (heights of other lanes would not fit these)
        walker = dataclasses.replace(self, lane1=c1 + o1 + shift, lane2=c2 + o2 + shift,
                                     patch_half_width=0.5 * terrain.patch_width_m,
                                     continuous=terrain.lanes == "continuous",
                                     heights1=None, heights2=None, ground_line=None)
        if terrain.is_slope:
            return walker
        from .terrain import terrain_ground

        return terrain_ground(walker, terrain, n_steps)

    @property
    def structure(self):
        """The walker's :class:`~walkerlab.walker.description.Structure`."""
        return self.data.structure

    @property
    def b(self) -> float:
        """Hip to leg-mass distance [m] (compass gait only; NaN otherwise)."""
        return self.L - self.a

    @property
    def total_mass(self) -> float:
        """Total mass [kg]."""
        return float(self.data.total_mass_kg)

    @property
    def dim(self) -> int:
        """The world's dimension ``d``: 2 (planar), 3 (in 3D, ``z`` lateral)."""
        return int(self.kernels.DIM)

    def static_penetration(self, load: float | None = None) -> float:
        """IMPACT static penetration (F / k)^(1/e) [m] under ``load`` [N] (default M g cos phi).

        The damping-free equilibrium of :func:`~walkerlab.models.contact.laws.impact_normal_force`
        (MSC Adams/Solver function reference, IMPACT): ``k delta^e = F``.
        """
        if load is None:
            load = self.total_mass * self.g * np.cos(self.phi)
        return (load / self.contact.k) ** (1.0 / self.contact.e)

    # ------------------------------------------------------------------ state layout
    @property
    def model_name(self) -> str:
        """``compass_gait_contact`` for two straight point-footed legs alike with their
        bodies on the axis and nothing else (the paper's family), else ``biped_contact``."""
        st = self.structure
        extra = (not contact_part(st).plain or st.torso or st.springs or st.asymmetric
                 or st.foot != "point"
                 or any(b.off_axis for b in st.bodies))
        return "biped_contact" if extra else "compass_gait_contact"

    @property
    def nq(self) -> int:
        """Number of generalised coordinates."""
        return len(self._coords)

    def coordinate_names(self) -> tuple[str, ...]:
        """Floating coordinates (:func:`walkerlab.codegen.floating.coordinate_names`)."""
        return self._coords

    def atol_scale(self) -> np.ndarray:
        """Per-state factor (2 nq,) on a contact run's absolute tolerance [-]:
        :data:`FOOT_RATE_ATOL_FACTOR` on each flat foot's rotation rate, 1 elsewhere (every
        state of a walker without flat feet)."""
        out = np.ones(2 * len(self._coords))
        names = self.state_names()
        for c in self._coords:
            if c.endswith("_foot_angle"):
                out[names.index(state_name(c, rate=True))] = FOOT_RATE_ATOL_FACTOR
        return out

    def state_names(self) -> tuple[str, ...]:
        """Names of the states, in order (module docstring)."""
        return (tuple(state_name(c) for c in self._coords)
                + tuple(state_name(c, rate=True) for c in self._coords))

    def state_units(self) -> tuple[str, ...]:
        """Units of :meth:`state_names`."""
        u = ("m",) * self.dim + ("rad",) * (self.nq - self.dim)
        return u + tuple(f"{s}/s" for s in u)

    def layout(self):
        """The floating state layout (:class:`walkerlab.walker.layout.StateLayout`)."""
        from walkerlab.walker.layout import StateLayout

        return StateLayout.floating(self._coords, self.state_names(), self.state_units())

    def rigid_layout(self):
        """The layout of the rigid hybrid view of the same walker (its ideal states)."""
        from walkerlab.walker.layout import StateLayout

        return StateLayout.rigid(self.structure.roles)

    def leg_angle_states(self, leg: str) -> tuple[str, ...]:
        """State names of ``leg``'s link angles, proximal first (``theta1`` or
        ``theta1_thigh``, ``theta1_shank``); their unit is [rad], their rates' (``d`` +
        name) [rad/s].

        Raises
        ------
        ValueError
            ``leg`` is not ``"leg1"`` or ``"leg2"``.
        """
        i = FOOT_NAMES.index(leg) + 1
        return tuple(s for s in self.state_names()[:self.nq] if s.startswith(f"theta{i}"))

    # ------------------------------------------------------------------ dynamics
    @property
    def kernel_lanes(self) -> tuple[np.ndarray, np.ndarray]:
        """The lanes as the kernels read them (:mod:`walkerlab.models.contact.generated`): leg1's
        and leg2's ``[centres (n), heights (n), largest height]``, each of shape (2 n + 1,)
        [m] for a lane of n patches."""
        return self._kernel_lane1, self._kernel_lane2

    def _args(self):
        return self.contact_params, self.walker_params, *self.kernel_lanes

    def mass_matrix(self, q) -> np.ndarray:
        """Mass matrix M(q) of the floating equations of motion M(q) q'' = h(q, q'), generated
        from the walker description (:mod:`walkerlab.codegen.floating`; Lagrange's equations).

        Parameters
        ----------
        q : array_like, shape (nq,) or longer
            Coordinates [m, m, rad, ...] in :meth:`coordinate_names` order (only the first
            ``nq`` entries are read, so a full state (2 nq,) works too).

        Returns
        -------
        ndarray, shape (nq, nq)
            Entries in [kg] (hip translations), [kg m] (coupling) and [kg m^2] (angles).
        """
        x = np.zeros(2 * self.nq)
        x[:self.nq] = np.asarray(q, float)[:self.nq]
        M, h = np.empty((self.nq, self.nq)), np.empty(self.nq)
        self.kernels.dyn(x, self.walker_params, M, h)
        return M

    def rhs(self, t, x) -> np.ndarray:
        """dx/dt (numba).  ``t`` [s] unused (autonomous).

        Parameters
        ----------
        t : float
            Time [s] (ignored).
        x : array_like, shape (2 nq,)
            State in :meth:`state_names` order, units :meth:`state_units`.

        Returns
        -------
        ndarray, shape (2 nq,)
            ``[dq, ddq]`` in [m/s, rad/s] and [m/s^2, rad/s^2].
        """
        return self.kernels.rhs(np.asarray(x, dtype=float), *self._args())

    def jac(self, t, x) -> np.ndarray:
        """Analytic Jacobian d(rhs)/dx (numba; :func:`walkerlab.models.contact.generated.jac`,
        with each contact point's patch membership held locally constant).

        Parameters
        ----------
        t, x
            As :meth:`rhs` (``t`` ignored; ``x`` of shape (2 nq,)).

        Returns
        -------
        ndarray, shape (2 nq, 2 nq)
            Row i, column j is d(dx_i/dt)/dx_j, in [unit of dx_i/dt / unit of x_j].
        """
        return self.kernels.jac(np.asarray(x, dtype=float), *self._args())

    def _check_pin(self):
        if self.structure.foot != "point":
            raise ValueError("contact_sim.pin_stance_until: pinning the stance foot needs "
                             "point feet")

    def pinned_state(self, x) -> np.ndarray:
        """Pinned state ``z = [link angles, their rates]`` of a full state.

        Parameters
        ----------
        x : array_like, shape (2 nq,)
            Full state (:meth:`state_names`).

        Returns
        -------
        ndarray, shape (2 (nq - d),)
            The link angles [rad] and their rates [rad/s] (the base's ``d`` slides and their
            rates dropped: the hip's position and velocity; in 3D the stance foot's).
        """
        x = np.asarray(x, float)
        n, d = self.nq, self.dim
        return np.concatenate([x[d:n], x[n + d:]])

    def rhs_pinned(self, t, z, foot2) -> np.ndarray:
        """Reduced dynamics dz/dt with leg2's foot held at ``foot2`` (d,) [m] (point feet).

        ``z = [link angles, their rates]`` (:meth:`pinned_state`); leg1's foot still feels
        its contact, the knees their stops.

        Parameters
        ----------
        t : float
            Time [s] (ignored).
        z : array_like, shape (2 (nq - d),)
            Link angles [rad] and rates [rad/s].
        foot2 : array_like, shape (d,)
            Position (x, y) [m] of leg2's pinned foot.

        Returns
        -------
        ndarray, shape (2 (nq - d),)
            dz/dt [rad/s, rad/s^2].

        Raises
        ------
        ValueError
            The walker's feet are not point feet.
        """
        self._check_pin()
        return self.kernels.rhs_pinned(np.asarray(z, float), *self._args(),
                                       np.asarray(foot2, float))

    def pinned_to_full(self, z, foot2) -> np.ndarray:
        """Full state from the pinned state z and the pinned foot position.

        Parameters
        ----------
        z : array_like, shape (2 (nq - d),)
            Link angles [rad] and rates [rad/s] (:meth:`pinned_state`).
        foot2 : array_like, shape (d,)
            Position (x, y) [m] of leg2's pinned foot.

        Returns
        -------
        ndarray, shape (2 nq,)
            State in :meth:`state_names` order (hip position and velocity from the pinned
            foot's kinematics), units :meth:`state_units`.
        """
        return self.kernels.pinned_to_full(np.asarray(z, float), self.walker_params,
                                           np.asarray(foot2, float))

    def link_state_from_ideal(self, x_ideal, rate_scale=(1.0, 1.0)) -> np.ndarray:
        """Pinned state z (link angles and rates, leg1 swing / leg2 stance) from a rigid
        model's state ``x_ideal`` (role order of the rigid walker), ``rate_scale`` =
        multipliers on leg1's and leg2's rates.

        Straight legs, absolute coordinates: ``[th_sw, th_st, w_sw, w_st]``; kneed:
        ``[th_swing_thigh, th_swing_shank, th_stance, rates]`` (the stance knee straight);
        flat feet: ``[th_sw, th_st, th_sw + r_sw, th_st + ankle, rates]`` (the swing foot at
        its spring's rest angle ``r``, the stance foot at the rigid view's ankle angle; a
        leg's scale multiplies its foot's rate too);
        other coordinate schemes through the rigid model's leg angles.

        Parameters
        ----------
        x_ideal : array_like, shape (2n,)
            The rigid model's state in its role order (``rigid_layout().state_names()``),
            angles [rad] and rates [rad/s].
        rate_scale : (float, float)
            Multipliers [-] on leg1's and leg2's rates.

        Returns
        -------
        ndarray, shape (2 (nq - d),)
            The pinned state z (:meth:`pinned_state`), [rad] and [rad/s].
        """
        return contact_part(self.structure).link_state(self, np.asarray(x_ideal, float),
                                                       rate_scale)

    # ------------------------------------------------------------------ compiled integrators
    def pack(self) -> np.ndarray:
        """Data vector ``[n1, n2, PC, p, c1, c2, nfev=0]`` of the compiled right-hand side
        (:mod:`walkerlab.models.contact.generated`).

        Returns
        -------
        ndarray, shape (2 + NPC + len(walker_params) + n1 + n2 + 1,), float64
            ``n1``, ``n2`` the kernel lanes' lengths (:attr:`kernel_lanes`), ``PC`` the contact
            parameters (SI: [N/m^e], [-], [N s/m], [m], [-], [m/s], ...), ``p`` the walker's
            parameters (SI), ``c1``, ``c2`` the kernel lanes [m], and a zero slot the compiled
            code counts right-hand-side evaluations in.
        """
        k1, k2 = self.kernel_lanes
        return np.concatenate([[len(k1), len(k2)], self.contact_params,
                               self.walker_params, k1, k2, [0.0]]
                              ).astype(np.float64)
