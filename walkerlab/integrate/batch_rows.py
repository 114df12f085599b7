"""The stacked system of many rows of one phase (:mod:`walkerlab.integrate.batch_step`): the
compiled loop that evaluates every row's flow and guards in one call (:func:`kernel`), the
DOP853 integrator on the stacked state, and the location of the rows' guard crossings on
its dense output (``scipy.optimize.elementwise.find_root``, vectorised).
"""

from __future__ import annotations

import numpy as np

__all__ = ["StackedRows", "dense_rows", "kernel"]

EPS = np.finfo(float).eps

_KERNEL = None


def kernel():
    """The compiled loop ``(f, Y, D, dY, G) -> None``: ``f`` a flow cfunc (first-class
    function argument), ``Y`` (N, m) states, ``D`` (N, c) data vectors, ``dY`` (N, m) flows,
    ``G`` (N, g) guard values (the cfunc's extra outputs)."""
    global _KERNEL
    if _KERNEL is None:
        from walkerlab.usercache import use_for_numba

        use_for_numba()
        from numba import njit

        @njit(cache=True)
        def _stacked(f, Y, D, dY, G):  # pragma: no cover - compiled
            m = Y.shape[1]
            g = G.shape[1]
            buf = np.empty(m + g)
            for i in range(Y.shape[0]):
                f(buf.ctypes, 0.0, Y[i].ctypes, D[i].ctypes)
                dY[i, :] = buf[:m]
                G[i, :] = buf[m:]
        _KERNEL = _stacked
    return _KERNEL


def _entry(kern, f, Y, D, dY, G) -> None:
    """Call the kernel; after its first compilation through the compiled entry point of its
    one signature (the dispatcher's typing of a first-class function argument costs more
    than the call itself on a few hundred rows)."""
    ep = _ENTRY.get(id(kern))
    if ep is None:
        kern(f, Y, D, dY, G)
        sigs = kern.signatures
        if len(sigs) == 1 and hasattr(kern.overloads.get(sigs[0]), "entry_point"):
            _ENTRY[id(kern)] = kern.overloads[sigs[0]].entry_point
        return
    ep(f, Y, D, dY, G)


_ENTRY: dict = {}


def dense_rows(dense, cols: np.ndarray, t: np.ndarray) -> np.ndarray:
    """DOP853 dense output of some components at per-row times.

    ``cols`` (k, m) component indices of the stacked state, ``t`` (k,) times [s] in the step;
    returns (k, m), each component in its state's unit ([rad], [rad/s]).  Same arithmetic as
    ``scipy.integrate._ivp.rk.Dop853DenseOutput`` (``F``, ``t_old``, ``h``, ``y_old``),
    restricted to the rows asked for."""
    x = ((t - dense.t_old) / dense.h)[:, None]
    y = np.zeros(cols.shape)
    for i, f in enumerate(reversed(dense.F)):
        y += f[cols]
        y *= x if i % 2 == 0 else (1 - x)
    return y + dense.y_old[cols]


class StackedRows:
    """The stacked system of one phase's rows: every row's compiled flow in one kernel call,
    the guard values (a footfall drop's heel strike on the swing foot's clearance), the
    DOP853 integrator (Hairer, Nørsett & Wanner, "Solving Ordinary Differential Equations
    I", 2nd ed. 1993, sec. II.10; scipy's ``DOP853``) and the location of the guards'
    crossings."""

    def __init__(self, cfunc, n_extra: int, gcols, goffs, nc: int, m: int, drop: bool,
                 hs: int | None, clear: int | None):
        self.kern, self.cfunc, self.n_extra = kernel(), cfunc, n_extra
        self.gcols, self.goffs, self.nc, self.m = gcols, goffs, nc, m
        self.drop, self.hs, self.clear = drop, hs, clear

    def guards(self, Yr: np.ndarray, Dr: np.ndarray) -> np.ndarray:
        """Guard values (k, g) of the rows ``Yr`` (k, m) with data ``Dr`` (k, c); a guard is
        in its own unit (a clearance [m] or an angle [rad]), its sign is what counts."""
        dY = np.empty_like(Yr)
        G = np.empty((Yr.shape[0], self.n_extra))
        _entry(self.kern, self.cfunc, np.ascontiguousarray(Yr),
               np.ascontiguousarray(Dr[:, :self.nc]), dY, G)
        vals = G[:, self.gcols] + self.goffs
        if self.drop:
            dr = Dr[:, self.nc] != 0
            vals[dr, self.hs] = G[dr, self.clear] + Dr[dr, self.nc]
        return vals

    def solver(self, Y0: np.ndarray, Dr: np.ndarray, t0: float, h: float | None,
               t_span: float, rtol: float, atol: float):
        """DOP853 on the stacked rows ``Y0`` from ``t0`` (first step ``h``) up to ``t_span``
        [s] past it, at the per-walker tolerances (module docstring).

        ``Y0`` (k, m): the rows' states ([rad], [rad/s]); ``Dr`` (k, c): their data vectors;
        ``t0`` and ``h`` [s]; ``rtol``, ``atol`` [-] and [state unit].  The integrator's
        state is ``Y0`` flattened, shape (k m,).
        """
        from scipy.integrate import DOP853

        m, kern, cfunc, n_extra = self.m, self.kern, self.cfunc, self.n_extra

        def fun(t, y, _D=np.ascontiguousarray(Dr[:, :self.nc])):
            Yr = y.reshape(-1, m)
            dY = np.empty_like(Yr)
            G = np.empty((Yr.shape[0], n_extra))
            _entry(kern, cfunc, Yr, _D, dY, G)
            return dY.ravel()
        scale = np.sqrt(Y0.size)
        return DOP853(fun, t0, Y0.ravel().copy(), t_bound=t0 + t_span + 1.0,
                      rtol=max(rtol / scale, 1e-13), atol=atol / scale, first_step=h)

    def locate(self, hit, G_old, G_new, dense, t_new: float, Dk, te, which) -> None:
        """The first crossing of each row whose guards changed sign in the step (``hit``
        (k, g)): its time in the step into ``te`` (k,) and its guard into ``which``, located
        on the dense output by Chandrupatla's method (``find_root``, vectorised).  ``t_new``
        and the located times ``te`` are in [s]; ``G_old``, ``G_new`` (k, g) guard values."""
        from scipy.optimize.elementwise import find_root

        m = self.m
        for j in np.flatnonzero(hit.any(axis=0)):
            r = np.flatnonzero(hit[:, j])
            cols = r[:, None] * m + np.arange(m)[None, :]
            Dr = Dk[r]
            g0, g1 = G_old[r, j], G_new[r, j]

            a = np.full(r.size, dense.t_old)
            b = np.full(r.size, t_new)
            tj = np.where(g1 == 0, b, np.where(g0 == 0, a, np.nan))
            todo = np.isnan(tj)
            if todo.any():
                cols_t, D_t = cols[todo], Dr[todo]

                def ft(t, idx, _c=cols_t, _D=D_t, _j=j, _d=dense):
                    # find_root passes only its unconverged elements (and their idx)
                    i = idx.astype(int)
                    return self.guards(dense_rows(_d, _c[i], t), _D[i])[:, _j]
                res = find_root(ft, (a[todo], b[todo]),
                                args=(np.arange(cols_t.shape[0], dtype=float),),
                                tolerances={"xatol": 1e-15, "xrtol": 4 * EPS})
                tj[todo] = res.x
            better = tj < te[r]
            te[r[better]] = tj[better]
            which[r[better]] = j
