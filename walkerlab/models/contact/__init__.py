"""The compliant-contact (MSC ADAMS-style) walker model of any walker description with positive
leg masses (generated from its floating view, :mod:`walkerlab.codegen.floating`): contact laws,
geometry, terrain, knee stops and the floating walker.  Only the model: integrating it is
:mod:`walkerlab.integrate.contact`, reading its gait :mod:`walkerlab.analysis.contact.gait` /
:mod:`walkerlab.analysis.contact.sim`, its settings live in :mod:`walkerlab.config.contact`.

The names below are loaded on first use (PEP 562 ``__getattr__``), so importing a settings
or law module does not load numba, which the model needs.
"""

from importlib import import_module

_WHERE = {
    "adams_step": "laws", "adams_step_derivative": "laws",
    "coulomb_friction_coefficient": "laws", "impact_normal_force": "laws",
    "FOOT_NAMES": "model", "ContactWalker": "model", "checkerboard_lanes": "model",
}

__all__ = sorted(_WHERE)


def __getattr__(name: str):
    if name in _WHERE:
        return getattr(import_module(f"{__name__}.{_WHERE[name]}"), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
