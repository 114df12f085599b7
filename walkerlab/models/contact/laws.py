"""Compliant-contact force laws of MSC ADAMS (STEP, IMPACT, Coulomb friction).

All functions are pure and vectorized (numpy broadcasting).  They are unit-agnostic: the
caller must pass every argument in one consistent unit system (``walkerlab.models.contact`` uses SI
internally).  The contact model's parameters in SI (:class:`ContactParamsSI`,
:class:`KneeStopSI`) come from a scene's settings, each number converted from the unit its
field names, by :func:`contact_params_si` and :func:`knee_stop_si`; the stiffness family is
applied on top by :func:`walkerlab.models.contact.rigid_limit.contact_si`, once per run.

Sources
-------
* MSC Adams/Solver function reference, ``STEP`` (cubic step) and ``IMPACT`` (one-sided
  spring-damper contact force); Adams/View contact dialog, Coulomb friction with stiction
  and friction transition velocities.
* The paper's Section 4 (its ADAMS model: IMPACT contact with Coulomb friction on a
  checkerboard terrain; :mod:`walkerlab.published.paper`).

Scalar, numba-compiled twins of these functions live in :mod:`walkerlab.models.contact._kernels`;
``tests/contact/test_laws_config.py`` checks that both agree
(``test_the_scalar_impact_law_is_the_array_law_bit_for_bit``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from walkerlab.config.contact import LENGTH_UNITS, ContactSettings, KneeStopSettings

__all__ = [
    "ContactParamsSI",
    "KneeStopSI",
    "contact_params_si",
    "knee_stop_si",
    "adams_step",
    "adams_step_derivative",
    "coulomb_friction_coefficient",
    "impact_normal_force",
    "impact_normal_force_scalar",
]


#: A contact point's torsional friction coefficient [m] as a fraction of the leg length,
#: for a walker in 3D when the scene gives none (``contact.torsional_friction_m``): the
#: largest moment about the ground's normal the foot's patch holds is this times its normal
#: force (MuJoCo's ``condim 4`` coefficient; the MJCF export's).  The rigid model's foot
#: does not twist; the yaw moment of a swinging leg ``w`` off the stance foot's line is
#: ~ ``m_leg a w`` (5 kg x 3 m/s^2 x 0.1 m = 1.5 N m on a 200 N load: 0.0075 m): 0.05 L
#: holds it with room.
TORSION_FRACTION = 0.05


def torsional_friction_m(settings, leg_length_m: float, in_3d: bool) -> float:
    """The torsional friction coefficient [m] of the scene's contact law ``settings``
    (:class:`walkerlab.config.contact.ContactSettings`): ``torsional_friction_m``, else
    :data:`TORSION_FRACTION` of the leg length ``leg_length_m`` [m] for a walker in 3D and
    0 in the plane (a planar contact has no normal to spin about)."""
    given = getattr(settings, "torsional_friction_m", None)
    if not in_3d:
        return 0.0
    return float(given) if given is not None else TORSION_FRACTION * float(leg_length_m)


@dataclass(frozen=True)
class ContactParamsSI:
    """Contact parameters in SI units (what the model kernels use).

    Attributes
    ----------
    k : float
        Stiffness ``[N/m**e]``.
    e : float
        Force exponent ``[-]``.
    cmax : float
        Maximum damping ``[N s/m]``.
    dmax : float
        Penetration at full damping ``[m]``.
    mu_s, mu_d : float
        Static / dynamic friction coefficients ``[-]``.
    v_s, v_d : float
        Stiction / friction transition velocities ``[m/s]``.
    """

    k: float
    e: float
    cmax: float
    dmax: float
    mu_s: float
    mu_d: float
    v_s: float
    v_d: float


@dataclass(frozen=True)
class KneeStopSI:
    """Knee-stop parameters in SI (the IMPACT law on the knee's hyperextension angle).

    Attributes
    ----------
    k : float
        Stiffness ``[N m/rad**e]``.
    e : float
        Exponent ``[-]``.
    cmax : float
        Maximum damping ``[N m s/rad]``.
    dmax : float
        Hyperextension at full damping ``[rad]``.
    latch : bool
        The stop also holds a loaded leg's knee against flexion (knee latch).
    latch_height : float
        Height of the foot above the ground at which the latch has released ``[m]``.
    latch_capture : float
        Flexion beyond which the latch does not hold ``[rad]``.
    """

    k: float
    e: float
    cmax: float
    dmax: float
    latch: bool = False
    latch_height: float = 0.002
    latch_capture: float = 0.01



def contact_params_si(settings: ContactSettings) -> ContactParamsSI:
    """The contact law of ``settings`` in SI, each number converted from the unit its field
    names (the stiffness family not applied:
    :func:`walkerlab.models.contact.rigid_limit.contact_si`).

    With ``f`` the metres per length unit of a field's name (1e-3 for ``..._mm``, 1 for
    ``..._m``): ``k_SI = k * f**-e``, ``c_SI = c / f``, lengths and velocities ``* f``.  E.g.
    ``stiffness_n_per_mm_pow_e: 1e5`` is ``1e5 * 1000**2.2 N/m^2.2``.

    Parameters
    ----------
    settings : ContactSettings

    Returns
    -------
    ContactParamsSI
    """
    def length(quantity: str) -> float:  # a length or a velocity [m, m/s]
        value, unit, _ = settings.written(quantity)
        return value * LENGTH_UNITS[unit]

    e = settings.exponent
    k, ku, _ = settings.written("stiffness")
    cmax, cu, _ = settings.written("max_damping")
    return ContactParamsSI(
        k=k * LENGTH_UNITS[ku] ** (-e),
        e=e,
        cmax=cmax / LENGTH_UNITS[cu],
        dmax=length("penetration_at_max_damping"),
        mu_s=settings.mu_static,
        mu_d=settings.mu_dynamic,
        v_s=length("stiction_velocity"),
        v_d=length("friction_velocity"),
    )


def knee_stop_si(settings: KneeStopSettings) -> KneeStopSI:
    """The knee stop of ``settings`` (already SI) as a :class:`KneeStopSI`."""
    return KneeStopSI(settings.stiffness_n_m_per_rad_pow_e, settings.exponent,
                      settings.max_damping_n_m_s_per_rad, settings.penetration_at_max_damping_rad,
                      settings.latch, settings.latch_release_height_m,
                      settings.latch_capture_rad)


def _unit_interval(x, x0, x1):
    return np.clip((np.asarray(x, dtype=float) - x0) / (x1 - x0), 0.0, 1.0)


def adams_step(x, x0, h0, x1, h1):
    """ADAMS ``STEP(x, x0, h0, x1, h1)``: cubic, C1 transition from ``h0`` to ``h1``.

    ``h0`` for ``x <= x0``, ``h1`` for ``x >= x1`` and
    ``h0 + (h1 - h0) * s**2 * (3 - 2*s)``, ``s = (x - x0) / (x1 - x0)``, in between
    (MSC Adams/Solver function reference, STEP).

    Parameters
    ----------
    x : array_like
        Independent variable, any shape, any unit ``[u]``.
    x0, x1 : float
        Start and end of the transition, ``[u]``, ``x1 > x0``.
    h0, h1 : float
        Values before and after the transition, any unit ``[w]``.

    Returns
    -------
    ndarray
        Same shape as ``x``, unit ``[w]``.
    """
    s = _unit_interval(x, x0, x1)
    return h0 + (h1 - h0) * s * s * (3.0 - 2.0 * s)


def adams_step_derivative(x, x0, h0, x1, h1):
    """Derivative of :func:`adams_step` with respect to ``x``.

    ``6 (h1 - h0) s (1 - s) / (x1 - x0)`` inside the transition, zero outside (the step is C1,
    so the derivative is continuous).  Needed for analytic Jacobians.

    Parameters
    ----------
    x : array_like
        Any shape, ``[u]``.
    x0, h0, x1, h1 : float
        As in :func:`adams_step`.

    Returns
    -------
    ndarray
        Same shape as ``x``, unit ``[w]/[u]``.
    """
    s = _unit_interval(x, x0, x1)
    return 6.0 * (h1 - h0) * s * (1.0 - s) / (x1 - x0)


def impact_normal_force(delta, delta_dot, k, e, cmax, dmax):
    """ADAMS ``IMPACT`` normal contact force (never pulls).

    ``Fn = max(0, k * delta**e + STEP(delta, 0, 0, dmax, cmax) * delta_dot)`` for
    ``delta > 0`` and ``Fn = 0`` otherwise (MSC Adams/Solver function reference,
    IMPACT).  The damping ramps in over the first ``dmax`` of penetration, so the force is
    continuous at touchdown.

    Parameters
    ----------
    delta : array_like
        Penetration depth ``[len]`` (``>= 0`` means in contact).
    delta_dot : array_like
        Penetration rate ``[len/s]``, positive when penetrating deeper.
    k : float
        Contact stiffness ``[N/len**e]``.
    e : float
        Force exponent ``[-]`` (``>= 1``; ADAMS default 2.2).
    cmax : float
        Maximum damping coefficient ``[N s/len]``.
    dmax : float
        Penetration at which full damping is reached ``[len]``.

    Returns
    -------
    ndarray
        Normal force ``[N]``, broadcast shape of ``delta`` and ``delta_dot``.
    """
    delta = np.asarray(delta, dtype=float)
    dpos = np.maximum(delta, 0.0)
    f = k * dpos**e + adams_step(dpos, 0.0, 0.0, dmax, cmax) * np.asarray(delta_dot, float)
    return np.where(delta > 0.0, np.maximum(f, 0.0), 0.0)


def impact_normal_force_scalar(delta: float, delta_dot: float, k: float, e: float,
                               cmax: float, dmax: float) -> float:
    """:func:`impact_normal_force` of one point, in plain Python floats: the same operations
    in the same order, so the same number bit for bit (``tests/contact/test_laws_config.py``),
    at a fraction of the array law's cost per call (what a Python right-hand side called
    from a compiled integrator pays per evaluation, the drop test's).

    Parameters
    ----------
    delta, delta_dot : float
        Penetration ``[len]`` and its rate ``[len/s]``.
    k, e, cmax, dmax : float
        As in :func:`impact_normal_force`.

    Returns
    -------
    float
        Normal force ``[N]`` (>= 0).
    """
    if not delta > 0.0:
        return 0.0
    s = min(max((delta - 0.0) / (dmax - 0.0), 0.0), 1.0)  # adams_step(delta, 0, 0, dmax, cmax)
    f = k * delta**e + (0.0 + (cmax - 0.0) * s * s * (3.0 - 2.0 * s)) * delta_dot
    return f if f > 0.0 else 0.0


def coulomb_friction_coefficient(v, mu_s, mu_d, v_s, v_d):
    """ADAMS-style regularized Coulomb friction coefficient (signed, opposes ``v``).

    * ``|v| < v_s``: ``mu = STEP(v, -v_s, mu_s, v_s, -mu_s)`` (so ``mu(0) = 0``);
    * ``v_s <= |v| <= v_d``: ``mu = -sign(v) * STEP(|v|, v_s, mu_s, v_d, mu_d)``;
    * ``|v| > v_d``: ``mu = -sign(v) * mu_d``.

    (Adams/View contact, Coulomb friction.)  The friction force is
    ``mu * Fn`` along the direction in which ``v`` is measured.

    Parameters
    ----------
    v : array_like
        Slip velocity ``[len/s]``.
    mu_s, mu_d : float
        Static and dynamic friction coefficients ``[-]``.
    v_s, v_d : float
        Stiction and friction transition velocities ``[len/s]``, ``0 < v_s < v_d``.

    Returns
    -------
    ndarray
        Signed coefficient ``[-]``, same shape as ``v``.
    """
    v = np.asarray(v, dtype=float)
    av = np.abs(v)
    inner = adams_step(v, -v_s, mu_s, v_s, -mu_s)
    outer = -np.sign(v) * adams_step(av, v_s, mu_s, v_d, mu_d)
    return np.where(av < v_s, inner, outer)
