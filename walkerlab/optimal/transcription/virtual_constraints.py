"""Virtual constraints designed by collocation: the full-order step of a walker with its
Bezier coefficients as decision variables and the hybrid zero dynamics' stability as a
constraint (FROST's formulation: A. Hereid & A. D. Ames (2017), "FROST: Fast robot
optimization and simulation toolkit", IROS 2017, 719-726; A. Hereid, E. A. Cousineau, C. M.
Hubicki & A. D. Ames (2016), "3D dynamic walking with underactuated humanoid robots: a
direct collocation framework for optimizing hybrid zero dynamics", ICRA 2016, 1447-1454;
Westervelt et al. 2007, *Feedback Control of Dynamic Bipedal Robot Locomotion*, Sec. 6.5).

Decision variables: the states ``x_j`` (2n,) and torques ``u_j`` (k,) at the ``2N + 1``
points of a separated Hermite-Simpson mesh on ``[0, T]`` (Kelly 2017, SIAM Review
59(4):849-904), the step period ``T`` and the coefficients ``alpha`` (k, M + 1).  With
``theta+ = theta(q_0)``, ``theta- = theta(q_2N)`` and ``s_j = (theta(q_j) - theta+) /
(theta- - theta+)`` the constraints are:

- the flow ``M(q) q'' + C(q, q') q' + G(q) = B u`` (the walker's own derivation,
  :func:`walkerlab.codegen.virtual_constraints.derive_equations`) by the Hermite-Simpson
  defects;
- the outputs and their rates zero at every point: ``y_j = h0(q_j) - hd(s_j, alpha) = 0``,
  ``y'_j = (dh0/dq - hd'(s_j) dtheta/dq / (theta- - theta+)) q'_j = 0``; at ``j = 0``
  (the state after the heel strike, below) they are the impact invariance conditions
  (Westervelt, Grizzle & Koditschek 2003, IEEE TAC 48(1):42-56, Theorem 3);
- periodicity through the heel strike ``x_0 = Delta(x_2N)`` (the walker's impact and
  relabelling), the step ending on the heel-strike guard with the swing foot ahead and
  moving down, the phase advancing at every point (``s' T >= 0.2``);
- ``|u| <= max_torque_n_m``, the stance foot pushing (``F_n >= 0``) inside its friction
  cone (``|F_t| <= mu F_n``), the swing foot's clearance ``>= min_clearance_m`` at every
  interior point, the targets (speed, step length, step period).  Straight legs pass the
  swing foot through the ground line where the legs cross at mid-stance (its height
  ``l (cos theta - cos phi)`` is zero at ``phi = theta``; McGeer 1990, Int. J. Robotics
  Research 9(2):62-82, ignores that scuffing), so their bound is lifted over the pass: the
  points whose swing foot is within ``W = 2 sqrt(2 c l)`` of the stance foot along the
  ground (``c`` the clearance, ``l`` the leg length: a straight leg lifts its foot by ``c``
  only ``sqrt(2 c l)`` from the stance foot when the stance leg is upright), with the bound
  relaxed continuously to the window's edge (:func:`clearance_bound`);
- ``delta^2(q_2N, alpha) <= max_multiplier``: the restricted Poincare map's multiplier
  (:func:`walkerlab.analysis.gait.zero_dynamics.impact_multiplier`), an algebraic function
  of the pre-impact configuration and the coefficients through the impact map: ``q'- =
  dq/dtheta`` on the surface at ``q-`` (``(dh0/dq; dtheta/dq) q'- = (hd'(1) / (theta- -
  theta+); 1)``, ``hd'(1) = M (c_M - c_{M-1})``), ``delta = b^T M(q+) Delta_dq q'- / b^T
  M(q-) q'-`` with ``b^T B = 0``.

The objective is the book's: ``int |u|^2 dt / step length`` [N^2 m s] (Westervelt et al.
2007, Sec. 6.5.2; Simpson's rule on the points).  CasADi's ``Opti`` with IPOPT solves it.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from math import comb

import numpy as np

from walkerlab.optimal.transcription.ipopt import CollocatedStep

__all__ = ["MID_STANCE_DIP_M", "HzdDesign", "HzdFunctions", "clearance_bound",
           "collocate_virtual_constraints", "hzd_functions", "mid_stance_window"]

KEY = "walker.actuation.virtual_constraints"


def bezier_sx(alpha, s):
    """``(hd (k,), hd' (k,))`` of Bezier coefficients ``alpha`` (k, M + 1) at ``s`` (CasADi
    scalars or matrices; as :func:`walkerlab.models.virtual_constraints.bezier`)."""
    M = alpha.shape[1] - 1
    hd = sum(alpha[:, j] * comb(M, j) * s ** j * (1 - s) ** (M - j) for j in range(M + 1))
    d1 = [M * (alpha[:, j + 1] - alpha[:, j]) for j in range(M)]
    hd1 = sum(d1[j] * comb(M - 1, j) * s ** j * (1 - s) ** (M - 1 - j) for j in range(M))
    return hd, hd1


def mid_stance_window(min_clearance_m: float, leg_length_m: float) -> float:
    """The half-width ``W = 2 sqrt(2 c l)`` [m] of the straight legs' mid-stance pass that
    the clearance bound ``c`` exempts (module docstring): the swing foot of a straight leg
    of length ``l`` is ``l (cos theta - cos phi)`` above the ground, ``c`` only when it is
    ``sqrt(2 c l)`` from an upright stance leg's foot; twice that leaves the stance leg a
    range of angles at the window's edges (a window of ``sqrt(2 c l)`` would need the
    stance leg upright at both)."""
    return 2.0 * float(np.sqrt(2.0 * max(float(min_clearance_m), 0.0) * float(leg_length_m)))


#: How far below the ground [m] a swing foot may pass at the middle of the mid-stance
#: window (any real dip: the bound is lifted there, not traded)
MID_STANCE_DIP_M = 1.0


def clearance_bound(ahead, min_clearance_m: float, window_m: float):
    """The swing foot's lowest height allowed [m] where it is ``ahead`` [m] of the stance
    foot along the ground: ``c - B max(0, 1 - (d / W)^2)^2`` (``c`` outside the window
    ``|d| >= W``, relaxed continuously (C1) to ``c - B`` at the stance foot,
    ``B = c +`` :data:`MID_STANCE_DIP_M`).

    Parameters
    ----------
    ahead : CasADi or float (m,)
        The swing foot ahead of the stance foot [m].
    min_clearance_m, window_m : float
        ``c`` and ``W`` [m] (:func:`mid_stance_window`).
    """
    import casadi as ca

    inside = ca.fmax(0.0, 1.0 - (ahead / window_m) ** 2) if window_m > 0 else 0.0 * ahead
    return min_clearance_m - (min_clearance_m + MID_STANCE_DIP_M) * inside ** 2


@dataclass
class HzdFunctions:
    """CasADi functions of one walker under one virtual-constraint spec (numbers of its
    parameters substituted).

    Attributes
    ----------
    n, k : int
        Coordinates and outputs (= actuators).
    flow : casadi.Function
        ``(x, u) -> [q', M^-1 (B u - C q' - G)]`` (2n,).
    chart : casadi.Function
        ``q -> ([h0; theta] (n,), its Jacobian (n, n))``.
    reset : casadi.Function
        ``x- -> x+`` (2n,): the heel strike and the legs' relabelling.
    matrix : casadi.Function
        ``q -> M(q)`` (n, n).
    feet : casadi.Function
        ``x -> [heel-strike guard, its rate, swing foot ahead [m], swing foot height [m]]``.
    grf : casadi.Function
        ``(x, u) -> (F_n, F_t)`` [N]: the ground's force on the stance foot along the
        ground's normal and tangent (forward positive), ``m (a_com + g)``.
    B, b : ndarray
        The actuated joints' columns (n, k) and the direction no actuator drives (n,)
        (:func:`walkerlab.models.virtual_constraints.annihilator`).
    clearance_guard : bool
        The heel-strike guard is the swing foot's height (kneed legs), so the swing foot is
        kept above the ground inside the step; straight legs pass through it mid-stance.
    """

    n: int
    k: int
    flow: object
    chart: object
    reset: object
    matrix: object
    feet: object
    grf: object
    B: np.ndarray
    b: np.ndarray
    clearance_guard: bool

    def outputs(self, x, alpha, th_p, th_m):
        """``(y, y')`` (k,) each at the state ``x`` (CasADi), the phase's ends ``th_p``,
        ``th_m``."""
        import casadi as ca

        n = self.n
        F, D = self.chart(x[:n])
        dth = th_m - th_p
        s = (F[-1] - th_p) / dth
        hd, hd1 = bezier_sx(alpha, s)
        rate = ca.mtimes(D, x[n:])
        return F[:-1] - hd, rate[:-1] - hd1 * rate[-1] / dth

    def delta2(self, q_minus, alpha):
        """``delta^2`` of the coefficients ``alpha`` with the step ending at ``q_minus``
        (module docstring; the same steps as
        :func:`walkerlab.analysis.gait.zero_dynamics.impact_multiplier`)."""
        import casadi as ca

        n = self.n
        M = alpha.shape[1] - 1
        q_plus = self.reset(ca.vertcat(q_minus, ca.DM.zeros(n)))[:n]
        th_p = self.chart(q_plus)[0][-1]
        F, D = self.chart(q_minus)
        dth = F[-1] - th_p
        hd1 = M * (alpha[:, -1] - alpha[:, -2])
        qd = ca.solve(D, ca.vertcat(hd1 / dth, 1.0))
        xp = self.reset(ca.vertcat(q_minus, qd))
        sig_m = ca.mtimes([self.b.reshape(1, -1), self.matrix(q_minus), qd])
        sig_p = ca.mtimes([self.b.reshape(1, -1), self.matrix(xp[:n]), xp[n:]])
        return (sig_p / sig_m) ** 2


def hzd_functions(data, vc, prefix: str = KEY) -> HzdFunctions:
    """:class:`HzdFunctions` of the walker ``data`` (:class:`~walkerlab.walker.description.
    WalkerData`) under the virtual constraints ``vc`` (:class:`walkerlab.config.actuation.
    VirtualConstraints`: its outputs, phase and joints), from the derivation its generated
    flow and the controller's pieces come from
    (:func:`walkerlab.codegen.virtual_constraints.derive_equations`, :func:`~walkerlab.
    codegen.virtual_constraints.output_expressions`); the CasADi functions cached on disk
    as the generated flows (``<user cache>/models/<structure key>-hzd-<hash>.casadi``, the
    hash covering the parameters, the outputs, phase and joints, this module's and the
    printer's source and CasADi's version).

    Raises
    ------
    ValueError
        A link, joint or coordinate the walker does not have, outputs and actuators that
        differ in number (one line naming the key).
    """
    import hashlib

    from walkerlab.codegen.cache import cache_key
    from walkerlab.codegen.casadi_functions import cached_functions
    from walkerlab.models.virtual_constraints import annihilator

    what = repr((tuple(float(v) for v in data.params), float(data.slope_rad),
                 float(data.gravity_m_per_s2), tuple(o.name for o in vc.outputs),
                 vc.phase.model_dump_json(), tuple(vc.joints or ()), _source_hash()))
    tag = hashlib.sha256(what.encode()).hexdigest()[:12]
    fns = cached_functions(f"{cache_key(data.structure)}-hzd-{tag}",
                           lambda: _build(data, vc, prefix))
    n, k = (int(v) for v in np.asarray(fns["sizes"].call([])[0], float).ravel())
    consts = np.asarray(fns["consts"].call([])[0], float).ravel()
    B = consts[:n * k].reshape(n, k)
    return HzdFunctions(n=n, k=k, flow=fns["flow"], chart=fns["chart"], reset=fns["reset"],
                        matrix=fns["matrix"], feet=fns["feet"], grf=fns["grf"], B=B,
                        b=annihilator(B), clearance_guard=bool(consts[-1]))


def _source_hash() -> str:
    """This module's, the output expressions' and the CasADi printer's source and CasADi's
    version (the cached functions' dependence on code)."""
    import hashlib
    from pathlib import Path

    import casadi as ca

    from walkerlab.codegen import casadi_functions
    from walkerlab.codegen import virtual_constraints as pieces

    h = hashlib.sha256(Path(__file__).read_bytes())
    for mod in (casadi_functions, pieces):
        h.update(Path(mod.__file__).read_bytes())
    h.update(ca.__version__.encode())
    return h.hexdigest()[:12]


def _build(data, vc, prefix: str) -> dict:
    """The CasADi functions of :func:`hzd_functions` (sympy derivation, then CasADi), with
    ``sizes`` (``n, k``) and ``consts`` (``vec(B)`` row-major, then 1 where the heel-strike
    guard is the swing foot's height) as functions of no input."""
    import casadi as ca
    import sympy as sp

    from walkerlab.codegen.casadi_functions import casadi_matrix
    from walkerlab.codegen.virtual_constraints import derive_equations, output_expressions
    from walkerlab.models.virtual_constraints import default_joints

    st = data.structure
    eq = derive_equations(st)
    n = len(eq.q)
    names = list(eq.leg_angles)
    joints = list(vc.joints) if vc.joints is not None else default_joints(
        names, bool(st.torso) and st.hinged_torso)
    outputs = [("link", o.link) if o.link is not None else ("joint", o.joint)
               for o in vc.outputs]
    k = len(outputs)
    if k != len(joints) or k != n - 1:
        raise ValueError(f"{prefix}.outputs: {k} outputs for {len(joints)} actuators on a "
                         f"walker of {n} coordinates: give {n - 1} (one per actuator)")
    h0, th, jexprs = output_expressions(eq, outputs, vc.phase, joints, prefix)
    x = ca.SX.sym("x", 2 * n)
    u = ca.SX.sym("u", k)
    q, dq = x[:n], x[n:]
    syms = [*eq.q, *eq.dq, *eq.params]
    args = [*ca.vertsplit(x), *[ca.SX(float(v)) for v in data.params]]

    def cas(exprs):
        return casadi_matrix(sp.Matrix(exprs), syms, args)
    Mq, C, G = cas(eq.M), cas(eq.C), cas(eq.G)
    Bm = ca.jacobian(cas([sp.sympify(e) for e in jexprs]), q)  # (k, n): B^T
    B = np.array(ca.DM(ca.evalf(ca.substitute(Bm, x, ca.DM.zeros(2 * n))))).T
    qdd = ca.solve(Mq, ca.DM(B) @ u - C @ dq - G)
    flow = ca.Function("flow", [x, u], [ca.vertcat(dq, qdd)])
    Phi = ca.vertcat(cas([sp.sympify(e) for e in h0]), cas([sp.sympify(th)]))
    qs = ca.SX.sym("q", n)
    Phi_q = ca.substitute(Phi, q, qs)
    chart = ca.Function("chart", [qs], [Phi_q, ca.jacobian(Phi_q, qs)])
    matrix = ca.Function("matrix", [qs], [ca.substitute(Mq, q, qs)])
    Mi, Bi = cas(eq.Mi), cas(eq.B)
    dq_post = ca.solve(Mi, Bi @ dq)
    qn = cas(eq.relabel_q)
    R = np.array(eq.relabel_rate, float)
    reset = ca.Function("reset", [x], [ca.vertcat(qn, ca.DM(R) @ dq_post)])
    guard = cas([eq.guards["heel_strike"]])
    height = cas([eq.guards["swing_clearance"]])
    ahead = cas([eq.guards["swing_foot_ahead"]])
    grate = ca.jtimes(guard, x, ca.vertcat(dq, ca.SX.zeros(n)))
    feet = ca.Function("feet", [x], [ca.vertcat(guard, grate, ahead, height)])
    # the ground's force on the stance foot: m (a_com + g) from the bodies' mass points
    pn = list(st.param_names)
    par = dict(zip(pn, (float(v) for v in data.params)))
    pts = [(par["M_hip"], "hip")] if st.hip_mass and "M_hip" in par else []
    for body in st.bodies:
        if not body.massless:
            pts += [(par[f"m_{body.name}"], f"{r}_{body.name}") for r in ("stance", "swing")]
    for body in st.torso or ():
        if not body.massless and f"torso_{body.name}" in eq.points:
            pts.append((par[f"m_torso_{body.name}"], f"torso_{body.name}"))
    mtot = sum(m for m, _ in pts)
    com = sum(m * cas(eq.points[p]) for m, p in pts) / mtot
    vel = ca.jacobian(com, q) @ dq
    acc = ca.jacobian(vel, x) @ ca.vertcat(dq, qdd)
    Fw = mtot * (acc + ca.vertcat(0, data.gravity_m_per_s2))
    gam = data.slope_rad
    grf = ca.Function("grf", [x, u], [ca.vertcat(ca.sin(gam) * Fw[0] + ca.cos(gam) * Fw[1],
                                                 ca.cos(gam) * Fw[0] - ca.sin(gam) * Fw[1])])
    clearance_guard = sp.simplify(sp.sympify(eq.guards["heel_strike"])
                                  - sp.sympify(eq.guards["swing_clearance"])) == 0
    consts = ca.DM([*B.ravel(), 1.0 if clearance_guard else 0.0])
    return {"flow": flow, "chart": chart, "reset": reset, "matrix": matrix, "feet": feet,
            "grf": grf, "sizes": ca.Function("sizes", [], [ca.DM([n, k])]),
            "consts": ca.Function("consts", [], [consts])}


@dataclass(kw_only=True)
class HzdDesign(CollocatedStep):
    """One optimised controller: the step (the fields of
    :class:`~walkerlab.optimal.transcription.ipopt.CollocatedStep`; ``u`` (m, k), the
    ``k`` actuated joints' torques) and its coefficients.

    Attributes
    ----------
    alpha : ndarray (k, M + 1)
        The Bezier coefficients [rad].
    objective : float
        ``int |u|^2 dt / step length`` [N^2 m s].
    effort : float
        ``int |u|^2 dt`` [N^2 m^2 s].
    delta2 : float
        ``delta^2`` at the optimum (the CasADi expression's value) [-].
    theta_plus, theta_minus : float
        The phase variable at the collocated step's ends.
    q_minus : ndarray (n,)
        The zero dynamics' pre-impact configuration of ``alpha`` (``h0 = c_M`` on the
        heel-strike guard; the collocated ``q_2N`` to the transcription's error).
    max_output, max_output_rate : float
        ``max |y|``, ``max |y'|`` over the points (the constraints' residual).
    cpu_time_s, build_time_s : float
        IPOPT's CPU time and the programme's build time [s].
    violations : str
        When IPOPT did not converge: the constraint groups it left violated at its last
        iterate (:func:`walkerlab.optimal.transcription.ipopt.largest_violations`).
    """

    alpha: np.ndarray
    effort: float
    delta2: float
    theta_plus: float
    theta_minus: float
    q_minus: np.ndarray
    max_output: float
    max_output_rate: float
    cpu_time_s: float
    build_time_s: float = 0.0
    violations: str = ""


def collocate_virtual_constraints(fns: HzdFunctions, spec, guess_t, guess_x, guess_u,
                                  guess_alpha, max_multiplier: float | None,
                                  gains: tuple[float, float], print_level: int = 0,
                                  mid_stance_window_m: float | None = None,
                                  cpu_budget_s: float | None = None,
                                  max_iterations: int = 1000) -> HzdDesign:
    """Optimise one step and its virtual constraints (module docstring).

    Parameters
    ----------
    fns : HzdFunctions
    spec : walkerlab.optimal.transcription.step.CollocationSpec
        ``intervals``, ``max_torque_n_m``, ``friction_coefficient``, ``min_clearance_m`` and
        the targets.
    guess_t : ndarray (2N + 1,)
        The guess's times [s] (uniform, from 0).
    guess_x, guess_u : ndarray (2N + 1, 2n), (2N + 1, k)
        The guess's states and torques there.
    guess_alpha : ndarray (k, M + 1)
        The guess's coefficients.
    max_multiplier : float or None
        ``delta^2 <=`` this (None: no stability constraint).
    gains : (kp [1/s^2], kd [1/s])
        The output dynamics ``y'' + kd y' + kp y = 0`` imposed at every point (the
        controller's closed loop).
    print_level : int
        IPOPT's.
    mid_stance_window_m : float, optional
        Straight legs (the heel-strike guard is not the swing foot's height): the half-width
        ``W`` [m] of the mid-stance pass exempted from ``spec.min_clearance_m``
        (:func:`clearance_bound`; :func:`mid_stance_window`); None: no clearance bound.
    cpu_budget_s : float, optional
        IPOPT's ``max_cpu_time`` [s] (it then ends with ``Maximum_CpuTime_Exceeded``): a
        limit a user asked for; None (default): none, the solve is bounded by its work.
    max_iterations : int
        IPOPT's ``max_iter`` (it then ends with ``Maximum_Iterations_Exceeded``).

    Returns
    -------
    HzdDesign
    """
    import casadi as ca

    from walkerlab.optimal.transcription.ipopt import (
        iteration_history,
        largest_violations,
        solve,
    )

    t_build = time.perf_counter()
    n, k = fns.n, fns.k
    kp, kd = (float(g) for g in gains)
    K = len(guess_t)
    N = (K - 1) // 2
    Mdeg = guess_alpha.shape[1] - 1
    opti = ca.Opti()
    X = opti.variable(2 * n, K)
    U = opti.variable(k, K)
    T = opti.variable()
    A = opti.variable(k, Mdeg + 1)
    h = T / N
    F = fns.flow.map(K)(X, U)
    xi, xm, xj = X[:, 0:K - 1:2], X[:, 1:K:2], X[:, 2:K:2]
    fi, fm, fj = F[:, 0:K - 1:2], F[:, 1:K:2], F[:, 2:K:2]
    opti.subject_to(ca.vec(xm - (xi + xj) / 2 - h / 8 * (fi - fj)) == 0)
    opti.subject_to(ca.vec(xj - xi - h / 6 * (fi + 4 * fm + fj)) == 0)
    th_p = fns.chart(X[:n, 0])[0][-1]
    th_m = fns.chart(X[:n, -1])[0][-1]
    xs, us = ca.SX.sym("x", 2 * n), ca.SX.sym("u", k)
    a_s = ca.SX.sym("a", k, Mdeg + 1)
    tp, tm = ca.SX.sym("tp"), ca.SX.sym("tm")
    y, dy = fns.outputs(xs, a_s, tp, tm)
    ddy = ca.jtimes(dy, xs, fns.flow(xs, us))
    out = ca.Function("out", [xs, us, a_s, tp, tm], [ca.vertcat(y, dy, ddy + kd * dy + kp * y)])
    Y = out.map(K)(X, U, A, th_p, th_m)  # A, th_p, th_m broadcast
    opti.subject_to(ca.vec(Y[2 * k:, :]) == 0)   # the output dynamics at every point
    opti.subject_to(Y[:2 * k, 0] == 0)           # on the surface after the heel strike
    opti.subject_to(X[:, 0] - fns.reset(X[:, -1]) == 0)          # periodic through impact
    feet = fns.feet.map(K)(X)
    opti.subject_to(feet[0, -1] == 0)                            # ends on the guard
    opti.subject_to(feet[1, -1] <= 0)                            # moving down
    opti.subject_to(feet[2, -1] >= 1e-3)                         # the swing foot ahead
    if fns.clearance_guard:
        opti.subject_to(feet[3, 1:K - 1] >= (spec.min_clearance_m or 0.0))
    elif spec.min_clearance_m is not None and mid_stance_window_m is not None:
        # straight legs: the clearance outside the mid-stance pass (module docstring)
        opti.subject_to(feet[3, 1:K - 1] >= clearance_bound(
            feet[2, 1:K - 1], float(spec.min_clearance_m), float(mid_stance_window_m)))
    # the phase advances at every point: s' T >= 0.2 (s' = theta' / (theta- - theta+))
    qs = ca.MX.sym("q", 2 * n)
    rate = ca.Function("rate", [qs], [ca.mtimes(fns.chart(qs[:n])[1][-1, :], qs[n:])])
    rates = rate.map(K)(X)
    opti.subject_to(ca.vec(rates * T / (th_m - th_p)) >= 0.2)
    grf = fns.grf.map(K)(X, U)
    opti.subject_to(grf[0, :] >= 0)                              # the stance foot pushes
    if spec.friction_coefficient is not None:
        mu = float(spec.friction_coefficient)
        opti.subject_to(ca.vec(grf[1, :] - mu * grf[0, :]) <= 0)
        opti.subject_to(ca.vec(-grf[1, :] - mu * grf[0, :]) <= 0)
    if spec.max_torque_n_m is not None:
        lim = float(spec.max_torque_n_m)
        opti.subject_to(opti.bounded(-lim, ca.vec(U), lim))
    opti.subject_to(opti.bounded(-np.pi / 2, X[:n, :], np.pi / 2))
    opti.subject_to(opti.bounded(0.1, T, 5.0))
    D = feet[2, -1]
    if spec.target_step_period_s is not None:
        opti.subject_to(T == float(spec.target_step_period_s))
    if spec.target_step_length_m is not None:
        opti.subject_to(D == float(spec.target_step_length_m))
    if spec.target_speed_m_per_s is not None:
        opti.subject_to(D == float(spec.target_speed_m_per_s) * T)
    # the zero dynamics' end of step: the configuration with h0 = c_M on the heel-strike
    # guard (the controller's q-, walkerlab.models.virtual_constraints), near q_2N
    Qm = opti.variable(n)
    opti.subject_to(fns.chart(Qm)[0][:k] - A[:, -1] == 0)
    opti.subject_to(fns.feet(ca.vertcat(Qm, ca.DM.zeros(n)))[0] == 0)
    opti.set_initial(Qm, guess_x[-1, :n])
    qz, az = ca.SX.sym("q", n), ca.SX.sym("a", k, Mdeg + 1)
    d2 = ca.Function("delta2", [qz, az], [fns.delta2(qz, az)])(Qm, A)
    if max_multiplier is not None:
        opti.subject_to(d2 <= float(max_multiplier))
    w = np.ones(K)
    w[1:K - 1:2], w[2:K - 1:2] = 4.0, 2.0
    usq = ca.sum1(U ** 2)
    effort = h / 3 * ca.mtimes(usq, ca.DM(w))
    objective = effort / D
    opti.minimize(objective)
    opti.set_initial(X, guess_x.T)
    opti.set_initial(U, guess_u.T)
    opti.set_initial(T, float(guess_t[-1]))
    opti.set_initial(A, guess_alpha)
    opti.solver("ipopt", {"expand": True, "print_time": False},
                {"print_level": print_level, "tol": 1e-10, "constr_viol_tol": 1e-11,
                 "max_iter": int(max_iterations), "sb": "yes",
                 **({} if cpu_budget_s is None else {"max_cpu_time": float(cpu_budget_s)})})
    build = time.perf_counter() - t_build
    status, get, wall, cpu = solve(opti)
    Tv = float(get(T))
    Xv = np.asarray(get(X), float).T
    Yv = np.asarray(get(Y), float)
    return HzdDesign(
        t=np.linspace(0.0, Tv, K), x=Xv, u=np.asarray(get(U), float).reshape(k, K).T,
        alpha=np.asarray(get(A), float).reshape(k, Mdeg + 1), step_period_s=Tv,
        step_length_m=float(get(D)), objective=float(get(objective)),
        effort=float(get(effort)), delta2=float(get(d2)), theta_plus=float(get(th_p)),
        theta_minus=float(get(th_m)), q_minus=np.asarray(get(Qm), float).ravel(),
        max_output=float(np.max(np.abs(Yv[:k]))),
        max_output_rate=float(np.max(np.abs(Yv[k:]))), status=status,
        iterations=int(opti.stats().get("iter_count", -1)), wall_time_s=wall, cpu_time_s=cpu,
        build_time_s=build, history=iteration_history(opti.stats()),
        violations="" if status == "Solve_Succeeded" else largest_violations(opti))
