"""Paper Table 3 quantities, computed from trajectories (never typed in).

The published values live in :mod:`walkerlab.published.paper`; this module only computes.
"""

from __future__ import annotations

import numpy as np

from walkerlab.io.trajectory import NamedTrajectory


def gait_metrics(tr: NamedTrajectory, left_leg: str | None = None, n_energy_steps: int = 5,
                 mass_kg: float | None = None, g: float = 9.81) -> dict[str, float]:
    """Table 3 quantities of a named trajectory.

    Steps are delimited by changes of ``stance_leg`` (the last sample closes the last step);
    a *left step* is a step in which the left leg (``legs[0]`` unless given) swings.  Only
    complete steps count: the last step only if it lasts at least 90 % of the median of the
    others (a rigid run ends at its last heel strike; a contact run at its end time, within
    a step, whose length and duration are not a step's), the first likewise (a contact run
    that starts at the rigid gait's mid-stance begins within a step); ``v_com`` then counts
    its cycles from the first complete step.  ``v_com`` is the hip's horizontal
    displacement over whole cycles divided by their duration (over a periodic cycle the
    centre of mass and the hip advance alike).
    ``E_avg`` is the time average of KE + PE over the first ``n_energy_steps`` steps with PE
    from the first stance foot; ``E_avg_stance_frame`` measures PE from the current stance
    foot instead (needs ``mass_kg``; NaN where the trajectory names no ``<leg>_foot`` of its
    stance leg).  ``n_steps`` counts the steps the run began: a rigid run ends at a heel
    strike, a contact run at its end time within a step, which counts too (the complete steps
    alone give the step periods and lengths).

    Returns
    -------
    dict
        ``t_left_s``, ``t_right_s``, ``t_cycle_s``, ``v_com_m_per_s``, ``E_avg_J``,
        ``E_avg_stance_frame_J``, ``step_length_m`` (the feet's distance at heel strike; flat
        feet: from the stance heel's touchdown point to the swing heel's; and per leg,
        ``step_length_left_m``, ``step_length_right_m``: the steps the left / right leg's
        swing ends), ``n_steps``, ``E_avg_steps`` (the steps the energies are averaged
        over: the first ``n_energy_steps``, fewer when the run has fewer).
    """
    left = left_leg or tr.legs[0]
    li = tr.legs.index(left)
    change = np.flatnonzero(np.diff(tr.stance_leg) != 0) + 1
    bounds = np.concatenate([[0], change, [tr.time.size - 1]])
    t_b = tr.time[bounds]
    periods = np.diff(t_b)
    stance = tr.stance_leg[bounds[:-1]]
    done = np.ones(periods.size, dtype=bool)
    if periods.size > 1 and periods[-1] < 0.9 * np.median(periods[:-1]):
        done[-1] = False  # the run ended within this step
    # a run that began within a step (a contact run from the rigid gait's mid-stance:
    # ``contact_sim.start: mid_stance``): its first step is no step either
    first = 1 if periods.size > 2 and periods[0] < 0.9 * np.median(periods[1:]) else 0
    done[:first] = False
    left_steps = periods[(stance != li) & done]  # left leg swings when it is not in stance
    right_steps = periods[(stance == li) & done]
    hip = tr.points.get("hip")
    out = {"n_steps": int(periods.size)}
    out["t_left_s"] = float(np.mean(left_steps)) if left_steps.size else np.nan
    out["t_right_s"] = float(np.mean(right_steps)) if right_steps.size else np.nan
    out["t_cycle_s"] = out["t_left_s"] + out["t_right_s"]
    n_cyc = (periods.size - first) // 2
    if hip is not None and n_cyc >= 1:
        i0, i1 = bounds[first], bounds[first + 2 * n_cyc]
        out["v_com_m_per_s"] = float((hip[0, i1] - hip[0, i0]) / (tr.time[i1] - tr.time[i0]))
        out.update(_step_lengths(tr, bounds, stance, done, li))
    else:
        out["v_com_m_per_s"] = np.nan
    out.setdefault("step_length_m", np.nan)
    out["E_avg_steps"] = int(min(n_energy_steps, periods.size))  # the steps E_avg is over
    out.update(_energies(tr, bounds[out["E_avg_steps"]], mass_kg, g))
    return out


def table3(trajectories: dict[str, NamedTrajectory], mass_kg: float,
           g: float) -> dict[str, dict[str, float]]:
    """Table 3 columns of loaded trajectories ``{label: NamedTrajectory}`` (total mass
    ``mass_kg`` [kg], gravity ``g`` [m/s^2])."""
    return {label: gait_metrics(tr, mass_kg=mass_kg, g=g) for label, tr in trajectories.items()}


def _step_lengths(tr: NamedTrajectory, bounds, stance, done, li: int) -> dict[str, float]:
    """:func:`gait_metrics`' step lengths over the complete steps (``done``; steps between
    ``bounds``, stance legs ``stance``, ``li`` the left leg): ``step_length_m`` and per leg
    ``step_length_left_m``, ``step_length_right_m``; none without both feet's points."""
    out = {}
    feet = [tr.points.get(f"{leg}_foot") for leg in tr.legs]
    # flat feet: heel to heel, from where the stance heel landed (the step's first
    # sample) to where the swing heel lands (the stance foot is heeled off by then and
    # its "foot" point, the ankle, is not on the ground)
    heels = [tr.points.get(f"{leg}_heel") for leg in tr.legs]
    flat = all(h is not None for h in heels)
    if all(f is not None for f in feet):
        lengths, left_step = [], []
        for k in np.flatnonzero(done) + 1:
            i = bounds[k] - 1 if k < len(bounds) - 1 else bounds[k]
            st = int(stance[k - 1])
            d = (heels[1 - st][:, i] - heels[st][:, bounds[k - 1]] if flat
                 else feet[0][:, i] - feet[1][:, i])
            # in 3D the step's length along the walk, as a planar walker's (its width apart)
            lengths.append(np.hypot(d[0], d[1]))
            left_step.append(stance[k - 1] != li)
        out["step_length_m"] = float(np.mean(lengths)) if lengths else np.nan
        lengths, left_step = np.array(lengths), np.array(left_step, dtype=bool)
        # per leg (legs that differ take steps of two lengths): the step its swing ends
        for side, m in (("left", left_step), ("right", ~left_step)):
            out[f"step_length_{side}_m"] = (float(np.mean(lengths[m])) if m.any()
                                            else np.nan)
    return out


def _energies(tr: NamedTrajectory, iE: int, mass_kg: float | None, g: float
              ) -> dict[str, float]:
    """:func:`gait_metrics`' time-averaged energies up to sample ``iE``: ``E_avg_J`` and,
    with ``mass_kg``, ``E_avg_stance_frame_J``."""
    out = {}
    sl = slice(0, max(iE, 2))
    tt = tr.time[sl]
    out["E_avg_J"] = float(np.trapezoid(tr.total[sl], tt) / (tt[-1] - tt[0]))
    if mass_kg is not None:
        y_st = np.full(tt.size, np.nan)  # NaN where no stance foot is named
        for k, leg in enumerate(tr.legs):
            foot = tr.points.get(f"{leg}_foot")
            if foot is not None:
                m = tr.stance_leg[sl] == k
                y_st[m] = foot[1, sl][m]
        e_st = tr.total[sl] - mass_kg * g * y_st
        out["E_avg_stance_frame_J"] = float(np.trapezoid(e_st, tt) / (tt[-1] - tt[0]))
    return out
