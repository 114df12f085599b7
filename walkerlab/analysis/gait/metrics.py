"""Gait metrics and named samples of a rigid hybrid trajectory."""

from __future__ import annotations

import math

import numpy as np

from walkerlab.config import MAX_SIMULATE_SAMPLES
from walkerlab.integrate.rigid import HybridTrajectory
from walkerlab.io.trajectory import NamedTrajectory


def _leg_point_name(name: str, roles_to_legs: dict[str, str]) -> str:
    for role, leg in roles_to_legs.items():
        if name.startswith(role + "_"):
            return leg + name[len(role):]
    return name


def total_mass_kg(walker) -> float:
    """Total mass [kg] of a walker, from its parameters (never recomputed from parts)."""
    if "total_mass_kg" in walker.params:
        return float(walker.params["total_mass_kg"])
    return float(walker.total_mass_kg)


def _phase_of(seg, times: np.ndarray, names: list[str]) -> np.ndarray:
    """Index in ``names`` (the walker's phase names) of the phase each sample time falls
    in, as :meth:`Segment.sample` assigns it (a boundary time belongs to the earlier
    phase; a step's phases may skip some of the walker's, e.g. a flat foot's modes)."""
    idx = np.full(times.size, -1, dtype=int)
    for j, (ph, _sol, (_ta, tb)) in enumerate(seg.pieces):
        last = j == len(seg.pieces) - 1
        idx[(idx < 0) & ((times <= tb) | last)] = names.index(ph.name)
    return idx


def sample_trajectory(traj: HybridTrajectory, rate_hz: float) -> NamedTrajectory:
    """Dense samples at ``rate_hz`` plus each step's end (pre-impact) state.

    Coordinates are named by the walker (:meth:`HybridWalker.leg_coordinates`), so any
    walker's trajectory has the same keys on every step.  Potential energy is measured from
    the first stance foot's height, so the total mechanical energy is constant in swing and
    drops at each heel strike.

    Parameters
    ----------
    traj : HybridTrajectory
    rate_hz : float
        Sample rate [Hz].

    Returns
    -------
    NamedTrajectory

    Raises
    ------
    ValueError
        More than :data:`walkerlab.config.MAX_SIMULATE_SAMPLES` samples (checked before any
        is taken; the message names ``simulate.sample_rate_hz``).
    """

    n = sum(math.ceil(max(s.t_end - s.t_start, 0.0) * rate_hz) + 1 for s in traj.segments)
    if n > MAX_SIMULATE_SAMPLES:
        span = sum(s.t_end - s.t_start for s in traj.segments)
        raise ValueError(f"simulate.sample_rate_hz: {rate_hz:g} Hz over {span:.3g} s "
                         f"gives {n:,} samples; at most {MAX_SIMULATE_SAMPLES:,} are kept "
                         "(lower simulate.sample_rate_hz or simulate.strides)")
    w = traj.walker
    legs = list(w.legs)
    units = dict(w.coordinate_units)
    chunks = {k: [] for k in ("t", "stance", "step", "ke", "pe", "phase")}
    coords: dict[str, list] = {name: [] for name in units}
    pts: dict[str, list] = {}
    g = w.params["gravity_m_per_s2"]
    mass = total_mass_kg(w)
    fall = np.array([math.cos(w.slope_rad), -math.sin(w.slope_rad)])
    ahead = 0.0  # how far the stance contacts ran ahead of their reference travel so far
    for seg in traj.segments:
        dt = 1.0 / rate_hz
        times = np.arange(seg.t_start, seg.t_end, dt)
        times = np.append(times, seg.t_end)
        X = seg.sample(times)
        r2l = w.role_to_leg(seg.stance_leg)
        for name, v in w.leg_coordinates(X, seg.stance_leg).items():
            coords[name].append(v)
        sw = w.for_stance(seg.stance_leg)  # legs that differ: that step's own numbers
        ke, pe = sw.energies(X)
        pe = pe + mass * g * seg.stance_foot_world[1]
        # feet curved in both directions: the walker further along the fall line than its
        # printed points and potential say (walkerlab.walker.foot_trees.creep_rate)
        shift = ahead + creep_along(sw, seg, times) if sw.creep_rate is not None else None
        if shift is not None:
            pe = pe + mass * g * fall[1] * shift
            ahead = float(shift[-1])
        chunks["t"].append(times)
        chunks["ke"].append(np.broadcast_to(ke, times.shape))
        chunks["pe"].append(np.broadcast_to(pe, times.shape))
        chunks["stance"].append(np.full(times.size, legs.index(seg.stance_leg)))
        chunks["step"].append(np.full(times.size, seg.index))
        chunks["phase"].append(_phase_of(seg, times, [p.name for p in w.phases]))
        for name, xy in sw.points(X).items():
            key = _leg_point_name(name, r2l)
            xy = np.array(xy, float) + seg.stance_foot_world[:, None]
            if shift is not None:
                xy[:2] += fall[:, None] * shift
            pts.setdefault(key, []).append(xy)
    cat = np.concatenate
    return NamedTrajectory(
        time=cat(chunks["t"]), legs=legs,
        coordinates={k: cat(v) for k, v in coords.items()}, units=units,
        stance_leg=cat(chunks["stance"]), step_index=cat(chunks["step"]),
        kinetic=cat(chunks["ke"]), potential=cat(chunks["pe"]),
        points={k: np.hstack(v) for k, v in pts.items()},
        phase=cat(chunks["phase"]), phase_names=[p.name for p in w.phases],
    )


