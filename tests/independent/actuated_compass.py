"""Independent reference: the ACTUATED compass-gait walker and Kuo's (2002) simplest walker.

Pure numpy/scipy, derived by hand from Lagrange's equations (no walkerlab import, no shared
code with walkerlab's generator).  Sources: Kuo A.D. (2002) "Energetics of actively powered
locomotion using the simplest walking model", J Biomech Eng 124:113-120; Goswami A.,
Thuilot B., Espiau B. (1996) "Compass-like biped robot Part I", INRIA RR-2996; McGeer T.
(1990) "Passive dynamic walking", Int J Robot Res 9(2):62-82.

Geometry (world frame, x horizontal forward, y up, gravity (0, -g), SI units)
-----------------------------------------------------------------------------
Two identical rigid legs of length L, each a point mass m at distance a from its FOOT
(b = L - a from the hip), hip point mass M_H.  State x = [theta1, theta2, dtheta1, dtheta2]
[rad, rad, rad/s, rad/s]: absolute angles from the true vertical, theta1 swing, theta2
stance, both counter-clockwise positive.  Stance foot F, s_i = sin theta_i, c_i = cos theta_i:

    hip   H  = F + L (-s2, c2)          stance-leg mass  P2 = F + a (-s2, c2)
    swing foot S = H + L (s1, -c1)      swing-leg mass   P1 = H + b (s1, -c1)

The walker goes in +x down the slope y = -x tan(phi) through F (phi > 0 downhill).  The
swing foot's height above the slope is proportional to cos(theta2+phi) - cos(theta1+phi),
so with the swing foot ahead (theta1 > theta2) heel strike is h = theta1 + theta2 + 2 phi
crossing zero downwards.

Lagrangian (pinned stance foot), delta = theta1 - theta2, mu = m a + (m + M_H) L:

    T = 1/2 m b^2 dth1^2 - m L b cos(delta) dth1 dth2 + 1/2 (m a^2 + (m + M_H) L^2) dth2^2
    V = g (mu c2 - m b c1)
    D(q) = [[m b^2,            -m L b cos(delta)],
            [-m L b cos(delta), m a^2 + (m + M_H) L^2]]
    D ddq + C dq + G = Q,   C dq + G = [ -m L b sin(delta) dth2^2 + m g b s1,
                                          m L b sin(delta) dth1^2 - mu g s2 ]

Hip torque tau [N m] acts on the swing leg (+ = increasing theta1) and -tau on the stance
leg: virtual work tau (d theta1 - d theta2), so Q = [tau, -tau] and the actuator power is
tau (dth1 - dth2).

Floating (extended) coordinates qe = (theta1, theta2, x_f, y_f), (x_f, y_f) the trailing
(stance) foot.  With every mass velocity = (dx_f, dy_f) + its pinned velocity:

    D_e = [[D,                 B^T         ],     B = [[ m b c1, -mu c2],
           [B,          (2m + M_H) I_2     ]]          [ m b s1, -mu s2]]

Push-off impulse P [N s] at the trailing foot along the trailing leg (foot -> hip,
e = (-s2, c2)), the foot otherwise free (the ground's pin is released):

    D_e (dqe' - dqe^-) = E_trail^T P e,   E_trail = [0 0 1 0; 0 0 0 1],  dqe^- = (dq^-, 0, 0)

Heel strike: plastic, no-slip at the leading foot S = F + L(s1 - s2, c2 - c1), with
E_lead = dS/dqe = [[L c1, -L c2, 1, 0], [L s1, -L s2, 0, 1]]:

    [[D_e, -E_lead^T], [E_lead, 0]] [dqe^+; F_imp] = [D_e dqe'; 0]

then the roles swap: x^+ = [theta2, theta1, dtheta2^+, dtheta1^+] (the new stance foot is S).
With P = 0 this is the classical compass-gait impact (angular momentum of the whole walker
about S and of the trailing leg about the hip are conserved); the self-check verifies it
from particle kinematics.

Kuo's simplest walker (M = 1 at the hip, massless legs, infinitesimal feet, l = g = 1;
theta stance-leg angle as theta2 above, phi the inter-leg angle, theta_swing = theta - phi,
heel strike at phi = 2 theta, theta^- < 0).  Hip velocity v^- = dtheta^- (-cos th, -sin th)
is perpendicular to the stance leg u_old = (-sin th, cos th).  Push-off adds P u_old, the
heel strike removes the component along the new leg u_new = (sin th, cos th) (angle 2 theta
between the legs), and the infinitesimal swing foot keeps its zero velocity component normal
to its (massless) leg.  Result (derived and checked numerically below; it agrees with Kuo):

    theta^+ = -theta,  dtheta^+ = cos(2th) dtheta + sin(2th) P,  phi^+ = -2 theta,
    dphi^+ = (1 - cos 2th) dtheta^+ = cos2th (1 - cos2th) dtheta + (1 - cos2th) sin2th P

Steady level walking at speed v = |dtheta| with half inter-leg angle alpha = |theta|:
P = v tan(alpha); push-off work = collision loss = P^2/2; without push-off (stance/hip
torque powering) the collision loses v^2 sin^2(2 alpha)/2, i.e. 4 cos^4(alpha) times more.
"""

