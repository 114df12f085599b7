"""Work-precision benchmark of the contact walker (integrators x tolerances).

:func:`run_benchmark` integrates the paper walker for ``n_strides`` strides with each method
and tolerance, and reports wall time, RHS / Jacobian evaluations and the maximum leg-angle
error against a tight reference (odeint, rtol 1e-12, checked against Radau in the tests).
"""

from __future__ import annotations

import dataclasses
import time

import numpy as np

from walkerlab.analysis.contact.sim import initial_state_from_ideal, simulate_contact
from walkerlab.config.contact import ContactSettings
from walkerlab.config.solver import SolverSettings
from walkerlab.config.terrain import TerrainSettings
from walkerlab.models.contact.model import ContactWalker
from walkerlab.walker.layout import StateIndex
from walkerlab.walker.plant import Plant

__all__ = ["BAND_FACTORS", "EXAMPLE_IDEAL", "SCAN_RTOLS", "TARGET_RTOLS", "leg_angle_columns",
           "rhs_cost", "run_benchmark", "run_scene_benchmark"]

#: Benchmark inputs only (approximate ideal fixed point of the paper walker on phi = 0.0174
#: rad, leg1 swing / leg2 stance): the lead supplies exact values at run time.
EXAMPLE_IDEAL = {"theta1": -0.2042, "theta2": 0.1694, "dtheta1": -0.6058, "dtheta2": -0.8610,
                 "step_length": 0.372, "step_period": 0.7036}


def leg_angle_columns(walker) -> list[int]:
    """State columns of the walker's leg angles: every generalised coordinate but the hip
    position (``hip_x``, ``hip_y``), by name."""
    idx = StateIndex(walker)
    return [i for i in range(idx.coordinates.start, idx.coordinates.stop)
            if idx.names[i] not in ("hip_x", "hip_y")]


def rhs_cost(walker: ContactWalker, x: np.ndarray, n: int = 2000) -> dict:
    """Mean cost [µs] per call of the generated numba RHS and Jacobian (through the walker's
    Python methods)."""
    out = {}
    for name, fn, reps in (("rhs_numba_us", walker.rhs, n), ("jac_numba_us", walker.jac, n)):
        fn(0.0, x)
        t = time.perf_counter()
        for _ in range(reps):
            fn(0.0, x)
        out[name] = (time.perf_counter() - t) / reps * 1e6
    return out


def _default_methods() -> tuple:
    """odeint, cyrk_bdf, LSODA, BDF, Radau, and numbalsoda when the optional extra is
    installed."""
    from walkerlab.integrate import numbalsoda_backend as lsoda

    return ("odeint", "cyrk_bdf") + (("numbalsoda",) if lsoda.available() else ()) + \
        ("LSODA", "BDF", "Radau")


#: Tolerance bands of the issue-10 contact target, per method (``atol = 0.1 rtol``): where
#: each method's max leg-angle error is just under 1e-6 rad on the bench case.  BDF's error
#: is ~20x smaller than LSODA's at the same rtol, hence its looser band.
TARGET_RTOLS = {"odeint": (1e-9, 1.5e-9, 2e-9, 3e-9), "numbalsoda": (1e-9, 1.5e-9, 2e-9, 3e-9),
                "cyrk_bdf": (1.5e-8, 2e-8, 3e-8, 4e-8)}


