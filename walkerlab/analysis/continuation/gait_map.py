"""The map a continuation follows: a walker family, its ``k``-step Poincaré map and the
fixed-point residual on the heel-strike section,

    F(z, p) = section(P^k(from_section(z); p)) - z,

with ``F_z = D section . DP^k . D from_section - I`` exact (``DP`` from the variational
equations with saltation matrices at every guard,
:func:`walkerlab.integrate.rigid.integrate_step`) and ``F_p`` a central finite difference
in ``p`` (step ``1e-6 (1 + |p|)``; two plain maps), and the test functions of the special
points on the reduced Jacobian ``M = F_z + I`` (eigenvalues ``mu``, the Floquet
multipliers without the one that is zero by construction): fold ``det(M - I)``, period
doubling ``det(M + I)``, Neimark-Sacker ``prod_{i<j} (mu_i mu_j - 1)`` (the bialternate
product).  Used by :mod:`walkerlab.analysis.continuation.branch` and
:mod:`walkerlab.analysis.continuation.two_parameter`.

Nothing here knows a state's row: states are ``(2n,)`` arrays of the walker's
``state_names()``.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from walkerlab.integrate.rigid import integrate_step
from walkerlab.integrate.rigid_phase import numeric_jacobian
from walkerlab.integrate.solver import Solver
from walkerlab.models.hybrid.base import HybridWalker, OffSection
from walkerlab.numerics import without_neutral

__all__ = ["RESIDUAL_TOL", "BranchSystem", "MapFailed", "WalkerFamily", "critical_vector",
           "state_from_section", "step_map", "test_functions"]

#: a residual ``max |F|`` below this is a fixed point [rad, rad/s]
RESIDUAL_TOL = 1e-10


class MapFailed(RuntimeError):
    """The ``k``-step map failed; ``cause`` says why in the field's words."""

    def __init__(self, cause: str, detail: str = ""):
        super().__init__(f"{cause}{': ' + detail if detail else ''}")
        self.cause = cause



@dataclass
class WalkerFamily:
    """A walker as a function of one or more named numeric parameters.

    Attributes
    ----------
    make : callable ``dict[str, float] -> HybridWalker``
        Builds the walker for the parameter values (by name: the dotted scene fields,
        :func:`walkerlab.studies.continuation.scene_family`); raises :class:`MapFailed` when
        the values leave the model's domain.
    path : str
        Name of the continuation parameter (``slope.angle_deg``, ...).
    solver : Solver
    max_step_time : float
        A step longer than this is a failure [s].
    fixed : dict
        Other parameters held at a value (the second parameter of a two-parameter run).
    steps_per_map : int, optional
        Steps of every member's Poincaré map (None: each walker's own,
        ``walker.steps_per_map``).  A field that makes the legs differ away from one value
        (a hip spring's rest angle from 0, one leg's mass from the other's) would switch
        the map from a step to a stride there; :meth:`sharing_map` fixes the stride for
        the whole family.
    """

    make: Callable[[dict], HybridWalker]
    path: str
    solver: Solver
    max_step_time: float = 5.0
    fixed: dict = field(default_factory=dict)
    steps_per_map: int | None = None
    _cache: dict = field(default_factory=dict, repr=False)

    def steps(self, walker: HybridWalker) -> int:
        """Steps of the Poincaré map of the member ``walker``."""
        return self.steps_per_map or walker.steps_per_map

    def sharing_map(self, values) -> WalkerFamily:
        """This family with one map for every member: a stride when the walker at any of
        ``values`` (the range's ends and start) has legs that differ, else a step."""
        steps = 1
        for v in values:
            try:
                steps = max(steps, self.walker(v).steps_per_map)
            except MapFailed:
                continue
        return dataclasses.replace(self, steps_per_map=steps, _cache={})

    def walker(self, p: float) -> HybridWalker:
        """The walker at ``p`` (built once per value).

        Raises
        ------
        MapFailed
            ``p`` leaves the model's domain.
        """
        key = float(p)
        w = self._cache.get(key)
        if w is None:
            w = self.make({self.path: key, **self.fixed})
            if len(self._cache) > 64:
                self._cache.clear()
            self._cache[key] = w
        return w

    def at(self, **fixed) -> WalkerFamily:
        """This family with more parameters held fixed (by name)."""
        return dataclasses.replace(self, fixed={**self.fixed, **fixed}, _cache={})