from __future__ import annotations

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import root

PAPER = dict(m=5.0, M_H=10.0, L=1.0, a=0.5, g=9.81)

RTOL = ATOL = 1e-12


class StepFailure(RuntimeError):
    """The walker fell or found no heel strike within the time limit."""


# --------------------------------------------------------------------------- dynamics
def _consts(p):
    m, MH, L, a, g = p["m"], p["M_H"], p["L"], p["a"], p["g"]
    b = L - a
    return m, MH, L, a, b, g, m * a + (m + MH) * L


def mass_matrix(q, p):
    """Pinned mass matrix D(q) [kg m^2], shape (2, 2); q = [theta1, theta2] [rad]."""
    m, MH, L, a, b, g, mu = _consts(p)
    d12 = -m * L * b * np.cos(q[0] - q[1])
    return np.array([[m * b * b, d12], [d12, m * a * a + (m + MH) * L * L]])


def bias(q, dq, p, phi=0.0):
    """C(q, dq) dq + G(q) [N m], shape (2,).  phi [rad] is unused (the slope enters only via
    the guard in the world frame) and kept for a uniform signature."""
    m, MH, L, a, b, g, mu = _consts(p)
    s = np.sin(q[0] - q[1])
    return np.array([-m * L * b * s * dq[1] ** 2 + m * g * b * np.sin(q[0]),
                     m * L * b * s * dq[0] ** 2 - mu * g * np.sin(q[1])])


def flow(x, p, phi=0.0, tau=0.0):
    """dx/dt, shape (4,), for state x (4,) and hip torque tau [N m] at that instant."""
    q, dq = x[:2], x[2:4]
    ddq = np.linalg.solve(mass_matrix(q, p), np.array([tau, -tau]) - bias(q, dq, p, phi))
    return np.array([dq[0], dq[1], ddq[0], ddq[1]])


def kinetic_energy(x, p):
    """Kinetic energy [J] of the pinned walker in state x (4,)."""
    dq = np.asarray(x[2:4])
    return 0.5 * dq @ mass_matrix(x[:2], p) @ dq


def potential_energy(x, p, foot_y=0.0):
    """Potential energy [J], stance foot at height foot_y [m] (gravity (0, -g))."""
    m, MH, L, a, b, g, mu = _consts(p)
    return g * ((2 * m + MH) * foot_y + mu * np.cos(x[1]) - m * b * np.cos(x[0]))


def total_energy(x, p, foot_y=0.0):
    """Kinetic + potential energy [J]; foot_y [m] the stance foot's absolute height."""
    return kinetic_energy(x, p) + potential_energy(x, p, foot_y)


