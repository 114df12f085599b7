"""Floating compass-gait walker with compliant ADAMS-style feet (:class:`ContactWalker`).

Conventions (shared with the rigid model): x downhill, y up, gravity (0, -g); ground line
y = -x tan(phi), outward normal n = (sin phi, cos phi), down-slope tangent
t = (cos phi, -sin phi).  foot_i = hip + L (sin th_i, -cos th_i); leg mass i at distance
b = L - a from the hip.  q = [hip_x, hip_y, theta1, theta2] [m, m, rad, rad], x = [q, qdot].
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from . import _kernels as K
from .config import ContactParamsSI, ContactSettings, TerrainSettings
from .reference import rhs_ref

__all__ = ["FOOT_NAMES", "ContactWalker", "checkerboard_lanes"]

FOOT_NAMES = ("leg1", "leg2")


def checkerboard_lanes(step_length: float, n_steps: int) -> tuple[np.ndarray, np.ndarray]:
    """Patch centres [m] (along-slope s) of each leg's lane.

    leg2 (first stance leg): s = 0, 2l, 4l, ...; leg1: s = l, 3l, ...; ``n_steps + 2`` footfalls
    in total so a run of ``n_steps`` steps never runs out of ground.

    Returns
    -------
    (c1, c2) : tuple of ndarray
        Centres of leg1's and leg2's patches [m].
    """
    k = n_steps // 2 + 2
    c2 = 2.0 * step_length * np.arange(k)
    c1 = step_length * (1.0 + 2.0 * np.arange(k))
    return c1, c2


@dataclass(frozen=True, eq=False)
class ContactWalker:
    """Walker parameters, slope, SI contact parameters and terrain.

    Attributes
    ----------
    L, m, MH, a, g : float
        Leg length [m], leg mass [kg], hip mass [kg], foot-to-leg-mass distance [m],
        gravity [m/s^2].
    phi : float
        Slope [rad], > 0 downhill in +x.
    contact : ContactParamsSI
        IMPACT and friction parameters in SI.
    lane1, lane2 : ndarray
        Patch centres [m] of leg1's / leg2's lane (ignored if ``continuous``).
    patch_half_width : float
        Half width of each patch [m].
    continuous : bool
        Ground everywhere (no lanes/gaps).
    """

    L: float = 1.0
    m: float = 5.0
    MH: float = 10.0
    a: float = 0.5
    g: float = 9.81
    phi: float = 0.0174
    contact: ContactParamsSI = field(default_factory=lambda: ContactSettings().to_si())
    lane1: np.ndarray = field(default_factory=lambda: np.zeros(0))
    lane2: np.ndarray = field(default_factory=lambda: np.zeros(0))
    patch_half_width: float = 0.05
    continuous: bool = True

    def __post_init__(self):
        c = self.contact
        P = np.empty(K.NPAR)
        P[K.I_L], P[K.I_M], P[K.I_MH], P[K.I_B], P[K.I_G], P[K.I_PHI] = (
            self.L, self.m, self.MH, self.L - self.a, self.g, self.phi)
        P[K.I_K], P[K.I_E], P[K.I_CMAX], P[K.I_DMAX] = c.k, c.e, c.cmax, c.dmax
        P[K.I_MUS], P[K.I_MUD], P[K.I_VS], P[K.I_VD] = c.mu_s, c.mu_d, c.v_s, c.v_d
        P[K.I_HW], P[K.I_CONT] = self.patch_half_width, 1.0 if self.continuous else 0.0
        object.__setattr__(self, "lane1", np.ascontiguousarray(self.lane1, dtype=float))
        object.__setattr__(self, "lane2", np.ascontiguousarray(self.lane2, dtype=float))
        object.__setattr__(self, "_P", P)

    # ------------------------------------------------------------------ construction
    @classmethod
    def from_settings(cls, contact: ContactSettings, terrain: TerrainSettings, *,
                      step_length: float, n_steps: int, L=1.0, m=5.0, MH=10.0, a=0.5,
                      g=9.81, phi=0.0174) -> ContactWalker:
        """Build from validated settings; ``step_length`` [m] is the ideal gait's step length."""
        c1, c2 = checkerboard_lanes(step_length, n_steps)
        return cls(L=L, m=m, MH=MH, a=a, g=g, phi=phi, contact=contact.to_si(), lane1=c1,
                   lane2=c2, patch_half_width=0.5 * terrain.patch_width_m,
                   continuous=terrain.kind == "continuous")

    @property
    def b(self) -> float:
        """Hip to leg-mass distance [m]."""
        return self.L - self.a

    @property
    def total_mass(self) -> float:
        """MH + 2 m [kg]."""
        return self.MH + 2.0 * self.m

    @property
    def normal(self) -> np.ndarray:
        """Outward ground normal n (2,)."""
        return np.array([np.sin(self.phi), np.cos(self.phi)])

    @property
    def tangent(self) -> np.ndarray:
        """Down-slope tangent t (2,)."""
        return np.array([np.cos(self.phi), -np.sin(self.phi)])

    def static_penetration(self, load: float | None = None) -> float:
        """IMPACT static penetration (F / k)^(1/e) [m] under ``load`` [N] (default M g cos phi)."""
        if load is None:
            load = self.total_mass * self.g * np.cos(self.phi)
        return (load / self.contact.k) ** (1.0 / self.contact.e)

    # ------------------------------------------------------------------ state layout
    @staticmethod
    def state_names() -> tuple[str, ...]:
        """Names of the 8 states, in order (leg i's angle ``theta{i}`` from the vertical)."""
        return ("hip_x", "hip_y", "theta1", "theta2", "vhip_x", "vhip_y", "dtheta1", "dtheta2")

    @staticmethod
    def state_units() -> tuple[str, ...]:
        """Units of :meth:`state_names`."""
        return ("m", "m", "rad", "rad", "m/s", "m/s", "rad/s", "rad/s")

    # ------------------------------------------------------------------ dynamics
    def mass_matrix(self, q) -> np.ndarray:
        """M(q) (4, 4) [kg, kg m, kg m^2]."""
        return K.mass_matrix(float(q[2]), float(q[3]), self._P)

    def rhs(self, t, x) -> np.ndarray:
        """dx/dt (8,) (numba).  ``t`` [s] unused (autonomous)."""
        return K.rhs(np.asarray(x, dtype=float), self._P, self.lane1, self.lane2)

    def jac(self, t, x) -> np.ndarray:
        """Analytic Jacobian d(rhs)/dx (8, 8) (numba)."""
        return K.jac(np.asarray(x, dtype=float), self._P, self.lane1, self.lane2)

    def rhs_numpy(self, t, x) -> np.ndarray:
        """Pure-numpy reference of :meth:`rhs` (slow)."""
        return rhs_ref(np.asarray(x, float), self.L, self.m, self.MH, self.a, self.g, self.phi,
                       self.contact, (self.lane1, self.lane2), self.patch_half_width,
                       self.continuous)

    def rhs_pinned(self, t, z, foot2) -> np.ndarray:
        """Reduced dynamics dz/dt (4,) with leg2's foot held at ``foot2`` (2,) [m].

        z = [theta1, theta2, dtheta1, dtheta2]; leg1's foot still feels its contact.
        """
        return K.rhs_pinned(np.asarray(z, float), self._P, self.lane1, self.lane2,
                            float(foot2[0]), float(foot2[1]))

    def pinned_to_full(self, z, foot2) -> np.ndarray:
        """Full state x (8,) from the pinned state z (4,) and the pinned foot position [m]."""
        t1, t2, w1, w2 = z
        L = self.L
        return np.array([foot2[0] - L * np.sin(t2), foot2[1] + L * np.cos(t2), t1, t2,
                         -L * np.cos(t2) * w2, -L * np.sin(t2) * w2, w1, w2])

    # ------------------------------------------------------------------ post-processing
    def foot_positions(self, X) -> np.ndarray:
        """Foot positions (n, 2, 2) [m] for states X (n, 8) or (8,) -> (2, 2)."""
        X = np.atleast_2d(X)
        th = X[:, 2:4]
        P = np.stack([X[:, [0]] + self.L * np.sin(th), X[:, [1]] - self.L * np.cos(th)], axis=-1)
        return P if len(P) > 1 else P[0]

    def hip_height(self, X) -> np.ndarray:
        """Hip height above the ground line, hip . n [m], for X (n, 8) -> (n,)."""
        X = np.ascontiguousarray(np.atleast_2d(X), dtype=float)
        return K.hip_heights(X, self._P)

    def fall_margin(self, x, threshold: float) -> float:
        """The one fall test: hip height of state ``x`` (8,) minus ``threshold`` [m]
        (negative = fallen).  Used as the fall event of every integration."""
        return float(K.hip_height(np.asarray(x, dtype=float), self._P)) - threshold

    def contact_quantities(self, X) -> dict[str, dict[str, np.ndarray]]:
        """Per-foot contact quantities for states X (n, 8).

        Returns
        -------
        dict
            ``{"leg1": {...}, "leg2": {...}}`` each with arrays (n,): ``penetration`` [m]
            (signed; negative = height above ground), ``penetration_rate`` [m/s],
            ``slip_velocity`` [m/s] (down-slope), ``s`` [m] along-slope position,
            ``normal_force`` [N], ``friction_force`` [N] (along t), ``power`` [W] (F . v),
            ``on_ground`` (1.0 where the foot's lane has ground, else 0.0).
        """
        X = np.ascontiguousarray(np.atleast_2d(X), dtype=float)
        tab = K.contact_table(X, self._P, self.lane1, self.lane2)
        names = ("penetration", "penetration_rate", "slip_velocity", "s", "normal_force",
                 "friction_force", "power", "on_ground")
        return {foot: {nm: tab[:, i, k].copy() for k, nm in enumerate(names)}
                for i, foot in enumerate(FOOT_NAMES)}

    def energies(self, X) -> dict[str, np.ndarray]:
        """Kinetic, potential (relative to y = 0) and total energy [J] for X (n, 8)."""
        X = np.atleast_2d(X)
        m, MH, b, g = self.m, self.MH, self.b, self.g
        vh2 = X[:, 4] ** 2 + X[:, 5] ** 2
        T = 0.5 * MH * vh2
        V = MH * g * X[:, 1]
        for j in (2, 3):
            th, w = X[:, j], X[:, j + 4]
            vx = X[:, 4] + b * np.cos(th) * w
            vy = X[:, 5] + b * np.sin(th) * w
            T = T + 0.5 * m * (vx**2 + vy**2)
            V = V + m * g * (X[:, 1] - b * np.cos(th))
        return {"kinetic": T, "potential": V, "total": T + V}