def _cause(walker: HybridWalker, seg) -> str:
    """The reason a step did not end in heel strike, in the field's words."""
    names = [g.name for ph in walker.phases for g in ph.guards]
    if seg.termination == "no_heel_strike":
        return "no heel strike (the walker does not move)"
    if seg.termination == "t_final":
        return "no heel strike within the step time limit"
    if seg.termination == "solver_failure":
        return "integrator failure"
    if "knee_strike" in names and "knee_strike" not in seg.phase_times:
        return f"knee strike lost ({seg.event})"
    if seg.event == "swing_foot_scuffs":
        return "swing foot scuffing"
    if seg.event == "swing_leg_falls_back":
        return "no heel strike (the swing leg falls back)"
    return f"fall ({seg.event})" if seg.event not in ("", None, "fall") else "fall"


def step_map(walker: HybridWalker, x: np.ndarray, solver: Solver, k: int = 1,
             jacobian: bool = False, max_step_time: float = 5.0, segments: bool = False,
             steps_per_map: int | None = None):
    """The ``k``-step Poincaré map ``P^k`` and (optionally) its Jacobian (variational
    equations with saltation matrices at every guard; :mod:`walkerlab.integrate.rigid`).

    Parameters
    ----------
    x : ndarray (2n,)
        State just after heel strike (role-ordered, ``walker.state_names()``; [rad],
        [rad/s]).
    k : int
        Maps composed (1: the Poincaré map, 2: its square, ...); a map is one step, or one
        stride (two steps) for a walker whose legs differ (``walker.steps_per_map``).
    jacobian : bool
        Also ``D(P^k)`` (2n, 2n), the product of the steps' variational Jacobians (with
        saltation matrices).
    steps_per_map : int, optional
        Steps of one map (default ``walker.steps_per_map``; a family's common map,
        :meth:`WalkerFamily.steps`).

    Returns
    -------
    x_k : ndarray (2n,)
    period : float
        Sum of the ``k`` step periods [s].
    J : ndarray (2n, 2n) or None
    segs : list of Segment, only with ``segments=True``

    Raises
    ------
    MapFailed
        A step did not end in heel strike (``cause``: fall, no heel strike, scuffing, knee
        strike lost, ...), or the state is not finite.
    """
    x = np.asarray(x, float)
    if not np.all(np.isfinite(x)):
        raise MapFailed("section coordinates leave their domain", "non-finite state")
    J = np.eye(x.size) if jacobian else None
    T = 0.0
    segs = []
    legs = walker.legs
    for i in range(k * (steps_per_map or walker.steps_per_map)):  # legs that differ: a stride
        stance = legs[1] if i % 2 == 0 else legs[0]
        seg = integrate_step(walker.for_stance(stance), x, solver, max_step_time=max_step_time,
                             variational=jacobian, stance_leg=stance)
        if seg.termination != "heel_strike":
            raise MapFailed(_cause(walker, seg), seg.message)
        if jacobian:
            J = seg.monodromy @ J
        T += seg.period
        x = seg.x_next
        segs.append(seg)
    out = (x, T, J)
    return (*out, segs) if segments else out


def state_from_section(walker: HybridWalker, z: np.ndarray) -> np.ndarray:
    """The state (2n,) of the section coordinates ``z`` (m,) (``walker.from_section``; the
    state in ``walker.state_names()`` order, [rad] and [rad/s]).

    Raises
    ------
    MapFailed
        ``z`` leaves the section's domain (no state on the heel-strike surface there,
        :class:`~walkerlab.models.hybrid.base.OffSection`, or a non-finite state).
    """
    with np.errstate(all="ignore"):
        try:
            x = np.asarray(walker.from_section(np.asarray(z, float)), float)
        except (ValueError, ArithmeticError, OffSection) as exc:
            raise MapFailed("section coordinates leave their domain", str(exc)) from None
    if not np.all(np.isfinite(x)):
        raise MapFailed("section coordinates leave their domain", "non-finite state")
    return x