def _particles(qe, dqe, p):
    """Positions and velocities (3, 2) of swing-leg mass, hip, stance-leg mass; masses (3,)."""
    m, MH, L, a, b, g, mu = _consts(p)
    t1, t2, xf, yf = qe
    d1, d2, dxf, dyf = dqe
    s1, c1, s2, c2 = np.sin(t1), np.cos(t1), np.sin(t2), np.cos(t2)
    F, dF = np.array([xf, yf]), np.array([dxf, dyf])
    H = F + L * np.array([-s2, c2])
    dH = dF + L * d2 * np.array([-c2, -s2])
    pos = np.array([H + b * np.array([s1, -c1]), H, F + a * np.array([-s2, c2])])
    vel = np.array([dH + b * d1 * np.array([c1, s1]), dH, dF + a * d2 * np.array([-c2, -s2])])
    return pos, vel, np.array([m, MH, m])


def extended_mass_matrix(qe, p):
    """Floating mass matrix D_e [kg, kg m, kg m^2], shape (4, 4), qe = (th1, th2, x_f, y_f)."""
    m, MH, L, a, b, g, mu = _consts(p)
    t1, t2 = qe[0], qe[1]
    De = np.zeros((4, 4))
    De[:2, :2] = mass_matrix(qe[:2], p)
    B = np.array([[m * b * np.cos(t1), -mu * np.cos(t2)],
                  [m * b * np.sin(t1), -mu * np.sin(t2)]])
    De[2:, :2] = B
    De[:2, 2:] = B.T
    De[2:, 2:] = (2 * m + MH) * np.eye(2)
    return De


# --------------------------------------------------------------------------- transition
def push_off_heel_strike(x_minus, p, phi, P):
    """Push-off impulse P [N s] then plastic heel strike, then the leg swap.

    x_minus: pre-impact state (4,) on the guard.  Returns x_plus (4,) and info: ke_minus,
    ke_after_pushoff, ke_plus [J]; pushoff_work = ke_after_pushoff - ke_minus [J];
    collision_loss = ke_after_pushoff - ke_plus [J]; trailing_foot_normal_velocity [m/s]
    (old stance foot, slope-normal component after the heel strike: >= 0 means it leaves the
    ground), trailing_foot_normal_velocity_after_pushoff [m/s]; impact_impulse (2,) [N s] at
    the leading foot (world frame); dqe_plus (4,) floating rates after the impact.
    """
    m, MH, L, a, b, g, mu = _consts(p)
    t1, t2 = x_minus[0], x_minus[1]
    qe = np.array([t1, t2, 0.0, 0.0])
    dqe_m = np.array([x_minus[2], x_minus[3], 0.0, 0.0])
    De = extended_mass_matrix(qe, p)
    E_tr = np.array([[0.0, 0, 1, 0], [0, 0, 0, 1]])
    e_leg = np.array([-np.sin(t2), np.cos(t2)])
    dqe_po = dqe_m + np.linalg.solve(De, E_tr.T @ (P * e_leg))
    E_ld = np.array([[L * np.cos(t1), -L * np.cos(t2), 1, 0],
                     [L * np.sin(t1), -L * np.sin(t2), 0, 1]])
    A = np.zeros((6, 6))
    A[:4, :4], A[:4, 4:], A[4:, :4] = De, -E_ld.T, E_ld
    sol = np.linalg.solve(A, np.concatenate([De @ dqe_po, np.zeros(2)]))
    dqe_p, Fimp = sol[:4], sol[4:]
    n = np.array([np.sin(phi), np.cos(phi)])  # slope normal (up)
    ke_m = 0.5 * dqe_m @ De @ dqe_m
    ke_po = 0.5 * dqe_po @ De @ dqe_po
    ke_p = 0.5 * dqe_p @ De @ dqe_p
    x_plus = np.array([t2, t1, dqe_p[1], dqe_p[0]])
    info = dict(ke_minus=ke_m, ke_after_pushoff=ke_po, ke_plus=ke_p,
                pushoff_work=ke_po - ke_m, collision_loss=ke_po - ke_p,
                trailing_foot_normal_velocity=float(dqe_p[2:] @ n),
                trailing_foot_normal_velocity_after_pushoff=float(dqe_po[2:] @ n),
                impact_impulse=Fimp, dqe_plus=dqe_p, dqe_after_pushoff=dqe_po)
    return x_plus, info


