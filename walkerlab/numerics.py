"""The numerical formulas every floor shares, each written once: the finite-difference and
complex-step Jacobians, the order of Floquet multipliers and which of them are neutral, and
the name of the Poincaré map they are of (a step, a stride).

Imports nothing of walkerlab; numpy only.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

__all__ = ["complex_step_jacobian", "fd_jacobian", "neutral_positions", "sort_multipliers",
           "without_neutral"]


def fd_jacobian(fun: Callable[[np.ndarray], np.ndarray], x, steps, *, central: bool = True,
                f0=None) -> np.ndarray:
    """Finite-difference Jacobian ``d fun / d x``, one column per coordinate.

    Column ``k`` is ``(fun(x + h_k e_k) - fun(x - h_k e_k)) / (2 h_k)`` (central, error
    O(h²)) or ``(fun(x + h_k e_k) - f0) / h_k`` (forward, error O(h), ``n`` calls instead
    of ``2n``); ``fun(x + h e)`` is always called before ``fun(x - h e)`` (Nocedal & Wright,
    "Numerical Optimization", 2nd ed. 2006, sec. 8.1).

    Parameters
    ----------
    fun : callable ``(n,) -> (p,)``
        Real function of real input (units of its output per unit of ``x``).
    x : array_like, shape (n,)
        Where to differentiate.
    steps : float or array_like, shape (n,)
        Step ``h_k`` of each coordinate, in the coordinate's own unit (> 0).
    central : bool
        Central differences (default) or forward ones.
    f0 : array_like, shape (p,), optional
        ``fun(x)`` for forward differences (computed when not given).

    Returns
    -------
    ndarray, shape (p, n)

    Raises
    ------
    ValueError
        ``steps`` has neither one value nor ``n``.
    """
    x = np.asarray(x, dtype=float)
    n = x.size
    h = np.broadcast_to(np.asarray(steps, dtype=float), (n,))
    if not central and f0 is None:
        f0 = fun(x)
    cols = []
    for k in range(n):
        e = np.zeros(n)
        e[k] = h[k]
        if central:
            cols.append((np.asarray(fun(x + e), float) - np.asarray(fun(x - e), float))
                        / (2 * e[k]))
        else:
            cols.append((np.asarray(fun(x + e), float) - f0) / e[k])
    return np.stack(cols, axis=1)


def complex_step_jacobian(fun: Callable[[np.ndarray], np.ndarray], x,
                          h: float = 1e-30) -> np.ndarray:
    """Jacobian of an analytic function by the complex-step method (exact to round-off).

    Squire & Trapp (1998), SIAM Review 40(1): ``df/dx_k = Im f(x + i h e_k) / h``.

    Parameters
    ----------
    fun : callable ``(m,) -> (p,)``
        Must accept complex input (units of its output per unit of ``x``, as
        :func:`fd_jacobian`).
    x : array_like, shape (m,)
    h : float
        Imaginary step (any tiny value: no subtraction, no cancellation).

    Returns
    -------
    ndarray, shape (p, m)

    Raises
    ------
    TypeError, ValueError
        ``fun`` does not take complex input (compiled functions of real input).
    """
    x = np.asarray(x, dtype=float)
    cols = []
    for k in range(x.size):
        xc = x.astype(complex)
        xc[k] += 1j * h
        cols.append(np.imag(fun(xc)) / h)
    return np.stack(cols, axis=1)


def sort_multipliers(ev) -> np.ndarray:
    """Floquet multipliers sorted by decreasing modulus, ties by decreasing real part (a
    complex pair keeps the eigen-solver's order: the sort is stable).

    Parameters
    ----------
    ev : array_like, shape (n,)
        Eigenvalues of a monodromy matrix or a Poincaré-map Jacobian [-].

    Returns
    -------
    ndarray, shape (n,), complex
    """
    ev = np.asarray(ev, dtype=complex)
    return ev[np.lexsort((-ev.real, -np.abs(ev)))]


def neutral_positions(mult, k: int) -> np.ndarray:
    """Positions of the ``k`` multipliers nearest 1 in ``mult``: those of a walker's neutral
    coordinates (a family of gaits along each, :attr:`HybridWalker.neutral`), which the
    stability verdict and the bifurcation tests set aside.

    Parameters
    ----------
    mult : array_like, shape (m,)
        Floquet multipliers [-].
    k : int
        How many are neutral (0: none).

    Returns
    -------
    ndarray of int, shape (k,)
    """
    return np.argsort(np.abs(np.asarray(mult) - 1.0), kind="stable")[:k]


def without_neutral(mult, k: int) -> np.ndarray:
    """``mult`` (m,) without its ``k`` neutral multipliers (:func:`neutral_positions`)."""
    return np.delete(np.asarray(mult), neutral_positions(mult, k))


