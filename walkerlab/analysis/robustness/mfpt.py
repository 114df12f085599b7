"""Metastability of a rigid walker on rough ground: the mean first-passage time (MFPT).

Byl & Tedrake (2009), "Metastable walking machines", IJRR 28(8): on ground whose slope is
drawn anew for every step, every passive walker eventually falls; the MFPT - here the expected
number of heel strikes before the fall, a walk that falls in its first step counting 0 - is
the measure.  Two estimates:

Monte Carlo (:func:`~walkerlab.analysis.robustness.montecarlo.monte_carlo`)
    Many walks from the gait on random slopes, their censored geometric maximum-likelihood
    MFPT (:mod:`walkerlab.analysis.robustness.montecarlo`; its names are re-exported here).

Mesh (:func:`mesh_mfpt`)
    The post-impact section is meshed where the walker actually goes (Byl & Tedrake's
    "reachable" mesh): the nodes are post-impact states visited by noisy walks from the gait
    at ``sd`` and ``1.5 sd``
    (:func:`~walkerlab.analysis.robustness.montecarlo.visited_states`), thinned to one per
    voxel of a lattice in the whitened coordinates of that cloud (:func:`whitening`,
    :func:`voxel_nodes`), so the tails where falls start are meshed as finely as the core.
    The region is fixed in absolute units by the walks, not scaled to a box: a state carries
    all it needs (the post-impact state on a per-step slope already encodes the previous
    step's slope: ``2n`` coordinates, ``d = 4`` for a compass walker; directions without
    spread, such as a locked knee's, drop out of the metric).  Each node is a Voronoi cell
    (nearest node, :class:`scipy.spatial.cKDTree`); from each node the step map is taken at
    the quadrature nodes of the slope distribution (Gauss-Hermite for the normal,
    Gauss-Legendre on the support for the uniform, :func:`slope_quadrature`), an image
    goes to its nearest node, and only a genuine fall (no heel strike) goes to the
    absorbing state; images farther from every node than 99 % of the nodes are from their
    neighbour are reported
    (``escaped``: their probability per step from the quasi-stationary distribution).
    With ``Q`` the transition matrix among nodes (``scipy.sparse``), the quasi-stationary
    MFPT is ``1 / (1 - lambda_2) - 1`` (``lambda_2`` the largest eigenvalue of ``Q``,
    ``scipy.sparse.linalg.eigs``) and the expected heel strikes from each node solve
    ``(I - Q) m = 1`` (minus the falling step); the MFPT from the gait is ``m`` at the gait's
    node minus one.  A coarse mesh is biased (a lattice mesh with multilinear weights
    spreads probability toward the fall boundary): :func:`mesh_mfpt_converged` doubles the
    nodes until the MFPT changes by less than 5 %, and that change is the stated error.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from walkerlab.analysis.robustness.montecarlo import (  # noqa: F401 (part of this API)
    HEIGHT_STREAM,
    MonteCarloResult,
    draw_slopes,
    geometric_mle,
    height_rows,
    monte_carlo,
    visited_states,
)
from walkerlab.integrate.batch_step import HEEL_STRIKE, BatchStepMap


def whitening(P: np.ndarray, rank_tol: float = 1e-10) -> np.ndarray:
    """``W`` (2n, d): ``(x - x') @ W`` measures distances in standard deviations of the
    cloud ``P`` (k, 2n) along its principal axes; directions without spread (a locked
    knee's equal thigh and shank angles) drop out, so ``d`` is the dimension of the set the
    post-impact states fill (4 for a compass walker on per-step slopes).

    PCA whitening, ``W = V diag(w)^(-1/2)`` over the covariance's eigenpairs with ``w >
    rank_tol max(w)``; ``P`` in ``state_names()`` order [rad, rad/s], ``W`` in [1 / state
    unit], so the whitened coordinates are dimensionless [standard deviations].
    """
    w, V = np.linalg.eigh(np.cov(np.asarray(P, float).T))
    keep = w > rank_tol * w.max()
    return V[:, keep] / np.sqrt(w[keep])


@dataclass
class MeshResult:
    """One mesh.

    Attributes
    ----------
    mfpt_steps : float
        Expected heel strikes before the fall from the gait's node.
    mfpt_quasi_stationary_steps : float
        ``1 / (1 - lambda_2) - 1``.
    lambda2 : float
        Largest eigenvalue of the transient block ``Q`` [-].
    cells : int
        Nodes (Voronoi cells) of the mesh.
    h : float
        Voxel side of the node selection (:func:`voxel_nodes`) [standard deviations of the
        visited cloud].
    escaped : float
        Probability per step, from the quasi-stationary distribution, that a heel strike
        lands off the mesh (farther from every node than 99 % of the nodes are from their
        nearest neighbour); such images go to their nearest node.
    steps_evaluated : int
        Step-map evaluations this mesh computed (the cached images not counted).
    expected_steps : ndarray, shape (cells,)
        Expected heel strikes before the fall from each node [steps].
    change, converged : float, bool
        Relative change [-] from the coarser mesh; :func:`mesh_mfpt_converged` criterion met.
    """

    mfpt_steps: float
    mfpt_quasi_stationary_steps: float
    lambda2: float
    cells: int
    h: float
    escaped: float
    steps_evaluated: int
    expected_steps: np.ndarray = field(repr=False, default=None)
    #: relative change of ``mfpt_steps`` from the previous (coarser) mesh
    change: float = math.nan
    converged: bool = False


def gauss_hermite(n: int, mean: float, sd: float) -> tuple[np.ndarray, np.ndarray]:
    """Nodes [rad] and weights (sum 1) of the normal distribution N(mean, sd^2)
    (``numpy.polynomial.hermite_e.hermegauss``); each of shape (n,)."""
    from numpy.polynomial.hermite_e import hermegauss

    z, w = hermegauss(n)
    return mean + sd * z, w / w.sum()


def gauss_legendre_uniform(n: int, mean: float, sd: float) -> tuple[np.ndarray, np.ndarray]:
    """Nodes [rad] and weights (sum 1) of the uniform distribution on
    ``mean -/+ sqrt(3) sd`` (standard deviation ``sd``; :func:`draw_slopes`'s uniform),
    Gauss-Legendre (``numpy.polynomial.legendre.leggauss``) mapped to that interval; each
    of shape (n,)."""
    from numpy.polynomial.legendre import leggauss

    z, w = leggauss(n)
    return mean + math.sqrt(3.0) * sd * z, w / w.sum()


def slope_quadrature(n: int, mean: float, sd: float, distribution: str = "normal"
                     ) -> tuple[np.ndarray, np.ndarray]:
    """``n`` nodes [rad] and weights (sum 1) of the per-step slope distribution.

    Parameters
    ----------
    n, mean, sd : int, float, float
        Number of nodes; mean and standard deviation of the slope [rad].
    distribution : {"normal", "uniform"}
        Gauss-Hermite (:func:`gauss_hermite`) or Gauss-Legendre on the uniform's support
        (:func:`gauss_legendre_uniform`).

    Returns
    -------
    (nodes, weights) : ndarray, shape (n,) each
        Slopes [rad] and probabilities [-].

    Raises
    ------
    ValueError
        Another distribution.
    """
    if distribution == "normal":
        return gauss_hermite(n, mean, sd)
    if distribution == "uniform":
        return gauss_legendre_uniform(n, mean, sd)
    raise ValueError(f"slope distribution {distribution!r}: normal or uniform")


def transition_matrix(images: np.ndarray, ok: np.ndarray, weights: np.ndarray,
                      nodes: np.ndarray, W: np.ndarray):
    """Sparse transition matrix among the Voronoi cells of ``nodes``.

    Parameters
    ----------
    images : ndarray (k, q, 2n)
        Post-impact state from node ``i`` on slope node ``j`` (``state_names()`` order,
        [rad, rad/s]).
    ok : ndarray of bool (k, q)
        Heel strike (else a fall: the absorbing state).
    weights : ndarray (q,)
        Quadrature weights.
    nodes : ndarray (k, 2n)
    W : ndarray (2n, d)
        The metric (:func:`whitening`).

    Returns
    -------
    Q : scipy.sparse.csr_matrix (k, k)
        Probability of going from node i to the cell of node j (rows sum to 1 - P(fall)).
    off : ndarray (k,)
        Probability from each node of landing off the mesh (see ``MeshResult.escaped``).
    h : float
        Median nearest-neighbour distance of the nodes, in the whitened chart [standard
        deviations].
    """
    from scipy.sparse import coo_matrix
    from scipy.spatial import cKDTree

    k, q, _ = images.shape
    Z = nodes @ W
    tree = cKDTree(Z)
    nn = tree.query(Z, k=2)[0][:, 1]
    src = np.repeat(np.arange(k), q)[ok.ravel()]
    wq = np.tile(weights, k)[ok.ravel()]
    dist, tgt = tree.query(images.reshape(k * q, -1)[ok.ravel()] @ W)
    off = np.zeros(k)
    far = dist > np.percentile(nn, 99)
    np.add.at(off, src[far], wq[far])
    Q = coo_matrix((wq, (src, tgt)), shape=(k, k)).tocsr()
    return Q, off, float(np.median(nn))


def solve_mesh(Q, start: int):
    """``(mfpt from start, quasi-stationary mfpt, lambda_2, expected heel strikes (k,),
    quasi-stationary distribution (k,))`` of the absorbing chain with transient block ``Q``
    (k, k) (heel strikes = transitions - 1): ``(I - Q) m = 1``
    (:func:`scipy.sparse.linalg.spsolve`) and the largest eigenvalue of ``Q`` with its left
    eigenvector (:func:`scipy.sparse.linalg.eigs`): the absorbing chain's expected time to
    absorption (Byl & Tedrake 2009); counts in heel strikes [steps], ``lambda_2`` [-]."""
    from scipy.sparse import identity
    from scipy.sparse.linalg import ArpackNoConvergence, eigs, spsolve

    k = Q.shape[0]
    m = spsolve((identity(k, format="csc") - Q.tocsc()), np.ones(k))
    try:  # the quasi-stationary distribution: left eigenvector of lambda_2
        # a fixed start vector: ARPACK's default is a random one (scipy >= 1.17 seeds it from
        # the OS), which made the eigenpair differ in the 10th digit from run to run
        lam, vec = eigs(Q.T.tocsr(), k=1, which="LM", maxiter=5000, tol=1e-10,
                        v0=np.full(k, 1.0 / math.sqrt(k)))
        lam2, pi = float(np.real(lam[0])), np.abs(np.real(vec[:, 0]))
    except ArpackNoConvergence:
        w, V = np.linalg.eig(Q.toarray().T)
        j = int(np.argmax(np.real(w)))
        lam2, pi = float(np.real(w[j])), np.abs(np.real(V[:, j]))
    pi = pi / pi.sum()
    qs = 1.0 / (1.0 - lam2) - 1.0 if lam2 < 1 else math.inf
    return float(m[start] - 1.0), qs, lam2, m - 1.0, pi


def first_of_each_row(V: np.ndarray) -> np.ndarray:
    """Index of the first occurrence of each distinct row of the integer array ``V`` (k, d)
    (the ``index`` of ``np.unique(V, axis=0, return_index=True)``, in that order: the rows
    sorted lexicographically).

    Each row is packed into one int64 (mixed radix over the columns' ranges, the first
    column most significant, so the order is the lexicographic one) and the 1-D keys go
    through ``np.unique`` (a stable sort: first occurrences), much faster than the
    structured sort of ``axis=0``; rows whose ranges do not fit in 62 bits take
    ``axis=0``.  Returns shape (distinct rows,)."""
    V = np.asarray(V, dtype=np.int64)
    if V.ndim != 2 or V.shape[0] == 0:
        return np.unique(V, axis=0, return_index=True)[1]
    lo = V.min(axis=0)
    span = V.max(axis=0) - lo + 1
    if float(np.prod(span.astype(float))) >= 2.0 ** 62:
        return np.unique(V, axis=0, return_index=True)[1]
    key = np.zeros(V.shape[0], dtype=np.int64)
    for j in range(V.shape[1]):
        key = key * span[j] + (V[:, j] - lo[j])
    return np.unique(key, return_index=True)[1]


def voxel_nodes(Z: np.ndarray, cells: int) -> tuple[np.ndarray, float]:
    """One state per occupied voxel of side ``r``: ``(indices into Z, r)`` with ``r``
    bisected so that about ``cells`` voxels are occupied (row 0, the gait, always in).

    ``Z`` (k, d): the states in the whitened chart.  Nodes spread evenly over the visited
    region, so the tails (where the falls start) are meshed as finely as the core.  The
    indices have shape (c,); ``r`` is in standard deviations (dimensionless)."""
    lo, hi = 1e-3, 10.0
    best = None
    for _ in range(40):
        r = math.sqrt(lo * hi)
        idx = first_of_each_row(np.floor(Z / r).astype(np.int64))
        best = (idx, r) if best is None or abs(len(idx) - cells) < abs(len(best[0]) - cells) \
            else best
        if len(idx) > cells:
            lo = r
        else:
            hi = r
        if hi / lo < 1.001:
            break
    idx, r = best
    return np.unique(np.concatenate([[0], idx])), r


def mesh_mfpt(step_map: BatchStepMap, P: np.ndarray, idx: np.ndarray, W: np.ndarray,
              sd: float, quadrature: int = 21, evaluate=None, cache: dict | None = None,
              distribution: str = "normal") -> MeshResult:
    """MFPT on the Voronoi mesh of the nodes ``P[idx]`` (see the module docstring; Byl &
    Tedrake 2009).

    Parameters
    ----------
    P : ndarray (k, 2n)
        Candidate nodes (post-impact states); ``P[0]`` is the gait (the start).
    idx : ndarray of int (c,)
        The nodes of this mesh (``idx[0] == 0``).
    W : ndarray (2n, d)
        The metric (:func:`whitening`).
    sd : float
        Slope standard deviation [rad].
    quadrature : int
        Quadrature nodes of the slope distribution (:func:`slope_quadrature`).
    evaluate : callable ``(X (k, 2n), gamma (k,)) -> (x_next (k, 2n), ok (k,))``, optional
        How the images are computed (e.g. on worker processes); default ``step_map.step``.
    cache : dict, optional
        Images of candidates computed by earlier meshes (reused and extended).
    distribution : {"normal", "uniform"}
        Of the per-step slope.

    Returns
    -------
    MeshResult
        MFPTs in heel strikes [steps].

    Raises
    ------
    ValueError
        ``distribution`` is neither ``"normal"`` nor ``"uniform"`` (:func:`slope_quadrature`).
    """
    g, w = slope_quadrature(quadrature, step_map.slope_rad, sd, distribution)
    q = len(g)
    cache = {} if cache is None else cache
    if "x" not in cache:
        cache["x"] = np.full((len(P), q, P.shape[1]), np.nan)
        cache["ok"] = np.zeros((len(P), q), dtype=bool)
        cache["done"] = np.zeros(len(P), dtype=bool)
    new = idx[~cache["done"][idx]]
    if new.size:
        XX = np.repeat(P[new], q, axis=0)
        GG = np.tile(g, new.size)
        if evaluate is None:
            r = step_map.step(XX, GG)
            xn, ok = r.x_next, r.outcome == HEEL_STRIKE
        else:
            xn, ok = evaluate(XX, GG)
        cache["x"][new] = xn.reshape(new.size, q, -1)
        cache["ok"][new] = ok.reshape(new.size, q)
        cache["done"][new] = True
    Q, off, h = transition_matrix(cache["x"][idx], cache["ok"][idx], w, P[idx], W)
    m0, qs, lam2, m, pi = solve_mesh(Q, 0)
    return MeshResult(m0, qs, lam2, len(idx), h, float(pi @ off),
                      int(cache["done"].sum()) * q, m)


def mesh_mfpt_converged(step_map: BatchStepMap, pool: np.ndarray, x0: np.ndarray, sd: float,
                        cells: int = 1000, refine: float = 2.0, rel_change: float = 0.05,
                        max_cells: int = 16_000, quadrature: int = 21, evaluate=None,
                        distribution: str = "normal", cache: dict | None = None,
                        on_mesh=None) -> tuple[MeshResult, list[MeshResult]]:
    """Refine the mesh (``cells <- refine cells``: smaller voxels of the visited states
    ``pool`` (k, 2n) plus the gait ``x0``, :func:`voxel_nodes`) until the MFPT changes by
    less than ``rel_change`` between two meshes, or the pool or ``max_cells`` is exhausted
    (module docstring: a coarse mesh is biased, so its change is the stated error).

    ``cache`` (see :func:`mesh_mfpt`; rows of ``[x0, *pool]``) carries images computed
    before, e.g. by an interrupted run; ``on_mesh(result, cache)`` is called after each mesh
    (to store the images so far).

    Returns
    -------
    (last mesh, all meshes) ; ``last.converged`` says whether the criterion was met, and
    ``last.change`` is the relative change it was judged by (the mesh's stated error).
    """
    P = np.concatenate([np.asarray(x0, float)[None], np.asarray(pool, float)])
    W = whitening(P)
    Z = (P - P[0]) @ W
    cache = {} if cache is None else cache
    results: list[MeshResult] = []
    n = min(cells, len(P))
    while True:
        idx, r = voxel_nodes(Z, n)
        res = mesh_mfpt(step_map, P, idx, W, sd, quadrature, evaluate, cache, distribution)
        res.h = r
        results.append(res)
        if on_mesh is not None:
            on_mesh(res, cache)
        if len(results) >= 2:
            a, b = results[-2].mfpt_steps, res.mfpt_steps
            res.change = abs(b - a) / max(abs(b), 1e-300)
            if res.change < rel_change:
                res.converged = True
                return res, results
        if n >= min(max_cells, len(P)) or len(idx) >= 0.9 * len(P):
            return res, results
        n = min(int(round(refine * n)), max_cells, len(P))