# --------------------------------------------------------------------------- torque laws
def constant_torque(tau0, tau_max=None):
    """torque_law(t, x) = tau0 [N m], optionally clipped to |tau| <= tau_max."""
    return spring_torque(tau0, 0.0, 0.0, 0.0, tau_max)


def spring_torque(tau0=0.0, k=0.0, c=0.0, r=0.0, tau_max=None):
    """tau = tau0 - k (th1 - th2 - r) - c (dth1 - dth2) [N m]; k [N m/rad], c [N m s/rad],
    r [rad]; optional saturation |tau| <= tau_max."""
    def law(t, x):
        tau = tau0 - k * (x[0] - x[1] - r) - c * (x[2] - x[3])
        return tau if tau_max is None else float(np.clip(tau, -tau_max, tau_max))
    return law


# --------------------------------------------------------------------------- step map
def step(x_plus, p, phi, P=0.0, torque_law=None, t_max=10.0):
    """One step from a post-impact state x_plus (4,) to the next post-impact state.

    torque_law(t, x) -> tau [N m] or None (passive).  The guard h = th1 + th2 + 2 phi
    (downward crossing) is armed only once th1 - th2 has become positive (swing foot passed
    the stance foot), so the touch at t = 0 and mid-stance scuffing are ignored.
    Returns (x_next_plus (4,), T [s], info) with info: period [s], step_length [m] (distance
    between the feet at heel strike), x_minus, actuator_work [J] (integral of
    tau (dth1 - dth2)), pushoff_work, collision_loss [J], energy_drift [J] (E(x^-) - E(x^+)
    - W_act over the swing), energy_balance_residual [J] (E_end - E_start - (W_act + W_po -
    loss), E with absolute foot heights), E_start, E_end, foot_drop [m], transition info.
    """
    law = (lambda t, x: 0.0) if torque_law is None else torque_law

    def rhs(t, z):
        tau = law(t, z[:4])
        return np.concatenate([flow(z[:4], p, phi, tau), [tau * (z[2] - z[3])]])

    def fall(t, z):  # hip below 0.1 L above its stance foot
        return np.cos(z[1]) - 0.1
    fall.terminal = True

    def passed(t, z):
        return z[0] - z[1]
    passed.terminal, passed.direction = True, 1

    def strike(t, z):
        return z[0] + z[1] + 2 * phi
    strike.terminal, strike.direction = True, -1

    z = np.concatenate([np.asarray(x_plus, float), [0.0]])
    t0 = 0.0
    if z[0] - z[1] <= 0:
        s = solve_ivp(rhs, (0.0, t_max), z, method="DOP853", rtol=RTOL, atol=ATOL,
                      events=[passed, fall])
        if s.status != 1 or len(s.t_events[0]) == 0:
            raise StepFailure("legs never passed each other (fell or time limit)")
        t0, z = s.t[-1], s.y[:, -1]
    s = solve_ivp(rhs, (t0, t_max), z, method="DOP853", rtol=RTOL, atol=ATOL,
                  events=[strike, fall])
    if s.status != 1 or len(s.t_events[0]) == 0:
        raise StepFailure("no heel strike (fell or time limit)")
    T, zm = s.t[-1], s.y[:, -1]
    x_minus, W = zm[:4], zm[4]
    if not x_minus[0] > x_minus[1]:
        raise StepFailure("heel strike with the swing foot behind")
    x_next, tinfo = push_off_heel_strike(x_minus, p, phi, P)
    L = p["L"]
    t1, t2 = x_minus[0], x_minus[1]
    foot_drop = L * (np.cos(t2) - np.cos(t1))  # new stance foot height rel. to old
    E0 = total_energy(x_plus, p, 0.0)
    Em = total_energy(x_minus, p, 0.0)
    E1 = total_energy(x_next, p, foot_drop)
    res = E1 - E0 - (W + tinfo["pushoff_work"] - tinfo["collision_loss"])
    info = dict(period=T, step_length=L * np.hypot(np.sin(t1) - np.sin(t2),
                                                   np.cos(t2) - np.cos(t1)),
                x_minus=x_minus, actuator_work=W, pushoff_work=tinfo["pushoff_work"],
                collision_loss=tinfo["collision_loss"], energy_drift=Em - E0 - W,
                energy_balance_residual=res, E_start=E0, E_end=E1, foot_drop=foot_drop,
                transition=tinfo)
    return x_next, T, info


