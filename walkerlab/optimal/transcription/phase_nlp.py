"""The nonlinear program of a sequence of phases
(:func:`walkerlab.optimal.transcription.mode_sequence.collocate_phases`): each phase's
Hermite-Simpson defects, guard and path constraints (Kelly 2017, "An introduction to trajectory
optimization", SIAM Review 59(4), sec. 4), the joins by reset or push-off and heel strike (Kuo
2002), the gait targets and the objective's terms (effort by Simpson's rule, peak torque, cost
of transport from the positive work)."""

from __future__ import annotations

import numpy as np


def _simpson(T, tau, values):
    """Simpson's rule on the 2N + 1 points ``T tau`` of one phase (``values`` (1, 2N + 1),
    ``tau`` (2N + 1,) from 0 to 1, mid-points halfway)."""
    import casadi as ca

    K = values.shape[1]
    w = np.zeros(K)
    for i in range(0, K - 1, 2):
        dt = tau[i + 2] - tau[i]
        w[i] += dt / 6
        w[i + 1] += 4 * dt / 6
        w[i + 2] += dt / 6
    return T * ca.sum2(ca.DM(w).T * values)


def _phase(opti, mp, spec, X, U, T, tau, first: bool, last: bool, fns):
    """One phase's defects (on the mesh ``T tau``), its guard at the end (transversal) and
    inside (its sign), its unilateral contacts and the path constraints."""
    import casadi as ca

    K = X.shape[1]
    several = U.shape[0] > 1  # several torques (k, K): a column a point

    def at(k):
        return U[:, k] if several else U[k]
    f = [mp.flow(X[:, k], at(k)) for k in range(K)]
    for i in range(0, K - 1, 2):
        m, j = i + 1, i + 2
        h = T * (tau[j] - tau[i])
        opti.subject_to(X[:, m] == 0.5 * (X[:, i] + X[:, j]) + h / 8 * (f[i] - f[j]))
        opti.subject_to(X[:, j] == X[:, i] + h / 6 * (f[i] + 4 * f[m] + f[j]))
    d = mp.direction
    opti.subject_to(mp.guard(X[:, -1], at(-1)) == 0)
    opti.subject_to(d * mp.guard_rate(X[:, -1], at(-1)) >= spec.touchdown_rate_rad_per_s)
    for k in range(1, K - 1) if mp.inside else ():  # the event has not happened inside
        opti.subject_to(d * mp.guard(X[:, k], at(k)) <= 0)
    if mp.keep is not None:  # unilateral contacts push
        for k in range(K):
            opti.subject_to(mp.keep(X[:, k], at(k)) >= 0)
    if spec.min_clearance_m is not None:
        for k in range(1 if first else 0, K - 1 if last else K):
            opti.subject_to(mp.clearance(X[:, k]) >= spec.min_clearance_m)
    if spec.hip_angle_range_rad is not None:
        lo, hi = spec.hip_angle_range_rad
        for k in range(K):
            opti.subject_to(opti.bounded(lo, fns["hip_angle"](X[:, k]), hi))
    if spec.max_torque_n_m is not None:
        opti.subject_to(opti.bounded(-spec.max_torque_n_m, U, spec.max_torque_n_m))
    if spec.friction_coefficient is not None:  # the stance foot's resultant in its cone
        mu = spec.friction_coefficient
        for k in range(K):
            F = mp.grf(X[:, k], at(k))
            opti.subject_to(F[0] >= 0)
            if F.shape[0] == 2:  # a planar walker's tangent
                opti.subject_to(opti.bounded(-mu * F[0], F[1], mu * F[0]))
            else:  # in 3D, the tangential force along the fall line and across it
                opti.subject_to(F[1] ** 2 + F[2] ** 2 <= (mu * F[0]) ** 2)
    return _simpson(T, tau, ca.sum1(U ** 2) if several else U ** 2)


def _positive_work(opti, fns, Xs, Us, Ts, taus, slack: bool):
    """The hip's positive work over the step [J]: Simpson's rule per phase on
    ``max(p, 0)`` at the points (``p = u d(hip angle)/dt``), exactly by slack variables
    when ``slack`` (:func:`walkerlab.optimal.transcription.step.positive_power`), else evaluated
    (for the record)."""
    import casadi as ca

    from walkerlab.optimal.transcription.step import positive_power

    work = 0
    for X, U, T, tau in zip(Xs, Us, Ts, taus):
        p = ca.horzcat(*[fns["power"](X[:, k], U[k]) for k in range(X.shape[1])])
        work = work + _simpson(T, tau, positive_power(opti, p) if slack else ca.fmax(p, 0))
    return work


def _pushes(spec) -> bool:
    """The spec has a push-off (fixed and positive, or free)."""
    return bool(spec.push_off_free or spec.push_off_n_s)


