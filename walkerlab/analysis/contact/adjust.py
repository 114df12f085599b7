"""Parameter adjustment by computation (replaces the paper's trial-and-error, Sec. 4, Table 2).

Objective (dimensionless, documented in the report): run the contact walker for the scene's
strides from the ideal fixed point with the initial rates scaled by ``s = (s1, s2)``; over
the last four steps,

    J(s) = mean(((T_k - T*) / T*)^2 + ((l_k - l*) / l*)^2)

with ``T*``, ``l*`` the ideal step period and step length; a run that does not complete all
heel strikes gets ``J = 1 + (missing steps)``.  The scene's own start is run first, then a
coarse grid (``scipy.optimize.brute``), refined by Nelder-Mead (``scipy.optimize.minimize``)
only when some grid start walked all its heel strikes (``J`` < 1: below that ``J`` is a step
function of the heel strikes made, on which Nelder-Mead only spends runs).  The search is
bounded by work: at most ``1 + n^2 +`` :data:`NELDER_MEAD_RUNS` contact runs, or fewer
(``contact_sim.adjust_max_contact_runs``); when they are spent the search stops and keeps the
best start found so far.  The same runs on any machine, so the same answer.
"""

from __future__ import annotations

import time

import numpy as np
from scipy.optimize import brute, minimize

from walkerlab import progress

#: Nelder-Mead's most contact runs after the grid
NELDER_MEAD_RUNS = 60


class _BudgetSpent(Exception):
    """The search's contact runs are spent (raised before the run past the bound)."""


def start_mismatch(walker, res, period: float, step_length: float, n_strides: int) -> float:
    """The objective ``J`` of one contact run (module docstring).

    Parameters
    ----------
    walker : ContactWalker
        The run's walker (its feet's positions).
    res : ContactResult
        The run (:func:`walkerlab.analysis.contact.sim.simulate_from`).
    period : float
        Ideal step period ``T*`` [s].
    step_length : float
        Ideal step length ``l*`` [m].
    n_strides : int
        Strides asked for (``2 n_strides`` heel strikes).

    Returns
    -------
    float
        ``J`` [-]: the mean squared relative period and step-length mismatch of the last
        four steps, or ``1 + missing heel strikes`` for a run that does not make them all.
    """
    n_hs = len(res.heel_strike_times)
    want = 2 * n_strides
    if n_hs < want or res.termination in ("fall", "trip", "airborne"):
        return 1.0 + (want - min(n_hs, want))
    steps = [st for st in res.steps if np.isfinite(st.period)][-4:]
    T = np.array([st.period for st in steps])
    feet = np.asarray(walker.foot_positions(res.x)).reshape(len(res.t), -1, 2)
    lens = []
    for th in res.heel_strike_times[-4:]:
        i = min(np.searchsorted(res.t, th), len(res.t) - 1)
        lens.append(np.hypot(*(feet[i, 0] - feet[i, 1])))
    lens = np.array(lens)
    return float(np.mean(((T - period) / period) ** 2)
                 + np.mean(((lens - step_length) / step_length) ** 2))


