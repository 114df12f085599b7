"""What every energy ledger of a rigid walker shares: its columns and the quadrature of a
power over a step (:mod:`walkerlab.analysis.gait.energy` for generated models,
:mod:`walkerlab.analysis.gait.energy_modes` for flat feet)."""

from __future__ import annotations

import numpy as np

from walkerlab.io.schemas.simulate import LEDGER_UNITS

__all__ = ["LEDGER_NAMES", "quad_work", "released_energy"]

#: the ledger's columns, each (step,) (units: the artifact's, ``LEDGER_UNITS``)
LEDGER_NAMES = tuple(LEDGER_UNITS)


def quad_work(f, a: float, b: float, scale: float) -> float:
    """``int_a^b f dt`` [J] by adaptive quadrature.  A kinked integrand (``max(p, 0)`` where
    the power changes sign, a saturated torque law) can keep quad from certifying its 1e-12
    tolerance (its IntegrationWarning); the value is kept: the ledger's ``closure``, an
    independent check, states the accuracy actually reached."""
    import warnings

    from scipy.integrate import IntegrationWarning, quad

    if b <= a:
        return 0.0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", IntegrationWarning)
        val, _ = quad(f, a, b, limit=400, epsabs=1e-13 * scale, epsrel=1e-12)
    return float(val)


def released_energy(walker, d: float, rise: float) -> float:
    """The potential energy [J] the ground releases over a step: the ledger's
    ``slope_energy``, what a passive gait's collisions (and dampers) take.

    Parameters
    ----------
    walker : HybridWalker
        The step's walker (its mass ``total_mass_kg`` [kg], ``params["gravity_m_per_s2"]``,
        ``slope_rad``).
    d : float
        The step's length [m] (:func:`walkerlab.analysis.gait.metrics.step_length`).
    rise : float
        The landing swing foot's height above the stance foot [m], world vertical
        (``points(x_end)["swing_foot"][1]``).

    Returns
    -------
    float
        On the slope ``M g d sin(phi)`` (Kuo 2002; Collins et al. 2005); on stairs and
        footholds (a walker of :func:`walkerlab.models.hybrid.ground.on_landing`, whose
        ``params`` record ``landing_drop_m``) gravity's work over the step's descent,
        ``-M g rise`` (down level treads of riser ``H``: ``M g H``).
    """
    m, g = float(walker.total_mass_kg), float(walker.params["gravity_m_per_s2"])
    if "landing_drop_m" in walker.params:
        return -m * g * rise
    return m * g * d * np.sin(float(walker.slope_rad))
