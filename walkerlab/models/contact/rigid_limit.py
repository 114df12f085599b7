"""The rigid-limit family of the compliant contact: one definition, used everywhere.

A contact ``kappa`` times stiffer than a reference contact (``k -> kappa k``) tends to the
rigid model's assumptions (instantaneous, plastic heel strike; a stance foot that neither
sinks nor slips) only if every other parameter of the contact follows the stiffness:

==================  ============================  =========================================
parameter           scaling                       why
==================  ============================  =========================================
``k``               ``kappa``                     the family's parameter
``cmax``            ``kappa^(1/(e+1))``           self-similar impact: same restitution
``dmax``            ``kappa^(-1/(e+1))``          (follows the impact's depth ``d*``)
``v_s``, ``v_d``    ``kappa^(-1/2)``              stance creep ``~ v_s`` vanishes faster
                                                  than the impact's duration
knee latch height   ``kappa^(-1/(e+1))``          the contact's length scale ``d*``
knee stop k         ``kappa``                     the knee strike is an impact too:
knee stop cmax      ``kappa^(1/(e_k+1))``         the same self-similar family with the
knee stop dmax      ``kappa^(-1/(e_k+1))``        stop's own exponent ``e_k``
``mu_s``, ``mu_d``  unchanged                     the rigid gait needs no more friction
==================  ============================  =========================================

Impact (normal direction).  A point mass ``m`` meeting the ground at speed ``v`` on
``F = k d^e + c(d) d'`` reaches the depth ``d* ~ (m v^2 / k)^(1/(e+1))`` in the time
``tau ~ d* / v ~ k^(-1/(e+1))``.  In the variables ``d / d*``, ``t / tau`` the equation is
unchanged when ``c ~ k^(1/(e+1))`` and ``dmax ~ d*``: the coefficient of restitution stays
the reference one (near-plastic on the paper's contact, 0.03; gravity during the impact
aside) for every ``kappa``, and the heel strike tends to the rigid plastic impact through its
duration ``tau`` alone.  (The constant-damping "paper" family becomes elastic as ``k``
grows: restitution 0.03 -> 0.99 for ``k`` 1e5 -> 1e9 N/mm^2.2.)

Friction (tangential direction).  The regularised Coulomb law has no true stiction: below
``v_s`` the friction coefficient is ``~ 1.5 mu_s v / v_s`` (slope of ADAMS's STEP at 0), so
a stance foot that must carry the tangential load ``F_t`` creeps at
``v ~ v_s F_t / (1.5 mu_s F_n)``: a gap proportional to ``v_s`` that no stiffness removes
(measured: 13 mm/s, 0.71087 s against the rigid 0.70360 s whatever ``k``).  Scaling
``v_s ~ kappa^(-1/2)`` makes the creep's share vanish faster than the impact's duration
(exponent 1/2 > 1/(e+1) for e >= 1).  The transition velocity ``v_d`` keeps its ratio to
``v_s``.

Observed order.  The period and step-length gaps to the rigid gait are then dominated by the
impact's duration: expected order ``1/(e+1)`` per factor of ``kappa`` (0.3125 for e = 2.2,
i.e. a factor ``10^0.3125 = 2.05`` per decade, the measured +3.62 / +1.46 / +0.80 /
+0.42 / +0.20 / +0.098 / +0.048 ms for kappa = 1 ... 1e6).

The knee latch of kneed walkers (:mod:`walkerlab.models.contact.generated`) releases when the
foot rises ``latch_height`` above the ground; a fixed height (2 mm) leaves a
stiffness-independent gap (kneed: 0.548518 s at any stiffness, 0.546596 s at 0.5 mm, rigid
0.54642 s), so it follows the contact's length scale ``d*`` too.
"""

from __future__ import annotations

import dataclasses
import math

from walkerlab.config.contact import ContactSettings

from .laws import ContactParamsSI, KneeStopSI, contact_params_si, knee_stop_si

__all__ = ["FRICTION_EXPONENT", "contact_si", "expected_order", "scale", "scale_walker"]