def run_benchmark(n_strides: int = 5, methods=None,
                  rtols=(1e-6, 1e-7, 1e-8, 1e-9), contact: ContactSettings | None = None,
                  patch_width_m: float = 0.3, rate_scale=(1.0, 1.0), ideal: dict | None = None,
                  repeats: int = 2, target_rtols: dict | None = None) -> dict:
    """Time each integrator on ``n_strides`` strides of the paper walker.

    Parameters
    ----------
    n_strides : int
        Strides (2 steps each) [-].
    methods : sequence of str, optional
        "odeint", "cyrk_bdf", "numbalsoda", "LSODA", "BDF", "Radau"; default all of them
        (numbalsoda only when installed).
    rtols : sequence of float
        Relative tolerances; ``atol = 1e-3 * rtol`` [m, rad, ...].
    contact : ContactSettings, optional
        Default: the paper's values in mm-kg-s.
    patch_width_m : float
        Checkerboard patch width [m] (0.3 m lets the unscaled ideal state walk 10 steps).
    rate_scale : (float, float)
        Multipliers on the initial (dtheta1, dtheta2).
    ideal : dict, optional
        theta1, theta2, dtheta1, dtheta2 [rad, rad/s], step_length [m], step_period [s];
        default :data:`EXAMPLE_IDEAL`.
    repeats : int
        Runs per case; the fastest wall time is reported.
    target_rtols : dict, optional
        The issue-10 contact target (max leg-angle error <= 1e-6 rad in <= 0.04 s): method ->
        rtols, each run with ``atol = 0.1 * rtol``; default :data:`TARGET_RTOLS` (for the
        methods benchmarked).  The step sequence of the contact model jumps with tiny
        tolerance changes (nfev varies by ~30 % between neighbouring rtols for LSODA), so the
        target is judged on the median time and the worst error over the band.

    Returns
    -------
    dict
        ``{"t_final_s", "reference": {...}, "rhs_cost": {...}, "issue10_target": {method:
        {rtols, wall_time_s, max_angle_error_rad, nfev, median_wall_time_s,
        worst_error_rad}}, "runs": [ {method, rtol, wall_time_s, nfev, njev,
        max_angle_error_rad, heel_strikes, termination}, ...]}``.
    """
    methods = _default_methods() if methods is None else tuple(methods)
    ideal = dict(EXAMPLE_IDEAL if ideal is None else ideal)
    contact = contact or ContactSettings()
    n_steps = 2 * n_strides
    walker = ContactWalker.from_settings(contact, TerrainSettings(patch_width_m=patch_width_m),
                                         step_length=ideal["step_length"], n_steps=n_steps + 2)
    x0 = initial_state_from_ideal(walker, ideal["theta1"], ideal["theta2"], ideal["dtheta1"],
                                  ideal["dtheta2"], rate_scale=rate_scale)
    t_final = 1.03 * n_steps * ideal["step_period"]  # the contact gait is ~1% slower
    case = _Case(walker, x0, t_final, None, 1e-12, 1e-15)
    target = {}
    bands = TARGET_RTOLS if target_rtols is None else target_rtols
    for method in [m for m in bands if m in methods]:
        rs = [case.fastest(method, rt, 0.1 * rt, repeats) for rt in bands[method]]
        target[method] = {"rtols": list(bands[method]), "atol_over_rtol": 0.1,
                          "wall_time_s": [r.wall_time_s for r, _ in rs],
                          "max_angle_error_rad": [e for _, e in rs],
                          "nfev": [r.nfev for r, _ in rs],
                          "median_wall_time_s": float(np.median([r.wall_time_s for r, _ in rs])),
                          "worst_error_rad": float(max(e for _, e in rs))}
    runs = []
    for method in methods:
        for rtol in rtols:
            best, err = case.fastest(method, rtol, 1e-3 * rtol, repeats)
            runs.append({"method": method, "rtol": rtol, "wall_time_s": best.wall_time_s,
                         "nfev": best.nfev, "njev": best.njev, "max_angle_error_rad": err,
                         "heel_strikes": best.walked_steps, "termination": best.termination})
    ref = case.ref
    return {"t_final_s": t_final,
            "reference": {"method": "odeint", "rtol": 1e-12, "wall_time_s": ref.wall_time_s,
                          "nfev": ref.nfev, "heel_strikes": ref.walked_steps,
                          "termination": ref.termination},
            "rhs_cost": rhs_cost(walker, x0),
            "issue10_target": target,
            "runs": runs}


