"""The one solver-settings section of a scene, for both models (pydantic v2).

A scene names its integrators in two sections of the same type, :class:`SolverSettings`:
``solver:`` (the rigid hybrid walker: a ``solve_ivp`` method and the library that runs it,
``backend``) and ``contact_solver:`` (the stiff compliant-contact walker: ``cyrk_bdf``,
``odeint``, ``numbalsoda`` or a ``solve_ivp`` method; its library is its method).  The two
sections differ only in their defaults (:data:`CONTACT_DEFAULTS` fill what a
``contact_solver:`` leaves out) and in which methods they take (:func:`check_rigid`,
:func:`check_contact`, one line each).  Both become the run-time
:class:`walkerlab.integrate.solver.Solver` in one place (``Solver.from_settings``).
"""

from __future__ import annotations

from typing import Literal

from pydantic import BaseModel, ConfigDict, Field

__all__ = ["CONTACT_DEFAULTS", "CONTACT_METHODS", "RIGID_METHODS", "SolverSettings",
           "check_contact", "check_rigid", "with_contact_defaults"]

#: ``solve_ivp`` methods the rigid model integrates with (``solver.method``).
RIGID_METHODS = ("RK45", "RK23", "DOP853", "Radau", "BDF", "LSODA")
#: Methods of the contact model (``contact_solver.method``): CyRK's BDF from compiled code,
#: scipy's odeint (LSODA), numbalsoda (LSODA from compiled code; optional extra) or a
#: ``solve_ivp`` method.
CONTACT_METHODS = ("odeint", "cyrk_bdf", "numbalsoda", "LSODA", "Radau", "BDF", "RK45", "DOP853")
#: What a ``contact_solver:`` section leaves out (CyRK's BDF at rtol 1e-8).
CONTACT_DEFAULTS = {"method": "cyrk_bdf", "rtol": 1e-8}
#: Tightest relative tolerance of a contact integration: LSODA/odeint cannot meet a tighter
#: one in double precision.
MIN_CONTACT_RTOL = 1e-13


class SolverSettings(BaseModel):
    """One integrator: method, tolerances, largest step and (rigid model) library.

    The defaults are the rigid model's (``solver:``); a ``contact_solver:`` section is
    completed with :data:`CONTACT_DEFAULTS` (:func:`with_contact_defaults`).
    """

    model_config = ConfigDict(extra="forbid", frozen=True, strict=True, allow_inf_nan=False)

    method: Literal["RK45", "RK23", "DOP853", "Radau", "BDF", "LSODA", "odeint", "cyrk_bdf",
                    "numbalsoda"] = Field(
        "DOP853", description="solver: a scipy solve_ivp method (RK45, RK23, DOP853, Radau, "
        "BDF, LSODA); contact_solver: cyrk_bdf (CyRK's BDF from compiled code; the default), "
        "odeint (scipy.integrate.odeint), numbalsoda (LSODA from compiled code; optional "
        "extra: pip install -e '.[numbalsoda]') or a solve_ivp method")
    rtol: float = Field(1e-10, gt=0, lt=1,
                        description="relative tolerance [-] (contact_solver: at least 1e-13, "
                        "as LSODA/odeint cannot meet a tighter one in double precision; "
                        "default 1e-8)")
    atol: float = Field(1e-10, gt=0, lt=1, description="absolute tolerance [state units]")
    max_step_s: float | None = Field(None, gt=0, description="largest step [s]; null = unbounded")
    backend: Literal["auto", "scipy", "cyrk", "cyrk_compiled"] = Field(
        "auto", description="solver only: library that integrates the rigid model: auto "
        "(cyrk for RK23/RK45/DOP853, else scipy; a 3D walker's phases cyrk_compiled, its "
        "Python flow being slow), scipy, cyrk, or cyrk_compiled (CyRK with "
        "the flow compiled by numba: no Python callbacks, ~1 s numba import per process; "
        "for many-point studies); the contact model's library is its method")

    @classmethod
    def for_contact(cls, **fields) -> SolverSettings:
        """Settings of a contact integration: ``fields`` over :data:`CONTACT_DEFAULTS`.

        Raises
        ------
        ValueError
            A field that does not validate, or a method / tolerance the contact model does
            not take (:func:`check_contact`).
        """
        out = cls(**with_contact_defaults(fields))
        why = check_contact(out)
        if why:
            raise ValueError(why)
        return out


def with_contact_defaults(value):
    """A ``contact_solver:`` mapping completed with :data:`CONTACT_DEFAULTS` (anything else
    is returned unchanged, for pydantic to judge)."""
    return {**CONTACT_DEFAULTS, **value} if isinstance(value, dict) else value


def check_rigid(s: SolverSettings) -> str:
    """Why ``s`` cannot be the rigid model's ``solver:`` ('' if it can)."""
    if s.method not in RIGID_METHODS:
        return (f"solver.method: {s.method} integrates the contact model (contact_solver); "
                f"the rigid model takes {', '.join(RIGID_METHODS)}")
    return ""


def check_contact(s: SolverSettings) -> str:
    """Why ``s`` cannot be the contact model's ``contact_solver:`` ('' if it can)."""
    if s.method not in CONTACT_METHODS:
        return (f"contact_solver.method: the contact model takes {', '.join(CONTACT_METHODS)}, "
                f"not {s.method}")
    if s.rtol < MIN_CONTACT_RTOL:
        return (f"contact_solver.rtol: at least {MIN_CONTACT_RTOL:g} (LSODA/odeint cannot "
                f"meet a tighter one in double precision; got {s.rtol:g})")
    if s.backend != "auto":
        return ("contact_solver.backend: the contact model's library is its method "
                f"({', '.join(CONTACT_METHODS[:3])}): remove backend")
    return ""
