"""Compiled right-hand sides of a walker's flow: numba ``cfunc``s for CyRK's C++ integrators.

The source comes from :func:`walkerlab.codegen.source.generate_compiled` (the same symbolic
equations as the Python module of :mod:`walkerlab.codegen.cache`) and is cached next to it as
``<key>_nb.py`` in the per-user cache (same key, same ownership/mode and sha256 checks,
atomic write); the per-row integrator's loops specialised to its flows
(:func:`rows_kernels`) in ``<key>_rows_<rows hash>_nb.py``.  Each is imported as a real
module so that numba's own disk cache (``cache=True``, in ``<user cache>/numba``,
:func:`walkerlab.usercache.use_for_numba`) keeps the machine code: a new process pays the
numba import and a cache load, not a compile.

numba and CyRK are imported only when :meth:`CompiledFlow.address` is first called (the
``cyrk_compiled`` solver backend); building a walker does not import them.
"""

from __future__ import annotations

import functools
import hashlib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from walkerlab.codegen import cache


def compiled_module(structure):
    """The imported compiled module of ``structure`` (generated on a cache miss).

    Raises
    ------
    ImportError
        numba is not installed.
    """
    key = cache.cache_key(structure)

    def build() -> str:
        if structure.foot == "flat":  # a flat foot's modes: their own generator
            from walkerlab.codegen import foot_modes as flatfoot

            return flatfoot.generate_flat_compiled(structure, key)
        from walkerlab.codegen import source as codegen

        return codegen.generate_compiled(cache.derive_equations(structure),
                                         structure.param_names, key)

    return cache.import_generated(f"{key}_nb.py", f"walkerlab_compiled_{key}", build)


@functools.cache
def rows_hash() -> str:
    """sha256 (12 hex digits) of :mod:`walkerlab.integrate.rows_dop853`'s source (once per
    process): :func:`rows_kernels` compile that loop into their own machine code, which
    numba's cache keeps against the kernels' file alone, so the file's name carries it (a
    changed loop: a new file, compiled afresh)."""
    path = Path(__file__).parents[1] / "integrate" / "rows_dop853.py"
    return hashlib.sha256(path.read_bytes()).hexdigest()[:12]


#: the loops of :mod:`walkerlab.integrate.rows_dop853` specialised, and the functions they
#: take first (the rest of their arguments are passed on as they are)
_LOOPS = {"walk_rows": ("f", "fs", "fg", "sel", "reset"),
          "phase_rows": ("f", "fs", "fg", "sel")}


def kernels_source(module_name: str, flows) -> str:
    """Source of the kernels module of the compiled module ``module_name`` (imported) with
    the flows ``flows``: for each flow ``k`` and each loop of :data:`_LOOPS`, ``<loop>_<k>``,
    an ``@njit(cache=True)`` entry point calling that loop of
    :mod:`walkerlab.integrate.rows_dop853` with the module's ``_<k>_full``, ``_<k>_plain``,
    ``_guard_one`` and ``_reset_flow`` made ``@njit`` functions on arrays, its other
    arguments named as the loop names them (read from its signature)."""
    import inspect

    from walkerlab.integrate import rows_dop853 as rows

    out = [f"# walkerlab per-row kernels of {module_name} (walkerlab.codegen.compiled); "
           f"rows_dop853 {rows_hash()}",
           "# Do not edit: regenerated when the model or walkerlab/integrate/rows_dop853.py "
           "changes.",
           "import sys", "", "from numba import njit", "",
           "from walkerlab.integrate import rows_dop853 as _rows", "",
           f"_m = sys.modules[{module_name!r}]",
           "_NJ = njit(error_model='numpy')",
           "_guard_one = _NJ(_m._guard_one)", "_reset_flow = _NJ(_m._reset_flow)"]
    for k in flows:
        out += [f"_{k}_full = _NJ(_m._{k}_full)", f"_{k}_plain = _NJ(_m._{k}_plain)"]
    for k in flows:
        fns = (f"_{k}_full", f"_{k}_plain", "_guard_one", "True", "_reset_flow")
        for loop, first in _LOOPS.items():
            params = list(inspect.signature(getattr(rows, loop).py_func).parameters)
            if tuple(params[:len(first)]) != first:  # pragma: no cover - a changed loop
                raise RuntimeError(f"rows_dop853.{loop}{tuple(params)}: not {first} first")
            args = ", ".join(params[len(first):])
            out += ["", "", "@njit(cache=True, error_model='numpy')",
                    f"def {loop}_{k}({args}):  # pragma: no cover - runs compiled",
                    f"    _rows.{loop}({', '.join(fns[:len(first)])}, {args})"]
    return "\n".join(out) + "\n"


