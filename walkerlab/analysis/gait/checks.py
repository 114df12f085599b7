"""Checks of a rigid run's trajectory the report states: energy drift between impacts, the
swing foot's clearance above the scene's ground, and whether the gait's ground contact is unilateral
(the ground pushes the stance foot, never pulls it)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from walkerlab.analysis.gait.friction import flat_foot_friction, stance_friction
from walkerlab.analysis.gait.rigid_run import rough_ground_steps
from walkerlab.integrate.rigid import simulate_steps
from walkerlab.io.trajectory import NamedTrajectory
from walkerlab.models.ground import foothold_steps, scene_ground
from walkerlab.models.hybrid.ground_reaction import StanceReaction


def energy_drift_in_swing(tr: NamedTrajectory) -> tuple[float, float]:
    """Largest change of the total energy within a continuous phase [J] and relative [-].

    A passive rigid walker conserves energy between impacts (heel strike, knee strike), so
    this measures the integration error.
    """
    tot, step = tr.total, tr.step_index
    phase = tr.phase if tr.phase is not None else np.zeros_like(step)
    key = step.astype(np.int64) * 1000 + phase
    drift = max(float(np.ptp(tot[key == k])) for k in np.unique(key))
    return drift, drift / float(np.max(np.abs(tot)))


def _foot(tr: NamedTrajectory, leg: str):
    """The ``<leg>_contact`` point (round feet) or else ``<leg>_foot`` (2, k); None."""
    return tr.points.get(f"{leg}_contact", tr.points.get(f"{leg}_foot"))


def footfalls(tr: NamedTrajectory) -> np.ndarray | None:
    """Where the feet of a two-legged run stood (k, 2) [m], in walking order: the first
    swing foot at the start, each step's stance foot, the last step's swing foot at its end
    (the ``<leg>_contact`` point when the walker has one); None for another walker."""
    if len(tr.legs) != 2:
        return None
    out = []
    for j, k in enumerate(np.unique(tr.step_index)):
        i = np.flatnonzero(tr.step_index == k)
        stance = int(tr.stance_leg[i[0]])
        feet = _foot(tr, tr.legs[stance]), _foot(tr, tr.legs[1 - stance])
        if feet[0] is None or feet[1] is None:
            return None
        if j == 0:
            out.append(feet[1][:, i[0]])
        out.append(feet[0][:, i[0]])
        last = feet[1][:, i[-1]]
    return np.asarray([*out, last], float) if out else None


def swing_foot_clearance(tr: NamedTrajectory, ground, margin: float = 0.1) -> float:
    """Lowest height [m] of the swing foot above the ground inside the steps of ``tr``.

    Heights are along the normal of the ground's piece under the foot
    (:meth:`walkerlab.models.ground.Ground.clearance`, the quantity the fixed point's stair
    check measures, :func:`walkerlab.analysis.gait.treads.tread_landing`); the first and
    last ``margin`` of each step (lift-off, heel strike, where the height is ~0) are left
    out.  A negative value means the foot passes through the ground (scuffing, which the
    rigid model ignores).  Round feet use the ``<leg>_contact`` point when the walker has
    one.

    Parameters
    ----------
    tr : NamedTrajectory
        A rigid run, points in its world frame.
    ground : walkerlab.models.ground.Ground or float
        The scene's ground (:func:`run_ground`), or a slope [rad]: the line through the
        first stance foot (the world origin).
    margin : float
        Fraction of each step left out at either end [-].
    """
    if not hasattr(ground, "clearance"):
        ground = scene_ground(None, float(ground))
    lowest = np.inf
    for k in np.unique(tr.step_index):
        m = tr.step_index == k
        t = tr.time[m]
        inner = (t > t[0] + margin * (t[-1] - t[0])) & (t < t[-1] - margin * (t[-1] - t[0]))
        swing = tr.legs[1 - int(tr.stance_leg[m][0])] if len(tr.legs) == 2 else None
        if swing is None or not inner.any():
            continue
        foot = _foot(tr, swing)
        if foot is None:
            continue
        xy = foot[:, m][:, inner]
        lowest = min(lowest, float(np.min(ground.clearance(xy[0], xy[1]))))
    return lowest


def run_ground(scene, tr: NamedTrajectory):
    """The scene's ground under a rigid run ``tr`` of it
    (:func:`walkerlab.models.ground.scene_ground`): footholds (and a drawn per-step ground,
    ``simulate.terrain_seed``) where the run's feet stood (:func:`footfalls`).

    Raises
    ------
    ValueError
        Footholds under a run without two legs' feet (one line).
    """
    terrain, phi = scene.terrain, float(scene.slope.phi_rad)
    sim = scene.simulate
    slopes = None
    if terrain is not None and terrain.kind == "footholds":
        steps = foothold_steps(terrain, phi)
        slopes = [g for _d, g in steps] if steps is not None else [phi]
    elif sim is not None and sim.terrain_seed is not None and terrain is not None \
            and terrain.per_step is not None:

        n = int(np.unique(tr.step_index).size)
        slopes = [g for _d, g in rough_ground_steps(scene, n)]
    if slopes is None and (terrain is None or terrain.kind == "slope"):
        return scene_ground(None, phi)
    return scene_ground(terrain, phi, footfalls(tr), slopes)


# ---------------------------------------------------------------------------- ground contact
#: dense samples of each continuous phase at which the stance foot's normal force is read
CONTACT_SAMPLES_PER_PHASE = 200


@dataclass
class GroundContact:
    """Whether a rigid gait's ground contact is unilateral: the ground pushes, never pulls.

    The rigid model pins the stance foot and takes the trailing foot off the ground at heel
    strike; a real foot needs a non-negative normal force along every continuous phase and
    non-negative normal impulses at the transition, and the trailing foot must move away
    from the ground after it (:mod:`walkerlab.models.hybrid.ground_reaction`).

    Attributes
    ----------
    min_normal_force_n : float
        Smallest normal force on the stance foot over the map's steps [N] (NaN: not
        checked).
    min_normal_time_s : float
        When it occurs, from the start of the map [s].
    max_friction_ratio : float
        Largest ``|tangential| / normal`` force while the normal force is positive [-]: the
        friction coefficient the gait needs.
    heel_strike_normal_impulse_n_s, push_off_normal_impulse_n_s : float
        Smallest normal component of the heel strike's / push-off's impulse [N s] over the
        map's transitions (push-off 0 without one).
    trailing_foot_normal_velocity_m_per_s : float
        Smallest normal velocity of the trailing foot just after a transition [m/s].
    not_checked : str
        Why the check could not be made ("" when it was): a walker without a floating view.
    friction : walkerlab.analysis.gait.friction.FrictionVerdict or None
        The friction the gait needs at every foot on the ground against the ground's
        ``mu`` (None: no ``mu`` given); made for flat feet too, whose normal forces the
        rigid model's own guards check.
    max_twist_n_m : float
        A walker in 3D: the largest moment about the slope's normal the stance foot carries
        over the map's continuous phases [N m] (the rigid model's stance joint lets the foot
        roll and pitch but never turn; a point foot on real ground cannot hold any); NaN in
        the plane.
    max_twist_time_s : float
        When it occurs, from the start of the map [s].
    twist_patch_radius_m : float
        A walker in 3D: the radius of the smallest round, evenly pressed foot patch whose
        Coulomb friction holds that twist, the largest over the samples of ``3 |M_n| /
        (2 mu F_n)`` (a disc of radius ``r`` pressed by ``F_n`` resists a turn with at most
        ``2 mu F_n r / 3``: the torsional friction of a uniform pressure disc); NaN in the
        plane or without ``mu``.
    """

    min_normal_force_n: float = np.nan
    min_normal_time_s: float = np.nan
    max_friction_ratio: float = np.nan
    heel_strike_normal_impulse_n_s: float = np.nan
    push_off_normal_impulse_n_s: float = np.nan
    trailing_foot_normal_velocity_m_per_s: float = np.nan
    not_checked: str = ""
    friction: object | None = None
    max_twist_n_m: float = np.nan
    max_twist_time_s: float = np.nan
    twist_patch_radius_m: float = np.nan

    @property
    def ok(self) -> bool | None:
        """True: the ground only pushes (every normal force and impulse >= 0, the trailing
        foot leaves); False: it would have to pull; None: not checked."""
        if self.not_checked:
            return None
        return bool(min(self.min_normal_force_n, self.heel_strike_normal_impulse_n_s,
                        self.push_off_normal_impulse_n_s,
                        self.trailing_foot_normal_velocity_m_per_s) >= 0)


def ground_contact(walker, data, x, solver, samples: int = CONTACT_SAMPLES_PER_PHASE,
                   mu: float | None = None, mu_source: str = "") -> GroundContact:
    """Check a rigid gait's ground contact over one Poincaré map from ``x`` (a step, or a
    stride for legs that differ): the stance foot's normal force at ``samples`` points of
    each continuous phase (its dense output), and the impulses of each transition
    (:class:`walkerlab.models.hybrid.ground_reaction.StanceReaction`).

    Parameters
    ----------
    walker : HybridWalker
    data : walkerlab.walker.description.WalkerData
        The walker's structure and numbers (``walker_data`` of its scene).
    x : ndarray (2n,)
        Post-impact state (the fixed point).
    solver : Solver
    samples : int
        Samples per continuous phase.
    mu : float, optional
        The ground's friction coefficient [-] (``mu_source``: where it comes from): the
        friction verdict (:attr:`GroundContact.friction`,
        :mod:`walkerlab.analysis.gait.friction`) is made with it; None: not made.

    Returns
    -------
    GroundContact
        ``not_checked`` set for a walker without a floating view (massless legs, flat
        feet) or a map that does not end in heel strikes.
    """
    try:
        reaction = {id(walker): StanceReaction(walker, data)}
        if walker.mirror is not None:
            reaction[id(walker.mirror)] = StanceReaction(walker.mirror, data.mirror)
    except ValueError as exc:
        friction = None
        if mu is not None and data.structure.kind.feet_have_modes:
            friction = flat_foot_friction(walker, data, x, solver, mu, mu_source, samples)
        return GroundContact(not_checked=str(exc), friction=friction)
    traj = simulate_steps(walker, np.asarray(x, float), walker.steps_per_map, solver)
    n = np.asarray(x).size
    n_min, t_min, ratio = np.inf, np.nan, 0.0
    twist, t_twist, radius = np.nan, np.nan, np.nan
    hs, po, vt = np.inf, np.inf, np.inf
    forces = []  # (t, F_n, F_t) of the stance foot: the friction verdict's samples
    for seg in traj.segments:
        if seg.termination != "heel_strike":
            return GroundContact(not_checked=f"the map ends in {seg.termination}")
        sr = reaction[id(walker.for_stance(seg.stance_leg))]
        for phase, sol, (ta, tb) in seg.pieces:
            for t in np.linspace(ta, tb, samples):
                xs = np.ravel(sol(t))[:n]
                F, moment = sr.force_and_twist(t, xs, phase.flow)
                fn, ft = sr.normal_and_tangential(F)
                forces.append((float(t), float(fn), float(ft)))
                if not np.isnan(moment):  # a walker in 3D: the twist its stance foot needs
                    if np.isnan(twist) or abs(moment) > twist:
                        twist, t_twist = abs(moment), float(t)
                    if mu is not None and fn > 0:  # no friction (mu 0): no foot holds it
                        radius = np.nanmax([radius, 1.5 * abs(moment) / (mu * fn)
                                            if mu > 0 else np.inf])
                if fn < n_min:
                    n_min, t_min = fn, float(t)
                if fn > 0:
                    ratio = max(ratio, abs(ft) / fn)
        imp = sr.transition(seg.x_end, seg.x_next)
        hs, po = min(hs, imp.heel_strike_normal), min(po, imp.push_off_normal)
        vt = min(vt, imp.trailing_foot_normal_velocity)
    friction = None
    if mu is not None:
        friction = stance_friction(forces, mu, mu_source,
                                   float(data.total_mass_kg) * float(data.gravity_m_per_s2))
    return GroundContact(float(n_min), t_min, float(ratio), float(hs), float(po), float(vt),
                         friction=friction, max_twist_n_m=float(twist),
                         max_twist_time_s=t_twist, twist_patch_radius_m=float(radius))