def creep_along(walker, seg, times) -> np.ndarray:
    """How far [m] the stance contact of feet curved in both directions has run along the
    fall line ahead of its reference travel (the integral of
    :attr:`walkerlab.models.hybrid.base.HybridWalker.creep_rate` from the step's start),
    at ``times`` (k,) [s] within the segment ``seg``: one adaptive integration (scipy's
    DOP853, rtol 1e-12) of the rate on each continuous piece's dense output, restarted at
    the step's resets (a knee strike's jump in the stance rate), read at ``times``.

    Returns
    -------
    ndarray (k,)
        Zeros for a walker whose feet roll holonomically (``creep_rate`` None).
    """
    from scipy.integrate import solve_ivp

    times = np.asarray(times, float)
    rate = walker.creep_rate
    out = np.zeros(times.size)
    if rate is None:
        return out
    n2, acc = seg.x_start.size, 0.0
    for k, (_ph, sol, (ta, tb)) in enumerate(seg.pieces):
        last = k == len(seg.pieces) - 1
        inside = (times >= ta) & ((times <= tb) | last)
        if tb > ta:
            def r(t, _y, sol=sol):
                y = np.asarray(sol(np.atleast_1d(float(t))), float)
                return [rate((y[:, 0] if y.ndim == 2 else y)[:n2])]
            ts = np.clip(times[inside], ta, tb)
            got = solve_ivp(r, (ta, tb), [0.0], method="DOP853", rtol=1e-12, atol=1e-15,
                            t_eval=np.unique(np.r_[ts, tb]))
            out[inside] = acc + np.interp(ts, got.t, got.y[0])
            acc += float(got.y[0, -1])
        else:
            out[inside] = acc
    return out


def step_length(walker, seg) -> float:
    """Length of a step that ended by a heel strike [m]: the distance from the stance foot
    to the swing foot at heel strike in the direction of walking, with the step's own
    numbers (legs that differ: ``walker.for_stance(seg.stance_leg)``).  The points' first
    two rows span the sagittal plane (``x`` downhill, ``y`` up); a 3D walker's third, the
    lateral one, is its step width, which gait analysis keeps apart from the step's length
    (and over which the slope releases no energy: the ledger's ``M g d sin(phi)`` is
    gravity's work only with ``d`` along the fall line).

    Parameters
    ----------
    walker : HybridWalker
    seg : walkerlab.integrate.rigid.Segment

    Returns
    -------
    float
        [m] (the walker's length unit).
    """
    foot = np.asarray(walker.for_stance(seg.stance_leg).points(seg.x_end)["swing_foot"], float)
    return float(np.linalg.norm(foot[:2]))


def step_table(traj: HybridTrajectory) -> dict[str, np.ndarray]:
    """Per-step metrics: period [s], step length [m], hip speed [m/s], impact loss [J], ...

    Step length is the distance between the stance foot and the swing foot at heel strike;
    hip speed is the horizontal hip displacement over the step divided by its period;
    ``impact_energy_loss`` [J] is the kinetic energy the heel-strike collision takes (a
    walker with a push-off impulse: after the push-off minus after the heel strike, the
    energy ledger's ``heel_strike_loss``), ``transition_energy_change`` [J] the net change of
    the kinetic energy across the whole step-to-step transition (push-off and heel strike;
    without a push-off minus the impact loss);
    ``phases`` lists the step's phases, each with the guard that ended it
    (``"early_swing (midstance) > late_swing (heel_strike)"``).
    """
    w = traj.walker
    rows = {k: [] for k in ("index", "stance_leg", "swing_leg", "t_start", "t_end", "period",
                            "termination", "event", "step_length", "hip_speed",
                            "impact_energy_loss", "transition_energy_change", "nfev",
                            "midstance_time", "phases")}
    for seg in traj.segments:
        r2l = w.role_to_leg(seg.stance_leg)
        rows["index"].append(seg.index)
        rows["stance_leg"].append(seg.stance_leg)
        rows["swing_leg"].append(r2l.get("swing", ""))
        rows["t_start"].append(seg.t_start)
        rows["t_end"].append(seg.t_end)
        rows["period"].append(seg.period)
        rows["termination"].append(seg.termination)
        rows["event"].append(seg.event)
        # the phases met, each with the guard that ended it (a flat foot's modes, a knee's
        # lock ...), found by events at run time
        rows["phases"].append(" > ".join(f"{name} ({end or 'cut'})"
                                         for name, _ta, _tb, end in seg.phase_log))
        rows["nfev"].append(seg.nfev)
        rows["midstance_time"].append(seg.phase_times.get("midstance", np.nan))
        sw = w.for_stance(seg.stance_leg)  # legs that differ: that step's own numbers
        p0, p1 = sw.points(seg.x_start), sw.points(seg.x_end)
        if seg.termination == "heel_strike":
            rows["step_length"].append(step_length(w, seg))
            rows["hip_speed"].append(float((p1["hip"][0] - p0["hip"][0]) / seg.period))
            ke_m, _ = sw.energies(seg.x_end)
            ke_p, _ = w.for_stance(r2l.get("swing", seg.stance_leg)).energies(seg.x_next)
            acts = sw.actuators
            if acts is not None and acts.spec.push_off is not None:  # the collision alone
                tr = acts.transition(seg.x_end)
                rows["impact_energy_loss"].append(float(tr["ke_push_off"] - tr["ke_plus"]))
            else:
                rows["impact_energy_loss"].append(float(ke_m - ke_p))
            rows["transition_energy_change"].append(float(ke_p - ke_m))
        else:
            rows["step_length"].append(np.nan)
            rows["hip_speed"].append(np.nan)
            rows["impact_energy_loss"].append(np.nan)
            rows["transition_energy_change"].append(np.nan)
    return {k: np.asarray(v) for k, v in rows.items()}
