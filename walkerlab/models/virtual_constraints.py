"""Virtual constraints as a walker's feedback controller (hybrid zero dynamics): Bezier
outputs of a monotone phase variable, made invariant under the heel strike, enforced by
computed torque on the rigid model.

Outputs and phase (Westervelt, Grizzle & Koditschek 2003, IEEE TAC 48(1):42-56, Sec. IV-V;
Westervelt et al. 2007, *Feedback Control of Dynamic Bipedal Robot Locomotion*, ch. 5-6)::

    y = h(q) = h0(q) - hd(s(q)),   s = (theta(q) - theta+) / (theta- - theta+),
    hd(s) = sum_k c_k C(M, k) s^k (1 - s)^(M - k)          (Bezier, degree M)

``theta-`` is where the step ends: the configuration ``q-`` with ``h0(q-) = c_M`` and
``theta(q-) = theta-`` has the swing foot on the ground, ahead; ``theta+ = theta(q+)``,
``q+`` the configuration after the heel strike (legs relabelled).  Invariance of the
surface ``Z = {y = 0, y' = 0}`` under the impact (Westervelt 2003, Theorem 3; the book's
Sec. 6.3.1) fixes the first two coefficients of every output::

    c_0 = h0(q+),   c_1 = c_0 + (theta- - theta+) / M * (dh0/dq q'+) / (dtheta/dq q'+)

``q'+`` the post-impact velocity of the pre-impact one ``q'- = dq/dtheta`` on ``Z`` at
``theta-`` (``(dh0/dq; dtheta/dq) q'- = (hd'(1) / (theta- - theta+); 1)``, ``hd'(1) = M
(c_M - c_{M-1})``).

Feedback (input-output linearisation, Isidori 1995)::

    u = (L_g L_f h)^-1 (-L_f^2 h - kp y - kd y'),
    L_g L_f h = (dh/dq) M^-1 B,   L_f^2 h = d/dt(dh/dq) dq + (dh/dq) M^-1 (-C dq - G)

with ``dh/dq = dh0/dq - hd'(s) dtheta/dq / (theta- - theta+)`` and ``d/dt(dh/dq) dq`` from
the symbolic second derivatives of ``h0`` and ``theta``
(:mod:`walkerlab.codegen.virtual_constraints`: the same derivation as the flow's ``M, C,
G``), saturated at ``max_torque_n_m``.

Below both views (the rigid view's :class:`walkerlab.models.hybrid.virtual_constraints.
VirtualConstraintActuators`, the contact view's :class:`walkerlab.models.contact.
virtual_constraints.VirtualConstraintJointTorques`) and the MuJoCo export's stepping loop:
each evaluates this controller at its own role state.
"""

from __future__ import annotations

from math import comb

import numpy as np

__all__ = ["Design", "VirtualConstraintController", "annihilator", "bezier", "default_joints"]

KEY = "walker.actuation.virtual_constraints"
#: largest condition number of the decoupling matrix along the designed step
MAX_CONDITION = 1e10


def bezier(c, s):
    """``(hd, hd', hd'')`` of the Bezier polynomials with coefficients ``c`` (k, M + 1) at
    ``s`` (scalar; derivatives with respect to ``s``), each (k,) (Westervelt et al. 2003,
    Eq. 36; its derivatives by the difference of the coefficients).  Complex-safe."""
    c = np.asarray(c)
    M = c.shape[1] - 1
    d1 = M * (c[:, 1:] - c[:, :-1])
    d2 = (M - 1) * (d1[:, 1:] - d1[:, :-1])
    ps, qs = [1.0], [1.0]  # powers of s and 1 - s
    for _ in range(M):
        ps.append(ps[-1] * s)
        qs.append(qs[-1] * (1 - s))

    def basis(m):
        return np.array([comb(m, j) * ps[j] * qs[m - j] for j in range(m + 1)])
    return c @ basis(M), d1 @ basis(M - 1), d2 @ basis(M - 2)


def annihilator(B) -> np.ndarray:
    """``b`` (n,) with ``b^T B = 0`` (the direction no actuator drives; for absolute link
    angles the rotation of the whole walker about its stance foot), scaled so that its
    largest entry is +1."""
    u, _s, _vt = np.linalg.svd(np.asarray(B, float))
    b = u[:, -1]
    return b / b[np.argmax(np.abs(b))]


