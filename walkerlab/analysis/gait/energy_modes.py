"""The energy ledger of a walker on flat feet with ankle springs (Wisse et al. 2006), passive
or with an ankle push-off (:mod:`walkerlab.models.hybrid.ankle_push_off`).

Its walker has no generated ``matrices`` (its modes pin the heel or the toe), so the terms of
:func:`walkerlab.analysis.gait.energy.step_ledger` are read from the modes' own quantities:

- ``actuator_work_positive`` / ``actuator_work_negative`` [J]: the ankle push-off torque's
  power ``tau(a) da/dt`` over the heel-off phases, its positive and negative parts apart
  (the torque is constant or linear in the ankle angle ``a``, so the ankle turning back
  towards the leg after an overshoot makes it negative);
- ``damper_work`` [J] (<= 0): the ankle damper's ``-c_ankle (da/dt)^2`` (in every mode: in
  foot flat ``da/dt = -d stance/dt``), the hip spring-dampers' ``-c (d delta/dt)^2`` and,
  in double support, the trailing ankle's (its phases' ``held_energy``);
- ``internal_collision_loss`` [J]: the kinetic energy the foot slaps take (plastic,
  positions unchanged);
- ``heel_strike_loss`` [J]: the kinetic energy the heel strike takes plus the trailing
  ankle spring's energy, lost when its massless foot leaves the ground and snaps to its
  rest angle (``k (a - r)^2 / 2`` at the strike; :mod:`walkerlab.codegen.foot_modes`); where
  the step begins in double support (the trailing toe kept down,
  :mod:`walkerlab.models.hybrid.rigid_foot_modes`) less what that spring gives back before its toe
  lifts (its energy at the step's start less at toe off: the rest is lost there) and plus
  the kinetic energy the toe-pinning impulse takes (the heel strike's second stage);
- ``push_off_work``, ``push_off_impulse``: 0 (no impulse).

The total energy ``E = T + V`` (gravity from the first stance heel and the springs, the
walker's ``energies``) then closes, ``closure = dE - sum`` being quadrature and integration
error (<= 1e-9 of the step's kinetic energy at the scenes' tolerances).  Cost of transport
as :mod:`walkerlab.analysis.gait.energy`: (positive actuator work + the slope's energy if
released) / (M g d).
"""

from __future__ import annotations

import numpy as np

from walkerlab.analysis.gait.ledger import LEDGER_NAMES, quad_work, released_energy
from walkerlab.analysis.gait.metrics import step_length

__all__ = ["flat_step_ledger", "flat_trajectory_ledger"]


def _state(sol, t: float, n2: int) -> np.ndarray:
    return np.asarray(sol(float(t)), float).ravel()[:n2]


def _damper_power(walker, x) -> float:
    """Power of the ankle damper and the hip spring-dampers [W] (<= 0)."""
    p = walker.params
    n = x.size // 2
    roles = list(walker.roles)
    ia = roles.index("stance_ankle")
    power = -float(p.get("c_ankle", 0.0)) * x[n + ia] ** 2
    i = 0
    while f"c_s{i}" in p:  # the springs between the legs act on swing - stance
        rate = x[n + roles.index("swing")] - x[n + roles.index("stance")]
        power -= float(p[f"c_s{i}"]) * rate ** 2
        i += 1
    return float(power)


