"""Where a rigid walker's energy goes, step by step: the energy ledger and the cost of
transport.

For each step (heel strike to heel strike) the change of the total mechanical energy
``E = T + V`` (``V``: gravity, measured in the world from the first stance foot, and the
springs) is the sum of

- ``actuator_work_positive`` / ``actuator_work_negative`` [J]: the joint torques' work,
  ``int max(tau ddelta, 0) dt`` and ``int min(tau ddelta, 0) dt``, by adaptive quadrature on
  the step's dense output (independent of ``E``: the ledger's closure checks the flow); a
  3D walker's hip-roll law (in its generated flow) the same with its power
  ``dV/dt - G . dq``;
- ``damper_work`` [J] (<= 0): ``int dq . (Mdot dq / 2 - C dq) dt``, the part of ``-C dq``
  that is not Christoffel's (zero without dampers: the Christoffel part does no work);
- ``push_off_work`` [J]: kinetic energy after the push-off impulse minus before
  (:meth:`walkerlab.models.hybrid.actuated.Actuators.transition`);
- ``-heel_strike_loss`` [J]: kinetic energy lost in the plastic heel strike;
- ``-internal_collision_loss`` [J]: knee strikes and foot slaps within the step;

``closure = dE - (sum of the above)`` [J] is round-off and quadrature error (<= 1e-9 of the
step's kinetic energy).  ``potential_work = -dV`` [J] is gravity's (and the springs') work.

Cost of transport (Kuo 2002; Collins et al. 2005): ``(positive actuator work + push-off
work + M g d sin(phi)^+) / (M g d)`` with ``M`` the walker's mass, ``d`` the step's length
along the ground and ``M g d sin(phi)`` (``slope_energy``) the potential energy the slope
releases over it (nothing uphill).  A passive gait's is ``sin(phi)``; a powered gait on level
ground's is the actuators' share alone.  On stairs and footholds
(:func:`walkerlab.models.hybrid.ground.on_landing`) ``slope_energy`` is ``M g h`` with ``h``
[m] the step's descent, the stance foot's height minus the landing swing foot's (a stair's
riser down level treads; the slope's drop plus the foothold's depth): a passive gait's cost
of transport is then ``h / d``.
"""

from __future__ import annotations

import math

import numpy as np

from walkerlab.analysis.gait.energy_modes import flat_trajectory_ledger
from walkerlab.analysis.gait.ledger import LEDGER_NAMES, quad_work, released_energy
from walkerlab.analysis.gait.metrics import creep_along, step_length
from walkerlab.integrate.rigid import other_leg, simulate_steps

__all__ = ["gait_ledger", "gait_measures", "step_ledger", "trajectory_ledger"]


def _damped(walker) -> bool:
    """The walker has a damper (a spring-damper with c > 0 at the hip, a knee or an ankle)."""
    return any(k.startswith(("c_s", "c_knee", "c_ankle")) and float(v) != 0.0
               for k, v in walker.params.items())


def _damper_power(walker, x) -> float:
    """``dq . (Mdot dq / 2 - C dq)`` [W] at ``x`` (generated ``matrices``; ``Mdot dq`` by
    the complex step along ``dq``)."""
    fns = walker.matrices
    if fns is None:
        return 0.0
    n = x.size // 2
    q, dq = x[:n], x[n:]
    M, C, _ = fns(x)
    h = 1e-30
    Mc = fns(np.concatenate([q + 1j * h * dq, dq]))[0]
    Mdot = np.imag(Mc) / h
    return float(dq @ (0.5 * Mdot @ dq - C @ dq))


def _flow_law_power(walker, x) -> float:
    """The power [W] of a torque law written into the generated flow (a 3D walker's
    hip-roll law, ``walker.hip_roll``: its generalised forces ``Q`` are in ``G = dV/dq -
    Q``): ``Q . dq = dV/dt - G . dq``, ``dV/dt`` by the complex step of the walker's
    potential energy along ``dq``."""
    n = x.size // 2
    q, dq = x[:n], x[n:]
    G = np.asarray(walker.matrices(x)[2], float).ravel()
    h = 1e-30
    dV = np.imag(walker.energies(np.concatenate([q + 1j * h * dq, dq]))[1]) / h
    return float(dV - G @ dq)


#: a step's ledger whose closure exceeds this fraction of its starting kinetic energy [-] is
#: integrated again with each power split at its sign changes (:func:`_signed_work`)
CLOSURE_RECHECK = 1e-9


