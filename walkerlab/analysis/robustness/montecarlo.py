"""Noisy walks of a rigid walker on rough ground: the Monte Carlo side of the mean
first-passage time (MFPT; Byl & Tedrake (2009), "Metastable walking machines", IJRR 28(8)).

Many walks from the gait, slopes ``gamma_k ~ N(mean, sd)`` (or uniform) drawn from a per-walk
random stream (``SeedSequence(seed, spawn_key=(walk,))``, so a walk's slopes do not depend on
how walks are grouped: :func:`draw_slopes`, :func:`height_rows`), stepped together by
:class:`walkerlab.integrate.batch_step.BatchStepMap` (:func:`monte_carlo`).  A fall is any step
that does not end in heel strike (the hip reaches the ground, the swing leg falls back,
scuffing, no heel strike within ``max_step_time_s``).  A walk that reaches the step cap is
*censored*, not a fall: with ``S`` heel strikes in all and ``F`` falls, the censored geometric
(exponential) maximum-likelihood estimate is ``MFPT = S / F`` with standard error
``sqrt(MFPT (MFPT + 1) / F)`` (Fisher information of the per-step fall probability
``p = F / (S + F)``, delta method; :func:`geometric_mle`).  The same walks, at ``sd`` and
``1.5 sd``, give the post-impact states the mesh estimate is built on
(:func:`visited_states`; :mod:`walkerlab.analysis.robustness.mfpt`, which re-exports this
module's names).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from walkerlab.analysis.robustness.slope_stream import slope_rows
from walkerlab.integrate.batch_step import HEEL_STRIKE, BatchStepMap


def geometric_mle(heel_strikes: int, falls: int) -> tuple[float, float]:
    """Censored geometric MLE of the MFPT and its standard error (module docstring;
    ``MFPT = S / F``, ``stderr = sqrt(MFPT (MFPT + 1) / F)``, Fisher information and delta
    method).

    Parameters
    ----------
    heel_strikes : int
        Heel strikes of all walks together (censored walks included).
    falls : int
        Walks that fell.

    Returns
    -------
    (mfpt, stderr) : float, float
        Steps; ``(inf, nan)`` when no walk fell.
    """
    if falls == 0:
        return math.inf, math.nan
    m = heel_strikes / falls
    return m, math.sqrt(m * (m + 1.0) / falls)


def draw_slopes(seed: int, walk: int, n: int, mean: float, sd: float,
                distribution: str = "normal") -> np.ndarray:
    """The slopes [rad] of the first ``n`` steps of walk number ``walk`` (reproducible).

    ``distribution``: ``normal`` (mean, standard deviation ``sd``) or ``uniform`` (on
    ``mean -/+ sqrt(3) sd``, the same standard deviation; any other value: normal); stream
    ``SeedSequence(seed, spawn_key=(walk,))``.  ``mean``, ``sd`` [rad]; returns shape (n,).
    """
    rng = np.random.default_rng(np.random.SeedSequence(int(seed), spawn_key=(int(walk),)))
    if distribution == "uniform":
        half = math.sqrt(3.0) * sd
        return rng.uniform(mean - half, mean + half, n)
    return mean + sd * rng.standard_normal(n)


#: walk ``w``'s landing heights come from the stream of walk ``w + HEIGHT_STREAM`` of the
#: same seed (:func:`height_rows`): independent of its slopes, replayable from the seed
HEIGHT_STREAM = 2**31


def height_rows(seed: int, walks, start: int, n: int, sd: float,
                distribution: str = "normal") -> np.ndarray:
    """Landing heights [m] above the slope line of steps ``start`` to ``start + n - 1`` of each
    walk in ``walks`` (each in ``[0, 2**31)``), about 0 with standard deviation ``sd`` [m]:
    :func:`walkerlab.analysis.robustness.slope_stream.slope_rows` of the walks
    ``w + HEIGHT_STREAM``; shape (len(walks), n).

    Raises
    ------
    ValueError
        A negative seed, a walk number outside ``[0, 2**31)``.
    """
    walks = [int(w) for w in walks]
    if any(not 0 <= w < HEIGHT_STREAM for w in walks):
        raise ValueError("walk numbers of per-step heights must be in [0, 2**31)")
    return slope_rows(seed, [w + HEIGHT_STREAM for w in walks], start, n, 0.0, sd,
                      distribution)


@dataclass
class MonteCarloResult:
    """Monte Carlo walks on per-step slopes.

    Attributes
    ----------
    steps : ndarray of int, shape (walks,)
        Heel strikes of each walk [steps].
    fell : ndarray of bool, shape (walks,)
        Whether the walk fell (False: censored at the step cap).
    """

    steps: np.ndarray
    fell: np.ndarray

    @property
    def mfpt(self) -> tuple[float, float]:
        """``(MFPT, standard error)`` [steps] (:func:`geometric_mle`)."""
        return geometric_mle(int(self.steps.sum()), int(self.fell.sum()))


def monte_carlo(step_map: BatchStepMap, x0: np.ndarray, sd: float, walks: range | list,
                max_steps: int, seed: int, mean: float | None = None,
                distribution: str = "normal", block: int = 64,
                heights: tuple[str, float] | None = None) -> MonteCarloResult:
    """Walk ``len(walks)`` walkers from ``x0`` on random per-step slopes until each falls or
    reaches ``max_steps`` heel strikes (Byl & Tedrake 2009; module docstring, "Monte
    Carlo").

    Parameters
    ----------
    step_map : BatchStepMap
    x0 : ndarray, shape (2n,)
        Start (the gait's post-impact state).
    sd : float
        Standard deviation of the per-step slope [rad].
    walks : sequence of int
        Walk numbers (each has its own random stream, :func:`draw_slopes`; drawn for all
        walks at once by :func:`walkerlab.analysis.robustness.slope_stream.slope_rows`, the
        same numbers).
    max_steps : int
        Step cap (censoring).
    seed : int
    mean : float, optional
        Mean slope [rad]; default the walker's.
    distribution : {"normal", "uniform"}
    heights : (distribution, sd [m]), optional
        Each step's landing also lies a height drawn so (:func:`height_rows`) above the
        slope line through the stance foot (``step_map`` built on
        :func:`walkerlab.models.hybrid.ground.with_clearance_guard`).

    Returns
    -------
    MonteCarloResult
    """
    mean = step_map.slope_rad if mean is None else float(mean)
    walks = list(walks)
    W = len(walks)
    X = np.tile(np.asarray(x0, dtype=float), (W, 1))
    steps = np.zeros(W, dtype=np.int64)
    fell = np.zeros(W, dtype=bool)
    alive = np.arange(W)
    if getattr(step_map, "can_walk", False):  # whole walks compiled, block after block
        wb = max(block, 200_000 // max(W, 1))  # (all walks' slopes of a block at once)
        for k in range(0, max_steps, wb):
            if alive.size == 0:
                break
            nb = min(wb, max_steps - k)
            slopes = slope_rows(seed, [walks[i] for i in alive], k, nb, mean, sd,
                                distribution)
            if heights is None:
                s, f, X[alive] = step_map.walk(X[alive], slopes)
            else:
                hts = height_rows(seed, [walks[i] for i in alive], k, nb, heights[1],
                                  heights[0])
                s, f, X[alive] = step_map.walk(X[alive], slopes, hts)
            steps[alive] += s
            fell[alive] = f
            alive = alive[~f]
        return MonteCarloResult(steps, fell)
    slopes = np.empty((W, 0))
    for k in range(max_steps):
        if alive.size == 0:
            break
        j = k % block
        if j == 0:  # the next block of slopes of every walk (same numbers for any grouping)
            slopes = slope_rows(seed, walks, k, block, mean, sd, distribution)
            if heights is not None:
                hts = height_rows(seed, walks, k, block, heights[1], heights[0])
        if heights is None:
            res = step_map.step(X[alive], slopes[alive, j])
        else:
            res = step_map.step(X[alive], slopes[alive, j], height_m=hts[alive, j])
        ok = res.outcome == HEEL_STRIKE
        steps[alive[ok]] += 1
        fell[alive[~ok]] = True
        X[alive[ok]] = res.x_next[ok]
        alive = alive[ok]
    return MonteCarloResult(steps, fell)


# -- the mesh ------------------------------------------------------------------------------

def visited_states(step_map: BatchStepMap, x0: np.ndarray, sds, walks: int, steps: int,
                   seed: int, burn_in: int = 1, distribution: str = "normal") -> np.ndarray:
    """Post-impact states visited by noisy walks from ``x0`` (the mesh's nodes; Byl &
    Tedrake 2009's "reachable" mesh).

    Parameters
    ----------
    x0 : ndarray, shape (2n,)
    sds : sequence of float
        Slope standard deviations [rad]; ``walks`` walks of ``steps`` steps at each (a walk
        that falls starts again from ``x0``, so about ``walks * steps`` states per sd).
    burn_in : int
        Steps of each walk not recorded.
    distribution : {"normal", "uniform"}
        Of the slopes (uniform: on ``mean -/+ sqrt(3) sd``).

    Returns
    -------
    ndarray, shape (k, 2n)
        Every post-impact state after the burn-in, falls left out, in a seeded random order
        (so the first ``N`` rows are a fair sample of all, and meshes of growing ``N`` are
        nested).
    """
    x0 = np.asarray(x0, float)
    sds = [float(sd) for sd in sds]
    pts: list[list] = [[] for _ in sds]  # per sd (the walks of all sds step together)
    rngs = [np.random.default_rng([int(seed), 24, i]) for i in range(len(sds))]
    X = np.tile(x0, (len(sds) * walks, 1))
    for k in range(steps):
        z = [rng.uniform(-math.sqrt(3.0), math.sqrt(3.0), walks)
             if distribution == "uniform" else rng.standard_normal(walks) for rng in rngs]
        r = step_map.step(X, np.concatenate([step_map.slope_rad + sd * zi
                                             for sd, zi in zip(sds, z)]))
        ok = r.outcome == HEEL_STRIKE
        if k >= burn_in:
            for i in range(len(sds)):
                rows = slice(i * walks, (i + 1) * walks)
                pts[i].append(r.x_next[rows][ok[rows]])
        X = np.where(ok[:, None], r.x_next, x0)  # a fallen walk starts again on the gait
    flat = [p for per_sd in pts for p in per_sd]
    P = np.concatenate(flat) if flat else np.empty((0, len(x0)))
    return P[np.random.default_rng([int(seed), 25]).permutation(len(P))]
