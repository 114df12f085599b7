"""The contact model's settings, which live in :mod:`walkerlab.config.contact`.

Kept so that the model modules' ``from .config import ...`` reads as before; the settings
package is the one place they are defined (it imports no model, so no import cycle).
"""

from walkerlab.config.contact import (  # noqa: F401
    MAX_CONTACT_STRIDES,
    ContactParamsSI,
    ContactSettings,
    ContactSimSettings,
    ContactSolverSettings,
    KneeStopSettings,
    KneeStopSI,
    TerrainSettings,
)