class _Case:
    """One benchmark case: the walker's contact run from ``x0`` to ``t_final`` (with
    ``limits``), its reference by ``ref_method`` at ``ref_rtol``/``ref_atol`` (run on
    creation, without a wall-time limit) and the leg-angle error of a run against it
    [rad]."""

    def __init__(self, walker: ContactWalker, x0: np.ndarray, t_final: float, limits,
                 ref_rtol: float, ref_atol: float, ref_method: str = "odeint"):
        self.walker, self.x0, self.t_final, self.limits = walker, x0, t_final, limits
        self.ref = self.run(ref_method, ref_rtol, ref_atol, unlimited=True)
        self.angles = leg_angle_columns(walker)

    def run(self, method: str, rtol: float, atol: float, unlimited: bool = False):
        """One contact run (:func:`~walkerlab.analysis.contact.sim.simulate_contact`);
        ``unlimited``: without the limits' wall-time limit and work bound (a reference must
        be complete)."""
        limits = self.limits
        if unlimited and limits is not None:
            limits = dataclasses.replace(limits, wall_time_limit_s=None,
                                         max_rhs_evaluations=None)
        return simulate_contact(self.walker, self.x0, self.t_final, SolverSettings.for_contact(
            method=method, rtol=rtol, atol=atol), limits)

    def complete(self, r) -> bool:
        """The run covered the whole span (its last sample within two sample intervals of
        the end time): a run that stopped early ("Excess work done", a fall) is compared
        with nothing past its end, so its error says nothing about the span."""
        rate = getattr(self.limits, "sample_rate_hz", None) or 1000.0
        dt = 2.0 / rate
        return bool(len(r.t)) and float(r.t[-1]) >= self.t_final - dt

    def error(self, r) -> float:
        """Largest leg-angle difference from the reference on the common samples [rad];
        infinite when the run or the reference stopped before the end time (a target is
        never reached on part of the span)."""
        if not (self.complete(r) and self.complete(self.ref)):
            return float("inf")
        n = min(len(r.t), len(self.ref.t))
        return float(np.abs(r.x[:n, self.angles] - self.ref.x[:n, self.angles]).max())

    def fastest(self, method: str, rtol: float, atol: float, repeats: int):
        """``(run, error)`` of the fastest of ``repeats`` runs."""
        best = None
        for _ in range(repeats):
            r = self.run(method, rtol, atol)
            if best is None or r.wall_time_s < best.wall_time_s:
                best = r
        return best, self.error(best)

    def median(self, method: str, rtol: float, repeats: int) -> tuple:
        """``(median wall time [s], error, nfev, termination)`` of ``repeats`` runs at
        ``atol = 0.1 rtol`` (error, nfev and termination of the first run)."""
        rs = [self.run(method, rtol, 0.1 * rtol) for _ in range(repeats)]
        return (float(np.median([r.wall_time_s for r in rs])), self.error(rs[0]), rs[0].nfev,
                rs[0].termination)


#: rtols scanned (loose to tight) for the band reaching the target error; each band is
#: ``r * BAND_FACTORS`` (the step sequence jumps with tiny tolerance changes, so a single
#: rtol could land on a lucky or unlucky run: the band's worst error and median time count).
SCAN_RTOLS = (1e-6, 5e-7, 2e-7, 1e-7, 5e-8, 2e-8, 1e-8, 5e-9, 2e-9, 1e-9, 5e-10, 2e-10, 1e-10,
              5e-11)
BAND_FACTORS = (1.0, 1 / 1.5, 1 / 2, 1 / 3)