def flat_step_ledger(walker, seg) -> dict[str, float]:
    """The energy ledger of one step of a flat-footed walker (module docstring).

    Parameters
    ----------
    walker : HybridWalker
        A flat-footed walker (legs alike), with or without an ankle push-off.
    seg : walkerlab.integrate.rigid.Segment
        The step, ended by a heel strike (other ends: every entry NaN).

    Returns
    -------
    dict[str, float]
        :data:`~walkerlab.analysis.gait.ledger.LEDGER_NAMES` [J; ``push_off_impulse`` N s;
        ``cost_of_transport`` -].
    """
    out = dict.fromkeys(LEDGER_NAMES, np.nan)
    if seg.termination != "heel_strike":
        return out
    acts = walker.actuators
    g, m = float(walker.params["gravity_m_per_s2"]), float(walker.total_mass_kg)
    n2 = seg.x_start.size
    ke0, pe0 = (float(v) for v in walker.energies(seg.x_start))
    scale = max(ke0, 1e-12)
    wpos = wneg = wdamp = internal = returned = 0.0
    prev_ke = None
    for ph, sol, (ta, tb) in seg.pieces:
        ke_a = float(walker.energies(_state(sol, ta, n2))[0])
        held = getattr(ph, "held_energy", None)
        if prev_ke is not None:  # a foot slap inside the step
            internal += prev_ke - ke_a
        elif held is not None:  # double support: the toe-pinning impulse at the start
            returned -= ke0 - ke_a
        prev_ke = float(walker.energies(_state(sol, tb, n2))[0])
        if tb <= ta:
            continue
        wdamp += quad_work(lambda t, sol=sol: _damper_power(walker, _state(sol, t, n2)),
                           ta, tb, scale)
        if held is not None:  # the trailing ankle's damper, and what its spring gives back
            wdamp += quad_work(lambda t, sol=sol, h=held: h(_state(sol, t, n2))[1], ta, tb,
                               scale)
            returned += held(_state(sol, ta, n2))[0] - held(_state(sol, tb, n2))[0]
        if acts is not None and getattr(acts, "links", None):  # joint torques: every mode
            wpos += quad_work(lambda t, sol=sol: max(acts.power(t, _state(sol, t, n2)), 0.0),
                              ta, tb, scale)
            wneg += quad_work(lambda t, sol=sol: min(acts.power(t, _state(sol, t, n2)), 0.0),
                              ta, tb, scale)
        if acts is not None and ph.name.startswith("heel_off") \
                and getattr(acts, "ankle", None) is not None:  # an ankle push-off, in heel off
            def power(t, sol=sol):
                x = _state(sol, t, n2)
                return acts.torque(x[acts.ankle]) * x[acts.ankle + n2 // 2]
            wpos += quad_work(lambda t: max(power(t), 0.0), ta, tb, scale)
            wneg += quad_work(lambda t: min(power(t), 0.0), ta, tb, scale)
    ke_end, pe_end = (float(v) for v in walker.energies(seg.x_end))
    step = np.asarray(walker.points(seg.x_end)["swing_foot"], float)
    ke_plus, pe_next = (float(v) for v in walker.energies(seg.x_next))
    pe_plus = pe_next + m * g * float(step[1])  # the next heel is step[1] higher
    loss = (ke_end + pe_end) - (ke_plus + pe_plus)  # collision + the trailing ankle spring
    push = impulse = 0.0
    if acts is not None and getattr(acts.spec, "push_off", None) is not None:
        tr = acts.transition(seg.x_end)  # the toe's push-off before the heel strike
        push, impulse = float(tr["ke_push_off"] - tr["ke_minus"]), float(tr["impulse"])
        loss += push
    if returned:  # double support: the spring's energy given back, the entry impulse's loss
        loss -= returned
    d_e = (ke_plus + pe_plus) - (ke0 + pe0)
    closure = d_e - (wpos + wneg + wdamp + push - loss - internal)
    d = step_length(walker, seg)
    slope_energy = released_energy(walker, d, float(step[1]))
    out.update(actuator_work_positive=wpos, actuator_work_negative=wneg, push_off_work=push,
               push_off_impulse=impulse, heel_strike_loss=loss, internal_collision_loss=internal,
               damper_work=wdamp, potential_work=-(pe_plus - pe0), energy_change=d_e,
               closure=closure, slope_energy=slope_energy,
               cost_of_transport=(wpos + push + max(slope_energy, 0.0)) / (m * g * d))
    return out


def flat_trajectory_ledger(traj) -> dict[str, np.ndarray]:
    """:func:`flat_step_ledger` of every step of a flat-footed walker's trajectory, each
    column (steps,).

    Legs alike only (the caller,
    :func:`~walkerlab.analysis.gait.energy.trajectory_ledger`, leaves legs that differ out).
    """
    w = traj.walker
    rows = {k: [] for k in LEDGER_NAMES}
    for seg in traj.segments:
        led = flat_step_ledger(w, seg)
        for k in LEDGER_NAMES:
            rows[k].append(led[k])
    return {k: np.asarray(v, float) for k, v in rows.items()}
