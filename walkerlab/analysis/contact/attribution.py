"""Why the contact gait differs from the rigid one: the gap split by cause, energy by sink.

The paper's Section 5 argues that the ADAMS walker needs a faster stance leg and walks a
slightly different gait than the ideal one.  Here each cause is switched off in turn on the
contact walker's own periodic gait (:mod:`walkerlab.analysis.contact.periodic`):

- **friction creep**: the stiction regularisation lets a loaded stance foot creep at
  ``~ v_s F_t / (1.5 mu_s F_n)``; switched off by dividing ``v_s`` and ``v_d`` by
  :data:`CREEP_OFF` (the creep vanishes with ``v_s``);
- **compliance**: the finite stiffness (impact duration, sinking): the creep-free gap less
  the gap :data:`COMPLIANCE_OFF` times stiffer along the rigid-limit family
  (:mod:`walkerlab.models.contact.rigid_limit`, whose ``v_s ~ kappa^(-1/2)`` takes the creep down
  too; a creep-free contact that stiff is too stiff for the step map's integrator);
- **residual**: what remains at that stiffness (the family's gap there).

The initial-rate adjustment does not change a periodic gait (an attractor forgets its
start); its effect is on the transient run, measured as the change of the mean step period
over a run's steps (:func:`adjustment_effect`).

Energy per step by sink, on one step of the periodic gait: normal damping
``(F_n - k d^e) d'`` (the IMPACT force less its spring, clipping included), friction
``-F_t v_t`` while both feet are loaded (the impact, double support) and while one is
(stance creep).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from walkerlab.analysis.contact.sim import simulate_from
from walkerlab.analysis.contact.step_map import PeriodicGaitError, StepMap
from walkerlab.integrate.rigid import simulate_steps
from walkerlab.integrate.solver import Solver
from walkerlab.models.contact.rigid_limit import scale_walker
from walkerlab.models.contact.scene import contact_setup, ideal_step_length

__all__ = ["COMPLIANCE_OFF", "CREEP_OFF", "Attribution", "adjustment_effect", "attribute",
           "energy_by_sink"]

#: Factor on v_s, v_d that switches the creep off [-] (creep ~ v_s: 1 % of it remains).
CREEP_OFF = 1e-2
#: Stiffness factor along the rigid-limit family that switches compliance off [-].
COMPLIANCE_OFF = 1e3


@dataclass
class Attribution:
    """Contact - rigid gaps of the periodic gait [s, m] and their split by cause.

    Attributes
    ----------
    period_gap_s, step_gap_m : float
        Scene's contact periodic gait - rigid gait.
    creep_s, creep_m : float
        Share of friction creep (gap - gap with the creep off).
    compliance_s, compliance_m : float
        Share of compliance (gap with creep off - gap with creep off and stiff contact).
    residual_s, residual_m : float
        Gap left with both off.
    energy_J : dict[str, float]
        Dissipation per step of the scene's periodic gait by sink: ``normal_damping``,
        ``friction_impact``, ``friction_stance`` [J].
    """

    period_gap_s: float
    step_gap_m: float
    creep_s: float
    creep_m: float
    compliance_s: float
    compliance_m: float
    residual_s: float
    residual_m: float
    energy_J: dict


def _no_creep(walker, factor: float = CREEP_OFF):
    c = walker.contact
    return dataclasses.replace(walker, contact=dataclasses.replace(
        c, v_s=c.v_s * factor, v_d=c.v_d * factor))


def _gap_or_nan(find, T0, L0):
    """(period gap, step gap, z) of a periodic-gait search; NaN gaps if it fails."""

    try:
        g = find()
    except PeriodicGaitError:
        return np.nan, np.nan, None
    if not g.converged:
        return np.nan, np.nan, None
    return g.period_s - T0, g.step_length_m - L0, g.z


def energy_by_sink(walker, z, n_samples: int = 20000) -> dict[str, float]:
    """Dissipation [J] on one step of the map from section state ``z``, by sink.

    Parameters
    ----------
    walker : ContactWalker
    z : ndarray (n,)
        Section state (:class:`~walkerlab.analysis.contact.step_map.StepMap` coordinates).
    n_samples : int
        Samples of the step's dense output for the trapezoidal integrals.
    """

    sm = StepMap(walker)
    run = sm.integrate(sm.to_state(z), stance_to_come=0, dense=True)
    t = np.linspace(run.t[0], run.t[-1], n_samples)
    X = run.dense(t).T
    w, c = sm.walker, sm.walker.contact
    cq = w.contact_quantities(X)
    # in contact: on a patch and below its top (the force may be clipped at 0 there: the
    # spring's energy is then lost to the clipping, counted with the damping)
    loaded = [q["on_ground"] * (q["penetration"] > 0) for q in cq.values()]
    pressed = [on * (q["normal_force"] > 0) for on, q in zip(loaded, cq.values())]
    # double support: both legs loaded (a flat foot's leg by any of its points)
    leg_pressed = {leg: np.zeros(len(t), dtype=bool) for leg in ("leg1", "leg2")}
    for name, pr in zip(cq, pressed):
        leg_pressed[w.contact_leg(name) if name not in leg_pressed else name] |= pr > 0
    both = leg_pressed["leg1"] & leg_pressed["leg2"]
    damp, fr_imp, fr_st = np.zeros(len(t)), np.zeros(len(t)), np.zeros(len(t))
    for q, on in zip(cq.values(), loaded):
        d = np.maximum(q["penetration"], 0.0)
        spring = c.k * d ** c.e * on
        damp += (q["normal_force"] - spring) * q["penetration_rate"] * on
        fric = -q["friction_force"] * q["slip_velocity"] * on
        fr_imp += np.where(both, fric, 0.0)
        fr_st += np.where(both, 0.0, fric)
    return {"normal_damping": float(np.trapezoid(damp, t)),
            "friction_impact": float(np.trapezoid(fr_imp, t)),
            "friction_stance": float(np.trapezoid(fr_st, t))}


def attribute(walker, ideal, **search) -> Attribution:
    """Split the contact-vs-rigid gap of the periodic gait by cause (module doc).

    Parameters
    ----------
    walker : ContactWalker
        The scene's contact walker.
    ideal : rigid fixed-point result (``x``, ``period_s``)
    **search
        Passed to :func:`~walkerlab.analysis.contact.periodic.find_contact_periodic_gait`.
    """
    from walkerlab.analysis.contact.periodic import find_contact_periodic_gait  # light

    search.setdefault("check_fd", False)
    T0, L0 = float(ideal.period_s), ideal_step_length(walker, ideal.x)
    g = find_contact_periodic_gait(walker, ideal.x, **search)
    gaps = [(g.period_s - T0, g.step_length_m - L0)]
    z = g.z
    for f in (0.1, CREEP_OFF):  # warm starts towards the creep-free contact
        if z is not None:
            dT, dL, z = _gap_or_nan(lambda f=f, z=z: find_contact_periodic_gait(
                _no_creep(walker, f), z, **search), T0, L0)
    gaps.append((dT, dL) if z is not None else (np.nan, np.nan))
    z = g.z
    for kappa in (10.0, 100.0, COMPLIANCE_OFF):  # warm starts up the family (creep too)
        if z is not None:
            dT, dL, z = _gap_or_nan(lambda k=kappa, z=z: find_contact_periodic_gait(
                scale_walker(walker, k), z, **search), T0, L0)
    gaps.append((dT, dL) if z is not None else (np.nan, np.nan))
    return Attribution(gaps[0][0], gaps[0][1], gaps[0][0] - gaps[1][0], gaps[0][1] - gaps[1][1],
                       gaps[1][0] - gaps[2][0], gaps[1][1] - gaps[2][1], gaps[2][0], gaps[2][1],
                       energy_by_sink(walker, g.z))


def adjustment_effect(scene, ideal, strides: int = 5, *, plant) -> dict:
    """Mean step period [s] of the scene's contact run from its adjusted start and from the
    unadjusted ideal start, and whether the rigid walker started from the adjusted state
    walks (stays in the rigid walker's basin).  ``plant``: the scene's
    :class:`~walkerlab.walker.plant.Plant`, from the stage.

    Returns
    -------
    dict
        ``adjusted_s``, ``unadjusted_s`` (NaN if that run fell), ``rate_scale``,
        ``rigid_from_adjusted`` (the rigid run's termination after ``2 strides`` steps),
        ``rigid_heel_strikes``.
    """
    from walkerlab.models.registry import build_walker

    scale = tuple(scene.contact_sim.initial_rate_scale) if scene.contact_sim else (1.0, 1.0)
    out = {"rate_scale": scale}
    setup = contact_setup(scene, plant=plant)
    for key, rs in (("adjusted_s", scale), ("unadjusted_s", (1.0, 1.0))):
        _, r, _, _ = simulate_from(setup, ideal.x, ideal.period_s, rate_scale=rs,
                                   strides=strides)
        T = np.diff(r.heel_strike_times)
        out[key] = float(np.mean(T)) if T.size and r.termination in ("t_final",
                                                                     "heel_strike") \
            else float("nan")
    iw = build_walker(setup.plant.with_(scene))  # the set-up's plant: the walker described once
    # leg1 swings first (paper Eq. 11): its rates take scale[0], the stance leg's scale[1]
    # (none asked: the gait itself, whatever its coordinates, a 3D walker's lean too)
    x = (np.array(ideal.x, float) if scale == (1.0, 1.0) else
         iw.layout().scale_rates(ideal.x, {"swing": scale[0], "stance": scale[1]}))
    run = simulate_steps(iw, x, 2 * strides, Solver.from_settings(scene.solver))
    out["rigid_from_adjusted"] = run.termination
    out["rigid_heel_strikes"] = sum(s.termination == "heel_strike" for s in run.segments)
    return out
