"""Bifurcation diagram of the ideal (rigid) walker over the slope (Goswami et al. 1996).

For each slope ``phi`` of a grid:

1. the period-1 fixed point and its Floquet multipliers (continuation from the neighbouring
   slope's fixed point);
2. the steady state: ``n_transient`` steps are simulated and the inter-leg angle at the last
   ``n_keep`` heel strikes is kept (the classic cascade plot).  The simulation starts from
   the previous slope's final state projected on this slope's heel-strike surface
   (attractor continuation), or from the period-1 fixed point slightly perturbed.

The period-doubling onset is where the most negative real multiplier crosses -1; it is
bracketed on the grid and located with :func:`scipy.optimize.brentq` on
``g(phi) = 1 + min real multiplier(phi)``.

Grid chunks (the runs up and down from the scene's slope) are evaluated with the sweep
executors (:func:`walkerlab.sweep.runner.iter_chunk_results`), locally or on Dask.  Arrays
are sized by the walker (``walker.state_names()``); the cached stage that writes the
artifact is :mod:`walkerlab.stages.bifurcation`.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.optimize import brentq

from walkerlab.config import Scene
from walkerlab.sweep.params import ParamAxis
from walkerlab.sweep.runner import iter_chunk_results, plan_chunks

__all__ = ["BifurcationResult", "bifurcation_diagram", "locate_period_doubling",
           "min_real_multiplier", "bifurcation_writer", "load_bifurcation"]


@dataclass(frozen=True)
class _BifTask:
    base: dict
    points: tuple            # ((index, (slope_deg,)), ...)
    n_transient: int
    n_keep: int
    steady_state: bool


def _scene_at(base: dict, slope_deg: float) -> Scene:
    from walkerlab.sweep.params import apply_point

    return apply_point(base, ["slope.angle_deg"], (slope_deg,), "<bifurcation>")


def min_real_multiplier(mult: np.ndarray, tol: float = 1e-9) -> float:
    """Most negative real Floquet multiplier (``|imag| <= tol``) of a set [-]."""
    mult = np.asarray(mult, complex)
    real = mult[np.abs(mult.imag) <= tol].real
    return float(real.min()) if real.size else math.nan


def _rate_nudge(walker, size: float) -> np.ndarray:
    """A state offset of ``size`` [rad/s] on the stance rate (by name), to leave the fixed point."""
    names = walker.state_names()
    dx = np.zeros(len(names))
    dx[names.index("stance_rate") if "stance_rate" in names else
       [k for k, n in enumerate(names) if n.endswith("_rate")][-1]] = size
    return dx


def _stance_angle(walker, x: np.ndarray) -> float:
    """The ``stance_angle`` state of ``x`` [rad] (NaN for a walker without one)."""
    names = walker.state_names()
    return float(x[names.index("stance_angle")]) if "stance_angle" in names else math.nan


def _bif_chunk(task: _BifTask) -> list[dict]:
    """Fixed point + steady state along one run of slopes (worker side)."""
    import warnings

    from walkerlab.analysis.hybrid import Solver, simulate_steps
    from walkerlab.models.registry import build_walker
    from walkerlab.sweep.points import _Outcome, ideal_fixed_point, interleg_angle, warm_up

    warm_up()
    out = []
    guess = None
    x_att = None
    for index, (slope,) in task.points:
        t0 = time.perf_counter()
        n = len(build_walker(_scene_at(task.base, slope)).state_names())
        row = {"index": index, "slope_deg": slope, "x": np.full(n, np.nan),
               "multipliers": np.full(n, np.nan, complex), "period_s": math.nan,
               "fp_outcome": "ok", "message": "", "hs_interleg": np.full(task.n_keep, np.nan),
               "hs_stance": np.full(task.n_keep, np.nan), "ss_outcome": "", "steps": 0}
        with warnings.catch_warnings(), np.errstate(all="ignore"):
            warnings.simplefilter("ignore")
            scene = _scene_at(task.base, slope)
            try:
                walker, res, _src = ideal_fixed_point(scene, guess)
                guess = res.x
                row.update(x=res.x, multipliers=np.asarray(res.multipliers_variational, complex),
                           period_s=res.period_s)
            except _Outcome as exc:
                row.update(fp_outcome=exc.outcome, message=exc.message)
                walker = build_walker(scene)
            except Exception as exc:  # noqa: BLE001
                row.update(fp_outcome="error", message=f"{type(exc).__name__}: {exc}")
                walker = build_walker(scene)
            if task.steady_state:
                if x_att is not None:
                    x0 = walker.from_section(walker.section(x_att))
                elif row["fp_outcome"] == "ok":
                    x0 = row["x"] + _rate_nudge(walker, 1e-6)
                    x0 = walker.from_section(walker.section(x0))
                else:
                    x0 = None
                if x0 is not None:
                    try:
                        traj = simulate_steps(walker, x0, task.n_transient,
                                              Solver.from_settings(scene.solver),
                                              max_step_time=5.0)
                        segs = [s for s in traj.segments if s.termination == "heel_strike"]
                        row["steps"] = len(segs)
                        row["ss_outcome"] = traj.termination
                        if len(segs) == task.n_transient:
                            keep = segs[-task.n_keep:]
                            row["hs_interleg"] = np.array([interleg_angle(walker, s.x_end)
                                                           for s in keep])
                            row["hs_stance"] = np.array([_stance_angle(walker, s.x_next)
                                                         for s in keep])
                            x_att = segs[-1].x_next
                            row["ss_outcome"] = "walks"
                        else:
                            x_att = None
                    except Exception as exc:  # noqa: BLE001
                        row["ss_outcome"] = f"error: {type(exc).__name__}"
                        x_att = None
        row["wall_time_s"] = time.perf_counter() - t0
        out.append(row)
    return out


def _g(scene_base: dict, slope_deg: float, guess) -> tuple[float, np.ndarray]:
    from walkerlab.sweep.points import ideal_fixed_point

    _w, res, _s = ideal_fixed_point(_scene_at(scene_base, slope_deg), guess)
    return 1.0 + min_real_multiplier(res.multipliers_variational), res.x


def locate_period_doubling(base: dict, slopes_deg: np.ndarray, mult: np.ndarray,
                           x: np.ndarray, xtol_deg: float = 1e-4) -> dict:
    """Slope where the most negative real multiplier crosses -1 (first crossing upward).

    Parameters
    ----------
    base : dict
        Base scene mapping.
    slopes_deg : ndarray (n,)
        Grid slopes [deg], increasing.
    mult : ndarray (n, 2m) complex
        Floquet multipliers at the grid slopes (NaN where no fixed point); 2m states.
    x : ndarray (n, 2m)
        Fixed points (continuation guesses for the refinement).
    xtol_deg : float
        brentq tolerance on the slope [deg].

    Returns
    -------
    dict
        ``onset_deg`` (NaN if no crossing), ``bracket_deg`` (2,), ``multiplier_at_onset``,
        ``evaluations``.
    """
    g = np.array([1.0 + min_real_multiplier(m) if np.all(np.isfinite(m)) else math.nan
                  for m in mult])
    g = np.where(np.isnan(g) & np.all(np.isfinite(mult), axis=1), 1.0, g)  # complex pair: > -1
    for k in range(len(g) - 1):
        if g[k] > 0 and g[k + 1] <= 0:
            lo, hi = float(slopes_deg[k]), float(slopes_deg[k + 1])
            state = {"guess": x[k], "n": 0}

            def f(s, state=state):
                val, xs = _g(base, s, state["guess"])
                state["n"] += 1
                state["guess"] = xs
                return val

            if g[k + 1] == 0:
                onset = hi
            else:
                onset = brentq(f, lo, hi, xtol=xtol_deg)
            return {"onset_deg": float(onset), "bracket_deg": np.array([lo, hi]),
                    "multiplier_at_onset": float(f(onset) - 1.0), "evaluations": state["n"]}
    return {"onset_deg": math.nan, "bracket_deg": np.array([math.nan, math.nan]),
            "multiplier_at_onset": math.nan, "evaluations": 0}


@dataclass
class BifurcationResult:
    """Bifurcation diagram data (all arrays along the slope grid, ``n`` slopes).

    Attributes
    ----------
    slopes_deg : ndarray (n,)
        Slopes [deg].
    state_names, state_units : list of str (2m,)
        The walker's state names and units (columns of ``fixed_point``).
    fixed_point : ndarray (n, 2m)
        Period-1 fixed point just after heel strike (NaN if none).
    fixed_point_interleg_deg : ndarray (n,)
        Inter-leg angle of the fixed point [deg] (see
        :func:`walkerlab.sweep.points.interleg_angle`).
    multipliers : ndarray (n, 2m) complex
        Floquet multipliers (variational), sorted by modulus.
    step_period_s : ndarray (n,)
        Period-1 step period [s].
    fp_outcome : ndarray (n,) str
        Typed outcome of the fixed-point search.
    interleg_deg : ndarray (n, n_keep)
        Inter-leg angle at the last ``n_keep`` heel strikes of the steady state [deg].
    stance_after_deg : ndarray (n, n_keep)
        Stance-leg angle just after those impacts [deg].
    ss_outcome : ndarray (n,) str
        ``walks`` or how the steady-state run ended (``fall``, ...).
    attractor_period : ndarray (n,) int
        Distinct values among the kept heel strikes (1, 2, 4, ...; 0 if none; n_keep = chaos).
    onset : dict
        See :func:`locate_period_doubling`.
    wall_time_s : ndarray (n,)
        Per-slope wall time [s].
    n_transient, n_keep : int
    """

    slopes_deg: np.ndarray
    state_names: list
    state_units: list
    fixed_point: np.ndarray
    fixed_point_interleg_deg: np.ndarray
    multipliers: np.ndarray
    step_period_s: np.ndarray
    fp_outcome: np.ndarray
    interleg_deg: np.ndarray
    stance_after_deg: np.ndarray
    ss_outcome: np.ndarray
    attractor_period: np.ndarray
    onset: dict
    wall_time_s: np.ndarray
    n_transient: int
    n_keep: int


def _distinct(v: np.ndarray, tol: float = 1e-4) -> int:
    v = np.sort(v[np.isfinite(v)])
    if v.size == 0:
        return 0
    return int(1 + np.sum(np.diff(v) > tol))


def bifurcation_diagram(scene: Scene, slopes_deg, n_transient: int = 100, n_keep: int = 30,
                        workers: int = 2, scheduler=None, steady_state: bool = True,
                        xtol_deg: float = 1e-4) -> BifurcationResult:
    """Compute the bifurcation diagram of the scene's rigid walker over the slope.

    Parameters
    ----------
    scene : Scene
        Walker, solver and ``fixedpoint`` settings (its slope anchors the continuation).
    slopes_deg : array_like (n,)
        Slopes [deg], increasing.
    n_transient : int
        Steps simulated per slope (transient + kept).
    n_keep : int
        Last heel strikes kept per slope.
    workers, scheduler
        As for :func:`walkerlab.sweep.runner.iter_chunk_results`.
    steady_state : bool
        Also simulate the steady state (False: fixed points and onset only).
    xtol_deg : float
        Onset tolerance [deg].

    Returns
    -------
    BifurcationResult
    """
    slopes = np.asarray(slopes_deg, float)
    axis = ParamAxis("slope.angle_deg", tuple(float(s) for s in slopes), "bifurcation")
    base = scene.model_dump(mode="json")
    chunks = plan_chunks([axis], base, workers=max(1, workers))
    tasks = [_BifTask(base, tuple(c), n_transient, n_keep, steady_state) for c in chunks]
    from walkerlab import progress

    rows = []
    with progress.task(f"bifurcation: {slopes.size} slopes", slopes.size) as bar:
        for rs in iter_chunk_results(tasks, workers, scheduler, fn=_bif_chunk):
            rows += rs
            bar.update(len(rows))
    rows.sort(key=lambda r: r["index"])
    x = np.array([r["x"] for r in rows])
    mult = np.array([r["multipliers"] for r in rows])
    onset = locate_period_doubling(base, slopes, mult, x, xtol_deg)
    il = np.degrees(np.array([r["hs_interleg"] for r in rows]))
    from walkerlab.models.registry import build_walker
    from walkerlab.sweep.points import interleg_angle

    walker = build_walker(scene)
    fp_il = np.degrees([interleg_angle(walker, xi) if np.all(np.isfinite(xi)) else math.nan
                        for xi in x])
    return BifurcationResult(
        slopes_deg=slopes, state_names=walker.state_names(), state_units=walker.state_units(),
        fixed_point=x, fixed_point_interleg_deg=fp_il, multipliers=mult,
        step_period_s=np.array([r["period_s"] for r in rows]),
        fp_outcome=np.array([r["fp_outcome"] for r in rows], object),
        interleg_deg=il, stance_after_deg=np.degrees(np.array([r["hs_stance"] for r in rows])),
        ss_outcome=np.array([r["ss_outcome"] for r in rows], object),
        attractor_period=np.array([_distinct(np.radians(v)) for v in il]),
        onset=onset, wall_time_s=np.array([r["wall_time_s"] for r in rows]),
        n_transient=n_transient, n_keep=n_keep)


def bifurcation_writer(res: BifurcationResult):
    """``writer(h5file)`` filling a ``bifurcation`` artifact (netCDF dimensions ``slope``,
    ``multiplier``, ``heel_strike``; units on every dataset)."""
    from walkerlab.io.artifacts import put
    from walkerlab.io.netcdf import coordinate

    def writer(f):
        coordinate(f, "slope", res.slopes_deg, "deg", "slope grid")
        coordinate(f, "multiplier", np.arange(res.multipliers.shape[1]), "-",
                   "Floquet multiplier number (sorted by modulus)")
        coordinate(f, "heel_strike", np.arange(res.n_keep), "-",
                   f"kept heel strike (last {res.n_keep} of {res.n_transient})")
        f.attrs["state_names"] = list(res.state_names)
        s = ("slope",)
        for k, (n, u) in enumerate(zip(res.state_names, res.state_units)):
            put(f, f"fixed_point/{n}", res.fixed_point[:, k], u,
                f"period-1 fixed point, {n} just after heel strike", dims=s)
        put(f, "fixed_point/interleg_angle", res.fixed_point_interleg_deg, "deg",
            "inter-leg angle of the period-1 fixed point", dims=s)
        put(f, "fixed_point/step_period", res.step_period_s, "s", "period-1 step period", dims=s)
        put(f, "fixed_point/outcome", [str(o) for o in res.fp_outcome], "-",
            "typed outcome of the fixed-point search", dims=s)
        sm = ("slope", "multiplier")
        put(f, "floquet/real", res.multipliers.real, "-", "Floquet multipliers, real part",
            dims=sm)
        put(f, "floquet/imag", res.multipliers.imag, "-", "Floquet multipliers, imaginary part",
            dims=sm)
        sh = ("slope", "heel_strike")
        put(f, "steady_state/interleg_angle", res.interleg_deg, "deg",
            f"inter-leg angle at the last {res.n_keep} of {res.n_transient} heel strikes",
            dims=sh)
        put(f, "steady_state/stance_angle_after_impact", res.stance_after_deg, "deg",
            "stance-leg angle just after those impacts", dims=sh)
        put(f, "steady_state/outcome", [str(o) for o in res.ss_outcome], "-",
            "'walks' or how the steady-state run ended", dims=s)
        put(f, "steady_state/attractor_period", res.attractor_period, "steps",
            "distinct kept values (1, 2, 4, ...; n_keep: no period found)", dims=s)
        put(f, "onset/onset_slope", res.onset["onset_deg"], "deg",
            "period-doubling onset: a multiplier crosses -1 (brentq)")
        put(f, "onset/bracket", res.onset["bracket_deg"], "deg", "grid bracket of the onset",
            dims=("bracket_end",))
        put(f, "onset/multiplier_at_onset", res.onset["multiplier_at_onset"], "-",
            "most negative real multiplier at the located onset")
        put(f, "stats/wall_time", res.wall_time_s, "s", "wall time per slope", dims=s)
        f.attrs["n_transient"] = res.n_transient
        f.attrs["n_keep"] = res.n_keep

    return writer


def load_bifurcation(path: Path) -> dict:
    """Arrays of a ``bifurcation`` artifact as a dict (names as in the file)."""
    from walkerlab.io.artifacts import open_artifact, read_named

    out = {}
    with open_artifact(Path(path), "bifurcation") as f:
        def visit(name, obj):
            import h5py

            if isinstance(obj, h5py.Dataset):
                out[name] = read_named(f, name)

        f.visititems(visit)
    return out