def step_ledger(walker, seg, next_walker=None) -> dict[str, float]:
    """The energy ledger of one step.

    Parameters
    ----------
    walker : HybridWalker
        The walker of this step (legs that differ: ``walker.for_stance(seg.stance_leg)``).
    seg : walkerlab.integrate.rigid.Segment
        The step, ended by a heel strike (other ends: every entry NaN).
    next_walker : HybridWalker, optional
        The walker of the next step (legs that differ: the other leg's numbers); default
        ``walker``.

    Returns
    -------
    dict[str, float]
        :data:`walkerlab.analysis.gait.ledger.LEDGER_NAMES` [J; ``push_off_impulse`` N s;
        ``cost_of_transport`` -].
    """
    out = dict.fromkeys(LEDGER_NAMES, np.nan)
    if seg.termination != "heel_strike":
        return out
    g = float(walker.params["gravity_m_per_s2"])
    m = float(walker.total_mass_kg)
    ke0, pe0 = (float(v) for v in walker.energies(seg.x_start))
    scale = max(ke0, 1e-12)
    wpos, wneg, wdamp, internal = _flow_work(walker, seg, scale)
    ke_end, pe_end = (float(v) for v in walker.energies(seg.x_end))
    pts = walker.points(seg.x_end)
    step = np.array(pts["swing_foot"], float)
    # feet whose rolling is not holonomic: the whole walker this far further along the fall
    # line than its printed points (walkerlab.walker.foot_trees.creep_rate)
    creep = float(creep_along(walker, seg, [seg.t_end])[-1])
    phi = float(walker.slope_rad)
    step[:2] += creep * np.array([math.cos(phi), -math.sin(phi)])
    nxt = walker if next_walker is None else next_walker
    push, loss, impulse, ke_plus = _heel_strike(walker, nxt, seg, ke_end)
    # the next stance foot (this step's swing foot) is step[1] higher in the world
    pe_plus = float(nxt.energies(seg.x_next)[1]) + m * g * float(step[1])
    d_e = (ke_plus + pe_plus) - (ke0 + pe0)
    closure = d_e - (wpos + wneg + wdamp + push - loss - internal)
    if abs(closure) > CLOSURE_RECHECK * scale:  # a kinked work integrand quad missed
        wpos, wneg, wdamp, internal = _flow_work(walker, seg, scale, split=True)
        closure = d_e - (wpos + wneg + wdamp + push - loss - internal)
    d = float(np.linalg.norm(step[:2]))  # the step's length (metrics.step_length's)
    slope_energy = released_energy(walker, d, float(step[1]))
    cot = (wpos + push + max(slope_energy, 0.0)) / (m * g * d)
    out.update(actuator_work_positive=wpos, actuator_work_negative=wneg, push_off_work=push,
               push_off_impulse=impulse, heel_strike_loss=loss,
               internal_collision_loss=internal, damper_work=wdamp,
               potential_work=-(pe_plus - pe0), energy_change=d_e, closure=closure,
               slope_energy=slope_energy, cost_of_transport=cot)
    return out


def _flow_work(walker, seg, scale: float, split: bool = False
               ) -> tuple[float, float, float, float]:
    """The works over the step's continuous pieces [J]: the joint torques' positive and
    negative work (the scene's laws, a virtual-constraint controller's, a law in the
    generated flow), the dampers' work and the kinetic energy lost at the resets inside
    the step (knee strike, foot slap); quadratures to a tolerance relative to ``scale``
    [J] (``split``: each power's integral split at its sign changes,
    :func:`_signed_work`)."""
    acts = walker.actuators
    wpos = wneg = wdamp = internal = 0.0
    damped = _damped(walker)
    # joint torques that do work: the scene's laws, or a virtual-constraint controller's
    torques = acts is not None and not acts.limit and (
        bool(acts.spec.torques) or getattr(acts, "controller", None) is not None)
    flow_law = "hip_roll" in walker.params  # its law is in the generated flow
    prev_ke = None
    n2 = seg.x_start.size
    for _ph, sol, (ta, tb) in seg.pieces:
        def x_at(t, sol=sol):
            y = np.asarray(sol(np.atleast_1d(float(t))), float)
            return (y[:, 0] if y.ndim == 2 else y)[:n2]

        ke_a = float(walker.energies(x_at(ta))[0])
        if prev_ke is not None:  # a reset inside the step: knee strike, foot slap
            internal += prev_ke - ke_a
        prev_ke = float(walker.energies(x_at(tb))[0])
        if tb <= ta:
            continue

        if torques:
            p, n = _signed_work(lambda t: acts.power(t, x_at(t)), ta, tb, scale, split)
            wpos, wneg = wpos + p, wneg + n
        if flow_law:
            p, n = _signed_work(lambda t: _flow_law_power(walker, x_at(t)), ta, tb, scale,
                                split)
            wpos, wneg = wpos + p, wneg + n
        if damped:
            wdamp += quad_work(lambda t: _damper_power(walker, x_at(t)), ta, tb, scale)
    return wpos, wneg, wdamp, internal