def default_joints(link_names, hinged_torso: bool) -> list[str]:
    """The joints virtual constraints drive by default: with a torso hinged at the hip (a
    coordinate of its own), torso to each leg (``stance_hip``, ``swing_hip``), else the hip
    between the legs (a bisecting torso follows the legs); each knee on a walker whose knees
    are free links."""
    from walkerlab.walker.joints import joint_links  # light

    names = set(link_names)
    out = ["stance_hip", "swing_hip"] if hinged_torso and "torso" in names else ["hip"]
    if "stance_shank" in names and "stance_thigh" in names:
        out += ["stance_knee", "swing_knee"]
    for j in out:
        joint_links(names, j, f"{KEY}.joints")
    return out


class Design:
    """The step's ends and the Bezier coefficients in force.

    Attributes
    ----------
    alpha : ndarray (k, M + 1)
        The coefficients [rad] (``invariant``: ``c_0``, ``c_1`` from the impact map).
    given : ndarray (k, M + 1)
        The scene's coefficients.
    theta_plus, theta_minus : float
        The phase variable at the step's start and end [rad, or m for the hip's position].
    q_minus, q_plus : ndarray (n,)
        The configurations at the step's end (before the heel strike) and start (after it).
    residual_position, residual_rate : float
        Invariance residuals of the coefficients in force: ``max |h0(q+) - c_0|`` [rad] and
        ``max |dh0/dq q'+ - hd'(0) dtheta/dq q'+ / (theta- - theta+)| / |dtheta/dq q'+|``
        [rad per unit of the phase] (0 to round-off with ``invariant: true``).
    """

    def __init__(self, alpha, given, theta_plus, theta_minus, q_minus, q_plus,
                 residual_position, residual_rate):
        self.alpha, self.given = alpha, given
        self.theta_plus, self.theta_minus = theta_plus, theta_minus
        self.q_minus, self.q_plus = q_minus, q_plus
        self.residual_position, self.residual_rate = residual_position, residual_rate


