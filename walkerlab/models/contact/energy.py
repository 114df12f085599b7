"""Energy of the contact walker as a guard on its integration.

The contact walker has no energy source: gravity is conservative, the IMPACT damping and the
regularised Coulomb friction only dissipate, so its total energy (kinetic + gravitational +
the elastic energy stored in the IMPACT springs ``k d^(e+1) / (e+1)`` of the feet on a patch
and of the knee stops) never rises.  A rise above the start by more than
:func:`energy_rise_bound` is therefore not physics: the samples from there on are not
trustworthy and the run ends as ``solver_failure`` at the last sample before it
(:func:`first_energy_violation`).

Exceptions the bound absorbs: the knee latch's engagement weight depends on the foot's
penetration, so a latch holding a slightly flexed knee can exchange ~1e-6 J; the
integrator's own error (relative ``rtol`` per step) moves the energy by ~``rtol`` of its
scale per step.

What makes a frictionless run blow up (paper_rods with mu = 0): with no friction
the stance foot slides off its patch into the gap and the walker sinks with both feet below
the patch tops (0.43 m and 0.27 m at 0.409 s) while its hip is still above the fall height;
then a foot enters the next patch *from its side*, 0.27 m below the top.  The IMPACT law
measures penetration from the top, so it reads a 0.27 m penetration: ``k d^e`` ~ 2e10 N and a
stored energy ~2e9 J appear within one step.  That is a trip (a foot hitting a patch's side),
which the sampled trip detection misses because the sample after it has already blown up.
Not the friction law's mu = 0 branch (it gives zero friction), not the stiction transition,
not the step size: odeint and CyRK's BDF produce the same blow-up, Radau stops there with a
step-size underflow.  :func:`side_entry` finds that trip on the last trustworthy sample.
"""

from __future__ import annotations

import numpy as np

__all__ = ["ENERGY_RISE_REL", "energy_rise_bound", "first_energy_violation", "side_entry",
           "total_energy"]

#: Relative rise of the total energy that ends a run [-], at least; see energy_rise_bound.
ENERGY_RISE_REL = 1e-4


def total_energy(walker, X) -> np.ndarray:
    """Kinetic + gravitational + stored elastic energy [J] of states ``X`` (n, 2 nq).

    Elastic: ``k d^(e+1) / (e+1)`` of each foot on a patch with penetration ``d > 0``, and
    ``k_k x^(e_k+1) / (e_k+1)`` of each knee stop at hyperextension ``x > 0`` (the integral
    of the IMPACT spring force ``k d^e``; MSC Adams/Solver function reference, IMPACT).

    Parameters
    ----------
    walker : ContactWalker
    X : array_like, shape (n, 2 nq) or (2 nq,)
        States in ``walker.state_names()`` order [m, rad, m/s, rad/s].

    Returns
    -------
    ndarray, shape (n,)
        Total energy [J] (potential relative to y = 0).
    """
    X = np.atleast_2d(np.asarray(X, float))
    E = walker.energies(X)["total"].astype(float)
    c = walker.contact
    for q in walker.contact_quantities(X).values():
        d = np.where(q["on_ground"] > 0.5, np.maximum(q["penetration"], 0.0), 0.0)
        E = E + c.k * d ** (c.e + 1) / (c.e + 1)
    ks = walker.knee_stop
    for q in walker.knee_stop_quantities(X).values():
        x = np.maximum(q["extension"], 0.0)
        E = E + ks.k * x ** (ks.e + 1) / (ks.e + 1)
    return E


#: The energy guard's bound for a walker whose joints carry a law that does work (a 3D
#: walker's hip-roll law, Kuo 1999): a fraction of the energy scale [-], far above the
#: law's work over a run's steps and far below a blow-up.
ACTIVE_RISE_REL = 0.5


def energy_rise_bound(walker, x0, rtol: float) -> float:
    """Largest rise of :func:`total_energy` above its start a trustworthy run can show [J].

    ``max(ENERGY_RISE_REL, 100 rtol) * (T0 + M g L)``: the energy scale is the start's kinetic
    energy plus the work of gravity over one leg length; the integrator's local error is
    ``rtol`` relative per step and the energy of a walking run at the shipped tolerances
    (rtol 1e-8) stays within ~1e-7 of that scale (measured), so 1e-4 of it is far above the
    integration error and far below any blow-up (1e10 J on 150 J).  A walker whose joints
    carry a law that does work (``kernels.STANCE_LAW``: a hip-roll law) gains energy from
    it: :data:`ACTIVE_RISE_REL` of the scale.

    Parameters
    ----------
    walker : ContactWalker
    x0 : array_like, shape (2 nq,)
        The run's first state (``walker.state_names()``).
    rtol : float
        The integrator's relative tolerance [-].

    Returns
    -------
    float
        The bound [J] (module docstring: the energy never rises without a source).
    """
    E = walker.energies(np.atleast_2d(x0))
    scale = float(E["kinetic"][0]) + walker.total_mass * walker.g * walker.L
    if walker.kernels.STANCE_LAW:  # a law at the joints does work (a hip-roll law): only
        return ACTIVE_RISE_REL * scale  # a blow-up is caught
    return max(ENERGY_RISE_REL, 100.0 * rtol) * scale


def first_energy_violation(walker, X, e_start: float, bound: float) -> int | None:
    """Index of the first state in ``X`` whose total energy exceeds ``e_start + bound``
    (None if none); a NaN energy counts as exceeding.

    Parameters
    ----------
    walker : ContactWalker
    X : array_like, shape (n, 2 nq)
        Samples of a run (``walker.state_names()``).
    e_start : float
        :func:`total_energy` of the run's start [J].
    bound : float
        Allowed rise [J] (:func:`energy_rise_bound`).
    """
    E = total_energy(walker, X)
    bad = np.flatnonzero(~(E <= e_start + bound))  # NaN counts as a violation
    return int(bad[0]) if bad.size else None


def side_entry(walker, x, dt: float) -> tuple[str, float, float, float] | None:
    """A foot below its lane's patch tops, in a gap, that reaches a patch's side within
    ``dt`` [s] at its present slip velocity (the trip the sampled detection misses when the
    step across it blows up).

    Returns
    -------
    (foot, edge_s_m, time_ahead_s, depth_m) or None
        The foot's name, the along-slope position of the side it reaches [m], when (from the
        state ``x``, linear extrapolation) [s], and its depth below the patch top [m].
    """
    if walker.continuous:
        return None
    cq = walker.contact_quantities(np.atleast_2d(x))
    for foot, q in cq.items():  # every contact point on its leg's lane
        lane = walker.lane(foot)
        if q["on_ground"][0] > 0.5:
            continue
        # depth below each side's patch top (the patches' own heights: stairs, rough ground)
        h = walker.lane_heights(foot)
        depth = q["penetration"][0] + np.concatenate([h, h])
        s, v = float(q["s"][0]), float(q["slip_velocity"][0])
        edges = np.concatenate([lane - walker.patch_half_width, lane + walker.patch_half_width])
        ahead = (edges - s) / v if v != 0 else np.full(edges.shape, np.inf)
        ok = (ahead >= 0) & (ahead <= dt) & (depth > 0)
        if ok.any():
            j = int(np.flatnonzero(ok)[np.argmin(ahead[ok])])
            return foot, float(edges[j]), float(ahead[j]), float(depth[j])
    return None