def _chain_phases(opti, fns, spec, guess, guess_u, dec, taus, push, sums):
    """Collocate each phase of a phase sequence and join it to the next by its reset
    (or push-off and heel strike), with its duration's bounds and the starting values.

    ``dec`` are the decision variables ``(Xs, Us, Ts)``, ``taus`` each phase's normalised
    mesh, ``push`` the push-off impulse [N s] and ``sums`` the running ``(effort, push-off
    work, heel strikes)``; returns them summed over the phases (Kuo 2002's push-off before
    each heel strike).
    """
    Xs, Us, Ts = dec
    effort, po_work, strikes = sums
    phases = fns["phases"]
    P, nu = len(phases), int(fns.get("torques", 1))
    for p, mp in enumerate(phases):  # a step starts at 0 and after each heel strike
        starts = p == 0 or phases[p - 1].guard_name == "heel_strike"
        effort = effort + _phase(opti, mp, spec, Xs[p], Us[p], Ts[p], taus[p], starts,
                                 p == P - 1 or mp.guard_name == "heel_strike", fns)
        nxt = Xs[p + 1][:, 0] if p + 1 < P else Xs[0][:, 0]
        if _pushes(spec) and mp.guard_name == "heel_strike":  # push-off + heel strike
            x_plus, w = mp.push_off(Xs[p][:, -1], push)
            opti.subject_to(nxt == x_plus)
            po_work, strikes = po_work + w, strikes + 1
        else:
            opti.subject_to(nxt == mp.reset(Xs[p][:, -1]))
        Tg = float(guess[p][1][-1])
        opti.subject_to(opti.bounded(0.05 * Tg, Ts[p], 5.0 * Tg))
        opti.set_initial(Ts[p], Tg)
        opti.set_initial(Xs[p], guess[p][2].T)
        size = guess[p][1].size
        opti.set_initial(Us[p], np.zeros((nu, size)) if guess_u is None
                         else np.asarray(guess_u[p], float).reshape(size, nu).T)
    return effort, po_work, strikes


def _objective(opti, spec, fns, dec, taus, sums, push):
    """The gait targets (:func:`_targets`) and the objective of
    :func:`walkerlab.optimal.transcription.mode_sequence.collocate_phases`:
    ``(obj, terms)``, the terms by name (effort, peak torque, cost of transport, push-off
    work) weighted as ``spec`` asks.

    ``dec`` are the decision variables ``(Xs, Us, Ts)``, ``sums`` the phases' ``(effort,
    push-off work, heel strikes)`` from :func:`_chain_phases`.
    """
    import casadi as ca

    from walkerlab.optimal.transcription.step import peak_torque

    Xs, Us, Ts = dec
    effort, po_work, strikes = sums
    period = sum(Ts[1:], Ts[0])
    distance = _targets(opti, spec, fns, Xs, period)
    U = ca.horzcat(*Us)
    asked = dict(spec.weights) if spec.objective == "weighted" else {spec.objective: 1.0}
    terms = {"effort": effort, "peak_torque": peak_torque(opti, U, asked)}
    if "power" in fns:  # the hip torque's power: the cost of transport
        work = _positive_work(opti, fns, Xs, Us, Ts, taus, "cost_of_transport" in asked)
        if _pushes(spec):  # the push-offs' work is positive work too
            work = work + po_work
        terms["cost_of_transport"] = work / (fns["total_mass_kg"] * fns["gravity"]
                                             * distance)
    if _pushes(spec):
        terms["push_off_work"] = po_work
    obj = sum(w * terms[k] for k, w in asked.items())
    if spec.objective == "effort" and spec.push_off_free:  # as one step's, at each strike
        obj = obj + strikes * spec.push_off_weight * push ** 2
    if spec.objective == "cost_of_transport":
        obj = obj + spec.cost_of_transport_effort_weight * effort
    return obj, terms


def _targets(opti, spec, fns, Xs, period):
    """Every heel strike with the swing foot ahead and the gait targets on the step (a
    stride: its mean step's period and length); returns the distance walked [m] (a
    stride's: its steps' sum)."""
    from walkerlab.optimal.transcription.step import target_constraints

    phases, P = fns["phases"], len(fns["phases"])
    strikes = [p for p, mp in enumerate(phases[:-1]) if mp.guard_name == "heel_strike"]
    for p in [*strikes, P - 1]:  # every heel strike with the swing foot ahead
        opti.subject_to(fns["ahead"](Xs[p][:, -1]) >= 1e-3)
    if strikes:  # a stride of steps: its mean step's period and length
        steps = [phases[p].step(Xs[p][:, -1]) for p in [*strikes, P - 1]]
        target_constraints(opti, spec, period / len(steps), sum(steps) / len(steps))
        return sum(steps)
    length = phases[-1].step(Xs[-1][:, -1])
    target_constraints(opti, spec, period, length)
    return length
