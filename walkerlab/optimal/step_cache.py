"""The straight-legged walkers' collocation functions
(:func:`walkerlab.optimal.collocation.step_functions`) built once per walker and cached on
disk like the generated flows (:mod:`walkerlab.codegen.cache`), so a warm
``walkerlab optimize`` neither derives the walker symbolically (sympy, ~1-2 s) nor converts
it to CasADi.

The functions have the walker's parameter values substituted (as the collocation builds
them), so the cache file is keyed on the walker's structure (its generator's key) *and* its
numbers: ``<user cache>/models/<cache_key(structure)>-steps-<hash>.casadi``, ``hash`` over
the parameter vector, slope, gravity and total mass (their ``repr``, exact), the collocation
module's and this module's sources and CasADi's version.  A deserialised CasADi function is
the same expression graph, so a cached and a freshly built optimisation agree bit for bit.
The file follows the generated code's rules (private folder, sha256 header; a damaged or
untrusted file is rebuilt).
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

__all__ = ["cached_step_functions"]

_memo: dict[str, dict] = {}
#: the entries of :func:`step_functions` that are numbers, not CasADi functions
_NUMBERS = ("n", "limit", "total_mass_kg", "gravity")


def _key(data) -> str:
    """The cache key of ``data``'s step functions (module docstring)."""
    import casadi as ca

    from walkerlab.codegen.cache import cache_key
    from walkerlab.optimal import collocation

    h = hashlib.sha256(repr((tuple(float(v) for v in data.params), float(data.slope_rad),
                             float(data.gravity_m_per_s2),
                             float(data.total_mass_kg))).encode())
    for mod in (collocation.__file__, __file__):
        h.update(Path(mod).read_bytes())
    h.update(ca.__version__.encode())
    return f"{cache_key(data.structure)}-steps-{h.hexdigest()[:16]}"


def cached_step_functions(data) -> dict:
    """:func:`walkerlab.optimal.collocation.step_functions` of ``data`` (a WalkerData),
    from this process's memo, the disk cache, or derived and built (and written there).

    Returns
    -------
    dict
        As :func:`~walkerlab.optimal.collocation.step_functions`.

    Raises
    ------
    ValueError
        A walker the transcription does not handle (one line; nothing cached).
    """
    import casadi as ca

    from walkerlab.codegen.cache import cache_dir, read_source, write_source
    from walkerlab.optimal.collocation import step_functions

    key = _key(data)
    if key in _memo:
        return _memo[key]
    folder = cache_dir()
    path = folder / f"{key}.casadi" if folder is not None else None
    text = read_source(path) if path is not None else None
    fns = None
    if text is not None:
        try:
            stored = json.loads(text)
            fns = {k: (v if k in _NUMBERS else ca.Function.deserialize(v))
                   for k, v in stored.items()}
        except (RuntimeError, ValueError, TypeError, AttributeError):
            fns = None  # damaged: rebuilt below
    if fns is None:
        from walkerlab.codegen import symbolic  # sympy: only on a miss (~0.5 s to import)

        fns = step_functions(data, symbolic.derive(data.structure))
        if path is not None:
            write_source(path, json.dumps({k: (v if k in _NUMBERS else v.serialize())
                                           for k, v in fns.items()}))
    _memo[key] = fns
    return fns
