"""The walker's symbolic equations printed to CasADi, and the CasADi functions' disk cache.

One printer (:func:`casadi_matrix`, :func:`casadi_function`) turns the sympy expressions
of :mod:`walkerlab.codegen.legged`, :mod:`walkerlab.codegen.foot_modes` and
:mod:`walkerlab.codegen.legged` (the derivation the generated numeric code is printed
from) into CasADi SX expressions, for every transcription of ``walkerlab optimize``.  One
cache (:func:`cached_functions`) stores the CasADi functions built from them as
``<user cache>/models/<key>.casadi`` through :mod:`walkerlab.codegen.cache` (its private
folder and sha256 header: a damaged or untrusted file is rebuilt), so a warm run neither
derives the walker (sympy) nor prints it again; a deserialised CasADi function is the same
expression graph, so a cached and a freshly built optimisation agree bit for bit.
"""

from __future__ import annotations

import json

from walkerlab import codestore

__all__ = ["cached_functions", "casadi_function", "casadi_matrix"]

#: the functions the printed expressions call (sympy name -> CasADi's), filled on first use
_FUNCTIONS: dict = {}
_memo: dict[str, dict] = {}


def _modules():
    import casadi as ca

    if not _FUNCTIONS:
        _FUNCTIONS.update({"sin": ca.sin, "cos": ca.cos, "sqrt": ca.sqrt, "atan": ca.atan,
                           "acos": ca.acos, "Abs": ca.fabs, "ImmutableDenseMatrix": list,
                           "MutableDenseMatrix": list})
    return [_FUNCTIONS, "math"]


def casadi_matrix(exprs, syms, args, values: dict | None = None):
    """The sympy matrix ``exprs`` as a CasADi SX matrix.

    Parameters
    ----------
    exprs : sympy Matrix or nested list (r, c) of sympy expressions
    syms : list of sympy.Symbol
        The symbols the expressions are functions of.
    args : list of casadi.SX
        Scalar SX expressions replacing ``syms`` (same length).
    values : dict, optional
        Symbols substituted by numbers first (a walker's parameters).

    Returns
    -------
    casadi.SX (r, c)
    """
    import casadi as ca
    import sympy as sp

    mat = sp.Matrix(exprs)
    if values is not None:
        mat = mat.subs(values)
    rows = sp.lambdify(syms, mat, modules=_modules())(*args)
    return ca.vertcat(*[ca.horzcat(*[v if isinstance(v, ca.SX) else ca.SX(float(v))
                                     for v in r]) for r in rows])


def casadi_function(exprs, syms, values: dict | None = None):
    """A CasADi function of the stacked ``syms`` (one SX input (len(syms),)) computing the
    sympy matrix ``exprs`` with ``values`` substituted (:func:`casadi_matrix`).

    Returns
    -------
    casadi.Function
        ``z (len(syms),) -> (r, c)``.
    """
    import casadi as ca

    args = [ca.SX.sym(str(s)) for s in syms]
    return ca.Function("f", [ca.vertcat(*args)], [casadi_matrix(exprs, syms, args, values)])


def cached_functions(key: str, build, encode=None, decode=None) -> dict:
    """The CasADi functions named ``key`` from this process's memo, the disk cache
    (``<user cache>/models/<key>.casadi``; a damaged file rebuilt) or ``build()`` (and
    written there).

    Parameters
    ----------
    key : str
        The file's stem: the walker's structure key (:func:`walkerlab.codegen.cache.
        cache_key`) and a hash of whatever else the functions depend on.
    build : callable
        ``() -> dict`` of the functions (and numbers).
    encode, decode : callable, optional
        ``dict -> str`` and back (default: a dict of ``casadi.Function`` by name, each
        serialised, in JSON).

    Returns
    -------
    dict
    """
    if key in _memo:
        return _memo[key]
    encode = encode or _encode
    decode = decode or _decode
    folder = codestore.cache_dir()
    path = folder / f"{key}.casadi" if folder is not None else None
    text = codestore.read_source(path) if path is not None else None
    fns = None
    if text is not None:
        try:
            fns = decode(text)
        except (RuntimeError, ValueError, TypeError, AttributeError, KeyError):
            fns = None  # damaged: rebuilt below
    if fns is None:
        fns = build()
        if path is not None:
            codestore.write_source(path, encode(fns))
    _memo[key] = fns
    return fns


def clear_memo() -> None:
    """Forget the functions built or read in this process (the disk cache stays)."""
    _memo.clear()


def _encode(fns: dict) -> str:
    return json.dumps({k: f.serialize() for k, f in fns.items()})


def _decode(text: str) -> dict:
    import casadi as ca

    return {k: ca.Function.deserialize(v) for k, v in json.loads(text).items()}
