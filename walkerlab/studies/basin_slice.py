"""The slice of the Poincaré section a basin map's cells lie on (Schwab & Wisse 2001,
"Basin of attraction of the simplest walking model", ASME DETC 2001): a cell's state from its
two axis values (:func:`slice_state`, :class:`HeelStrikeSlice`) and the axes' cell centres
(:func:`axis_values`).  The three starts (``basin.start``) are described in
:mod:`walkerlab.studies.basin`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from walkerlab.numerics import fd_jacobian

__all__ = ["BasinError", "slice_state", "HeelStrikeSlice", "heel_strike_slice", "axis_values"]


class BasinError(ValueError):
    """Bad basin settings (message names the field)."""


def _index(names: list[str], name: str, field: str) -> int:
    if name not in names:
        raise BasinError(f"basin.{field}: unknown state {name!r}; choose from "
                         f"{', '.join(names)}")
    return names.index(name)


def slice_state(walker, x_star: np.ndarray, axes: tuple[str, str],
                values: tuple[float, float], project: bool = True) -> np.ndarray:
    """Post-heel-strike state of one cell (``basin.start: fixed_point``; Schwab & Wisse
    2001's grid of post-heel-strike states), or with ``project`` False the state as given
    (``basin.start: phase_plane``: any state of the stance phase, Coleman, Chatterjee &
    Ruina 1997's phase plane of the rimless wheel).

    Parameters
    ----------
    walker : HybridWalker
    x_star : ndarray, shape (2n,)
        Period-1 fixed point (role-ordered, just after heel strike).
    axes : (str, str)
        State names of the two grid axes.
    values : (float, float)
        Their values [rad or rad/s].

    Returns
    -------
    ndarray, shape (2n,)
        ``x*`` with the two axis coordinates replaced, projected on the heel-strike surface.

    Raises
    ------
    BasinError
        An unknown state name, or an axis that the heel-strike constraint fixes.
    """
    names = walker.state_names()
    ix = _index(names, axes[0], "x_axis")
    iy = _index(names, axes[1], "y_axis")
    if ix == iy:
        raise BasinError("basin: x_axis and y_axis name the same state")
    x = np.array(x_star, dtype=float)
    x[ix], x[iy] = values
    if not project:
        return x
    x = np.asarray(walker.from_section(walker.section(x)), dtype=float)
    for i, field, v in ((ix, "x_axis", values[0]), (iy, "y_axis", values[1])):
        if abs(x[i] - v) > 1e-12 * (1 + abs(v)):
            raise BasinError(f"basin.{field}: {names[i]!r} is fixed by the heel-strike "
                             "constraint; choose another state")
    return x


@dataclass(frozen=True)
class HeelStrikeSlice:
    """Cells as states just after a heel strike (``basin.start: heel_strike``).

    Attributes
    ----------
    z_pre : ndarray, shape (2n - 1,)
        Section coordinates (``walker.section``) of the fixed point's pre-impact state
        [rad, rad/s].
    free : ndarray of int, shape (2,)
        Which of them vary from cell to cell: the two the post-impact axis values depend on
        most (column-pivoted QR of that 2 x (2n - 1) Jacobian at ``z_pre``).
    axes : ndarray of int, shape (2,)
        State indices of the x and y axes.

    The cell is Schwab & Wisse (2001)'s: a state just after a heel strike (module
    docstring, ``heel_strike``).
    """

    z_pre: np.ndarray
    free: np.ndarray
    axes: np.ndarray

    def post(self, walker, u: np.ndarray) -> np.ndarray:
        """Post-impact state ``walker.reset(x-)`` of the pre-impact state with ``free = u``
        (legs that differ: the heel strike that closes a stride, leg2 swinging).

        ``u`` (2,) are the two free section coordinates [rad or rad/s]; returns the
        post-impact state (2n,) in ``walker.state_names()`` order [rad, rad/s] (the heel
        strike's impact map, ``walker.reset``).
        """
        z = self.z_pre.copy()
        z[self.free] = u
        last = walker.for_stance(walker.legs[0])
        return np.asarray(last.reset(np.asarray(last.from_section(z), dtype=float)),
                          dtype=float)

    def state(self, walker, values: tuple[float, float]) -> np.ndarray | None:
        """The cell's post-impact state, or None where no heel strike lands on it.

        The two free pre-impact coordinates are found by ``scipy.optimize.root`` (MINPACK
        hybrd) from the fixed point's; the cell is unreachable unless the axis values are
        matched to 1e-10 (relative) and the pre-impact state is finite.

        Parameters
        ----------
        walker : HybridWalker
        values : (float, float)
            The x and y axis values [rad or rad/s].

        Returns
        -------
        ndarray, shape (2n,) or None
            Post-impact state (``walker.state_names()``, [rad, rad/s]) through the heel
            strike's impact map ``walker.reset`` (Schwab & Wisse 2001's cell).
        """
        from scipy.optimize import root

        target = np.asarray(values, dtype=float)

        def residual(u):
            return self.post(walker, u)[self.axes] - target

        with np.errstate(all="ignore"):
            sol = root(residual, self.z_pre[self.free], method="hybr", options={"xtol": 1e-13})
            x = self.post(walker, sol.x)
        if not (np.all(np.isfinite(x)) and
                np.max(np.abs(x[self.axes] - target)) <= 1e-10 * (1 + np.max(np.abs(target)))):
            return None
        return x


def heel_strike_slice(walker, x_pre: np.ndarray, axes: tuple[str, str]) -> HeelStrikeSlice:
    """Set up :class:`HeelStrikeSlice` from the fixed point's pre-impact state ``x_pre``
    (shape (2n,), on the heel-strike guard; ``walker.state_names()`` order, [rad, rad/s]).
    ``axes`` are two state names; the free coordinates are chosen by column-pivoted QR of the
    axis values' finite-difference Jacobian (Schwab & Wisse 2001's post-impact cells).

    Raises
    ------
    BasinError
        An unknown axis name, or axes the heel strike leaves fixed (the 2 x (2n - 1)
        Jacobian has rank < 2).
    """
    names = walker.state_names()
    ax = np.array([_index(names, axes[0], "x_axis"), _index(names, axes[1], "y_axis")])
    if ax[0] == ax[1]:
        raise BasinError("basin: x_axis and y_axis name the same state")
    from scipy.linalg import qr

    z = np.asarray(walker.section(np.asarray(x_pre, dtype=float)), dtype=float)
    base = HeelStrikeSlice(z, np.arange(z.size), ax)
    # forward differences are enough: only the pivot order (and the rank) is taken from it
    jac = np.atleast_2d(fd_jacobian(lambda zz: base.post(walker, zz)[ax], z, 1e-7,
                                     central=False))
    _, r, piv = qr(jac, pivoting=True)
    if abs(r[1, 1]) <= 1e-9 * max(abs(r[0, 0]), 1e-300):
        raise BasinError(f"basin: the heel strike fixes a relation between {axes[0]!r} and "
                         f"{axes[1]!r}; choose other axes or basin.start: fixed_point")
    return HeelStrikeSlice(z, np.sort(piv[:2]), ax)


def axis_values(settings, walker, x_star: np.ndarray,
                grid: tuple[int, int] | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Cell-centre values of the x and y axes [rad or rad/s].

    Default ranges: the fixed point -/+ 0.3 rad for an angle, -/+ 1.2 rad/s for a rate.

    Parameters
    ----------
    settings : BasinSettings
        Axes (state names), ranges and grid.
    walker : HybridWalker
    x_star : ndarray, shape (2n,)
        Period-1 fixed point (``walker.state_names()``).
    grid : (nx, ny), optional
        Overrides ``settings.grid``.

    Returns
    -------
    (x, y) : ndarray, shapes (nx,) and (ny,)
        Cell centres [rad or rad/s].

    Raises
    ------
    BasinError
        An unknown axis name, or a range whose upper end does not exceed its lower.
    """
    names = walker.state_names()
    nx, ny = grid or settings.grid
    out = []
    for name, rng, n, field in ((settings.x_axis, settings.x_range, nx, "x_axis"),
                                (settings.y_axis, settings.y_range, ny, "y_axis")):
        c = float(x_star[_index(names, name, field)])
        if rng is None:
            half = 1.2 if name.endswith("_rate") else 0.3
            rng = (c - half, c + half)
        lo, hi = float(rng[0]), float(rng[1])
        if not hi > lo:
            raise BasinError(f"basin.{field[0]}_range: the upper end must exceed the lower")
        edges = np.linspace(lo, hi, n + 1)
        out.append(0.5 * (edges[:-1] + edges[1:]))
    return out[0], out[1]
