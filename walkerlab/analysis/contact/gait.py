"""What a contact run's samples mean: touchdowns, heel strikes, steps, and how the run ended.

Input: the samples of :func:`walkerlab.integrate.contact.integrate_contact` (times, states
named by ``walker.state_names()``) and the model's per-foot contact quantities
(``walker.foot_quantities``: per leg; a flat foot's heel and toe combined, and
``walker.contact_quantities`` per contact point).  Output: per-foot traces with touchdown /
lift-off times, the heel strikes and one :class:`StepSummary` per step (slip, creep,
bounces, scuffs, peak penetration), from which the run's typed
:class:`~walkerlab.analysis.contact.verdict.Outcome` is read (its ``kind`` one of the shared
run ends, :mod:`walkerlab.integrate.ends`).  Nothing here integrates or reads a state by
row.

Touchdown and lift-off are the zero crossings of the penetration, located on the cubic
Hermite interpolant of the samples and their rates; a heel strike is a touchdown of the
non-stance foot at least ``min_step_m`` downhill of the stance foot's touchdown point, other
touchdowns of that foot are scuffs, of the stance foot bounces.

The run's outcome and verdict are :mod:`walkerlab.analysis.contact.verdict`'s, the
footfalls against a checkerboard :mod:`walkerlab.analysis.contact.terrain_fit`'s, the
records (:class:`~walkerlab.analysis.contact.result.ContactResult`, :class:`StepSummary`,
:class:`FootTrace`) :mod:`walkerlab.analysis.contact.result`'s.
"""

from __future__ import annotations

import numpy as np

from walkerlab.analysis.contact.result import FootTrace, StepSummary
from walkerlab.integrate.contact import hermite_root
from walkerlab.models.contact.parts import contact_part

__all__ = ["FOOT_MODES", "foot_modes", "gait_events", "heel_strike_count", "phase_slip"]


def _crossings(t, pen, rate, on):
    """Touchdown / lift-off times from sampled penetration, its rate and ground flags.

    Crossings of zero penetration are located on the cubic Hermite interpolant (values and
    rates at the samples); a change of the ground flag (patch edge) counts at the sample.
    """
    c = (pen > 0) & on
    td, lo = [], []
    if c.size and c[0]:
        td.append(t[0])
    for k in np.flatnonzero(c[1:] != c[:-1]) + 1:
        tc = t[k]
        if on[k] and on[k - 1]:
            r = hermite_root(t[k - 1], t[k], pen[k - 1], pen[k], rate[k - 1], rate[k],
                             rising=bool(c[k]))
            if r is not None:
                tc = r
        (td if c[k] else lo).append(tc)
    return np.array(td), np.array(lo)


def phase_slip(t, s, td, lo, ta, tb, v=None):
    """Slide [m] of a foot over its contact phases starting in [ta, tb): sum of s(lo) - s(td)
    per phase (a point foot: its contact point is its material point), or, given the
    material point's tangential velocity ``v`` (n,) [m/s], its integral over each phase (an
    arc foot: the contact point also moves as the foot rolls, ``R dtheta``, which is not
    slip); NaN if the last such phase has no lift-off."""
    total, any_phase = 0.0, False
    for tdj in td:
        if not (ta - 1e-12 <= tdj < tb):
            continue
        any_phase = True
        nxt = lo[lo > tdj]
        if not nxt.size:
            return np.nan
        if v is None:
            total += float(np.interp(nxt[0], t, s) - np.interp(tdj, t, s))
        else:
            m = (t > tdj) & (t < nxt[0])
            tt = np.concatenate([[tdj], t[m], [nxt[0]]])
            vv = np.concatenate([[np.interp(tdj, t, v)], v[m], [np.interp(nxt[0], t, v)]])
            total += float(np.trapezoid(vv, tt))
    return total if any_phase else np.nan


def stance_phases(td, lo, ta, tb) -> list[tuple[float, float]] | None:
    """Contact phases [(touchdown, lift-off)] [s] of a foot that start in [ta, tb); None if
    the last such phase has no lift-off (as :func:`phase_slip`'s NaN)."""
    out = []
    for tdj in td:
        if ta - 1e-12 <= tdj < tb:
            nxt = lo[lo > tdj]
            if not nxt.size:
                return None
            out.append((float(tdj), float(nxt[0])))
    return out