def _signed_work(power, a: float, b: float, scale: float, split: bool = False
                 ) -> tuple[float, float]:
    """The positive and the negative work [J] of ``power`` (t -> W) over ``[a, b]`` [s]:
    ``quad_work`` of ``max(p, 0)`` and of ``min(p, 0)``; with ``split``, the interval cut
    at the sign changes of ``p`` (bracketed on a 2000-point grid, located by brentq) and
    each piece's ``quad_work(p)`` of the smooth integrand added to its sign's total.
    Kinked where ``p`` changes sign, the first can miss a steep stretch that quad
    certifies wrongly (measured: 1.7e-5 J over a step of ``configs/hip_width_powered.yaml``,
    whose hip-roll law delivers a 40 W transient after the heel strike): the ledger asks
    for ``split`` when its closure fails (:data:`CLOSURE_RECHECK`)."""
    if not split:
        return (quad_work(lambda t: max(power(t), 0.0), a, b, scale),
                quad_work(lambda t: min(power(t), 0.0), a, b, scale))
    from scipy.optimize import brentq

    t = np.linspace(a, b, 2001)
    p = np.array([power(ti) for ti in t])
    cuts = [a] + [brentq(power, t[i], t[i + 1], xtol=1e-15)
                  for i in np.flatnonzero(np.sign(p[:-1]) * np.sign(p[1:]) < 0)] + [b]
    pos = neg = 0.0
    for t0, t1 in zip(cuts[:-1], cuts[1:]):
        w = quad_work(power, t0, t1, scale)
        pos, neg = (pos + w, neg) if w > 0 else (pos, neg + w)
    return pos, neg


def _heel_strike(walker, nxt, seg, ke_end: float) -> tuple[float, float, float, float]:
    """The heel strike's push-off work, kinetic energy loss [J], push-off impulse [N s] and
    the kinetic energy after it [J] (on the next step's walker ``nxt``), from the step's
    kinetic energy at its end ``ke_end`` [J]."""
    acts = walker.actuators
    if acts is not None and acts.spec.push_off is not None:
        tr = acts.transition(seg.x_end)
        push, loss, impulse = tr["ke_push_off"] - tr["ke_minus"], \
            tr["ke_push_off"] - tr["ke_plus"], float(tr["impulse"])
        return push, loss, impulse, float(tr["ke_plus"])
    ke_plus = float(nxt.energies(seg.x_next)[0])
    return 0.0, ke_end - ke_plus, 0.0, ke_plus


def trajectory_ledger(traj) -> dict[str, np.ndarray]:
    """:func:`step_ledger` of every step of a
    :class:`~walkerlab.integrate.rigid.HybridTrajectory`, each column (steps,); flat feet
    (no generated flow matrices: their modes pin the heel or the toe) by
    :func:`walkerlab.analysis.gait.energy_modes.flat_trajectory_ledger`, empty for flat
    feet on legs that differ."""
    w = traj.walker
    if w.matrices is None:
        return {} if w.mirror is not None else flat_trajectory_ledger(traj)
    rows = {k: [] for k in LEDGER_NAMES}
    for seg in traj.segments:
        led = step_ledger(w.for_stance(seg.stance_leg), seg,
                          w.for_stance(other_leg(w, seg.stance_leg)))
        for k in LEDGER_NAMES:
            rows[k].append(led[k])
    return {k: np.asarray(v, float) for k, v in rows.items()}


def gait_measures(walker, x, steps: int, solver, max_step_time: float = 5.0
                  ) -> dict[str, float]:
    """Step length, speed and cost of transport of a periodic gait through ``x``
    (:func:`gait_ledger` without the ledger).

    Parameters
    ----------
    walker : HybridWalker
    x : ndarray, shape (2n,)
        A post-impact state of the gait (``legs[0]`` about to swing).
    steps : int
        Steps of the gait's period (1, 2, 4, ...; legs that differ: a stride).
    solver : walkerlab.integrate.solver.Solver
    max_step_time : float
        [s]

    Returns
    -------
    dict[str, float]
        ``step_length`` [m] (mean), ``speed`` [m/s] (distance along the ground over the
        period's time), ``cost_of_transport`` [-] (mean over the steps; NaN without a
        ledger); all NaN when a step does not end by a heel strike.
    """
    return gait_ledger(walker, x, steps, solver, max_step_time)[0]


def gait_ledger(walker, x, steps: int, solver, max_step_time: float = 5.0
                ) -> tuple[dict[str, float], dict[str, np.ndarray]]:
    """The measures of :func:`gait_measures` and the energy ledger of every step of a
    periodic gait through ``x`` (one period simulated, :func:`trajectory_ledger`, as the
    ``simulate`` stage computes them).

    Parameters
    ----------
    As :func:`gait_measures`.

    Returns
    -------
    measures : dict[str, float]
        As :func:`gait_measures`.
    ledger : dict[str, ndarray (steps,)]
        :data:`LEDGER_NAMES` per step [J; ``push_off_impulse`` N s; ``cost_of_transport``
        -]; empty when a step does not end by a heel strike, or for flat feet on legs that
        differ (no ledger).
    """
    traj = simulate_steps(walker, np.asarray(x, float), int(steps), solver,
                          max_step_time=max_step_time)
    segs = traj.segments
    if len(segs) < steps or any(s.termination != "heel_strike" for s in segs):
        return {"step_length": np.nan, "speed": np.nan, "cost_of_transport": np.nan}, {}
    lengths = [step_length(walker, s) for s in segs]
    led = trajectory_ledger(traj)
    cot = float(np.mean(led["cost_of_transport"])) if led else np.nan
    return ({"step_length": float(np.mean(lengths)),
             "speed": float(np.sum(lengths) / (segs[-1].t_end - segs[0].t_start)),
             "cost_of_transport": cot}, led)
