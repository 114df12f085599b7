"""The collocation functions - the straight-legged walkers' one step
(:func:`walkerlab.optimal.transcription.step.step_functions`) and the phases of a step of a kneed
or flat-footed walker or of a stride
(:func:`walkerlab.optimal.transcription.phases.mode_functions`) -
built once per walker and cached on disk like the generated flows (the one CasADi
cache, :func:`walkerlab.codegen.casadi_functions.cached_functions`), so a warm
``walkerlab optimize`` neither derives the walker symbolically (sympy) nor converts it to
CasADi (``walkerlab bench optimize`` times both runs, cold and warm).

The functions have the walker's parameter values substituted (as the collocation builds
them), so the cache file is keyed on the walker's structure (its generator's key) *and* its
numbers: ``<user cache>/models/<cache_key(structure)>-steps-<hash>.casadi`` (the phases':
``-modes-``), ``hash`` over the parameter vector, slope, gravity and total mass (their
``repr``, exact), the phase order, the collocation and phases modules' and this module's
sources and CasADi's version.  A deserialised CasADi function is
the same expression graph, so a cached and a freshly built optimisation agree bit for bit.
The file follows the generated code's rules (private folder, sha256 header; a damaged or
untrusted file is rebuilt).
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

__all__ = ["cached_mode_functions", "cached_step_functions"]

#: the entries of :func:`step_functions` that are numbers, not CasADi functions
_NUMBERS = ("n", "limit", "total_mass_kg", "gravity")


def _key(data, kind: str = "steps", extra=()) -> str:
    """The cache key of ``data``'s step (``kind`` "steps") or phase ("modes", ``extra``
    the phase order) functions (module docstring)."""
    import casadi as ca

    from walkerlab.codegen.cache import cache_key
    from walkerlab.optimal.transcription import phases  # light
    from walkerlab.optimal.transcription import step as collocation  # light

    h = hashlib.sha256(repr((tuple(float(v) for v in data.params), float(data.slope_rad),
                             float(data.gravity_m_per_s2),
                             float(data.total_mass_kg)) + ((tuple(extra),) if extra
                                                           else ())).encode())
    from walkerlab.codegen import casadi_functions

    for mod in ((collocation.__file__, __file__, casadi_functions.__file__)
                + ((phases.__file__,) if extra else ())):
        h.update(Path(mod).read_bytes())
    h.update(ca.__version__.encode())
    return f"{cache_key(data.structure)}-{kind}-{h.hexdigest()[:16]}"


#: a phase's CasADi functions (:class:`walkerlab.optimal.transcription.phases.ModePhase`), in order
_PHASE_FNS = ("flow", "guard", "guard_rate", "reset", "keep", "clearance", "step", "grf",
              "push_off")


def _encode(fns: dict) -> str:
    """``fns`` (numbers, CasADi functions, a list of :class:`ModePhase`) as JSON."""
    def phase(p):
        return {"name": p.name, "guard_name": p.guard_name, "direction": p.direction,
                "inside": p.inside,
                **{f: (None if getattr(p, f) is None else getattr(p, f).serialize())
                   for f in _PHASE_FNS}}
    return json.dumps({k: (v if k in _NUMBERS else [phase(p) for p in v] if k == "phases"
                           else v.serialize()) for k, v in fns.items()})


def _decode(text: str) -> dict:
    """:func:`_encode`'s inverse (raises on a damaged text)."""
    import casadi as ca

    from walkerlab.optimal.transcription.phases import ModePhase  # light

    def phase(p):
        return ModePhase(p["name"], p["guard_name"], int(p["direction"]),
                         inside=bool(p.get("inside", True)),
                         **{f: (None if p[f] is None else ca.Function.deserialize(p[f]))
                            for f in _PHASE_FNS})
    return {k: (v if k in _NUMBERS else [phase(p) for p in v] if k == "phases"
                else ca.Function.deserialize(v)) for k, v in json.loads(text).items()}


def _cached(key: str, build) -> dict:
    """The functions of ``key`` through the one CasADi cache
    (:func:`walkerlab.codegen.casadi_functions.cached_functions`: memo, disk, or
    ``build()``)."""
    from walkerlab.codegen.casadi_functions import cached_functions

    return cached_functions(key, build, _encode, _decode)


def cached_mode_functions(data, walker, order=None) -> dict:
    """:func:`walkerlab.optimal.transcription.phases.mode_functions` of ``data`` (a WalkerData) in
    the
    phase order ``order`` (default: the rigid ``walker``'s), from this process's memo, the
    disk cache, or built (and written there).

    Returns
    -------
    dict
        As :func:`~walkerlab.optimal.transcription.phases.mode_functions`.

    Raises
    ------
    ValueError
        A walker or phase the transcription has no symbolic form for (one line; nothing
        cached).
    """
    from walkerlab.optimal.transcription import phases  # light

    order = [tuple(o) for o in (order if order is not None else phases.phase_order(walker))]
    return _cached(_key(data, "modes", order),
                   lambda: phases.mode_functions(data, walker, order))


def cached_step_functions(data) -> dict:
    """:func:`walkerlab.optimal.transcription.step.step_functions` of ``data`` (a WalkerData),
    from this process's memo, the disk cache, or derived and built (and written there).

    Returns
    -------
    dict
        As :func:`~walkerlab.optimal.transcription.step.step_functions`.

    Raises
    ------
    ValueError
        A walker the transcription does not handle (one line; nothing cached).
    """
    from walkerlab.optimal.transcription import step as collocation  # light

    def build():
        from walkerlab.codegen.cache import derive_equations  # sympy: only on a miss

        return collocation.step_functions(data, derive_equations(data.structure))
    return _cached(_key(data), build)
