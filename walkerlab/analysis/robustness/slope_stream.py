"""The per-walk slope streams of the Monte Carlo walks for many walks at once: the numbers of
:func:`walkerlab.analysis.robustness.montecarlo.draw_slopes` bit for bit, drawn into one array.

Walk ``w`` of seed ``s`` draws from ``Generator(PCG64(SeedSequence(s, spawn_key=(w,))))``,
NumPy's public seeding (``numpy.random.SeedSequence``, whose streams NumPy keeps stable), so
the numbers do not depend on NumPy's internals; the draws themselves are NumPy's (ziggurat
normal, uniform) and the tests pin the first draws of one walk and compare
:func:`slope_rows` with ``draw_slopes`` bit for bit (several seeds, walks, both
distributions).  The seeding costs ~10 us a walk and block of steps, small beside the
walks' own integration of a block (``scripts/bench_mfpt.py``).
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["slope_rows"]


def slope_rows(seed: int, walks, start: int, n: int, mean: float, sd: float,
               distribution: str = "normal") -> np.ndarray:
    """Slopes [rad] of steps ``start`` to ``start + n - 1`` of each walk in ``walks``: row ``i``
    is ``draw_slopes(seed, walks[i], start + n, mean, sd, distribution)[start:]`` bit for bit
    (:func:`walkerlab.analysis.robustness.montecarlo.draw_slopes`).

    Parameters
    ----------
    seed : int
        Non-negative.
    walks : sequence of int
        Walk numbers, each in ``[0, 2**32)``.
    start, n : int
        First step and number of steps.
    mean, sd : float
        Mean and standard deviation of the slope [rad].
    distribution : {"normal", "uniform"}
        Uniform on ``mean -/+ sqrt(3) sd``; any other value: normal (as ``draw_slopes``).

    Returns
    -------
    ndarray, shape (len(walks), n)

    Raises
    ------
    ValueError
        A negative seed, a walk number outside ``[0, 2**32)``.
    """
    seed = int(seed)
    if seed < 0:
        raise ValueError(f"seed {seed}: a random seed must be a non-negative integer")
    w = np.asarray(list(walks), dtype=np.int64).reshape(-1)
    if w.size and (w.min() < 0 or w.max() >= 2**32):
        raise ValueError("walk numbers must be in [0, 2**32)")
    total, start = int(start) + int(n), int(start)
    z = np.empty((w.size, total))
    half = math.sqrt(3.0) * sd
    for i, walk in enumerate(w.tolist()):
        gen = np.random.Generator(np.random.PCG64(np.random.SeedSequence(seed,
                                                                         spawn_key=(walk,))))
        if distribution == "uniform":
            z[i] = gen.uniform(mean - half, mean + half, total)
        else:
            gen.standard_normal(out=z[i])
    if distribution == "uniform":
        return z[:, start:].copy()
    return mean + sd * z[:, start:]
