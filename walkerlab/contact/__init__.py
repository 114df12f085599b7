"""Compliant-contact (MSC ADAMS-style) compass-gait walker: laws, model, simulation."""

from .config import ContactParamsSI, ContactSettings, ContactSimSettings, TerrainSettings
from .laws import (adams_step, adams_step_derivative, coulomb_friction_coefficient,
                   impact_normal_force)
from .model import FOOT_NAMES, ContactWalker, checkerboard_lanes
from .simulate import (ContactResult, FootTrace, StepSummary, initial_state_from_ideal,
                       simulate_contact)

__all__ = [
    "ContactParamsSI", "ContactSettings", "ContactSimSettings", "TerrainSettings",
    "adams_step", "adams_step_derivative", "coulomb_friction_coefficient", "impact_normal_force",
    "FOOT_NAMES", "ContactWalker", "checkerboard_lanes",
    "ContactResult", "FootTrace", "StepSummary", "initial_state_from_ideal", "simulate_contact",
]
