"""The Poincaré (step-to-step) map of a rigid walker for many states at once, each state on its
own slope: the workhorse of the metastability studies (:mod:`walkerlab.analysis.robustness.mfpt`).

One step of ``N`` walkers: each row is integrated on its own, phase after phase, by a
compiled DOP853 calling the walker's compiled flow (the numba ``cfunc`` of
:class:`walkerlab.models.compiled_flows.CompiledFlow`, the same generated equations as every other
rigid integration; where the generated module allows it, that loop compiled with the flow
inlined, :func:`walkerlab.integrate.rows_dop853.kernels`, the same numbers) to its first
guard crossing, located on the step's dense output
(:func:`walkerlab.integrate.rows_dop853.phase_rows`: one compiled call per phase for all
rows, so a row's numbers do not depend on the other rows of its batch); heel strikes are
reset by the generated module's compiled reset (``reset_rows``) when it is the walker's own
(checked bit for bit on a probe), else row by row.  The phases of a step (early/late swing,
unlocked/locked knee) are run one after the other, each from the phase-local time 0 (the
flows are autonomous), a row starting each phase with the step size it would have taken
next.  A footfall drop (``drop_m``, the robustness study's step-down) keeps the stacked
system: all its rows integrated as one system by scipy's DOP853 (``scipy.integrate.DOP853``,
stepped one step at a time), its right-hand side the walker's compiled flow for every row
in one compiled loop (:func:`walkerlab.integrate.batch_rows.kernel`); guards are the
cfunc's extra outputs; after each integrator step the rows whose guard changed sign in its
direction (``solve_ivp``'s rule) are located on the step's dense output by
``scipy.optimize.elementwise.find_root`` (Chandrupatla's method, vectorised) and leave the
stacked system.

Per-step slope (a walker on rough terrain, Byl & Tedrake 2009): each row has its own slope
``gamma``: the parameter vector of the compiled functions (``Structure.param_names``) with
``gamma`` replaced, so the heel-strike guard of a compass walker becomes
``theta_swing + theta_stance = -2 gamma_n`` (the ground of step ``n`` is the line through the
stance foot at slope ``gamma_n``); the model generator is untouched.

Accuracy: a row's error estimate (the 2-norm over its 2n components of the scaled error)
stays below 1 at the requested tolerances, as if it were integrated alone; the stacked
system divides them by ``sqrt(N 2n)`` (scipy's error norm is the RMS over all components).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from walkerlab.integrate.batch_rows import StackedRows, dense_rows

#: How a step of one row ended (``outcome`` codes are indices into this tuple).
STEP_OUTCOMES = ("heel_strike", "fall", "timeout", "solver_failure")
HEEL_STRIKE, FALL, TIMEOUT, SOLVER_FAILURE = range(4)
#: a guard that leads to the next phase of the step (its reset applied)
NEXT_PHASE = 9
#: a guard's ``outcome`` -> how its row's phase ends
GUARD_OUTCOME = {"heel_strike": HEEL_STRIKE, "fall": FALL, "next_phase": NEXT_PHASE}

@dataclass
class BatchStep:
    """One step of ``N`` rows.

    Attributes
    ----------
    outcome : ndarray of int8, shape (N,)
        Index into :data:`STEP_OUTCOMES`.
    x_pre : ndarray, shape (N, 2n)
        State at the step's end (just before heel strike; at the fall guard for a fall;
        NaN for a timeout or solver failure).
    x_next : ndarray, shape (N, 2n)
        State just after heel strike (role-ordered, the next step's start); NaN otherwise.
    step_time_s : ndarray, shape (N,)
        Duration of the step [s] (NaN for a timeout or failure).
    """

    outcome: np.ndarray
    x_pre: np.ndarray
    x_next: np.ndarray
    step_time_s: np.ndarray


def step_rows(X, gamma, slope_rad: float) -> tuple[np.ndarray, np.ndarray]:
    """A step map's input as rows: the states ``X`` (2n,) or (N, 2n) as (N, 2n) and each
    row's slope (N,) [rad] from ``gamma`` (an array, a float, or None: ``slope_rad``)."""
    X = np.atleast_2d(np.asarray(X, dtype=float))
    return X, np.broadcast_to(slope_rad if gamma is None else np.asarray(gamma, dtype=float),
                              (X.shape[0],)).copy()


def walker_on_slope(step_map, gamma: float):
    """The walker of a step map (its ``walker``, ``walker_at``, ``slope_rad`` and a dict
    ``_walkers``) on the slope ``gamma`` [rad]: its own walker on its slope, else one built
    by ``walker_at(gamma)`` and kept (at most 4096 slopes; then the cache starts again)."""
    if gamma == step_map.slope_rad:
        return step_map.walker
    w = step_map._walkers.get(gamma)
    if w is None:
        if len(step_map._walkers) > 4096:
            step_map._walkers.clear()
        w = step_map._walkers[gamma] = step_map.walker_at(gamma)
    return w


class BatchStepMap:
    """The step map ``x_{k+1} = P(x_k; gamma_k)`` of a rigid walker, for many rows at once.

    Parameters
    ----------
    walker : HybridWalker
        Built from generated code (every phase has a compiled flow).
    walker_at : callable ``gamma [rad] -> HybridWalker``
        The same walker on another slope (its reset maps, where they depend on the slope).
    rtol, atol : float
        Per-walker tolerances of DOP853 (see the module docstring).
    max_step_time_s : float
        A step longer than this ends as ``timeout`` (a fall: no heel strike) [s].
    specialised : bool
        Run the per-row loops specialised to the walker's flow where its compiled module
        allows them (:func:`walkerlab.integrate.rows_dop853.kernels`: the flow inlined into
        the loop); False: the loops calling the flow's cfuncs.  The same numbers either way.

    Raises
    ------
    ValueError
        A phase without a compiled flow (e.g. ``ideal.variant: appendix_a``), or a walker
        whose state coordinates depend on the slope (``coordinates: slope_relative``): a
        state could not be carried from one step's slope to the next.
    """

    def __init__(self, walker, walker_at, rtol: float = 1e-9, atol: float = 1e-9,
                 max_step_time_s: float = 5.0, specialised: bool = True):
        from walkerlab.codegen.compiled import compiled_module

        self.walker, self.walker_at = walker, walker_at
        self.specialised = specialised
        self.rtol, self.atol, self.max_step_time_s = rtol, atol, max_step_time_s
        self.n = walker.layout().size
        self.phases = []
        for ph in walker.phases:
            cf = ph.compiled
            if cf is None or cf.guard_columns() is None:
                raise ValueError(f"{walker.name} ({walker.variant}): phase {ph.name!r} has no "
                                 "compiled flow; per-step terrain needs the generated model "
                                 "(ideal.variant: derived)")
            mod = compiled_module(cf.structure)
            n_extra, cols, offs = cf.guard_columns()
            self.phases.append((ph, getattr(mod, cf.name), n_extra, cols, offs,
                                np.array([g.direction for g in ph.guards])))
        # the compiled per-row integrator's arguments, one dtype each (one specialisation)
        self._gcols = [np.ascontiguousarray(p[3], dtype=np.int64) for p in self.phases]
        self._goffs = [np.ascontiguousarray(p[4], dtype=float) for p in self.phases]
        self._dirs = [np.ascontiguousarray(p[5], dtype=np.int64) for p in self.phases]
        # a step-down (or up) of the ground at the footfall: the last phase's heel strike
        # becomes the swing foot's clearance above the slope line reaching -drop
        lastc = walker.phases[-1].compiled
        names = compiled_module(lastc.structure).GUARDS
        self._hs = [j for j, g in enumerate(walker.phases[-1].guards)
                    if g.outcome == "heel_strike"]
        self._clear = names.index("swing_clearance") if "swing_clearance" in names else None
        first = walker.phases[0].compiled
        self._constants_rows = compiled_module(first.structure).constants_rows
        self._params = np.array(first.params, dtype=float)
        self._ig = list(first.structure.param_names).index("gamma")
        self.slope_rad = float(walker.slope_rad)
        self._resets_depend_on_slope = self._probe_slope_dependence()
        self._reset_flow = self._probe_compiled_reset(compiled_module(lastc.structure))
        # per phase: the heel-strike guard's index (-1: none) and whether it is the swing
        # foot's clearance above the slope line (a per-row landing height is then an offset)
        self._hs_phase = [next((j for j, g in enumerate(p[0].guards)
                                if g.outcome == "heel_strike"), -1) for p in self.phases]
        self.clearance_guard = all(
            h < 0 or p[0].compiled.guards[h][0] in ("swing_clearance",) or (
                p[0].compiled.guards[h][0] == "heel_strike" and "swing_clearance" not in
                compiled_module(p[0].compiled.structure).GUARDS)
            for p, h in zip(self.phases, self._hs_phase))
        #: rows integrated by the compiled per-row integrator (phases), for the record
        self.integrated = 0
        self._walkers: dict[float, object] = {}
        self._fns: dict = {}  # the per-row integrator's cfuncs (by phase) and kernels

    # -- slope handling -------------------------------------------------------------------
    def _probe_slope_dependence(self) -> bool:
        """Check the state coordinates are slope-independent; return whether the reset maps
        are (probe: a generic state on two slopes)."""
        w2 = self.walker_at(self.slope_rad + 0.01)
        probe = np.linspace(0.11, 0.37, self.n) * np.array([1, -1] * (self.n // 2))
        a = self.walker.leg_coordinates(probe, self.walker.legs[-1])
        b = w2.leg_coordinates(probe, w2.legs[-1])
        if any(not np.allclose(a[k], b[k], rtol=0, atol=1e-14) for k in a):
            raise ValueError("terrain.per_step: the walker's state coordinates are measured "
                             "from the slope (walker.coordinates: slope_relative); per-step "
                             "slopes need absolute coordinates")
        same = np.array_equal(np.asarray(self.walker.reset(probe)), np.asarray(w2.reset(probe)))
        for p1, p2 in zip(self.walker.phases, w2.phases):
            for g1, g2 in zip(p1.guards, p2.guards):
                if g1.reset is not None:
                    same &= np.array_equal(np.asarray(g1.reset(probe)), np.asarray(g2.reset(probe)))
        return not same

    def _probe_compiled_reset(self, mod):
        """The generated module's compiled heel-strike reset if it gives the walker's own
        reset bit for bit on a probe state on two slopes (a walker built with another reset,
        e.g. an impulse at push-off, keeps its own), else None."""
        from walkerlab.integrate.rows_dop853 import reset_rows  # light

        make = getattr(mod, "reset_flow", None)
        if make is None:  # pragma: no cover - a module generated before reset_flow
            return None
        fn = make()
        probe = np.linspace(0.11, 0.37, self.n) * np.array([1, -1] * (self.n // 2))
        for g in (self.slope_rad, self.slope_rad + 0.01):
            out = np.empty((1, self.n))
            reset_rows(fn, probe[None], self.data(np.array([g])), out)
            w = self.walker if g == self.slope_rad else self.walker_at(g)
            if not np.array_equal(out[0], np.asarray(w.reset(probe), dtype=float)):
                return None
        return fn

    @property
    def can_walk(self) -> bool:
        """Whether :meth:`walk` runs whole walks compiled: one compiled flow for every phase
        of a step, no reset between phases, and the compiled heel-strike reset."""
        cf = {id(p[1]) for p in self.phases}
        no_mid_reset = all(g.reset is None for p in self.phases for g in p[0].guards
                           if g.outcome == "next_phase")
        return len(cf) == 1 and no_mid_reset and self._reset_flow is not None

    def walk(self, X: np.ndarray, gamma: np.ndarray, height_m: np.ndarray | None = None):
        """Walk every row up to ``gamma.shape[1]`` steps, step ``s`` of row ``w`` on the
        slope ``gamma[w, s]`` [rad], until it falls (any step that does not end in heel
        strike), all in compiled code (:func:`walkerlab.integrate.rows_dop853.walk_rows`;
        the same numbers as :meth:`step` step after step).

        Parameters
        ----------
        X : ndarray, shape (W, 2n)
            Post-impact states [rad, rad/s].
        gamma : ndarray, shape (W, S)
            Slopes [rad].
        height_m : ndarray, shape (W, S), optional
            Landing heights [m] above the slope line through the stance foot (as
            :meth:`step`'s).

        Returns
        -------
        steps : ndarray of int, shape (W,)
            Heel strikes of each row.
        fell : ndarray of bool, shape (W,)
        X_end : ndarray, shape (W, 2n)
            Each row's last post-impact state.

        Raises
        ------
        ValueError
            A walker :attr:`can_walk` says no to.
        """
        from walkerlab.integrate.rows_dop853 import walk_rows  # light

        if not self.can_walk:
            raise ValueError(f"{self.walker.name}: compiled walks need one compiled flow for "
                             "every phase, no intra-step reset and the compiled reset")
        X = np.array(X, dtype=float, order="C", ndmin=2)
        W, S = gamma.shape
        P = np.tile(self._params, (W * S, 1))
        P[:, self._ig] = np.asarray(gamma, dtype=float).ravel()
        D = self._constants_rows(P).reshape(W, S, -1)  # (as data(): one row per slope)
        g = self._guard_table()
        steps = np.zeros(W, np.int64)
        fell = np.zeros(W, np.bool_)
        hoff = (np.zeros((1, 1)) if height_m is None else
                self._height_offsets(height_m, gamma).reshape(W, S))
        args = (X, D, S, float(self.max_step_time_s), *g, float(self.rtol), float(self.atol),
                self.n + self.phases[0][2], steps, fell, height_m is not None, hoff)
        kern = self._kernels(0)
        if kern is not None:  # (its reset: the module's, as self._reset_flow is)
            kern[0](*args)
        else:
            walk_rows(*self._cfuncs(0), self._reset_flow, *args)
        return steps, fell, X

    def _height_offsets(self, height_m, gamma) -> np.ndarray:
        """The heel-strike guard's offsets ``-h cos(gamma)`` [m] of landings ``h`` [m] above
        the slope line (the clearance's normal distance, :func:`walkerlab.models.hybrid.
        ground.on_landing`), C-contiguous float.

        Raises
        ------
        ValueError
            A walker whose heel-strike guard is not the swing foot's clearance (one line).
        """
        if not self.clearance_guard:
            raise ValueError(f"{self.walker.name}: per-step heights need the heel strike as "
                             "the swing foot's clearance (ground.with_clearance_guard)")
        h = np.asarray(height_m, dtype=float)
        return np.ascontiguousarray(-h * np.cos(np.broadcast_to(gamma, h.shape)))

    def _cfuncs(self, k: int) -> tuple:
        """Phase ``k``'s cfuncs for the per-row integrator
        (:func:`walkerlab.integrate.rows_dop853.cfuncs`; made on first use)."""
        from walkerlab.codegen.compiled import compiled_module
        from walkerlab.integrate.rows_dop853 import cfuncs  # light

        if k not in self._fns:
            ph = self.phases[k]
            cf = ph[0].compiled
            self._fns[k] = cfuncs(compiled_module(cf.structure), cf.name, ph[1])
        return self._fns[k]

    def _kernels(self, k: int):
        """Phase ``k``'s loops specialised to its flow
        (:func:`walkerlab.integrate.rows_dop853.kernels`), or None (not :attr:`specialised`,
        or a module without them)."""
        if not self.specialised:
            return None
        from walkerlab.integrate.rows_dop853 import kernels  # light

        key = ("kernels", k)
        if key not in self._fns:
            cf = self.phases[k][0].compiled
            self._fns[key] = kernels(cf.structure, cf.name)
        return self._fns[key]

    def _guard_table(self):
        """``(gstart, gcols, goffs, dirs, gout)``: every phase's guards in flat arrays."""
        if not hasattr(self, "_gtab"):
            sizes = [len(p[0].guards) for p in self.phases]
            gout = [GUARD_OUTCOME[gd.outcome] for p in self.phases for gd in p[0].guards]
            self._gtab = (np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64),
                          np.concatenate(self._gcols), np.concatenate(self._goffs),
                          np.concatenate(self._dirs), np.array(gout, dtype=np.int64))
        return self._gtab

    def _walker(self, gamma: float):
        if not self._resets_depend_on_slope:
            return self.walker
        return walker_on_slope(self, gamma)

    def data(self, gamma: np.ndarray) -> np.ndarray:
        """Data vectors (N, c) of the compiled functions, one per slope [rad]."""
        uniq, inv = np.unique(np.asarray(gamma, dtype=float), return_inverse=True)
        P = np.tile(self._params, (uniq.size, 1))
        P[:, self._ig] = uniq
        return np.ascontiguousarray(self._constants_rows(P)[inv.ravel()])

    # -- the map --------------------------------------------------------------------------
    def step(self, X: np.ndarray, gamma: np.ndarray | float | None = None,
             drop_m: np.ndarray | float | None = None,
             height_m: np.ndarray | float | None = None) -> BatchStep:
        """One step of every row.

        Parameters
        ----------
        X : ndarray, shape (N, 2n)
            Role-ordered states just after a heel strike.
        gamma : ndarray (N,) or float, optional
            Slope of this step [rad] for each row; default the walker's slope.
        drop_m : ndarray (N,) or float, optional
            The ground at this step's footfall lies ``drop_m`` [m] below the slope line
            through the stance foot (a step-down; negative: a step-up), measured as the
            model's swing-foot clearance above that line: the heel strike is the clearance
            reaching ``-drop_m`` after the foot has risen above both ground levels (rows
            with ``drop_m = 0`` keep the ordinary heel-strike guard).
        height_m : ndarray (N,) or float, optional
            Landing height [m] of this step above the slope line through the stance foot
            (rough ground, ``terrain.per_step.height_sd_m``): the heel strike is the swing
            foot's clearance reaching ``height_m cos(gamma)``, armed as the walker's own
            guard (its late swing), integrated by the compiled per-row integrator (the
            guard's offset per row).  Needs a walker whose heel strike is the clearance
            (:func:`walkerlab.models.hybrid.ground.with_clearance_guard`).

        Raises
        ------
        ValueError
            ``drop_m`` for a walker whose generated model has no swing-foot clearance;
            ``height_m`` with ``drop_m`` or for a walker whose heel strike is not the
            clearance.

        Returns
        -------
        BatchStep
        """
        X, gamma = step_rows(X, gamma, self.slope_rad)
        N, m = X.shape
        D = self.data(gamma)
        nc = D.shape[1]
        self._hoff = None
        if height_m is not None:
            if drop_m is not None:
                raise ValueError("BatchStepMap.step: a drop_m or a height_m, not both")
            self._hoff = self._height_offsets(
                np.broadcast_to(np.asarray(height_m, dtype=float), (N,)), gamma)
        if drop_m is not None:
            if self._clear is None:
                raise ValueError(f"{self.walker.name}: no swing-foot clearance in the model; "
                                 "a step-down cannot be located")
            drop = np.broadcast_to(np.asarray(drop_m, dtype=float), (N,))
            D = np.hstack([D, drop[:, None]])
        out = BatchStep(np.full(N, TIMEOUT, np.int8), np.full((N, m), np.nan),
                        np.full((N, m), np.nan), np.full(N, np.nan))
        rows, Y, T = np.arange(N), X.copy(), np.zeros(N)
        self._h_rows = np.zeros(N)  # step size carried from phase to phase [s]
        for k, phase in enumerate(self.phases):
            if rows.size == 0:
                break
            rows, Y, T = self._phase(k, phase, rows, Y, T, D, nc, gamma, out)
        return out

    def _phase(self, k, phase, rows, Y, T, D, nc, gamma, out):
        """Integrate rows through phase ``k``; returns the rows that go on to phase k + 1
        (their entry states and times).  ``D[:, :nc]`` are the data vectors; a column
        after them is the per-row drop of the footfall [m] (last phase only)."""
        ph, cfunc, n_extra, gcols, goffs, dirs = phase
        # a step-down/up (rows with a nonzero drop, last phase): the heel strike is the
        # swing foot's clearance reaching -drop, armed once the foot has risen above both
        # ground levels (just after mid-stance a point foot is below the slope line: the
        # scuffing the ideal model ignores, which must not count as the landing)
        drop = D.shape[1] > nc and k == len(self.phases) - 1
        hs = self._hs[0] if self._hs else None
        m = self.n
        last = k == len(self.phases) - 1
        nxt: tuple[list, list, list] = ([], [], [])
        cap = self.max_step_time_s - T  # remaining time of each row [s]
        ok = cap > 0
        out.outcome[rows[~ok]] = TIMEOUT
        rows, Y, T, cap = rows[ok], Y[ok], T[ok], cap[ok]
        if not drop:
            return self._phase_rows(k, phase, rows, Y, T, D[rows, :nc], cap, gamma, out)
        Dk = D[rows]
        if drop:  # one more column: armed (1) or not (0)
            Dk = np.hstack([Dk, np.zeros((rows.size, 1))])
        stk = StackedRows(cfunc, n_extra, gcols, goffs, nc, m, drop, hs, self._clear)
        solver = stk.solver(Y, Dk, 0.0, None, float(cap.max()), self.rtol, self.atol)
        G_old = stk.guards(Y, Dk)
        while rows.size:
            solver.step()
            if solver.status == "failed":
                out.outcome[rows] = SOLVER_FAILURE
                break
            t_new = solver.t
            Yn = solver.y.reshape(-1, m)
            G_new = stk.guards(Yn, Dk)
            up = (G_old <= 0) & (G_new >= 0) & (dirs >= 0)
            down = (G_old >= 0) & (G_new <= 0) & (dirs <= 0)
            hit = up | down
            if drop:
                dr = Dk[:, nc] != 0
                hit[dr, hs] &= Dk[dr, nc + 1] > 0
                clearance = G_new[:, hs] - Dk[:, nc]
                Dk[dr & (clearance > np.maximum(0.0, -Dk[:, nc])), nc + 1] = 1.0
            done = hit.any(axis=1)
            te = np.full(rows.size, np.inf)
            which = np.full(rows.size, -1)
            if done.any():
                dense = solver.dense_output()
                stk.locate(hit, G_old, G_new, dense, t_new, Dk, te, which)
            late = ~done & (t_new >= cap)
            # rows that ended (guard or time cap) leave the stacked system
            idone = np.flatnonzero(done)
            Y_ev = (dense_rows(dense, idone[:, None] * m + np.arange(m)[None, :], te[idone])
                    if idone.size else None)
            for y_ev, i in zip(Y_ev if idone.size else (), idone):
                self._leave(k, ph.guards[which[i]], which[i], rows[i], T[i] + te[i], y_ev,
                            gamma, out, nxt, last)
            out.outcome[rows[late]] = TIMEOUT
            keep = ~(done | late)
            if solver.status == "finished" and keep.any():  # pragma: no cover - t_bound > cap
                out.outcome[rows[keep]] = TIMEOUT
                break
            if not keep.all():
                rows, T, cap, Dk = rows[keep], T[keep], cap[keep], Dk[keep]
                Yk = Yn[keep]
                G_old = G_new[keep]
                if rows.size:
                    h = solver.step_size
                    solver = stk.solver(Yk, Dk, t_new, h, float(cap.max()), self.rtol,
                                        self.atol)
            else:
                G_old = G_new
        if nxt[0]:
            return np.array(nxt[0]), np.array(nxt[1]), np.array(nxt[2])
        return np.empty(0, int), np.empty((0, m)), np.empty(0)

    def _phase_rows(self, k, phase, rows, Y, T, Dk, cap, gamma, out):
        """Phase ``k`` of rows without a footfall drop, each row integrated alone by the
        compiled DOP853 (:func:`walkerlab.integrate.rows_dop853.phase_rows`); returns the
        rows that go on to phase k + 1 (their entry states and times)."""
        from walkerlab.integrate.rows_dop853 import FAILED, phase_rows  # light

        ph, _, n_extra, gcols, goffs, dirs = phase
        N, m = Y.shape
        which = np.empty(N, np.int64)
        te = np.empty(N)
        Yev = np.empty((N, m))
        H = self._h_rows[rows]
        hoff = getattr(self, "_hoff", None)
        hs = self._hs_phase[k] if hoff is not None else -1
        args = (np.ascontiguousarray(Y, dtype=float), np.ascontiguousarray(Dk),
                np.ascontiguousarray(cap, dtype=float), self._gcols[k], self._goffs[k],
                self._dirs[k], float(self.rtol), float(self.atol), m + n_extra, which, te,
                Yev, H, hs, hoff[rows] if hs >= 0 else np.zeros(1))
        kern = self._kernels(k)
        if kern is not None:
            kern[1](*args)
        else:
            phase_rows(*self._cfuncs(k), *args)
        self._h_rows[rows] = H
        out.outcome[rows[which == FAILED]] = SOLVER_FAILURE  # (TIMEOUT: already set)
        self.integrated += N
        outcome = np.array([GUARD_OUTCOME.get(g.outcome, -1) for g in ph.guards] + [-1, -1])
        kind = outcome[which]  # which = -1 / -2 pick the trailing -1s
        t_end = T + te
        fell = kind == FALL
        out.outcome[rows[fell]] = FALL
        out.x_pre[rows[fell]] = Yev[fell]
        out.step_time_s[rows[fell]] = t_end[fell]
        hs = np.flatnonzero(kind == HEEL_STRIKE)
        if hs.size:
            r = rows[hs]
            out.outcome[r] = HEEL_STRIKE
            out.x_pre[r] = Yev[hs]
            out.step_time_s[r] = t_end[hs]
            out.x_next[r] = self._resets(Yev[hs], gamma[r], Dk[hs])
        go = np.flatnonzero(kind == NEXT_PHASE)
        if k == len(self.phases) - 1:  # pragma: no cover - a last phase without heel strike
            out.outcome[rows[go]] = SOLVER_FAILURE
            go = go[:0]
        Y1 = Yev[go]
        for j in np.unique(which[go]):  # the guard's reset (e.g. a knee strike), if any
            if ph.guards[j].reset is not None:
                for i in np.flatnonzero(which[go] == j):
                    gw = self._walker(float(gamma[rows[go[i]]])).phases[k].guards[j]
                    Y1[i] = np.asarray(gw.reset(Yev[go[i]]), float)
        return rows[go], Y1, t_end[go]

    def _resets(self, Y: np.ndarray, gamma: np.ndarray, D: np.ndarray) -> np.ndarray:
        """Heel-strike resets (k, 2n) of the pre-impact states ``Y`` (k, 2n), each on its
        row's slope ``gamma`` (k,) [rad] (data vectors ``D`` (k, c) of the last phase):
        compiled (``reset_rows`` of the generated module) when the walker's reset is the
        generated one, else the walker's reset row by row."""
        if self._reset_flow is not None:
            from walkerlab.integrate.rows_dop853 import reset_rows  # light

            out = np.empty_like(Y)
            reset_rows(self._reset_flow, np.ascontiguousarray(Y), np.ascontiguousarray(D), out)
            return out
        if not self._resets_depend_on_slope:
            reset = self.walker.reset
            return np.array([reset(y) for y in Y], dtype=float).reshape(Y.shape)
        return np.array([self._walker(float(g)).reset(y) for y, g in zip(Y, gamma)],
                        dtype=float).reshape(Y.shape)

    def _leave(self, k, g, j, r0, t_end, y_ev, gamma, out, nxt, last) -> None:
        """Row ``r0`` met guard ``g`` (index ``j`` of phase ``k``) at ``t_end`` [s] in state
        ``y_ev``: a fall or a heel strike ends its step in ``out``; a next-phase guard
        (with its intra-step reset, e.g. a knee strike) appends its entry to ``nxt`` (rows,
        states, times)."""
        if g.outcome == "fall":
            out.outcome[r0] = FALL
            out.x_pre[r0] = y_ev
            out.step_time_s[r0] = t_end
        elif g.outcome == "heel_strike":
            w = self._walker(float(gamma[r0]))
            out.outcome[r0] = HEEL_STRIKE
            out.x_pre[r0] = y_ev
            out.x_next[r0] = np.asarray(w.reset(y_ev), dtype=float)
            out.step_time_s[r0] = t_end
        elif last:  # pragma: no cover - a model whose last phase has no heel strike
            out.outcome[r0] = SOLVER_FAILURE
        else:
            w = self._walker(float(gamma[r0]))
            gw = w.phases[k].guards[j]
            y1 = np.asarray(gw.reset(y_ev), float) if gw.reset is not None else y_ev
            nxt[0].append(r0)
            nxt[1].append(y1)
            nxt[2].append(t_end)
