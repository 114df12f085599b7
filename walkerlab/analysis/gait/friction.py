"""The friction a rigid gait needs: the largest ``|tangential / normal|`` ground force at every
foot on the ground over the map's steps, against the scene's friction coefficient.

The rigid model pins the stance foot (and, in a flat foot's double support, the trailing
toe): it assumes no slip whatever force that takes.  A real foot holds only while its force
stays inside the Coulomb cone, ``|F_t| <= mu F_n`` (Coulomb's law of static friction), so a
gait whose ratio exceeds the ground's ``mu`` is not a gait on that ground, as one whose
normal force would pull is not (:class:`walkerlab.analysis.gait.checks.GroundContact`).

- Point, arc and spoke feet: the stance foot's force from the floating view
  (:class:`walkerlab.models.hybrid.ground_reaction.StanceReaction`), sampled along each
  continuous phase by :func:`walkerlab.analysis.gait.checks.ground_contact`.
- Flat feet (:mod:`walkerlab.models.hybrid.rigid_foot_modes`): the whole walker's force from
  Newton's second law on its point masses, ``F = sum m_i (a_i + g e_y)``, each ``a_i`` the
  second difference of the point's position relative to the pinned point of the phase (the
  stance heel, or the stance toe in heel off: fixed in the world while the phase lasts) along
  ``q + s dq + s^2 qdd / 2`` (error O(s^2)); in double support the trailing toe's force is
  the closed chain's multiplier (the generated ``double_support_<m>_forces``) and the
  leading foot carries the rest, ``F - lambda``.  A foot flat on the ground slips as one
  body: its ratio is its total tangential over its total normal force.

The friction coefficient is the contact section's static one (``contact.mu_static``), or
its default (the contact model's, :class:`walkerlab.config.ContactSettings`) when the scene
has none.
"""

from __future__ import annotations

import math

import numpy as np

from walkerlab.config import ContactSettings
from walkerlab.integrate.rigid import simulate_steps
from walkerlab.io.friction import FrictionVerdict
from walkerlab.models.hybrid.rigid_foot_modes import mode_of

__all__ = ["FrictionVerdict", "scene_friction", "flat_foot_friction", "stance_friction",
           "UNLOADED"]


#: a foot whose normal force is at most this fraction of the walker's weight is unloaded:
#: its ratio is infinite when its tangential force is above it too, else it is left out
UNLOADED = 1e-9


class _Worst:
    """The largest friction ratio met so far, where and when, and the first time the
    force left the cone ``|F_t| <= mu F_n``."""

    def __init__(self, mu: float, weight: float):
        self.mu, self.tiny = mu, UNLOADED * weight
        self.ratio, self.foot, self.time = 0.0, "", math.nan
        self.exit, self.unloaded = math.nan, math.nan
        self.seen = False

    def add(self, foot: str, fn: float, ft: float, t: float) -> None:
        self.seen = True
        if fn <= self.tiny:
            if abs(ft) <= self.tiny or fn < -self.tiny:  # off the ground, or nothing to hold
                return
            r = math.inf
            if math.isnan(self.unloaded):
                self.unloaded = ft
        else:
            r = abs(ft) / fn
        if r > self.mu and math.isnan(self.exit):
            self.exit = t
        if r > self.ratio:
            self.ratio, self.foot, self.time = r, foot, t


def scene_friction(scene) -> tuple[float, str]:
    """The ground's static friction coefficient ``mu`` [-] of ``scene`` and where it comes
    from (the contact section's ``mu_static``, or the contact model's default)."""
    if getattr(scene, "contact", None) is not None:
        return float(scene.contact.mu_static), "contact.mu_static"

    return float(ContactSettings.model_fields["mu_static"].default), \
        "the contact model's default"


def _point_masses(walker, data) -> dict[str, float] | str:
    """``{point name: mass [kg]}`` of a flat-footed walker (``M_hip`` at ``hip``, each leg
    body's ``m_<body>`` at ``stance_<body>`` and ``swing_<body>``, feet with mass ``m_foot``
    at the ankles), or why not (a str): they must add up to the walker's total mass."""
    p = walker.params
    masses = {"hip": float(p.get("M_hip", 0.0))}
    for b in data.structure.bodies:
        if b.massless:
            continue
        m = p.get(f"m_{b.name}")
        if m is None:
            return f"no mass parameter for the body {b.name!r}"
        for role in ("stance", "swing"):
            masses[f"{role}_{b.name}"] = float(m)
    if p.get("m_foot"):
        for role in ("stance", "swing"):
            masses[f"{role}_ankle"] = float(p["m_foot"])
    total = float(data.total_mass_kg)
    if not math.isclose(sum(masses.values()), total, rel_tol=1e-12, abs_tol=1e-12):
        return (f"the point masses ({sum(masses.values()):.6g} kg) are not the walker's "
                f"total ({total:.6g} kg)")
    return masses