class BranchSystem:
    """``F(z, p)`` of the period-``k`` branch with memoised maps (one per iterate);
    ``p_scale`` is the parameter's scale in the arclength (``u = (z, p / p_scale)``), in the
    parameter's unit; ``z`` (m,) are section coordinates [rad, rad/s].

    Attributes
    ----------
    n_maps, n_variational : int
        Steps integrated so far without / with the variational equations.
    """

    def __init__(self, family: WalkerFamily, k: int, p_scale: float):
        self.family, self.k, self.p_scale = family, k, p_scale
        self.n_maps = 0
        self.n_variational = 0
        self._last: dict = {}
        self._held: tuple | None = None  # the neutral coordinates: positions, values

    def _hold(self, w: HybridWalker, z: np.ndarray, r: np.ndarray) -> np.ndarray:
        """A walker's neutral coordinates (:attr:`HybridWalker.neutral`, the 3D wheel's
        heading: its gaits form a family along it) held at their first iterate's values:
        their equations of ``F`` (singular along the family) replaced by ``z_i - z_i0``, so
        the branch follows the parameter, not the family."""
        if not w.neutral:
            return r
        if self._held is None:
            pos = w.neutral_in_section()
            self._held = (pos, np.asarray(z, float)[pos].copy())
        pos, val = self._held
        r = np.asarray(r, float).copy()
        r[pos] = np.asarray(z, float)[pos] - val
        return r

    def residual(self, z: np.ndarray, p: float) -> np.ndarray:
        """``F(z, p) = section(P^k(from_section(z); p)) - z`` (m,) [rad, rad/s] (module
        docstring); the last one is memoised.

        Raises
        ------
        MapFailed
            A step did not end in heel strike, or ``z`` leaves the section's domain.
        """
        key = (np.asarray(z, float).tobytes(), float(p))
        if key in self._last:
            return self._last[key].copy()
        w = self.family.walker(p)
        x = state_from_section(w, z)
        xk, _, _ = step_map(w, x, self.family.solver, self.k,
                            steps_per_map=self.family.steps(w),
                            max_step_time=self.family.max_step_time)
        self.n_maps += self.k
        r = self._hold(w, z, np.asarray(w.section(xk), float) - z)
        self._last.clear()
        self._last[key] = r
        return r.copy()

    def dp(self, z: np.ndarray, p: float) -> np.ndarray:
        """``dF/dp`` (m,) by central differences (step ``1e-6 (1 + |p|)``); one-sided next
        to a branch end, where the map fails on one side.  Unit: the section's [rad, rad/s]
        per unit of ``p``.

        Raises
        ------
        MapFailed
            The map fails on both sides of ``p``.
        """
        h = 1e-6 * (1.0 + abs(p))
        try:
            up = self.residual(z, p + h)
        except MapFailed:
            return (self.residual(z, p) - self.residual(z, p - h)) / h
        try:
            return (up - self.residual(z, p - h)) / (2 * h)
        except MapFailed:
            return (up - self.residual(z, p)) / h

    def full(self, z: np.ndarray, p: float) -> dict:
        """Everything at ``(z, p)``: state, period, ``D(P^k)``, ``F_z``, reduced ``M``.

        Returns
        -------
        dict
            ``x`` (2n,) [rad, rad/s], ``period`` [s], ``J`` = ``D(P^k)`` (2n, 2n), ``M`` =
            ``D section . J . D from_section`` (m, m), ``Fz`` = ``M - I``, ``orbit`` (k, 2n)
            the post-impact states of the ``k`` steps, ``F`` (m,) the residual, ``walker``.

        Raises
        ------
        MapFailed
            As :meth:`residual`.
        """
        w = self.family.walker(p)
        x = state_from_section(w, z)
        xk, T, J, segs = step_map(w, x, self.family.solver, self.k, jacobian=True,
                                  steps_per_map=self.family.steps(w),
                                  max_step_time=self.family.max_step_time, segments=True)
        self.n_variational += self.k
        try:  # its difference steps may leave the surface next to the branch's end
            D_from = numeric_jacobian(w.from_section, np.asarray(z, float))
        except (ValueError, ArithmeticError, OffSection) as exc:
            raise MapFailed("section coordinates leave their domain", str(exc)) from None
        D_sec = numeric_jacobian(w.section, np.asarray(xk, float))
        M = D_sec @ J @ D_from
        Fz = M - np.eye(z.size)
        pos = w.neutral_in_section()  # their equations held (:meth:`_hold`): unit rows
        Fz[pos, :] = 0.0
        Fz[pos, pos] = 1.0
        return {"x": x, "period": T, "J": J, "M": M, "Fz": Fz,
                "orbit": np.array([sg.x_start for sg in segs]),
                "F": self._hold(w, z, np.asarray(w.section(xk), float) - z), "walker": w}


