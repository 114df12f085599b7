"""Metastability of a rigid walker on rough ground: the mean first-passage time (MFPT).

Byl & Tedrake (2009), "Metastable walking machines", IJRR 28(8): on ground whose slope is
drawn anew for every step, every passive walker eventually falls; the MFPT - here the expected
number of heel strikes before the fall, a walk that falls in its first step counting 0 - is
the measure.  Two estimates:

Monte Carlo (:func:`monte_carlo`)
    Many walks from the gait, slopes ``gamma_k ~ N(mean, sd)`` (or uniform) drawn from a
    per-walk random stream (``SeedSequence(seed, spawn_key=(walk,))``, so a walk's slopes do
    not depend on how walks are grouped), stepped together by
    :class:`walkerlab.integrate.batch_step.BatchStepMap`.  A fall is any step that does not
    end in heel strike (the hip reaches the ground, the swing leg falls back, scuffing, no
    heel strike within ``max_step_time_s``).  A walk that reaches the step cap is *censored*,
    not a fall: with ``S`` heel strikes in all and ``F`` falls, the censored geometric
    (exponential) maximum-likelihood estimate is ``MFPT = S / F`` with standard error
    ``sqrt(MFPT (MFPT + 1) / F)`` (Fisher information of the per-step fall probability
    ``p = F / (S + F)``, delta method).

Mesh (:func:`mesh_mfpt`)
    The post-impact section is meshed where the walker actually goes (Byl & Tedrake's
    "reachable" mesh): the nodes are post-impact states visited by noisy walks from the gait
    at ``sd`` and ``1.5 sd`` (:func:`visited_states`), thinned to one per voxel
    of a lattice in the whitened coordinates of that cloud (:func:`whitening`,
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