def _to_section(x, phi):
    return np.array([x[0], x[2], x[3]])


def _from_section(z, phi):
    return np.array([z[0], -2 * phi - z[0], z[1], z[2]])


def fixed_point(p, phi, P=0.0, torque_law=None, guess=(-0.2, 0.17, -0.6, -0.85), h=1e-6):
    """Period-1 gait: post-impact fixed point of the step map.

    Unknowns (theta1, dtheta1, dtheta2) with theta2 = -2 phi - theta1 (the post-impact
    section).  guess: a 4-state (theta2 is re-projected) or a 3-vector.  Returns (x_star (4,),
    T [s], multipliers (4,) complex) with the multipliers the eigenvalues of a central
    finite-difference Jacobian (step h) of the full 4-state map (one is ~0).  Raises
    StepFailure if no fixed point is found.
    """
    g = np.asarray(guess, float)
    z0 = _to_section(g, phi) if g.size == 4 else g

    def res(z):
        try:
            xn, _, _ = step(_from_section(z, phi), p, phi, P, torque_law)
        except StepFailure:
            return np.full(3, 1e3)
        return _to_section(xn, phi) - z

    sol = root(res, z0, method="hybr", options=dict(xtol=1e-12))
    if not sol.success or np.max(np.abs(res(sol.x))) > 1e-8:
        raise StepFailure(f"no fixed point: {sol.message}")
    x_star = _from_section(sol.x, phi)
    _, T, _ = step(x_star, p, phi, P, torque_law)
    J = np.zeros((4, 4))
    for j in range(4):
        e = np.zeros(4)
        e[j] = h
        J[:, j] = (step(x_star + e, p, phi, P, torque_law)[0]
                   - step(x_star - e, p, phi, P, torque_law)[0]) / (2 * h)
    mult = np.linalg.eigvals(J)
    return x_star, T, mult[np.argsort(-np.abs(mult))]


# --------------------------------------------------------------------------- Kuo 2002
def kuo_transition(theta, dtheta, P):
    """Kuo (2002) simplest-walker push-off + heel strike (nondimensional, M = l = g = 1).

    theta, dtheta: pre-impact stance angle (< 0) and rate; P: push-off impulse (units of
    M sqrt(g l)).  Returns (theta+, dtheta+, phi+, dphi+), phi the inter-leg angle.
    """
    c, s = np.cos(2 * theta), np.sin(2 * theta)
    dth = c * dtheta + s * P
    return -theta, dth, -2 * theta, (1 - c) * dth


def kuo_transition_vectors(theta, dtheta, P):
    """The same transition from first principles (hip-point-mass momentum, vectors)."""
    u_old = np.array([-np.sin(theta), np.cos(theta)])          # old stance leg, foot->hip
    v = dtheta * np.array([-np.cos(theta), -np.sin(theta)])     # hip velocity
    v = v + P * u_old                                           # push-off (M = 1)
    u_new = np.array([np.sin(theta), np.cos(theta)])            # new stance (swing th1=-th)
    v = v - (v @ u_new) * u_new                                 # heel strike: massless leg
    th_p = -theta
    dth_p = v @ np.array([-np.cos(th_p), -np.sin(th_p)])
    # new swing leg (old stance, angle theta): foot = hip + (sin theta, -cos theta); the
    # infinitesimal foot keeps a zero velocity component normal to its massless leg
    dsw = -(v @ np.array([np.cos(theta), np.sin(theta)]))
    return th_p, dth_p, th_p - theta, dth_p - dsw