class VirtualConstraintController:
    """Computed torque on the virtual constraints of one walker (module docstring).

    Parameters
    ----------
    spec : walkerlab.config.actuation.VirtualConstraints
    fns : dict
        The walker's generated functions (``matrices``, ``reset``, ``leg_angles``).
    structure, params
        The walker's structure and parameters (the symbolic pieces' derivation).

    Raises
    ------
    ValueError
        One line naming the key: a link or joint the walker does not have, outputs and
        actuators that differ in number (or not one fewer than the coordinates), a phase
        that is not monotone over the step or no coordinate with the outputs, a singular
        decoupling matrix (naming the outputs), no heel strike at the outputs' end.
    """

    def __init__(self, spec, fns, structure, params):
        from walkerlab.codegen.virtual_constraints import output_module
        from walkerlab.models.compiled_flows import OutputPieces
        from walkerlab.walker.joints import link_angles  # light

        self.spec, self.fns = spec, fns
        if any(b.massless for b in structure.bodies):
            raise ValueError(f"{KEY}: needs legs whose bodies all carry mass (a massless "
                             "link has no inertia for the computed torque to act on)")
        n = len(structure.roles)
        self.n = n
        names = link_angles(fns["leg_angles"](np.zeros(2 * n)))
        joints = list(spec.joints) if spec.joints is not None else default_joints(
            names, bool(structure.torso) and structure.hinged_torso)
        self.joints = joints
        outputs = [("link", o.link) if o.link is not None else ("joint", o.joint)
                   for o in spec.outputs]
        self.output_names = [o.name for o in spec.outputs]
        k = len(outputs)
        if len(joints) < k:
            raise ValueError(f"{KEY}.outputs: {k} outputs but {len(joints)} actuators (joints: "
                             f"{', '.join(joints)}): give one output per actuator")
        if len(joints) > k:
            raise ValueError(f"{KEY}.outputs: {k} outputs for {len(joints)} actuators (joints: "
                             f"{', '.join(joints)}): give one output per actuator")
        if k != n - 1:
            raise ValueError(f"{KEY}.outputs: the walker has {n} coordinates: {n - 1} outputs "
                             f"(and actuators) leave a two-dimensional zero dynamics, not {k}")
        self.pieces = OutputPieces(output_module(structure, params, outputs, spec.phase, joints,
                                                 KEY))
        self._pieces_args = (structure, params, outputs, spec.phase, joints, KEY)
        self._law = None  # the compiled law (:meth:`_compiled_law`)
        self.B = self.pieces.B()
        self.kp = spec.feedback.kp_per_s2
        self.kd = spec.feedback.kd_per_s
        self.limit = spec.max_torque_n_m
        self.design = self._design(np.array([o.bezier_rad for o in spec.outputs], float))
        self._check_path()
        self._compiled_law()  # built here, not within the first (timed) step it speeds up

    # ------------------------------------------------------------------ configurations
    def chart(self, q):
        """``(Phi(q), dPhi/dq)``: the outputs' ``h0`` and the phase ``theta`` (n,), and
        their Jacobian (n, n)."""
        x = np.concatenate([q, np.zeros(self.n)])
        h0, J, _dd, th, gth, _ddth = self.pieces(x)
        return np.append(h0, th), np.vstack([J, gth])

    def configuration(self, target, q0, where: str = "phase"):
        """The configuration ``q`` (n,) with ``Phi(q) = target`` (n,), by Newton from
        ``q0``.

        Raises
        ------
        ValueError
            No such configuration near ``q0`` (one line naming ``where``).
        """
        q = np.array(q0, float)
        for _ in range(50):
            F, D = self.chart(q)
            r = F - target
            if not np.all(np.isfinite(D)) or abs(np.linalg.det(D)) < 1e-12:
                break
            dq = np.linalg.solve(D, r)
            q -= dq
            if np.max(np.abs(dq)) < 1e-14 * (1 + np.max(np.abs(q))):
                return q
        F, _ = self.chart(q)
        if np.max(np.abs(F - target)) < 1e-11:
            return q
        raise ValueError(f"{KEY}.{where}: with the outputs, the phase variable is no "
                         "coordinate of the walker there (no configuration has these "
                         "outputs and phase)")

    def tangent(self, q, hd1, dtheta):
        """``q' = dq/dtheta`` (n,) on the surface at ``q``: ``dPhi/dq q' = (hd'(s) /
        (theta- - theta+); 1)``."""
        _F, D = self.chart(q)
        return np.linalg.solve(D, np.append(hd1 / dtheta, 1.0))

    def _end(self, cM):
        """``(theta-, q-)``: where the outputs at ``c_M`` put the swing foot on the ground
        ahead of the stance foot (scan of the phase, then Brent's method)."""
        from scipy.optimize import brentq

        ph = self.spec.phase
        span = 1.0 if ph.point is not None else (
            1.5 * sum(abs(v) for v in ph.coordinates.values()) if ph.coordinates else 1.5)
        grid = np.linspace(-span, span, 301)
        q = np.zeros(self.n)
        rows = []
        for th in grid:
            try:
                q = self.configuration(np.append(cM, th), q, "outputs")
            except ValueError:
                rows.append(None)
                q = np.zeros(self.n)
                continue
            rows.append((q.copy(), *self.pieces.foot(q)))
        cands = []
        for i in range(len(grid) - 1):
            a, b = rows[i], rows[i + 1]
            if a is None or b is None or a[1] * b[1] > 0 or a[2] <= 0 or b[2] <= 0:
                continue

            def height(th, q0=a[0]):
                return self.pieces.foot(self.configuration(np.append(cM, th), q0))[0]
            th = brentq(height, grid[i], grid[i + 1], xtol=1e-15, rtol=1e-15)
            q = self.configuration(np.append(cM, th), a[0])
            ahead = self.pieces.foot(q)[1]
            if ahead > 1e-9:  # not where the feet pass each other
                cands.append((ahead, th, q))
        if not cands:
            raise ValueError(f"{KEY}.outputs: at the last Bezier coefficients (c_M) the swing "
                             "foot reaches the ground ahead of the stance foot for no value "
                             "of the phase variable: no heel strike ends the step")
        # the swing foot lands ahead: the configuration where it is furthest ahead
        _ahead, th, q = max(cands, key=lambda c: c[0])
        # every coordinate is an angle: the scan's Newton iterates can drift by whole turns
        # where the phase is flat in a coordinate (a hip position near a leg's horizontal);
        # the same configuration, its angles in (-pi, pi]
        return th, np.where(np.abs(q) > np.pi, np.remainder(q + np.pi, 2 * np.pi) - np.pi, q)

    def _design(self, given):
        """:class:`Design` of the scene's coefficients ``given`` (k, M + 1)."""
        k, M1 = given.shape
        M = M1 - 1
        n = self.n
        th_m, q_m = self._end(given[:, -1])
        q_p = np.real(self.fns["reset"](np.concatenate([q_m, np.zeros(n)]))[:n])
        F, _ = self.chart(q_p)
        th_p = float(F[-1])
        dth = th_m - th_p
        if abs(dth) < 1e-6 * (1 + abs(th_m)):
            raise ValueError(f"{KEY}.phase: not monotone over the step: it takes the same "
                             f"value ({th_m:.6g}) at the step's start and end")
        alpha = given.copy()
        hd1_end = M * (given[:, -1] - given[:, -2])
        qd_m = self.tangent(q_m, hd1_end, dth)
        xp = np.real(self.fns["reset"](np.concatenate([q_m, qd_m])))
        qd_p = xp[n:]
        _h0, J, _dd, _th, gth, _ = self.pieces(xp)
        th_rate = float(gth @ qd_p)
        if self.spec.invariant:
            alpha[:, 0] = F[:-1]
            alpha[:, 1] = alpha[:, 0] + dth / M * (J @ qd_p) / th_rate
        res_pos = float(np.max(np.abs(F[:-1] - alpha[:, 0])))
        res_rate = float(np.max(np.abs(J @ qd_p - M * (alpha[:, 1] - alpha[:, 0]) / dth
                                       * th_rate)) / abs(th_rate))
        return Design(alpha, given, th_p, th_m, q_m, q_p, res_pos, res_rate)

    def path(self, s_values):
        """Configurations ``q(s)`` (len(s), n) and tangents ``dq/dtheta`` on the surface at
        the phases ``s`` (increasing from 0), by Newton from the step's start."""
        d = self.design
        dth = d.theta_minus - d.theta_plus
        q = d.q_plus.copy()
        qs, ts = [], []
        for s in s_values:
            hd, hd1, _ = bezier(d.alpha, s)
            q = self.configuration(np.append(hd, d.theta_plus + s * dth), q)
            qs.append(q.copy())
            ts.append(self.tangent(q, hd1, dth))
        return np.array(qs), np.array(ts)

    def _check_path(self):
        """The phase advances with the hip, the decoupling matrix is regular along the
        designed step and the stance foot is a pin (the rotation ``b`` no actuator drives
        leaves the kinetic energy unchanged: the zero dynamics' quadrature); one line naming
        the key otherwise."""
        s = np.linspace(0.0, 1.0, 41)
        qs, tangents = self.path(s)
        hip = np.array([self.pieces.foot(q)[2] for q in qs])
        d = np.diff(hip)
        if not (np.all(d > 0) or np.all(d < 0)):
            i = int(np.argmax(d * np.sign(hip[-1] - hip[0]) <= 0))
            raise ValueError(f"{KEY}.phase: not monotone over the step: the hip moves back "
                             f"while the phase advances near s = {s[i]:.3f} (hip "
                             f"{hip[i]:.4g} -> {hip[i + 1]:.4g} m)")
        for si, q in zip(s, qs):
            A = self.decoupling(np.concatenate([q, np.zeros(self.n)]))
            sv = np.linalg.svd(A, compute_uv=False)
            if not sv[-1] > sv[0] / MAX_CONDITION:  # the outputs in its left null space
                w = np.abs(np.linalg.svd(A)[0][:, -1])
                names = [self.output_names[i] for i in np.flatnonzero(w > 0.1 * w.max())]
                raise ValueError(f"{KEY}.outputs: the decoupling matrix L_g L_f h is singular "
                                 f"at s = {si:.3f} (condition {sv[0] / max(sv[-1], 1e-300):.3g}):"
                                 f" the actuators ({', '.join(self.joints)}) cannot drive "
                                 f"the outputs {', '.join(names)} independently")
        b = annihilator(self.B)
        W, I_ = [], []
        for q, qp in zip(qs, tangents):  # dT/db = q'^T (dM/db) q' / 2 = 0 on a pin
            x = np.concatenate([q, qp]).astype(complex)
            x[:self.n] += 1e-30j * b
            M = self.fns["matrices"](x)[0]
            W.append(qp @ (np.imag(M) / 1e-30) @ qp)
            I_.append(b @ np.real(M) @ qp)
        if np.max(np.abs(W)) > 1e-9 * np.max(np.abs(I_)):
            raise ValueError(f"{KEY}: the stance foot is no pin (the kinetic energy changes "
                             "under the rotation no actuator drives, as on rolling feet): the "
                             "zero dynamics' quadrature needs point feet")

    # ------------------------------------------------------------------ feedback
    def terms(self, x):
        """``(y, dy, LgLfh (k, k), Lf2h (k,), M^-1 B (n, k))`` at the state ``x`` (2n,)
        (complex-safe)."""
        n = self.n
        d = self.design
        dth = d.theta_minus - d.theta_plus
        dq = x[n:]
        h0, J0, dd0, th, gth, ddth = self.pieces(x)
        s = (th - d.theta_plus) / dth
        ds = (gth @ dq) / dth
        hd, hd1, hd2 = bezier(d.alpha, s)
        J = J0 - np.outer(hd1, gth) / dth
        y = h0 - hd
        dy = J @ dq
        M, C, G = self.fns["matrices"](x)
        sol = np.linalg.solve(M, np.column_stack([self.B, -(C @ dq) - np.ravel(G)]))
        MinvB, f0 = sol[:, :-1], sol[:, -1]
        Lf2 = dd0 - hd2 * ds ** 2 - hd1 * ddth / dth + J @ f0
        return y, dy, J @ MinvB, Lf2, MinvB

    def acceleration(self, x):
        """``(u (k,), M^-1 B u (n,))``: the torques [N m] (saturated) and the acceleration
        they add [rad/s^2] at the state ``x`` (2n,) (complex-safe).

        Runs the law compiled by numba
        (:func:`walkerlab.codegen.virtual_constraints.compiled_controller`: the same
        expressions, equal to :meth:`acceleration_numpy` to round-off), for real states and
        for complex ones (the complex-step derivatives of the variational equations)."""
        law = self._compiled_law()
        if law is None:
            return self.acceleration_numpy(x)
        d = self.design
        x = np.ascontiguousarray(x, dtype=complex if np.iscomplexobj(x) else float)
        return law(x, d.alpha, d.theta_plus, d.theta_minus - d.theta_plus, self.B, self.kp,
                   self.kd, -1.0 if self.limit is None else float(self.limit))

    def acceleration_numpy(self, x):
        """:meth:`acceleration` by numpy from :meth:`terms` (the reference of the compiled
        law; used where numba is missing)."""
        y, dy, A, Lf2, MinvB = self.terms(x)
        u = self._saturate(np.linalg.solve(A, -Lf2 - self.kp * y - self.kd * dy))
        return u, MinvB @ u

    def __getstate__(self):  # the compiled law is rebuilt (from the user cache) on first use
        state = dict(self.__dict__)
        state["_law"] = None
        state.pop("_law_module", None)  # a module: set again with the law
        return state

    def _compiled_law(self):
        """The compiled ``law`` (see :meth:`acceleration`; built once, loaded from the user
        cache), or None without numba or for Bezier polynomials of degree 16 or more (the
        numpy law then)."""
        if self._law is False:
            return None
        if self._law is None:
            self._law = False
            if self.design.alpha.shape[1] <= 16:
                from walkerlab.codegen.virtual_constraints import compiled_controller

                mod = compiled_controller(*self._pieces_args)
                if mod is not None:
                    self._law = mod.law
                    self._law_module = mod
                    d = self.design  # numba compiles (or loads) on the first call: here
                    x0 = np.concatenate([d.q_plus, np.zeros(self.n)])
                    for x in (x0, x0.astype(complex)):  # real and complex states
                        self._law(x, d.alpha, d.theta_plus, d.theta_minus - d.theta_plus,
                                  self.B, 0.0, 0.0, -1.0)
        return self._law or None

    def compiled_module(self):
        """The generated numba module of the compiled law
        (:func:`walkerlab.codegen.virtual_constraints.compiled_controller`: its ``law``),
        or None where the numpy law runs (:meth:`_compiled_law`); for compiled code that
        calls the law (the contact view's compiled right-hand side,
        :mod:`walkerlab.models.contact.virtual_constraints`)."""
        return getattr(self, "_law_module", None) if self._compiled_law() else None

    def _saturate(self, u):
        if self.limit is None:
            return u
        lim = self.limit
        return np.where(np.real(u) > lim, lim, np.where(np.real(u) < -lim, -lim, u))

    def decoupling(self, x):
        """The decoupling matrix ``L_g L_f h = (dh/dq) M^-1 B`` (k, k) at ``x`` (2n,)."""
        return self.terms(x)[2]

    def torques(self, x):
        """The actuators' torques ``u`` (k,) [N m] at the state ``x`` (2n,), saturated at
        ``max_torque_n_m`` (complex-safe: the saturation compares real parts)."""
        return self.acceleration(x)[0]

    def outputs(self, x):
        """``(y, y')`` (k,) each [rad, rad/s] at the state ``x`` (2n,)."""
        y, dy, *_ = self.terms(np.asarray(x, float))
        return y, dy