def _newton_force(walker, masses, pin: str, x, xdot, g: float, h: float = 1e-4):
    """``sum m_i (a_i + g e_y)`` (2,) [N]: the ground's total force on the walker at state
    ``x`` (2n,) with ``xdot = flow(t, x)``; accelerations relative to the pinned point
    ``pin`` (second differences along ``q + s dq + s^2 qdd / 2``, step ``h``)."""
    n = walker.n_coordinates
    q, dq, qdd = np.asarray(x, float)[:n], np.asarray(x, float)[n:], np.asarray(xdot)[n:]
    zero = np.zeros(n)

    def rel(qq):
        pts = walker.points(np.concatenate([qq, zero]))
        o = np.asarray(pts[pin], float)
        return {k: np.asarray(pts[k], float) - o for k in masses}

    mid = q + 0.5 * h * h * qdd
    a, b, c = rel(mid + h * dq), rel(mid - h * dq), rel(q)
    F = np.zeros(2)
    for k, m in masses.items():
        F += m * ((a[k] + b[k] - 2.0 * c[k]) / (h * h) + np.array([0.0, g]))
    return F


def _forces_of(phase):
    """The double support's force function ``(t, x) -> (4,)`` [N] of a phase (the one its
    ``toe_off`` guard reads: trailing toe normal and tangential, leading foot normal and
    its toe's share)."""
    guard = next(gd for gd in phase.guards if gd.name == "toe_off")
    return guard.function.args[0]


def flat_foot_friction(walker, data, x, solver, mu: float, mu_source: str,
                       samples: int = 200) -> FrictionVerdict:
    """The friction a flat-footed walker's gait from ``x`` needs over one map (module
    docstring): every foot on the ground, single and double support, at ``samples`` points
    of each continuous phase.

    Parameters
    ----------
    walker : HybridWalker
        A flat-footed rigid walker
        (:func:`walkerlab.models.hybrid.rigid_foot_modes.make_flat_walker`).
    data : walkerlab.walker.description.WalkerData
    x : ndarray (2n,)
        Post-impact state (the fixed point) [rad, rad/s].
    solver : Solver
    mu : float
        The ground's friction coefficient [-]; ``mu_source`` where it comes from.
    samples : int
        Samples per continuous phase.

    Returns
    -------
    FrictionVerdict
        ``not_checked`` set when the walker's masses cannot be read or the map does not end
        in heel strikes.
    """
    masses = _point_masses(walker, data)
    if isinstance(masses, str):
        return FrictionVerdict(mu=mu, mu_source=mu_source, not_checked=masses)
    phi = float(walker.slope_rad)
    normal, tangent = np.array([np.sin(phi), np.cos(phi)]), np.array([np.cos(phi), -np.sin(phi)])
    g = float(data.gravity_m_per_s2)
    weight = float(data.total_mass_kg) * g
    traj = simulate_steps(walker, np.asarray(x, float), walker.steps_per_map, solver)
    n = np.asarray(x).size
    single, double = _Worst(mu, weight), _Worst(mu, weight)
    for seg in traj.segments:
        if seg.termination != "heel_strike":
            return FrictionVerdict(mu=mu, mu_source=mu_source,
                                   not_checked=f"the map ends in {seg.termination}")
        for phase, sol, (ta, tb) in seg.pieces:
            if tb <= ta:
                continue
            in_double = phase.name.startswith("double_support")
            mode = mode_of(phase.name.split(":", 1)[1] if in_double else phase.name)
            pin = "stance_toe" if mode == "heel_off" else "stance_heel"
            forces = _forces_of(phase) if in_double else None
            for t in np.linspace(ta, tb, samples):
                xs = np.ravel(sol(t))[:n]
                F = _newton_force(walker, masses, pin, xs, phase.flow(t, xs), g)
                fn, ft = float(F @ normal), float(F @ tangent)
                if forces is None:
                    single.add("stance foot", fn, ft, float(t))
                    continue
                lam_n, lam_t, lead_n, _toe = (float(v) for v in forces(t, xs))
                double.add("trailing toe", lam_n, lam_t, float(t))
                double.add("leading foot", lead_n, ft - lam_t, float(t))
    return _verdict(single, double, mu, mu_source)


def _verdict(single: _Worst, double: _Worst, mu: float, mu_source: str) -> FrictionVerdict:
    top = single if single.ratio >= double.ratio else double
    exits = [w.exit for w in (single, double) if not math.isnan(w.exit)]
    return FrictionVerdict(
        float(top.ratio), top.foot, top.time, float(single.ratio) if single.seen else math.nan,
        float(double.ratio) if double.seen else math.nan, mu, mu_source,
        exit_time_s=min(exits) if exits else math.nan,
        unloaded_tangential_n=top.unloaded if math.isinf(top.ratio) else math.nan)


def stance_friction(samples, mu: float, mu_source: str, weight: float) -> FrictionVerdict:
    """The verdict of a single stance foot's forces ``samples`` (iterable of ``(t [s], F_n
    [N], F_t [N])``), the point-foot walkers' (no double support of finite length)."""
    single = _Worst(mu, weight)
    for t, fn, ft in samples:
        single.add("stance foot", fn, ft, t)
    return _verdict(single, _Worst(mu, weight), mu, mu_source)