def kuo_steady_pushoff(v, alpha):
    """Push-off impulse for steady level walking: P = v tan(alpha) (nondimensional)."""
    return v * np.tan(alpha)


def kuo_collision_loss_ratio(alpha):
    """Collision loss with stance/hip-torque powering over that with push-off: 4 cos^4 a."""
    return 4 * np.cos(alpha) ** 4


# --------------------------------------------------------------------------- self-check
def _angular_momentum(pos, vel, mass, about):
    r = pos - about
    return float(np.sum(mass * (r[:, 0] * vel[:, 1] - r[:, 1] * vel[:, 0])))


def _check_classical_impact(x_minus, p, phi):
    """P = 0: H about the new contact (whole walker) and about the hip (trailing leg)."""
    x_plus, info = push_off_heel_strike(x_minus, p, phi, 0.0)
    qe = np.array([x_minus[0], x_minus[1], 0.0, 0.0])
    dqe_m = np.array([x_minus[2], x_minus[3], 0.0, 0.0])
    pm, vm, mass = _particles(qe, dqe_m, p)
    pp, vp, _ = _particles(qe, info["dqe_plus"], p)
    L = p["L"]
    S = L * np.array([np.sin(x_minus[0]) - np.sin(x_minus[1]),
                      np.cos(x_minus[1]) - np.cos(x_minus[0])])
    H = pm[1]
    d_contact = _angular_momentum(pp, vp, mass, S) - _angular_momentum(pm, vm, mass, S)
    d_hip = (_angular_momentum(pp[2:], vp[2:], mass[2:], H)
             - _angular_momentum(pm[2:], vm[2:], mass[2:], H))
    # new contact pinned: leading foot velocity after the impact
    d1, d2, dxf, dyf = info["dqe_plus"]
    t1, t2 = x_minus[:2]
    vS = np.array([dxf + L * (np.cos(t1) * d1 - np.cos(t2) * d2),
                   dyf + L * (np.sin(t1) * d1 - np.sin(t2) * d2)])
    ke_swap = kinetic_energy(x_plus, p)
    return d_contact, d_hip, np.max(np.abs(vS)), ke_swap - info["ke_plus"]


def _fmt(v, n=4):
    return "[" + ", ".join(f"{x:+.{n}f}" for x in np.real(v)) + "]"


def _gait_line(p, phi, P, law, guess):
    x, T, mu = fixed_point(p, phi, P, law, guess)
    _, _, info = step(x, p, phi, P, law)
    Mt = 2 * p["m"] + p["M_H"]
    sl = info["step_length"]
    cot = (info["pushoff_work"] + max(info["actuator_work"], 0.0)) / (Mt * p["g"] * sl)
    return x, T, sl, sl / T, np.max(np.abs(mu)), cot, info


