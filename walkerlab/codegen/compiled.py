"""Compiled right-hand sides of a walker's flow: numba ``cfunc``s for CyRK's C++ integrators.

The source comes from :func:`walkerlab.codegen.compiled_source.generate_compiled` (the same symbolic
equations as the Python module of :mod:`walkerlab.codegen.cache`) and is cached next to it as
``<key>_nb.py`` in the per-user cache (same key, same ownership/mode and sha256 checks,
atomic write); the per-row integrator's loops specialised to its flows
(:func:`walkerlab.integrate.rows_dop853.kernels`) in ``<key>_rows_<hash>_nb.py``.  Each is
imported as a real module so that numba's own disk cache (``cache=True``, in ``<user
cache>/numba``, :func:`walkerlab.usercache.use_for_numba`) keeps the machine code: a new
process pays the numba import and a cache load, not a compile.

numba and CyRK are imported only when :meth:`CompiledFlow.address` is first called (the
``cyrk_compiled`` solver backend); building a walker does not import them.
"""

from __future__ import annotations

from dataclasses import dataclass, field

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
            from walkerlab.codegen import foot_modes as flatfoot  # light

            return flatfoot.generate_flat_compiled(structure, key)
        from walkerlab.codegen.compiled_source import generate_compiled  # light

        return generate_compiled(cache.derive_equations(structure),
                                         structure.param_names, key)

    return cache.import_generated(f"{key}_nb.py", f"walkerlab_compiled_{key}", build)


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
    by_default : bool
        The ``auto`` solver backend runs this compiled flow, not the Python one
        (``cyrk_compiled`` instead of ``cyrk``): set by the model for a walker whose printed
        Python flow is slow to call (a 3D walker's: about 100 us a call for
        ``configs/hip_width_stabilised.yaml``'s, against 4 us for the compass gait's), so
        that its gait search is not spent in Python callbacks; its variational equations
        (a few integrations a run: the multipliers) stay in Python, as numba would take
        longer to compile them than Python to run them.  The result moves by the
        integrators' round-off only (the same Runge-Kutta pair and step control).
    """

    structure: object
    params: tuple
    name: str = "flow"
    guards: tuple | None = None
    first_chunk_steps: int = 24
    chunk_rtol: float | None = None
    by_default: bool = False
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