#: Exponent of the stiction/friction transition velocities: ``v_s ~ kappa^(-1/2)``.
FRICTION_EXPONENT = 0.5


def expected_order(e: float) -> float:
    """Observed order of the period / step-length gaps in ``kappa`` along the family [-]:
    ``min(1/(e+1), FRICTION_EXPONENT)`` (impact duration vs. stance creep; derived in the
    module docstring, "Observed order").

    Parameters
    ----------
    e : float
        The IMPACT force exponent [-].
    """
    return min(1.0 / (e + 1.0), FRICTION_EXPONENT)


def scale(contact: ContactParamsSI, knee: KneeStopSI, kappa: float
          ) -> tuple[ContactParamsSI, KneeStopSI]:
    """The reference contact and knee latch ``kappa`` times stiffer along the family.

    Parameters
    ----------
    contact : ContactParamsSI
        Reference contact (SI).
    knee : KneeStopSI
        Reference knee stop: its stiffness, damping and damping depth follow the family
        with the stop's own exponent, its ``latch_height`` [m] the ground contact's length
        scale (the latch is released by the foot's height above the ground).
    kappa : float
        Stiffness factor [-], > 0 (1 returns the inputs).

    Returns
    -------
    (ContactParamsSI, KneeStopSI)

    Raises
    ------
    ValueError
        ``kappa`` not positive and finite.
    """
    if not (math.isfinite(kappa) and kappa > 0):
        raise ValueError(f"rigid-limit factor kappa must be positive and finite, got {kappa}")
    p = 1.0 / (contact.e + 1.0)
    length = kappa ** (-p)
    slow = kappa ** (-FRICTION_EXPONENT)
    new = dataclasses.replace(contact, k=contact.k * kappa, cmax=contact.cmax * kappa ** p,
                              dmax=contact.dmax * length, v_s=contact.v_s * slow,
                              v_d=contact.v_d * slow)
    pk = 1.0 / (knee.e + 1.0)
    return new, dataclasses.replace(knee, k=knee.k * kappa, cmax=knee.cmax * kappa ** pk,
                                    dmax=knee.dmax * kappa ** (-pk),
                                    latch_height=knee.latch_height * length)


def contact_si(settings: ContactSettings | None) -> tuple[ContactParamsSI, KneeStopSI]:
    """The scene's contact and knee stop in SI, with its ``stiffness_family`` applied: the
    contact model's parameters of a run (built once per run,
    :func:`walkerlab.models.contact.scene.build`).  ``settings`` None (a scene without a
    ``contact`` section): the paper's contact law, :class:`ContactSettings`' defaults.

    ``stiffness_family: paper`` returns the numbers as written, converted to SI
    (:func:`walkerlab.models.contact.laws.contact_params_si`).  ``rigid_limit`` reads the maximum
    damping, the penetration at maximum damping, the transition velocities and the latch
    height as holding at the reference stiffness and applies :func:`scale` with
    ``kappa = stiffness / reference stiffness`` (the ratio of the numbers as written when
    both are written in the same unit, else of their SI values).

    Returns
    -------
    (ContactParamsSI, KneeStopSI)
    """
    settings = ContactSettings() if settings is None else settings
    si, knee = contact_params_si(settings), knee_stop_si(settings.knee_stop)
    if settings.stiffness_family != "rigid_limit":
        return si, knee
    (k, ku, _), (kr, kru, _) = (settings.written(q) for q in ("stiffness",
                                                              "reference_stiffness"))
    if ku == kru:
        kappa = k / kr
    else:
        kappa = si.k / contact_params_si(settings.with_written("stiffness", kr, kru)).k
    return scale(dataclasses.replace(si, k=si.k / kappa), knee, kappa)


def scale_walker(walker, kappa: float):
    """Copy of a :class:`~walkerlab.models.contact.model.ContactWalker` whose contact (and knee
    latch) is ``kappa`` times stiffer along the family (:func:`scale`)."""
    contact, knee = scale(walker.contact, walker.knee_stop, kappa)
    return dataclasses.replace(walker, contact=contact, knee_stop=knee)