if __name__ == "__main__":
    p = PAPER
    phi = 0.0174
    print("== passive paper walker, phi = 0.0174 rad")
    x, T, mu = fixed_point(p, phi, 0.0, None, (-0.2022, 0.1674, -0.60, -0.84))
    print("  x* =", _fmt(x), " ref [-0.2022, +0.1674, -0.60, -0.84]")
    print(f"  T = {T:.4f} s, |multipliers| = {_fmt(np.abs(mu))}")
    assert abs(x[0] + 0.2022) < 0.01 and abs(x[1] - 0.1674) < 0.01
    assert abs(x[2] + 0.60) < 0.05 and abs(x[3] + 0.84) < 0.05

    print("== energy balance of one step (torque + push-off), phi = 0.0174")
    law = spring_torque(tau0=0.5, k=20.0, c=1.0, r=0.1, tau_max=3.0)
    _, _, info = step(x, p, phi, 0.7, law)
    scale = abs(info["E_start"])
    print(f"  W_act = {info['actuator_work']:+.6f} J, W_po = {info['pushoff_work']:+.6f} J, "
          f"loss = {info['collision_loss']:+.6f} J")
    print(f"  E_end - E_start = {info['E_end'] - info['E_start']:+.6f} J, residual = "
          f"{info['energy_balance_residual']:.2e} J "
          f"(rel {abs(info['energy_balance_residual']) / scale:.1e}),"
          f" swing drift {info['energy_drift']:.1e} J")
    assert abs(info["energy_balance_residual"]) / scale <= 1e-9

    print("== P = 0 impact vs classical angular-momentum impact")
    d_c, d_h, vs, dke = _check_classical_impact(info["x_minus"], p, phi)
    print(f"  dH(new contact) = {d_c:.1e}, dH(trailing leg about hip) = {d_h:.1e}, "
          f"|v lead foot| = {vs:.1e}, KE(swap) - KE(floating) = {dke:.1e}")
    assert max(abs(d_c), abs(d_h), vs, abs(dke)) < 1e-12

    print("== Kuo 2002 transition vs first-principles vectors; steady push-off; loss ratio")
    rng = np.random.default_rng(0)
    err = 0.0
    for _ in range(100):
        th, dth, PP = -rng.uniform(0.05, 0.6), -rng.uniform(0.1, 1.0), rng.uniform(0, 0.5)
        err = max(err, np.max(np.abs(np.subtract(kuo_transition(th, dth, PP),
                                                 kuo_transition_vectors(th, dth, PP)))))
    print(f"  max |closed form - vectors| = {err:.1e}")
    assert err < 1e-13
    for alpha, v in [(0.2, 0.4), (0.35, 0.7)]:
        Ps = kuo_steady_pushoff(v, alpha)
        _, dthp, _, _ = kuo_transition(-alpha, -v, Ps)
        loss_po = 0.5 * (v * v + Ps * Ps) - 0.5 * dthp ** 2
        _, dth0, _, _ = kuo_transition(-alpha, -v, 0.0)
        loss_tq = 0.5 * v * v - 0.5 * dth0 ** 2
        print(f"  alpha={alpha}: P={Ps:.4f}, dtheta+={dthp:+.6f} (-v={-v}), "
              f"loss ratio {loss_tq / loss_po:.6f} vs 4cos^4 {kuo_collision_loss_ratio(alpha):.6f}")
        assert abs(dthp + v) < 1e-14 and abs(loss_tq / loss_po - 4 * np.cos(alpha) ** 4) < 1e-12

    print("== level ground (phi = 0), push-off only (100 steps from the passive gait, then Newton)")
    print("  P[Ns]  x* (post-impact)                      T[s]   step[m] v[m/s] max|mu| "
          "CoT     lift")
    x_pass = x

    def scan(P, law, label):
        xx = x_pass.copy()
        try:
            for _ in range(100):
                xx = step(xx, p, 0.0, P, law)[0]
            xs, T, sl, v, mmax, cot, inf = _gait_line(p, 0.0, P, law, xx)
            lift = inf["transition"]["trailing_foot_normal_velocity"] >= 0
            print(f"  {label}  {_fmt(xs)}  {T:.3f}  {sl:.3f}   {v:.3f}  {mmax:.3f}   "
                  f"{cot:.4f}  {lift}")
        except StepFailure as e:
            print(f"  {label}  no period-1 gait: {str(e)[:60]}")

    for P in [0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 3.5, 3.75, 4.0]:
        scan(P, None, f"{P:4.2f}")
    print("== level ground, push-off + hip spring tau = -k (th1 - th2)")
    for k in [10.0, 30.0, 50.0]:
        for P in [1.0, 3.0]:
            scan(P, spring_torque(0.0, k, 0.0, 0.0), f"k={k:2.0f} P={P:3.1f}")
    print("== recommended scene 'powered_compass': phi = 0, P = 3.0 N s, no hip torque")
