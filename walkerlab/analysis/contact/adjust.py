"""Parameter adjustment by computation (replaces the paper's trial-and-error, Sec. 4, Table 2).

Objective (dimensionless, documented in the report): run the contact walker for the scene's
strides from the ideal fixed point with the initial rates scaled by ``s = (s1, s2)``; over
the last four steps,

    J(s) = mean(((T_k - T*) / T*)^2 + ((l_k - l*) / l*)^2)

with ``T*``, ``l*`` the ideal step period and step length; a run that does not complete all
heel strikes gets ``J = 1 + (missing steps)``.  A coarse grid (``scipy.optimize.brute``)
is refined by Nelder-Mead (``scipy.optimize.minimize``).
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import brute, minimize


def adjust_rates(setup, x_fp: np.ndarray, period: float, grid=(0.8, 1.5, 8)) -> dict:
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

    Returns
    -------
    dict
        ``scale`` (2,), ``objective``, ``evaluations``, ``grid_best`` (2,).
    """
    from walkerlab.analysis.contact.sim import simulate_from

    n_strides = setup.sim.n_strides
    count = {"n": 0}

    def J(s):
        count["n"] += 1
        s = np.clip(np.asarray(s, float), 0.2, 5.0)
        walker, res, _, l_star = simulate_from(setup, x_fp, period, rate_scale=tuple(s))
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
                     + np.mean(((lens - l_star) / l_star) ** 2))

    from walkerlab import progress

    lo, hi, n = grid
    with progress.task("adjust: contact runs (grid, then Nelder-Mead; at most)",
                       n * n + 60) as bar:
        def J_shown(s):  # progress: contact runs done of the most there can be
            v = J(s)
            bar.update(count["n"], info=f"rate scale {s[0]:.3f}, {s[1]:.3f}: J {v:.3g}")
            return v

        x0, fval, _, _ = brute(J_shown, ((lo, hi), (lo, hi)), Ns=n, full_output=True,
                               finish=None)
        res = minimize(J_shown, x0, method="Nelder-Mead",
                       options={"xatol": 1e-3, "fatol": 1e-8, "maxfev": 60})
    best = res.x if res.fun <= fval else x0
    return {"scale": np.asarray(best, float), "objective": float(min(res.fun, fval)),
            "evaluations": count["n"], "grid_best": np.asarray(x0, float)}


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


def better_start(scene_run, adjusted_run) -> tuple[str, str]:
    """Which start of ``contact-sim --adjust`` to keep: the adjusted rates minimise the
    period and step-length mismatch (:func:`adjust_rates`), which does not guarantee a
    better walk, so the two runs are compared by outcome (walked cleanly > walked with a
    scuff or slip > failed), then heel strikes, then the largest stance slip.

    Parameters
    ----------
    scene_run, adjusted_run : ContactResult
        The run from the scene's ``contact_sim.initial_rate_scale`` and from the adjusted
        scale.

    Returns
    -------
    kept : {"adjusted", "scene"}
        The adjusted start unless the scene's is strictly better.
    reason : str
        One line: both outcomes (``t_final after 10 heel strikes, max slip 1.4 mm``).
    """
    a, s = _standing(adjusted_run), _standing(scene_run)
    kept = "scene" if s < a else "adjusted"
    why = f"adjusted start: {_said(adjusted_run)}; the scene's start: {_said(scene_run)}"
    return kept, why
