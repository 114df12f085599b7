"""Handles on a walker's compiled flows, built by the model layer and run by the integrators:
the passive flow (:class:`CompiledFlow`), a flow driven by joint-torque laws
(:class:`ActuatedFlow`), the closed loop under virtual constraints
(:class:`VirtualConstraintFlow`), and the numpy functions of a controller's outputs
(:class:`OutputPieces`).  Each holds a structure and its numbers and finds its generated
module through the loaders of :mod:`walkerlab.codegen` (:func:`~walkerlab.codegen.compiled.
compiled_module`, :func:`~walkerlab.codegen.actuated.actuated_module`,
:func:`~walkerlab.codegen.virtual_constraint_flow.closed_loop_module`), which print and
store the code; numba and CyRK are imported only when a cfunc's address is first asked for.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from walkerlab.codegen.actuated import actuated_module
from walkerlab.codegen.compiled import compiled_module
from walkerlab.codegen.virtual_constraint_flow import closed_loop_module

__all__ = ["ActuatedFlow", "CompiledFlow", "OutputPieces", "VirtualConstraintFlow"]


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
        ``"flow_<mode>"`` (:func:`walkerlab.codegen.compiled_source.generate_flat_compiled`).
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


#: constants of compiled flows by their numbers (:meth:`ActuatedFlow.constants`: one array
#: per value)
_CONSTANTS: dict = {}

#: most entries of :data:`_SHARED_ROWS` (cleared when full)
SHARED_ROWS_KEPT = 4096
#: :meth:`ActuatedFlow.data_rows`' flows (by their ids, in order) -> ``(the flows, their
#: shared constants or None)``: whether a batch of flows shares its constants, found once
_SHARED_ROWS: dict = {}


@dataclass(frozen=True, eq=False)
class ActuatedFlow(CompiledFlow):
    """Handle on an actuated walker's compiled flow (:class:`CompiledFlow` with laws).

    Attributes
    ----------
    joints : tuple of (str, str)
        Each actuator's (first, second) link (keys of the generated ``leg_angles``).
    laws : ndarray
        The law block (:func:`walkerlab.codegen.torque_law.pack_laws`).
    actuators : object
        Holds ``t_origin`` [s], the time the present step began (written into the law
        block by :meth:`data`).
    """

    joints: tuple = ()
    laws: np.ndarray | None = None
    actuators: object = None
    #: the batched step map runs the passive module's flows: not this one
    batchable = False

    def module(self):
        return actuated_module(self.structure, self.joints)

    def address(self, variational: bool = False) -> int:
        """C address of the cfunc ``(dy, t, y, d)`` (:meth:`CompiledFlow.address`), compiled
        or loaded on first use (the module's ``cfunc_of``)."""
        k = (self.name, variational)
        if k not in self._memo:
            name = f"{self.name}_variational" if variational else self.name
            self._memo[k] = self.module().cfunc_of(name).address
        return self._memo[k]

    def data(self) -> np.ndarray:
        """Constants, the law block (with the present step's start time) and a zeroed
        call counter."""
        key = ("blank", self.laws.size)  # (a flow replaced with other laws: its own)
        blank = self._memo.get(key)
        if blank is None:  # the constants and a zeroed counter, kept (data_into's numbers)
            blank = np.empty(self.data_size())
            self.data_into(blank)
            blank = self._memo[key] = (blank, blank.size - 1 - self.laws.size)
        out = blank[0].copy()
        nc = blank[1]
        out[nc:-1] = self.laws
        out[nc + 2] = float(getattr(self.actuators, "t_origin", 0.0))
        return out

    def data_size(self) -> int:
        """The length of :meth:`data`'s vector."""
        return self.constants().size + self.laws.size + 1

    def constants(self) -> np.ndarray:
        """The constants at the head of :meth:`data`'s vector (read only), one array for
        every flow with the same numbers (:data:`_CONSTANTS`: the walkers of a scene share
        it, so :meth:`data_rows` writes it once for all)."""
        c = self._memo.get("consts")
        if c is None:
            c = np.array(self.module().constants(self.params), dtype=float)
            c.flags.writeable = False
            c = self._memo["consts"] = _CONSTANTS.setdefault((c.size, c.tobytes()), c)
        return c

    def data_into(self, out: np.ndarray) -> None:
        """:meth:`data` written into ``out`` (:meth:`data_size`,) (a row of many walkers'
        data vectors: :mod:`walkerlab.gym.rigid_rows`), the same numbers."""
        c = self.constants()
        nc = c.size
        out[:nc] = c
        out[nc:-1] = self.laws
        out[nc + 2] = float(getattr(self.actuators, "t_origin", 0.0))
        out[-1] = 0.0

    @staticmethod
    def data_rows(flows, out: np.ndarray) -> None:
        """Each flow's :meth:`data` written into its row of ``out`` (N, size) (``flows``:
        N flows of one module and law block size, each row the numbers :meth:`data_into`
        writes), the rows' shared parts at once where the flows share their constants
        (:meth:`constants`), else row by row."""
        key = tuple(map(id, flows))
        shared = _SHARED_ROWS.get(key)
        if shared is None:  # (the flows kept with their answer: their ids stay theirs)
            if len(_SHARED_ROWS) >= SHARED_ROWS_KEPT:
                _SHARED_ROWS.clear()
            c = flows[0].constants()
            shared = _SHARED_ROWS[key] = (tuple(flows), None if any(
                f.constants() is not c for f in flows) else c)
        c = shared[1]
        if c is None:
            for f, row in zip(flows, out):
                f.data_into(row)
            return
        nc = c.size
        out[:, :nc] = c
        out[:, nc:-1] = [f.laws for f in flows]
        out[:, nc + 2] = [float(getattr(f.actuators, "t_origin", 0.0)) for f in flows]
        out[:, -1] = 0.0


@dataclass(frozen=True, eq=False)
class VirtualConstraintFlow(CompiledFlow):
    """Handle on a phase's compiled closed loop under virtual constraints (module
    docstring): a :class:`~walkerlab.models.compiled_flows.CompiledFlow` whose cfuncs live in
    :func:`closed_loop_module`'s module.  Its guards are the phase's Python functions
    (:attr:`CompiledFlow.guards` None: the integrator calls them at its step points).
    It runs where a solver asks the compiled backend (``backend: cyrk_compiled``); a
    scipy method (the shipped scenes' LSODA) keeps the Python flow.

    Attributes
    ----------
    law_module : module
        The controller's compiled module (its ``law`` and ``flow_terms``).
    numbers : ndarray
        The data vector without its call counter (module docstring).
    """

    law_module: object = None
    numbers: np.ndarray | None = None
    #: the batched step map runs the passive module's flows: not this one
    batchable = False

    @classmethod
    def of(cls, controller, structure, params):
        """The closed loop of ``controller`` (a :class:`walkerlab.models.virtual_constraints.
        VirtualConstraintController`) on the walker ``structure`` with ``params``, or None
        where its law is not compiled (no numba, a Bezier degree of 16 or more)."""
        mod = controller.compiled_module()
        if mod is None:
            return None
        d = controller.design
        alpha = np.asarray(d.alpha, float)
        limit = -1.0 if controller.limit is None else float(controller.limit)
        head = [d.theta_plus, d.theta_minus - d.theta_plus, controller.kp, controller.kd,
                limit, alpha.shape[1]]
        numbers = np.concatenate([np.asarray(head, float),
                                  np.asarray(controller.B, float).ravel(), alpha.ravel()])
        return cls(structure, tuple(params), law_module=mod, numbers=numbers)

    def module(self):
        return closed_loop_module(self.law_module)

    def address(self, variational: bool = False) -> int:
        """C address of the cfunc ``(dy, t, y, d)`` (:meth:`CompiledFlow.address`),
        compiled or loaded on first use."""
        if variational not in self._memo:
            name = "flow_variational" if variational else "flow"
            self._memo[variational] = self.module().cfunc_of(name).address
        return self._memo[variational]

    def data(self) -> np.ndarray:
        """The controller's numbers and a zeroed call counter (a fresh vector)."""
        return np.append(self.numbers, 0.0)


class OutputPieces:
    """Numpy functions of the outputs and the phase variable (module docstring), from the
    generated module (:func:`generate_pieces`, cached on disk as the walker's flow).

    Parameters
    ----------
    module : module
        The generated module.
    """

    def __init__(self, module):
        self._mod = module
        self.k, self.n = module.K, module.N

    def __call__(self, x):
        """``(h0 (k,), Jh0 (k, n), dd0 (k,), theta, dtheta (n,), ddtheta)`` at the state
        ``x`` (2n,) (see the module docstring)."""
        import numpy as np

        v = np.array(self._mod.out(x), dtype=complex if np.iscomplexobj(x) else float)
        k, n = self.k, self.n
        a = k + k * n
        return (v[:k], v[k:a].reshape(k, n), v[a:a + k], v[a + k], v[a + k + 1:a + k + 1 + n],
                v[-1])

    def foot(self, q):
        """``(swing foot height [m], swing foot ahead (> 0: ahead of the stance foot; an
        angle or a distance, as the walker's guard), hip along the ground [m])`` at the
        configuration ``q`` (n,)."""
        import numpy as np

        return tuple(float(np.real(v))
                     for v in self._mod.foot(np.concatenate([q, np.zeros(self.n)])))

    def B(self):
        """``B`` (n, k): each actuated joint's column ``d(delta)/dq`` (constant)."""
        import numpy as np

        return np.array(self._mod.B(np.zeros(2 * self.n)), dtype=float).reshape(self.n, self.k)
