"""What every energy ledger of a rigid walker shares: its columns and the quadrature of a
power over a step (:mod:`walkerlab.analysis.gait.energy` for generated models,
:mod:`walkerlab.analysis.gait.energy_modes` for flat feet)."""

from __future__ import annotations

from walkerlab.io.schemas.simulate import LEDGER_UNITS

__all__ = ["LEDGER_NAMES", "quad_work"]

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
