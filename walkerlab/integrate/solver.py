"""The one solver-settings object of both models, and the integration libraries available.

:class:`Solver` carries an integrator choice (method, tolerances, largest step, library) to
every integration: the rigid hybrid walker's steps (:mod:`walkerlab.integrate.rigid`) and the
compliant-contact walker's runs (:mod:`walkerlab.integrate.contact`).  The scene's typed
settings (:class:`walkerlab.config.SolverSettings` of ``solver:`` and ``contact_solver:``)
become a :class:`Solver` in one place, :meth:`Solver.from_settings`.

Rigid backends (``backend``):

- ``"scipy"``: ``scipy.integrate.solve_ivp``;
- ``"cyrk"``: ``CyRK.pysolve_ivp`` (the same Runge-Kutta pairs as scipy, in C++);
- ``"cyrk_compiled"``: CyRK with the phase's flow compiled by numba;
- ``"auto"``: ``cyrk`` for the methods it shares with scipy when CyRK is installed, else
  ``scipy``; a phase whose model marks its compiled flow
  (:attr:`walkerlab.models.compiled_flows.CompiledFlow.by_default`: a 3D walker's, whose Python
  flow costs about 100 us a call) runs ``cyrk_compiled``.

The contact model names its library in ``method`` (``odeint``, ``cyrk_bdf``, ``numbalsoda``
or a ``solve_ivp`` method) and ignores ``backend``.  Importing this module loads nothing heavy.
"""

from __future__ import annotations

import importlib.util
from dataclasses import dataclass

__all__ = ["BACKENDS", "CYRK_METHODS", "Solver", "available_backends"]

#: Rigid-model backends a :class:`Solver` may name.
BACKENDS = ("auto", "scipy", "cyrk", "cyrk_compiled")

#: Methods both rigid backends implement with the same Runge-Kutta pair and step control.
CYRK_METHODS = ("RK23", "RK45", "DOP853")


def available_backends() -> tuple[str, ...]:
    """The rigid-model integration libraries installed here.

    Returns
    -------
    tuple of str
        ``("scipy", "cyrk", "cyrk_compiled")`` when CyRK is installed, else ``("scipy",)``
        (found without importing CyRK).
    """
    if importlib.util.find_spec("CyRK") is not None:
        return ("scipy", "cyrk", "cyrk_compiled")
    return ("scipy",)


@dataclass(frozen=True)
class Solver:
    """Integrator settings of one integration, rigid or contact.

    Attributes
    ----------
    method : str
        Rigid: a ``solve_ivp`` method (``"DOP853"``, ...).  Contact: ``"odeint"``,
        ``"cyrk_bdf"``, ``"numbalsoda"`` or a ``solve_ivp`` method.
    rtol, atol : float
        Relative tolerance [-] and absolute tolerance [state units].
    max_step_s : float or None
        Largest step [s] (None: unbounded).
    backend : {"auto", "scipy", "cyrk", "cyrk_compiled"}
        Library that integrates the rigid model (see the module docstring); the contact
        model's library is its ``method``.
    """

    method: str = "DOP853"
    rtol: float = 1e-10
    atol: float = 1e-10
    max_step_s: float | None = None
    backend: str = "auto"

    @classmethod
    def from_settings(cls, s) -> Solver:
        """The :class:`Solver` of a scene's typed settings.

        Parameters
        ----------
        s : walkerlab.config.SolverSettings or Solver
            A scene's ``solver:`` or ``contact_solver:`` section (or a Solver, returned
            as it is).
        """
        if isinstance(s, Solver):
            return s
        return cls(s.method, s.rtol, s.atol, s.max_step_s, s.backend)

    def kwargs(self) -> dict:
        """``solve_ivp`` keyword arguments (method, rtol, atol and max_step when bounded)."""
        kw = {"method": self.method, "rtol": self.rtol, "atol": self.atol}
        if self.max_step_s is not None:
            kw["max_step"] = self.max_step_s
        return kw

    def resolved_backend(self) -> str:
        """The rigid backend that runs: ``"scipy"``, ``"cyrk"`` or ``"cyrk_compiled"``.

        Raises
        ------
        ValueError
            ``backend="cyrk"`` with a method CyRK does not share with scipy, CyRK missing, or
            an unknown backend.
        """
        if self.backend == "scipy":
            return "scipy"
        ok = self.method in CYRK_METHODS
        if self.backend in ("cyrk", "cyrk_compiled"):
            if not ok:
                raise ValueError(f"solver.backend: cyrk integrates {', '.join(CYRK_METHODS)}, "
                                 f"not {self.method}")
            if "cyrk" not in available_backends():
                raise ValueError("solver.backend: cyrk is not installed (pip install CyRK)")
            return self.backend
        if self.backend != "auto":
            raise ValueError(f"solver.backend: unknown backend {self.backend!r} "
                             "(auto | scipy | cyrk | cyrk_compiled)")
        return "cyrk" if ok and "cyrk" in available_backends() else "scipy"