def phase_integral(t, y, phases) -> float:
    """Trapezoidal integral of the samples ``y`` (n,) on ``t`` (n,) [s] over ``phases``
    [(a, b)] [s], the ends interpolated; NaN if ``phases`` is None (an unfinished phase)."""
    if phases is None:
        return np.nan
    total = 0.0
    for a, b in phases:
        m = (t > a) & (t < b)
        tt = np.concatenate([[a], t[m], [b]])
        yy = np.concatenate([[np.interp(a, t, y)], y[m], [np.interp(b, t, y)]])
        total += float(np.trapezoid(yy, tt))
    return total


def _intervals(td, lo, t_end):
    """Contact intervals [(touchdown, lift-off)] of a foot (lift-off = ``t_end`` if none)."""
    out = []
    for a in td:
        nxt = lo[lo > a]
        out.append((float(a), float(nxt[0]) if nxt.size else t_end))
    return out


def _foot_traces(walker, t, X, points: bool = False) -> dict[str, FootTrace]:
    """Traces per leg (``walker.foot_quantities``), or per contact point (``points``)."""
    cq = walker.contact_quantities(X) if points else walker.foot_quantities(X)
    feet = {}
    for name, d in cq.items():
        on = d["on_ground"] > 0.5
        td, lo = _crossings(t, d["penetration"], d["penetration_rate"], on)
        feet[name] = FootTrace(d["normal_force"], d["friction_force"], d["penetration"],
                               d["slip_velocity"], d["s"], on, td, lo,
                               d.get("lateral_slip_velocity"), d.get("spin_rate"))
    return feet


def _first_stance(feet, initial_stance: str) -> str:
    """The foot in stance at the start: ``initial_stance``, or, for a walker whose feet are
    not legs (a rimless wheel's spokes, ``spoke0``, ...), its first contact point (the
    stance spoke of the rigid view's state it starts from)."""
    return initial_stance if initial_stance in feet else next(iter(feet))


def _heel_strikes(t, feet, min_step_m, initial_stance):
    """Heel strikes (times, feet) and the bounces / scuffs counted per step; the feet are
    the legs or, for a rimless wheel, its spokes (a heel strike is a spoke other than the
    stance spoke touching down ahead of it)."""
    evs = sorted((tt, name) for name in feet for tt in feet[name].touchdown_times)
    stance = _first_stance(feet, initial_stance)
    s_stance = float(np.interp(t[0], t, feet[stance].s))
    hs_t, hs_leg, bounces, scuffs = [], [], [0], [0]
    for tt, name in evs:
        if tt == t[0]:
            continue
        s_here = float(np.interp(tt, t, feet[name].s))
        if name != stance and s_here > s_stance + min_step_m:
            hs_t.append(tt)
            hs_leg.append(name)
            bounces.append(0)
            scuffs.append(0)
            stance, s_stance = name, s_here
        elif name == stance:
            bounces[-1] += 1
        else:
            scuffs[-1] += 1
    return hs_t, hs_leg, bounces, scuffs


def heel_strike_count(walker, t, X, min_step_m: float = 0.05,
                      initial_stance: str = "leg2") -> int:
    """Heel strikes in the samples ``t`` (n,) [s], ``X`` (n, N) (``walker.state_names()``)
    (the strides cap's count); a touchdown counts only ``min_step_m`` [m] downhill of the
    stance foot (as :func:`gait_events`)."""
    feet = _foot_traces(walker, t, X)
    return len(_heel_strikes(t, feet, min_step_m, initial_stance)[0])


def _double_support(t, feet, names) -> list:
    """Double-support intervals ``[(start, end, (foot, foot))]`` [s]: the overlaps of the
    feet's contact intervals (event times); a wheel: any two of its spokes, each overlap
    with the pair of spokes in contact."""
    iv = {f: _intervals(feet[f].touchdown_times, feet[f].liftoff_times, float(t[-1]))
          for f in names}
    return [(max(a1, a2), min(b1, b2), (f1, f2)) for j, f1 in enumerate(names)
            for f2 in names[j + 1:] for a1, b1 in iv[f1] for a2, b2 in iv[f2]
            if min(b1, b2) > max(a1, a2)]