def test_functions(M: np.ndarray, neutral: int = 0) -> dict:
    """Fold, period-doubling and Neimark-Sacker test functions of the reduced Jacobian.

    ``det(M - I)``, ``det(M + I)`` and the bialternate product ``prod_{i<j} (mu_i mu_j -
    1)`` (Kuznetsov, "Elements of Applied Bifurcation Theory", 3rd ed. 2004, ch. 10;
    module docstring).

    Parameters
    ----------
    M : ndarray, shape (m, m)
        Reduced Jacobian ``F_z + I`` (dimensionless in the section's coordinates).
    neutral : int
        Multipliers that are 1 on the whole branch (a walker's neutral coordinates, the 3D
        wheel's heading): the ``neutral`` nearest 1 are left out of the three products
        (``prod (mu_i - 1)`` for the fold, ``prod (mu_i + 1)``), else the fold's would be 0
        everywhere.

    Returns
    -------
    dict
        ``fold``, ``period_doubling``, ``neimark_sacker`` (float, [-]) and ``mu`` (the
        eigenvalues, complex ndarray of shape (m,)).
    """
    mu = np.linalg.eigvals(M)
    if neutral:
        keep = without_neutral(mu, neutral)
        m = keep.size
        pairs = [(i, j) for i in range(m) for j in range(i + 1, m)]
        prod = np.array([keep[i] * keep[j] for i, j in pairs]) if pairs else np.zeros(0)
        return {"fold": float(np.prod(keep - 1.0).real),
                "period_doubling": float(np.prod(keep + 1.0).real),
                "neimark_sacker": float(np.prod(prod - 1.0).real) if pairs else 1.0,
                "mu": mu}
    m = mu.size
    pairs = [(i, j) for i in range(m) for j in range(i + 1, m)]
    prod = np.array([mu[i] * mu[j] for i, j in pairs]) if pairs else np.zeros(0)
    ns = float(np.prod(prod - 1.0).real) if pairs else 1.0
    return {"fold": float(np.linalg.det(M - np.eye(m))),
            "period_doubling": float(np.linalg.det(M + np.eye(m))),
            "neimark_sacker": ns, "mu": mu}



def critical_vector(M: np.ndarray, target: complex) -> tuple[np.ndarray, complex]:
    """The unit eigenvector of ``M`` whose eigenvalue lies nearest ``target`` (real when the
    eigenvalue is), and that eigenvalue.

    Parameters
    ----------
    M : ndarray, shape (m, m)
    target : complex
        E.g. -1 for a period doubling, +1 for a fold (Floquet multipliers).

    Returns
    -------
    (v, mu) : ndarray of shape (m,) (real or complex), complex
    """
    mu, V = np.linalg.eig(M)
    i = int(np.argmin(np.abs(mu - target)))
    v = V[:, i].real if abs(mu[i].imag) < 1e-12 else V[:, i]
    return v / np.linalg.norm(v), mu[i]
