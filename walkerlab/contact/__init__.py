"""Compliant-contact (MSC ADAMS-style) walker of any walker description with positive leg
masses (generated from its floating view, :mod:`walkerlab.models.floating`): laws, model,
simulation.

The names below are loaded on first use (PEP 562 ``__getattr__``): ``import
walkerlab.contact.config`` (what :mod:`walkerlab.config` needs) must not load numba or
scipy.integrate, which the model and the simulation need.
"""

from importlib import import_module

_WHERE = {
    "ContactParamsSI": "config", "ContactSettings": "config", "ContactSimSettings": "config",
    "KneeStopSI": "config", "KneeStopSettings": "config", "TerrainSettings": "config",
    "adams_step": "laws", "adams_step_derivative": "laws",
    "coulomb_friction_coefficient": "laws", "impact_normal_force": "laws",
    "FOOT_NAMES": "model", "ContactWalker": "model", "checkerboard_lanes": "model",
    "ContactResult": "simulate", "FootTrace": "simulate", "StepSummary": "simulate",
    "initial_state_from_ideal": "simulate", "simulate_contact": "simulate",
}

__all__ = sorted(_WHERE)


def __getattr__(name: str):
    if name in _WHERE:
        return getattr(import_module(f"{__name__}.{_WHERE[name]}"), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