def _held_phases(t, phases, dt_sample):
    """The stance phases from the first sample one sample interval after each touchdown:
    the heel-strike collision (a fraction of a millisecond) falls between the samples, and
    a sample that happens to land in it would alias its sliding (0.6 m/s against ~0.01 m/s
    of creep) into the slip path (its loss is the heel strike's); None as ``phases``."""
    held = None if phases is None else [
        (a if a <= t[0] else float(t[min(np.searchsorted(t, a + dt_sample), t.size - 1)]),
         b) for a, b in phases]
    return held if held is None else [(a, b) for a, b in held if b > a]


def _step_summary(t, feet, points, names, starts, loaded, ds, j, ta, leg, bounces, scuffs,
                  rolling, leg_of, dt_sample) -> StepSummary:
    """Step ``j`` of :func:`gait_events`: from ``ta`` [s] (``starts[j]``) with ``leg`` in
    stance to the next heel strike, its slip, slip path, friction work, double-support
    creep (over ``ds``, :func:`_double_support`) and peak penetration."""
    tb = starts[j + 1] if j + 1 < len(starts) else np.nan
    tb_or_end = tb if np.isfinite(tb) else t[-1]
    # stance phases of this leg that begin between its heel strike and the other foot's
    # (its touchdowns after that are the swing foot's scuffs, not stance)
    t_other = starts[j + 1] if j + 1 < len(starts) else np.inf
    t_next = starts[j + 2] if j + 2 < len(starts) else np.inf
    ft = feet[leg]
    td = ft.touchdown_times
    if j == 0 and (not td.size or td[0] > t[0]) and loaded[leg][0]:
        td = np.concatenate([[t[0]], td])
    slip = phase_slip(t, ft.s, td, ft.liftoff_times, ta, t_other,
                      ft.slip_velocity if rolling else None)
    phases = stance_phases(td, ft.liftoff_times, ta, t_other)
    held = _held_phases(t, phases, dt_sample)
    path = phase_integral(t, np.abs(ft.slip_velocity), held)
    mine = [p for name, p in points.items()
            if name == leg or (name not in feet and leg_of is not None
                               and leg_of(name) == leg)]
    friction = -sum(phase_integral(t, p.friction_force * p.slip_velocity, held)
                    for p in mine) if phases else np.nan
    lo_mine = ft.liftoff_times[(ft.liftoff_times > ta) & (ft.liftoff_times < t_next)]
    sel = (t >= ta) & (t <= tb_or_end)
    creep = 0.0
    for a, b, pair in ds:
        a, b = max(a, ta), min(b, tb_or_end)
        if b > a:
            creep += sum(abs(float(np.interp(b, t, feet[f].s) - np.interp(a, t, feet[f].s)))
                         for f in pair)
    peak = max(float(np.max(feet[f].penetration[sel] * feet[f].on_ground[sel]))
               for f in names) if sel.any() else np.nan
    lateral = turn = np.nan
    if ft.spin_rate is not None and phases:  # a walker in 3D: across the slope, the turn
        lateral = float(1e3 * phase_integral(t, ft.lateral_slip_velocity, held))
        turn = float(1e3 * phase_integral(t, ft.spin_rate, held))
    return StepSummary(j, leg, float(ta), float(tb), float(tb - ta),
                       float(1e3 * slip), float(1e3 * creep), int(bounces),
                       int(scuffs), max(peak, 0.0),
                       float(lo_mine[-1]) if lo_mine.size else np.nan,
                       stance_slip_path_mm=float(1e3 * path) if phases else np.nan,
                       friction_work_j=float(friction) if phases else np.nan,
                       stance_lateral_slip_mm=lateral, stance_turn_mrad=turn)


def _annotate_foot_modes(t, points, steps) -> None:
    """Flat feet: set each step's ``foot_modes`` from the contact table (modes shorter than
    two sample intervals left out, repeats merged)."""
    dt = 2.0 * float(np.median(np.diff(t))) if t.size > 1 else 0.0
    for st in steps:
        tb = st.t_end if np.isfinite(st.t_end) else float(t[-1])
        segs = [(m, a) for m, a, b in foot_modes(t, points, st.stance_leg, st.t_start, tb)
                if b - a >= dt]
        merged = [s_ for k, s_ in enumerate(segs) if k == 0 or s_[0] != segs[k - 1][0]]
        st.foot_modes = " > ".join(f"{m} ({a:.4f} s)" for m, a in merged)