def adjust_rates(setup, x_fp: np.ndarray, period: float, grid=(0.8, 1.5, 8),
                 max_contact_runs: int | None = None) -> dict:
    """Find initial-rate scale factors that make the contact gait match the ideal one.

    Parameters
    ----------
    setup : walkerlab.models.contact.scene.ContactSetup
        The scene's contact model (runs ``contact_sim.n_strides`` strides).
    x_fp : ndarray (n,)
        Ideal fixed point (rigid walker's ``state_names()`` order) [rad, rad/s].
    period : float
        Ideal step period [s].
    grid : (float, float, int)
        Lower and upper scale and points per axis of the coarse grid.
    max_contact_runs : int, optional
        The most contact runs the search may make (the scene's own start counts; it is
        always run); default ``contact_sim.adjust_max_contact_runs`` (None there: the
        search's own bound, ``1 + n^2 + NELDER_MEAD_RUNS``).

    Returns
    -------
    dict
        ``scale`` (2,) (the best start found; the scene's own when nothing beat it),
        ``objective`` (its ``J``), ``scene_objective`` (``J`` of the scene's
        ``initial_rate_scale``), ``evaluations`` (contact runs), ``grid_best`` (2,),
        ``cpu_s`` (CPU time spent [s]), ``gave_up`` (one line when the budget ran out,
        else ""), ``time_limited_runs`` (runs a wall-clock limit,
        ``contact_sim.wall_time_limit_s``, cut short: a result of the machine's speed),
        ``note`` (one line on a skipped refinement or on trial runs that ended in
        an error, ``ValueError``/``RuntimeError``/``ArithmeticError``, counted as failed
        starts; else "") and ``runs``: the
        :func:`~walkerlab.analysis.contact.sim.simulate_from` results of the scene's start
        (``"scene"``) and of the best start (``"best"``), so that neither is run again.
    """
    cs = setup.sim
    budget = (getattr(cs, "adjust_max_contact_runs", None) if max_contact_runs is None
              else max_contact_runs)
    scene_scale = np.asarray(cs.initial_rate_scale, float)
    lo, hi, n = grid
    most = 1 + n * n + NELDER_MEAD_RUNS
    trials = _Trials(setup, x_fp, period, budget, scene_scale)
    best = trials.best
    gave_up = note = ""
    x0 = scene_scale
    with progress.task("adjust: contact runs (the scene's start, a grid, then Nelder-Mead; "
                       "at most)", most) as bar:
        try:
            scene_J = trials(scene_scale, bar)
            x0 = np.asarray(brute(lambda s: trials(s, bar), ((lo, hi), (lo, hi)), Ns=n,
                                  finish=None), float)
            if best["J"] >= 1.0:  # no start walked all its heel strikes: J is a step function
                note = (f"no start walked all {2 * cs.n_strides} heel strikes "
                        f"(best J {best['J']:.3g}); the Nelder-Mead refinement was skipped")
            else:
                minimize(lambda s: trials(s, bar), x0, method="Nelder-Mead",
                         options={"xatol": 1e-3, "fatol": 1e-8, "maxfev": NELDER_MEAD_RUNS})
        except _BudgetSpent:
            gave_up = (f"the search gave up after {trials.count} of at most {most} contact "
                       f"runs (contact_sim.adjust_max_contact_runs: {budget}); kept the best "
                       "start found so far")
    note = _errors_note(note, trials.errors)
    return {"scale": np.asarray(best["scale"], float), "objective": float(best["J"]),
            "scene_objective": float(scene_J), "evaluations": trials.count,
            "grid_best": np.asarray(x0, float),
            "cpu_s": float(time.process_time() - trials.cpu0),
            "gave_up": gave_up, "note": note, "time_limited_runs": trials.time_limited,
            "runs": {"scene": trials.runs.get("scene"), "best": best["run"]}}


class _Trials:
    """The search's objective over rate scales (:func:`adjust_rates`): each call one contact
    run from the ideal fixed point, its ``J`` (:func:`start_mismatch`); keeps the count of
    runs, the best start, the scene's own run (the first) and the trial runs that ended in
    an error (``ValueError``/``RuntimeError``/``ArithmeticError``: a failed start, ``J = 2 +
    2 n_strides``); raises :class:`_BudgetSpent` before a run past the bound ``budget`` (the
    most contact runs; None: none)."""

    def __init__(self, setup, x_fp, period, budget, scene_scale):
        self.setup, self.x_fp, self.period, self.budget = setup, x_fp, period, budget
        self.n_strides = setup.sim.n_strides
        self.cpu0 = time.process_time()
        self.count = 0
        self.best = {"J": np.inf, "scale": scene_scale, "run": None}
        self.runs = {}
        self.errors = []  # (scale, exception) of trial runs that ended in an error
        self.time_limited = 0  # runs a wall-clock limit (wall_time_limit_s) cut short

    def __call__(self, s, bar):
        from walkerlab.analysis.contact.sim import simulate_from  # light

        best, runs, budget = self.best, self.runs, self.budget
        if self.count and budget is not None and self.count >= budget:
            raise _BudgetSpent
        self.count += 1
        s = np.clip(np.asarray(s, float), 0.2, 5.0)
        try:
            run = simulate_from(self.setup, self.x_fp, self.period, rate_scale=tuple(s))
        except (ValueError, RuntimeError, ArithmeticError) as exc:
            if "scene" not in runs:  # the scene's own start: as without --adjust
                raise
            # an off-nominal start the integrator could not finish (e.g. scipy's event
            # location on a powered run): a start that does not walk, worse than any fall
            self.errors.append((s, exc))
            v = 2.0 + 2 * self.n_strides
            bar.update(self.count, info=f"rate scale {s[0]:.3f}, {s[1]:.3f}: run failed")
            return v
        walker, res, _, l_star = run
        if res.termination == "time_limit":  # a wall-clock limit: the machine's speed
            self.time_limited += 1
        v = start_mismatch(walker, res, self.period, l_star, self.n_strides)
        if "scene" not in runs:
            runs["scene"] = run
        if v < best["J"]:
            best.update(J=v, scale=s, run=run)
        bar.update(self.count, info=f"rate scale {s[0]:.3f}, {s[1]:.3f}: J {v:.3g}; best "
                   f"{best['J']:.3g}")
        return v


