"""A contact run's samples in the shared named layout of
:class:`walkerlab.io.trajectory.NamedTrajectory` (:func:`named_trajectory`): the figures,
animations and comparisons read the contact view as they read the rigid one.

Leg coordinates are renamed to the rigid view's (:func:`trajectory_names`); the stance leg
follows the heel strikes; a walker whose feet are not its legs (a spoked wheel) gets its leg
coordinates and feet from its stance and next contact points.  The run itself comes from
:mod:`walkerlab.analysis.contact.sim`, which re-exports this module's names.
"""

from __future__ import annotations

import numpy as np

from walkerlab.analysis.contact.result import ContactResult
from walkerlab.models.contact.model import state_name
from walkerlab.walker.layout import StateIndex


def trajectory_names(walker, legs=("leg1", "leg2")) -> dict[str, str]:
    """State name -> name in the shared trajectory layout for every leg coordinate of the
    walker (the hip position and velocity are points): the floating coordinate's name
    (``<leg>_angle``, kneed ``<leg>_thigh_angle``, ``<leg>_shank_angle``; the same names as
    the rigid walker's ``leg_coordinates``) and ``..._rate`` for its rate (angles [rad],
    rates [rad/s]).
    """
    idx = StateIndex(walker)
    n = idx.coordinates.stop
    out = {}
    for i, coord in enumerate(walker.coordinate_names()):
        if i < walker.dim:  # the floating base's slides (the hip's, or a 3D walker's
            continue        # stance foot's position): points of their own
        leg = coord.split("_", 1)[0]
        new = coord if leg not in ("leg1", "leg2") else legs[int(leg[-1]) - 1] + coord[4:]
        if not new.endswith("_angle"):  # a 3D walker's heading and rolls, as the rigid
            new += "_angle"             # view names its angles (leg1_roll_angle, ...)
        out[idx.names[i]] = new
        out[idx.names[n + i]] = new.removesuffix("_angle") + "_rate"
    return out


def _stance_points(walker, res: ContactResult, t) -> tuple[list, list]:
    """The contact points of a walker whose feet are not its legs (a spoked wheel's spoke
    tips) that stand for the legs, per sample: the stance point (the last heel strike's, at
    first the run's initial stance point) and the point that strikes next (the next heel
    strike's; after the last one the contact point listed after the stance point,
    ``walker.contact_names()`` being in the order the points touch down)."""
    names = list(walker.contact_names())
    order = [res.steps[0].stance_leg if res.steps else names[0], *res.heel_strike_legs]
    nxt = order[1:] + [names[(names.index(order[-1]) + 1) % len(names)]]
    k = np.searchsorted(np.asarray(res.heel_strike_times, float), t, side="right")
    return ([names.index(order[j]) for j in k], [names.index(nxt[j]) for j in k])


def _legs_from_points(walker, res: ContactResult, stance, legs) -> tuple[dict, dict]:
    """Leg coordinates and feet of a walker whose feet are not its legs (a spoked wheel,
    whose legs are the spokes of a step): per sample, the stance leg's foot is the stance
    contact point, the other leg's the point that strikes next (:func:`_stance_points`),
    each leg's angle that of the line from the hip to its foot from the downward vertical
    (positive: the foot ahead), ``psi = atan2(dx, -dy)``, and its rate
    ``(dx dvy - dy dvx) / (dx^2 + dy^2)`` from the points' velocities (the rigid view's leg
    angles: :meth:`HybridWalker.leg_coordinates`).

    Returns
    -------
    coordinates : dict[str, ndarray (n,)]
        ``<leg>_angle`` [rad], ``<leg>_rate`` [rad/s].
    feet : dict[str, ndarray (2, n)]
        ``<leg>_foot`` [m].
    """
    t, X = res.t, np.ascontiguousarray(np.atleast_2d(res.x), dtype=float)
    st_pt, sw_pt = _stance_points(walker, res, t)
    nf, n, d = len(walker.contact_names()), walker.nq, walker.dim
    P, V, J = np.empty((nf, d)), np.empty((nf, d)), np.empty((nf, d, n))
    pos, vel = np.empty((t.size, nf, d)), np.empty((t.size, nf, d))
    for r in range(t.size):
        walker.kernels.feet(X[r], walker.walker_params, P, V, J)
        pos[r], vel[r] = P, V
    col = dict(zip(walker.state_names(), X.T))
    rows = np.arange(t.size)
    if d == 3:  # in 3D the spokes' angles in the wheel's plane, as the rigid view's
        return _spoke_angles(col, pos, rows, stance, st_pt, sw_pt, legs)
    hip = np.vstack([col[state_name(c)] for c in ("hip_x", "hip_y")])
    hip_v = np.vstack([col[state_name(c, rate=True)] for c in ("hip_x", "hip_y")])
    coords, feet = {}, {}
    for i, leg in enumerate(legs):
        pt = np.where(stance == i, st_pt, sw_pt)
        foot, foot_v = pos[rows, pt].T, vel[rows, pt].T
        (dx, dy), (dvx, dvy) = foot - hip, foot_v - hip_v
        coords[f"{leg}_angle"] = np.arctan2(dx, -dy)
        coords[f"{leg}_rate"] = (dx * dvy - dy * dvx) / (dx ** 2 + dy ** 2)
        feet[f"{leg}_foot"] = foot
    return coords, feet