def gait_events(walker, t, X, min_step_m: float = 0.05, initial_stance: str = "leg2") -> dict:
    """Foot traces, heel strikes and step summaries of a contact run's samples.

    Parameters
    ----------
    walker : ContactWalker
    t : ndarray (n,)
        [s].
    X : ndarray (n, N)
        States named by ``walker.state_names()``.
    min_step_m : float
        A touchdown of the swing foot counts as a heel strike only if it lands at least this
        far [m] downhill of the stance foot's touchdown point (else it is a scuff).
    initial_stance : str
        The foot in stance at ``t[0]``.

    Returns
    -------
    dict
        ``feet`` {foot: FootTrace}, ``hs_t`` (k,) [s], ``hs_leg`` [foot], ``steps``
        [StepSummary], ``points`` {contact point: FootTrace} (the contact table per point
        with its touchdowns and lift-offs: a flat foot's heel and toe; the same traces as
        ``feet`` for one point per leg).
    """
    feet = _foot_traces(walker, t, X)
    hs_t, hs_leg, bounces, scuffs = _heel_strikes(t, feet, min_step_m, initial_stance)
    initial_stance = _first_stance(feet, initial_stance)
    # an arc's contact point moves as it rolls, a flat foot's loaded point changes from heel
    # to toe: their slip is the integral of the material point's tangential velocity
    st = getattr(walker, "structure", None)
    rolling = st is not None and contact_part(st).foot_rolls(st)
    names = list(feet)
    starts = [t[0]] + hs_t
    legs = [initial_stance] + hs_leg
    loaded = {f: (feet[f].penetration > 0) & feet[f].on_ground for f in names}
    ds = _double_support(t, feet, names)
    points = feet if tuple(walker.contact_names()) == tuple(feet) else \
        _foot_traces(walker, t, X, points=True)
    leg_of = getattr(walker, "contact_leg", None)
    dt_sample = float(np.median(np.diff(t))) if t.size > 1 else 0.0
    steps = [_step_summary(t, feet, points, names, starts, loaded, ds, j, ta, leg,
                           int(bounces[j]), int(scuffs[j]), rolling, leg_of, dt_sample)
             for j, (ta, leg) in enumerate(zip(starts, legs))]
    if all(f"{st.stance_leg}_heel" in points and f"{st.stance_leg}_toe" in points
           for st in steps):  # flat feet: each step's mode sequence from the contact table
        _annotate_foot_modes(t, points, steps)
    return {"feet": feet, "hs_t": np.array(hs_t), "hs_leg": hs_leg, "steps": steps,
            "points": points}


# ---------------------------------------------------------------------------- foot modes
#: Mode of a flat foot by which of its points carry load (heel, toe): the rigid view's
#: names (:mod:`walkerlab.models.hybrid.rigid_foot_modes`), ``off`` when neither does.
FOOT_MODES = {(True, False): "heel_contact", (True, True): "foot_flat",
              (False, True): "heel_off", (False, False): "off"}


def foot_modes(t, points: dict, leg: str, t0: float = -np.inf,
               t1: float = np.inf) -> list[tuple[str, float, float]]:
    """The modes of ``leg``'s flat foot read from the contact table: which of its heel and
    toe carry a normal force, sample by sample (:data:`FOOT_MODES`), merged into segments.

    Parameters
    ----------
    t : ndarray (n,)
        Sample times [s].
    points : dict[str, FootTrace]
        Per contact point (``ContactResult.points``), with ``<leg>_heel``, ``<leg>_toe``.
    leg : str
    t0, t1 : float
        Window [s] (e.g. one step, heel strike to heel strike).

    Returns
    -------
    list of (mode, start [s], end [s])
        Consecutive segments at the samples' resolution.
    """
    sel = (t >= t0) & (t <= t1)
    heel = points[f"{leg}_heel"].normal_force[sel] > 0
    toe = points[f"{leg}_toe"].normal_force[sel] > 0
    ts = t[sel]
    out: list[tuple[str, float, float]] = []
    for k in range(ts.size):
        m = FOOT_MODES[(bool(heel[k]), bool(toe[k]))]
        if out and out[-1][0] == m:
            out[-1] = (m, out[-1][1], float(ts[k]))
        else:
            out.append((m, float(ts[k]), float(ts[k])))
    return out