def rows_kernels(structure, name: str) -> tuple | None:
    """``(walk_rows, phase_rows)`` of :mod:`walkerlab.integrate.rows_dop853` specialised to
    the flow ``name`` of ``structure``'s compiled module, or None for a module without the
    plain functions they need (a flat foot's): :func:`kernels_source`'s entry points, their
    arguments those of the loops after the functions, the same numbers bit for bit (the
    flow inlined into the loop).  The kernels module is generated and imported once
    (``<key>_rows_<rows_hash()>_nb.py`` beside the compiled module, the same checks) and
    compiled on first call or loaded from numba's cache (``cache=True``: its file)."""
    mod = compiled_module(structure)
    flows = getattr(mod, "FLOWS", ())
    if name not in flows:
        return None
    key = cache.cache_key(structure)
    kern = cache.import_generated(f"{key}_rows_{rows_hash()}_nb.py",
                                  f"walkerlab_rows_{key}_{rows_hash()}",
                                  lambda: kernels_source(mod.__name__, flows))
    return tuple(getattr(kern, f"{loop}_{name}") for loop in _LOOPS)


@dataclass(frozen=True, eq=False)
class CompiledFlow:
    """Handle on the compiled flow of one phase (built by the model layer, compiled lazily).

    Attributes
    ----------
    structure : Structure
        Walker structure (the cache key).
    params : tuple of float
        Parameter vector (``structure.param_names`` order).
    name : str
        ``"flow"`` or ``"flow_locked"`` (kneed walker, knee locked); a flat foot's
        ``"flow_<mode>"`` (:func:`walkerlab.codegen.foot_modes.generate_flat_compiled`).
    guards : tuple of (str, float), optional
        For each guard of the phase, in order: the generated guard it is and a constant added
        to it (``Guard.function = guard_<name> + offset``); the guards are then evaluated in
        the cfunc (extra outputs).  None: the integrator calls the Python guards.
    first_chunk_steps : int
        Steps of the first chunk the ``cyrk_compiled`` backend integrates before it looks
        at the guards (:mod:`walkerlab.integrate._compiled`; the chunks then double): the
        steps after a crossing in a chunk are wasted, so a phase that often ends within a
        few steps wants a short first chunk (a flat foot's modes: 8).
    chunk_rtol : float, optional
        The tolerance ``first_chunk_steps`` was measured at: the chunk then scales with the
        solver's ``rtol`` as a phase's step count does
        (:func:`walkerlab.integrate._compiled.first_chunk`); None: the same at every rtol.
    """

    structure: object
    params: tuple
    name: str = "flow"
    guards: tuple | None = None
    first_chunk_steps: int = 24
    chunk_rtol: float | None = None
    _memo: dict = field(default_factory=dict, repr=False, compare=False)
    #: the batched step map may run this flow (its module's ``flow`` cfuncs and reset)
    batchable = True

    def module(self):
        """The imported compiled module this flow's cfuncs live in."""
        return compiled_module(self.structure)

    def address(self, variational: bool = False) -> int:
        """C address of the cfunc ``(dy, t, y, d)``: the flow (2n outputs) or, with
        ``variational``, the flow and ``A(x) Phi`` (``2n + (2n)^2`` outputs, ``Phi``
        row-major in ``y[2n:]``)."""
        k = (self.name, variational)
        if k not in self._memo:
            mod = self.module()
            fn = getattr(mod, f"{self.name}_variational" if variational else self.name)
            self._memo[k] = fn.address
        return self._memo[k]

    def data(self) -> np.ndarray:
        """A fresh data vector (constants, then a zeroed call counter as the last entry)."""
        if "data" not in self._memo:
            self._memo["data"] = self.module().constants(self.params)
        return self._memo["data"].copy()

    def guard_columns(self) -> tuple[int, np.ndarray, np.ndarray] | None:
        """``(n_extra, columns, offsets)``: how many extra outputs the cfuncs write and, for
        each guard of the phase, its column among them and its offset; None without
        :attr:`guards`."""
        if self.guards is None:
            return None
        if "guards" not in self._memo:
            names = self.module().GUARDS
            self._memo["guards"] = (len(names), np.array([names.index(g) for g, _ in self.guards]),
                                    np.array([float(o) for _, o in self.guards]))
        return self._memo["guards"]