def run_scene_benchmark(scene, n_strides: int = 5, methods=("cyrk_bdf", "odeint"),
                        target_error_rad: float = 1e-6, repeats: int = 5,
                        reference_rtol: float = 1e-12,
                        reference_method: str = "cyrk_bdf") -> dict:
    """Time for ``n_strides`` contact strides of any scene's walker at a target accuracy.

    The walker, start and limits are the scene's contact run
    (:func:`walkerlab.analysis.contact.sim.scene_start`) from its rigid fixed point; the
    reference is ``reference_method`` at ``reference_rtol`` (``atol = 1e-2 rtol``), run
    without the scene's wall-time limit; the time span is 3 % longer than ``2 n_strides``
    rigid step periods.  The default reference, CyRK's BDF at rtol 1e-12, agrees with CyRK's
    Radau at rtol 1e-11 to 1.8e-9 rad (kneed.yaml) and 1.4e-9 rad (flat_feet.yaml); odeint
    at rtol 1e-11, the reference before, is 4.4e-6 rad off on flat_feet.yaml (LSODA loses
    accuracy at every heel strike there: the touchdown's kink in the damping), which no
    integrator could then get below.  For each method, the loosest band
    ``r * BAND_FACTORS`` (``r`` from :data:`SCAN_RTOLS`, ``atol = 0.1 rtol``) whose worst
    leg-angle error (every link angle, on the common samples) is <= ``target_error_rad`` is
    reported with the median wall time (per rtol the median of ``repeats`` runs, then the
    median over the band).

    Parameters
    ----------
    scene : walkerlab.config.Scene
        A scene with a ``contact`` and a ``fixedpoint`` section.
    n_strides : int
        Strides (2 steps each) [-].
    methods : sequence of str
        Contact integrators (:class:`SolverSettings` ``method``).
    target_error_rad : float
        Worst leg-angle error allowed [rad].
    repeats : int
        Runs per tolerance (median wall time).
    reference_rtol : float
        Tolerance of the reference run [-].
    reference_method : str
        Integrator of the reference run (:class:`SolverSettings` ``method``).

    Returns
    -------
    dict
        ``{"scene", "n_strides", "t_final_s", "reference": {...}, "rhs_cost": {...},
        "target": {method: {rtols, max_angle_error_rad, wall_time_s, nfev,
        median_wall_time_s, worst_error_rad, reached}}, "scan": {method: [{rtol, error,
        wall_time_s, nfev}]}}``.

    Raises
    ------
    ValueError
        The scene has no ``fixedpoint`` section.
    ContactSceneError
        The scene has no ``contact`` section or a massless body.
    """
    from walkerlab.analysis.contact.periodic import ideal_gait  # light
    from walkerlab.analysis.contact.sim import scene_start
    from walkerlab.models.contact.scene import contact_setup

    plant = Plant.from_scene(scene)  # the bench's scene, described once
    ideal = ideal_gait(scene, plant=plant)
    walker, x0, limits, _ = scene_start(contact_setup(scene, plant=plant), ideal.x,
                                        n_strides + 1)
    t_final = 1.03 * 2 * n_strides * ideal.period_s
    case = _Case(walker, x0, t_final, limits, reference_rtol, 1e-2 * reference_rtol,
                 reference_method)
    target, scan = {}, {}
    for method in methods:
        scan[method], best = _scan(case, method, target_error_rad, repeats)
        target[method] = _target_entry(best)
    return {"scene": scene.name, "n_strides": n_strides, "t_final_s": t_final,
            "reference": _reference_entry(case, reference_method, reference_rtol),
            "rhs_cost": rhs_cost(walker, x0), "target": target, "scan": scan}


def _target_entry(best: list[dict] | None) -> dict:
    """A method's entry of :func:`run_scene_benchmark`'s ``target``: whether a band reached
    the target and, if so, its tolerances, errors, wall times [s] and their median."""
    entry = {"reached": best is not None}
    if best is not None:
        entry.update(
            rtols=[r["rtol"] for r in best], atol_over_rtol=0.1,
            max_angle_error_rad=[r["error"] for r in best],
            wall_time_s=[r["wall_time_s"] for r in best], nfev=[r["nfev"] for r in best],
            median_wall_time_s=float(np.median([r["wall_time_s"] for r in best])),
            worst_error_rad=float(max(r["error"] for r in best)))
    return entry


def _reference_entry(case: _Case, method: str, rtol: float) -> dict:
    """:func:`run_scene_benchmark`'s ``reference``: the reference run's integrator, tolerance,
    wall time [s], evaluations and how it ended."""
    ref = case.ref
    return {"method": method, "rtol": rtol, "wall_time_s": ref.wall_time_s, "nfev": ref.nfev,
            "heel_strikes": len(ref.heel_strike_times), "termination": ref.termination,
            "end_time_s": float(ref.t[-1]) if len(ref.t) else 0.0,
            "complete": case.complete(ref), "message": ref.message}


def _scan(case: _Case, method: str, target_error_rad: float, repeats: int
          ) -> tuple[list[dict], list[dict] | None]:
    """Bands ``r * BAND_FACTORS`` from loose to tight (:data:`SCAN_RTOLS`) until one's every
    run reaches ``target_error_rad``: ``(rows run, that band's rows or None)`` (a band stops
    at its first run that misses the target)."""
    scan: list[dict] = []
    for r0 in SCAN_RTOLS:
        band = [r0 * f for f in BAND_FACTORS]
        rows = []
        for rt in band:
            t, e, nf, term = case.median(method, rt, repeats)
            rows.append({"rtol": rt, "error": e, "wall_time_s": t, "nfev": nf,
                         "termination": term})
            if e > target_error_rad:
                break  # this band misses the target: the next tighter one
        scan += rows
        if len(rows) == len(band) and all(r["error"] <= target_error_rad for r in rows):
            return scan, rows
    return scan, None