def _spoke_angles(col, pos, rows, stance, st_pt, sw_pt, legs) -> tuple[dict, dict]:
    """:func:`_legs_from_points` of a spoked wheel in 3D: each leg's angle that of its
    spoke in the wheel's plane from the downward vertical (the rigid view's ``stance``,
    ``swing``; :mod:`walkerlab.codegen.derive_3d`), spoke ``k``'s the wheel's angle (spoke
    0's, ``wheel_angle``) plus ``2 pi k / n``, its rate the wheel's; ``pos`` the
    spoke tips (n samples, nf, 3) [m], ``col`` the states by name."""
    nf = pos.shape[1]
    theta, rate = col[state_name("wheel_angle")], col[state_name("wheel_angle", rate=True)]
    coords, feet = {}, {}
    for i, leg in enumerate(legs):
        pt = np.where(stance == i, st_pt, sw_pt)
        coords[f"{leg}_angle"] = theta + 2.0 * np.pi * pt / nf
        coords[f"{leg}_rate"] = rate.copy()
        feet[f"{leg}_foot"] = pos[rows, pt].T
    return coords, feet


def named_trajectory(walker, res: ContactResult, legs=("leg1", "leg2")):
    """A :class:`ContactResult` in the shared named layout of
    :class:`walkerlab.io.trajectory.NamedTrajectory` (stance leg from the heel strikes;
    coordinates by :func:`trajectory_names`, points from the generated floating view: hip,
    each body ``<leg>_<body>``, feet, knees; points in [m], angles [rad], rates [rad/s],
    times [s]).

    A walker whose feet are not its legs (a spoked wheel: its heel strikes are contact points
    ``spoke<k>``, the legs of the vocabulary are the spokes of a step) alternates its stance
    leg at each heel strike as the rigid view does, and gets the rigid view's leg coordinates
    and feet from its stance and next contact points (:func:`_legs_from_points`): ``<leg>_angle``,
    ``<leg>_rate`` and the points ``<leg>_foot``.
    """
    from walkerlab.io.trajectory import NamedTrajectory  # light

    legs = list(legs)
    t = res.t
    stance = np.full(t.size, legs.index("leg2"))
    step = np.zeros(t.size, dtype=int)
    by_points = False
    for k, (ths, leg) in enumerate(zip(res.heel_strike_times, res.heel_strike_legs)):
        m = t >= ths
        if leg not in legs:  # a contact point, not a leg (a wheel's spoke): the other leg
            by_points = True
            leg = legs[1 - int(stance[m][0])] if m.any() else leg
        if leg in legs:
            stance[m] = legs.index(leg)
        step[m] = k + 1
    by_points = by_points or bool(res.steps) and res.steps[0].stance_leg not in legs
    X = res.x
    en = walker.energies(X)
    pts = {k: np.asarray(v, float).reshape(walker.dim, -1)
           for k, v in walker.points(X).items()}
    names = trajectory_names(walker, legs)
    units = dict(zip(walker.state_names(), walker.state_units()))
    coords = {new: res.column(old) for old, new in names.items()}
    units = {names[o]: units[o] for o in names}
    if by_points:
        leg_coords, feet = _legs_from_points(walker, res, stance, legs)
        for name, v in leg_coords.items():
            coords.setdefault(name, v)
            units.setdefault(name, "rad" if name.endswith("_angle") else "rad/s")
        for name, v in feet.items():
            pts.setdefault(name, v)
    return NamedTrajectory(
        time=t, legs=legs, coordinates=coords, units=units,
        stance_leg=stance, step_index=step, kinetic=en["kinetic"], potential=en["potential"],
        points=pts)
