"""Metastability of a rigid walker on rough ground: the mean first-passage time (MFPT).

Byl & Tedrake (2009), "Metastable walking machines", IJRR 28(8): on ground whose slope is
drawn anew for every step, every passive walker eventually falls; the MFPT - here the expected
number of heel strikes before the fall, a walk that falls in its first step counting 0 - is
the measure.  Two estimates:

Monte Carlo (:func:`monte_carlo`)
    Many walks from the gait, slopes ``gamma_k ~ N(mean, sd)`` (or uniform) drawn from a
    per-walk random stream (``SeedSequence(seed, spawn_key=(walk,))``, so a walk's slopes do
    not depend on how walks are grouped), stepped together by
    :class:`walkerlab.analysis.batch_step.BatchStepMap`.  A fall is any step that does not
    end in heel strike (the hip reaches the ground, the swing leg falls back, scuffing, no
    heel strike within ``max_step_time_s``).  A walk that reaches the step cap is *censored*,
    not a fall: with ``S`` heel strikes in all and ``F`` falls, the censored geometric
    (exponential) maximum-likelihood estimate is ``MFPT = S / F`` with standard error
    ``sqrt(MFPT (MFPT + 1) / F)`` (Fisher information of the per-step fall probability
    ``p = F / (S + F)``, delta method).

Mesh (:func:`mesh_mfpt`)
    The post-impact section is meshed: the post-impact states of a walker on per-step slopes
    fill a set of dimension ``d`` (``2n - 1`` section coordinates plus the previous step's
    slope: ``d = 4`` for a compass walker; linear constraints such as a locked knee's reduce
    it).  The mesh lives in the principal axes of the stationary covariance of the linearised
    noisy map (``Sigma = A Sigma A^T + sd^2 b b^T``, ``A`` the Poincaré-map Jacobian from
    the variational equations, ``b = dP/dgamma``; :func:`scipy.linalg.solve_discrete_lyapunov`),
    in units of its standard deviations, as a lattice of spacing ``h`` inside the ball of
    radius ``R``: the mesh adapts to the gait and to the walker, whatever its states are
    called.  From each vertex the step map is taken at the Gauss-Hermite nodes of the slope
    distribution; an image is spread on the ``2^d`` vertices around it by multilinear
    weights (an image outside the ball is pulled back radially to it, and that probability
    is reported as ``escaped``), a fall goes to the absorbing state.  With ``Q`` the
    transition matrix among vertices (``scipy.sparse``), the quasi-stationary MFPT is
    ``1 / (1 - lambda_2) - 1`` (``lambda_2`` the largest eigenvalue of ``Q``,
    ``scipy.sparse.linalg.eigs``) and the expected heel strikes from each vertex solve
    ``(I - Q) m = 1`` (minus the falling step); the MFPT from the gait is ``m`` at the gait's
    vertex minus one.  A coarse mesh spreads probability toward the fall boundary and
    underestimates the MFPT: :func:`mesh_mfpt_converged` refines ``h`` until the MFPT changes
    by less than 5 %.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from walkerlab.analysis.batch_step import HEEL_STRIKE, BatchStepMap


def geometric_mle(heel_strikes: int, falls: int) -> tuple[float, float]:
    """Censored geometric MLE of the MFPT and its standard error.

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
    ``mean -/+ sqrt(3) sd``, the same standard deviation).
    """
    rng = np.random.default_rng(np.random.SeedSequence(int(seed), spawn_key=(int(walk),)))
    if distribution == "uniform":
        half = math.sqrt(3.0) * sd
        return rng.uniform(mean - half, mean + half, n)
    return mean + sd * rng.standard_normal(n)


@dataclass
class MonteCarloResult:
    """Monte Carlo walks on per-step slopes.

    Attributes
    ----------
    steps : ndarray of int, shape (walks,)
        Heel strikes of each walk.
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
                distribution: str = "normal", block: int = 64) -> MonteCarloResult:
    """Walk ``len(walks)`` walkers from ``x0`` on random per-step slopes until each falls or
    reaches ``max_steps`` heel strikes.

    Parameters
    ----------
    step_map : BatchStepMap
    x0 : ndarray, shape (2n,)
        Start (the gait's post-impact state).
    sd : float
        Standard deviation of the per-step slope [rad].
    walks : sequence of int
        Walk numbers (each has its own random stream, :func:`draw_slopes`).
    max_steps : int
        Step cap (censoring).
    seed : int
    mean : float, optional
        Mean slope [rad]; default the walker's.
    distribution : {"normal", "uniform"}

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
    slopes = np.empty((W, 0))
    for k in range(max_steps):
        if alive.size == 0:
            break
        j = k % block
        if j == 0:  # the next block of slopes of every walk (same numbers for any grouping)
            slopes = np.stack([draw_slopes(seed, w, k + block, mean, sd, distribution)[k:]
                               for w in walks])
        res = step_map.step(X[alive], slopes[alive, j])
        ok = res.outcome == HEEL_STRIKE
        steps[alive[ok]] += 1
        fell[alive[~ok]] = True
        X[alive[ok]] = res.x_next[ok]
        alive = alive[ok]
    return MonteCarloResult(steps, fell)


# -- the mesh ------------------------------------------------------------------------------

@dataclass
class MeshChart:
    """Coordinates of the mesh: ``x = x_ref + V (scale * u)``.

    Attributes
    ----------
    x_ref : ndarray (2n,)
        The gait's post-impact state.
    V : ndarray (2n, d)
        Principal axes of the stationary covariance (orthonormal columns).
    scale : ndarray (d,)
        Their standard deviations at the reference sd [rad, rad/s].
    """

    x_ref: np.ndarray
    V: np.ndarray
    scale: np.ndarray

    def to_state(self, U: np.ndarray) -> np.ndarray:
        return self.x_ref + (U * self.scale) @ self.V.T

    def to_chart(self, X: np.ndarray) -> np.ndarray:
        return ((X - self.x_ref) @ self.V) / self.scale


def slope_sensitivity(step_map: BatchStepMap, x_star: np.ndarray, h: float = 1e-6
                      ) -> np.ndarray:
    """``b = dP/dgamma`` (2n,) at the gait: central difference of the step map in the
    slope of the step (the map itself is exact to ~1e-11, so ~1e-5 relative)."""
    g = step_map.slope_rad
    r = step_map.step(np.tile(x_star, (2, 1)), np.array([g + h, g - h]))
    return (r.x_next[0] - r.x_next[1]) / (2 * h)


def chart_for(A: np.ndarray, b: np.ndarray, x_star: np.ndarray, sd: float,
              rank_tol: float = 1e-9, floor: float = 0.25) -> MeshChart:
    """Principal axes of ``Sigma = A Sigma A^T + sd^2 b b^T`` (shapes (2n, 2n), (2n,)),
    keeping the directions whose variance exceeds ``rank_tol`` times the largest.

    ``floor``: no axis is scaled below this fraction of the largest standard deviation (a
    thin direction of the linear covariance is where the map's curvature shows first: an
    axis scaled to its tiny linear spread would put every nonlinear image off the mesh)."""
    from scipy.linalg import solve_discrete_lyapunov

    S = solve_discrete_lyapunov(A, sd ** 2 * np.outer(b, b))
    S = 0.5 * (S + S.T)
    w, V = np.linalg.eigh(S)
    keep = w > rank_tol * w.max()
    w, V = w[keep][::-1], V[:, keep][:, ::-1]
    sdev = np.sqrt(w)
    return MeshChart(np.asarray(x_star, float), V, np.maximum(sdev, floor * sdev[0]))


def lattice(d: int, h: float, radius: float) -> np.ndarray:
    """Integer vertices ``i`` (k, d) with ``|h i| <= radius`` (the ball of the mesh)."""
    n = int(math.floor(radius / h))
    axes = np.arange(-n, n + 1)
    grid = np.stack(np.meshgrid(*([axes] * d), indexing="ij"), -1).reshape(-1, d)
    return grid[np.sum((h * grid) ** 2, axis=1) <= radius ** 2 + 1e-12]


@dataclass
class MeshResult:
    """One mesh.

    Attributes
    ----------
    mfpt_steps : float
        Expected heel strikes before the fall from the gait's vertex.
    mfpt_quasi_stationary_steps : float
        ``1 / (1 - lambda_2) - 1``.
    lambda2 : float
    cells : int
        Mesh vertices.
    h, radius : float
        Spacing and ball radius [standard deviations].
    escaped : float
        Share of the quasi-stationary fall rate that is probability leaving the ball
        (counted as falls).
    steps_evaluated : int
    """

    mfpt_steps: float
    mfpt_quasi_stationary_steps: float
    lambda2: float
    cells: int
    h: float
    radius: float
    escaped: float
    steps_evaluated: int
    expected_steps: np.ndarray = field(repr=False, default=None)
    #: relative change of ``mfpt_steps`` from the previous (coarser) mesh
    change: float = math.nan
    converged: bool = False


def gauss_hermite(n: int, mean: float, sd: float) -> tuple[np.ndarray, np.ndarray]:
    """Nodes [rad] and weights (sum 1) of the normal distribution N(mean, sd^2)
    (``numpy.polynomial.hermite_e.hermegauss``)."""
    from numpy.polynomial.hermite_e import hermegauss

    z, w = hermegauss(n)
    return mean + sd * z, w / w.sum()


def transition_matrix(images: np.ndarray, ok: np.ndarray, weights: np.ndarray,
                      verts: np.ndarray, chart: MeshChart, h: float, radius: float,
                      interpolation: str = "multilinear"):
    """Sparse transition matrix among vertices from the images of every vertex.

    Parameters
    ----------
    images : ndarray (k, q, 2n)
        Post-impact state from vertex ``i`` on slope node ``j``.
    ok : ndarray of bool (k, q)
        Heel strike (else a fall).
    weights : ndarray (q,)
    verts : ndarray of int (k, d)
    interpolation : {"multilinear", "nearest"}
        Spread an image on the ``2^d`` vertices of its cell (Byl & Tedrake's barycentric
        idea on a lattice), or put it on its nearest vertex.

    Returns
    -------
    Q : scipy.sparse.csr_matrix (k, k)
        Probability of going from vertex i to vertex j (rows sum to 1 - P(fall)).
    escaped : ndarray (k,)
        Probability of leaving the ball from each vertex.
    """
    import itertools

    from scipy.sparse import coo_matrix

    k, q, _ = images.shape
    d = verts.shape[1]
    index = {tuple(v): i for i, v in enumerate(verts.tolist())}
    rows, cols, vals = [], [], []
    escaped = np.zeros(k)
    src = np.repeat(np.arange(k), q)[ok.ravel()]
    wq = np.tile(weights, k)[ok.ravel()]
    U = chart.to_chart(images.reshape(k * q, -1)[ok.ravel()]) / h  # lattice units
    r = np.linalg.norm(U, axis=1) * h
    lim = radius - h * math.sqrt(d)  # every corner of a cell inside lim lies in the ball
    out = r > lim  # off the mesh: counted with the falls (absorbing), and reported
    np.add.at(escaped, src[out], wq[out])
    src, wq, U = src[~out], wq[~out], U[~out]
    if interpolation == "nearest":  # all of an image's weight on its nearest vertex
        tgt = np.array([index.get(tuple(v), -1) for v in np.rint(U).astype(int).tolist()])
        good = tgt >= 0
        np.add.at(escaped, src[~good], wq[~good])
        Q = coo_matrix((wq[good], (src[good], tgt[good])), shape=(k, k)).tocsr()
        return Q, escaped
    base = np.floor(U).astype(int)
    frac = U - base
    for corner in itertools.product((0, 1), repeat=d):
        c = np.array(corner)
        w = np.prod(np.where(c, frac, 1 - frac), axis=1) * wq
        tgt = [index.get(tuple(v)) for v in (base + c).tolist()]
        tgt = np.array([-1 if t is None else t for t in tgt])
        good = (tgt >= 0) & (w > 0)
        rows.append(src[good])
        cols.append(tgt[good])
        vals.append(w[good])
    Q = coo_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                   shape=(k, k)).tocsr()
    return Q, escaped


def solve_mesh(Q, start: int, escaped: np.ndarray | None = None):
    """``(mfpt from start, quasi-stationary mfpt, lambda_2, expected heel strikes (k,),
    escape share)`` of the absorbing chain with transient block ``Q`` (heel strikes =
    transitions - 1).  ``escape share``: the part of the quasi-stationary fall rate that is
    probability leaving the mesh (``escaped``, per vertex), NaN without it."""
    from scipy.sparse import identity
    from scipy.sparse.linalg import ArpackNoConvergence, eigs, spsolve

    k = Q.shape[0]
    m = spsolve((identity(k, format="csc") - Q.tocsc()), np.ones(k))
    try:  # the quasi-stationary distribution: left eigenvector of lambda_2
        lam, vec = eigs(Q.T.tocsr(), k=1, which="LM", maxiter=5000, tol=1e-10)
        lam2, pi = float(np.real(lam[0])), np.abs(np.real(vec[:, 0]))
    except ArpackNoConvergence:
        w, V = np.linalg.eig(Q.toarray().T)
        j = int(np.argmax(np.real(w)))
        lam2, pi = float(np.real(w[j])), np.abs(np.real(V[:, j]))
    pi = pi / pi.sum()
    share = math.nan
    if escaped is not None:
        fall = 1.0 - np.asarray(Q.sum(axis=1)).ravel()
        rate = float(pi @ fall)
        share = float(pi @ escaped) / rate if rate > 0 else 0.0
    qs = 1.0 / (1.0 - lam2) - 1.0 if lam2 < 1 else math.inf
    return float(m[start] - 1.0), qs, lam2, m - 1.0, share


def mesh_mfpt(step_map: BatchStepMap, chart: MeshChart, sd: float, h: float, radius: float,
              nodes: int = 15, evaluate=None) -> MeshResult:
    """MFPT on one mesh (see the module docstring).

    Parameters
    ----------
    chart : MeshChart
        From :func:`chart_for` (its ``scale`` at this sd).
    h, radius : float
        Lattice spacing and ball radius [standard deviations].
    nodes : int
        Gauss-Hermite nodes of the slope distribution.
    evaluate : callable ``(X (k, 2n), gamma (k,)) -> (x_next (k, 2n), ok (k,))``, optional
        How the images are computed (e.g. on worker processes); default ``step_map.step``.
    """
    verts = lattice(chart.V.shape[1], h, radius)
    g, w = gauss_hermite(nodes, step_map.slope_rad, sd)
    X = chart.to_state(verts * h)
    k, q = len(verts), len(g)
    XX = np.repeat(X, q, axis=0)
    GG = np.tile(g, k)
    if evaluate is None:
        r = step_map.step(XX, GG)
        xn, ok = r.x_next, r.outcome == HEEL_STRIKE
    else:
        xn, ok = evaluate(XX, GG)
    Q, esc = transition_matrix(xn.reshape(k, q, -1), ok.reshape(k, q), w, verts, chart, h,
                               radius)
    start = int(np.flatnonzero(np.all(verts == 0, axis=1))[0])
    m0, qs, lam2, m, share = solve_mesh(Q, start, esc)
    return MeshResult(m0, qs, lam2, k, h, radius, share, k * q, m)


def mesh_mfpt_converged(step_map: BatchStepMap, chart: MeshChart, sd: float,
                        radius: float = 4.0, h0: float = 1.0, refine: float = 0.75,
                        rel_change: float = 0.05, max_cells: int = 60_000, nodes: int = 15,
                        evaluate=None) -> tuple[MeshResult, list[MeshResult]]:
    """Refine the mesh (``h <- refine h``) until the MFPT changes by less than
    ``rel_change`` between two meshes, or the next mesh would exceed ``max_cells``.

    Returns
    -------
    (last mesh, all meshes) ; ``last.converged`` says whether the criterion was met, and
    ``last.change`` is the relative change it was judged by (the mesh's stated error).
    """
    d = chart.V.shape[1]
    results: list[MeshResult] = []
    h = h0
    while len(lattice(d, h, radius)) > max_cells:  # the first mesh fits the cap
        h /= refine
    while True:
        res = mesh_mfpt(step_map, chart, sd, h, radius, nodes, evaluate)
        results.append(res)
        if len(results) >= 2:
            a, b = results[-2].mfpt_steps, res.mfpt_steps
            res.change = abs(b - a) / max(abs(b), 1e-300)
            if res.change < rel_change:
                res.converged = True
                return res, results
        h *= refine
        if len(lattice(d, h, radius)) > max_cells:
            res.converged = False
            return res, results