def _errors_note(note: str, errors) -> str:
    """``note`` with one line on the trial runs that ended in an error (none: unchanged)."""
    if not errors:
        return note
    (s0, e0) = errors[0]
    first = str(e0).splitlines()[0] if str(e0) else type(e0).__name__
    return "; ".join(filter(None, [note, (
        f"{len(errors)} trial run(s) ended in an error and count as failed starts "
        f"(the first at rate scale {s0[0]:.3g}, {s0[1]:.3g}: {first})")]))


#: run ends of a contact walker that walked cleanly; then those that walked with a defect
_CLEAN = ("heel_strike", "t_final")
_DEFECT = ("scuff", "slip")


def _standing(res) -> tuple:
    """Sort key of a contact run (smaller is better): walked cleanly, then walked with a
    scuff or a slip beyond the limit, then failed; then more heel strikes; then less slip."""
    kind = res.outcome.kind
    tier = 0 if kind in _CLEAN else 1 if kind in _DEFECT else 2
    slip = res.max_stance_slip_mm if np.isfinite(res.max_stance_slip_mm) else np.inf
    return (tier, -int(res.walked_steps), slip)


def _said(res) -> str:
    slip = res.max_stance_slip_mm
    return (f"{res.outcome.kind} after {int(res.walked_steps)} heel strikes"
            + (f", max slip {slip:.3g} mm" if np.isfinite(slip) else ""))


def better_start(scene_run, adjusted_run, scene_objective: float = np.nan,
                 adjusted_objective: float = np.nan) -> tuple[str, str]:
    """Which start of ``contact-sim --adjust`` to keep: the adjusted rates minimise the
    period and step-length mismatch (:func:`adjust_rates`), which does not guarantee a
    better walk, so the two runs are compared by outcome (walked cleanly > walked with a
    scuff or slip > failed), then heel strikes, then the largest stance slip.  An adjusted
    start that walks no better is not kept: on a tie the scene's start stays, unless both
    walked and the adjusted one matches the ideal gait better (a smaller objective ``J``:
    what the adjustment is for).

    Parameters
    ----------
    scene_run, adjusted_run : ContactResult
        The run from the scene's ``contact_sim.initial_rate_scale`` and from the adjusted
        scale.
    scene_objective, adjusted_objective : float, optional
        Their objectives ``J`` [-] (:func:`start_mismatch`); NaN: unknown (a tie then keeps
        the scene's start).

    Returns
    -------
    kept : {"adjusted", "scene"}
        The adjusted start only if it walks better than the scene's (or as well, both
        having walked, with a smaller ``J``).
    reason : str
        One line: why, and both outcomes (``adjusted start: fall after 2 heel strikes;
        the scene's start: fall after 2 heel strikes``).
    """
    a, s = _standing(adjusted_run), _standing(scene_run)
    both = f"adjusted start: {_said(adjusted_run)}; the scene's start: {_said(scene_run)}"
    if a < s:
        return "adjusted", f"it walks better: {both}"
    if s < a:
        return "scene", f"the adjusted start walks worse: {both}"
    if a[0] < 2 and adjusted_objective < scene_objective:  # NaN compares False
        return "adjusted", (f"both walk alike and it matches the ideal gait better (J "
                            f"{adjusted_objective:.3g} against {scene_objective:.3g}): {both}")
    return "scene", f"no adjusted start walked better than the scene's: {both}"
