"""Compliant-contact (MSC ADAMS-style) compass-gait walker: laws, model, simulation."""

from .config import ContactParamsSI, ContactSettings, ContactSimSettings, TerrainSettings
from .laws import (
                   adams_step,
                   adams_step_derivative,
                   coulomb_friction_coefficient,
                   impact_normal_force,
)
from .model import FOOT_NAMES, ContactWalker, checkerboard_lanes
from .simulate import (
                   ContactResult,
                   FootTrace,
                   StepSummary,
                   initial_state_from_ideal,
                   simulate_contact,
)

__all__ = [
                   "FOOT_NAMES",
                   "ContactParamsSI",
                   "ContactResult",
                   "ContactSettings",
                   "ContactSimSettings",
                   "ContactWalker",
                   "FootTrace",
                   "StepSummary",
                   "TerrainSettings",
                   "adams_step",
                   "adams_step_derivative",
                   "checkerboard_lanes",
                   "coulomb_friction_coefficient",
                   "impact_normal_force",
                   "initial_state_from_ideal",
                   "simulate_contact",
]
