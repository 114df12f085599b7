"""Joint-torque laws of ``walker.actuation`` evaluated the same way in both views of a walker
(the rigid hybrid model, :mod:`walkerlab.models.hybrid.actuated`, and the compliant-contact
model, :mod:`walkerlab.models.contact.actuation`): one formula, one place.

A law is data (:class:`walkerlab.config.actuation.TorqueLaw`): ``tau = constant - K (delta -
rest) - D ddelta``, or with a reference ``h_d(s)`` of the phase variable ``s`` (the stance
leg's absolute angle) the PD tracking ``tau = -K (delta - h_d(s)) - D (ddelta - h_d'(s) ds)``
(a virtual constraint, Westervelt, Grizzle & Koditschek 2003, IEEE TAC 48(1):42-56), each
saturated at ``max_torque_n_m``.  ``delta`` is the hip angle, swing minus stance leg angle
[rad]; ``+tau`` acts on the swing leg, ``-tau`` on the stance leg (Kuo 2002).

Everything is complex-safe to first order (a complex argument ``u + i e`` gives ``f(u) + i e
f'(u)``), which the rigid model's complex-step Jacobians need.
"""

from __future__ import annotations

import numpy as np

from walkerlab.walker.joints import joint_angles, joint_columns, joint_links, link_angles

__all__ = ["JointMap", "TorqueLaws", "TorqueOfTime", "phase_reference", "push_off_impulse",
           "refuse_actuators", "saturate", "shared_phase_table", "torque_feature"]


def phase_reference(table):
    """``(h, dh)``: the reference ``h_d(s)`` [rad] and its slope ``h_d'(s)`` [rad/rad] of a
    phase table (:class:`walkerlab.config.actuation.PhaseReference`), piecewise linear or a
    not-a-knot cubic spline (:class:`scipy.interpolate.CubicSpline`), held at its end values
    outside the table (slope 0 there)."""
    from scipy.interpolate import CubicSpline

    s, y = np.asarray(table.phase_rad, float), np.asarray(table.values_rad, float)
    if table.interpolation == "cubic" and len(s) >= 3:
        cs = CubicSpline(s, y, bc_type="not-a-knot", extrapolate=False)
        d1, d2 = cs.derivative(), cs.derivative(2)

        def val(u, f, df):
            r = np.clip(np.real(u), s[0], s[-1])
            inside = (np.real(u) > s[0]) & (np.real(u) < s[-1])
            return f(r) + (1j * np.imag(u) * df(r) * inside if np.iscomplexobj(u) else 0.0)

        return (lambda u: val(u, cs, d1)), (lambda u: val(u, d1, d2) * (
            (np.real(u) > s[0]) & (np.real(u) < s[-1])))
    slope = np.diff(y) / np.diff(s)

    def lin(u):
        r = np.clip(np.real(u), s[0], s[-1])
        k = np.clip(np.searchsorted(s, r) - 1, 0, len(s) - 2)
        out = y[k] + slope[k] * (r - s[k])
        inside = (np.real(u) > s[0]) & (np.real(u) < s[-1])
        return out + (1j * np.imag(u) * slope[k] * inside if np.iscomplexobj(u) else 0.0)

    def dlin(u):
        r = np.real(u)
        k = np.clip(np.searchsorted(s, r) - 1, 0, len(s) - 2)
        return slope[k] * ((r > s[0]) & (r < s[-1]))

    return lin, dlin


def shared_phase_table(torques):
    """The references ``[(h_i, dh_i)]`` of laws that all track cubic phase tables on the
    same abscissa, from ONE vector-valued spline (the same not-a-knot
    :class:`scipy.interpolate.CubicSpline` per column as
    :func:`phase_reference`, held at its end values outside,
    complex-step aware), evaluated once per phase value; None when the laws differ."""
    tabs = [t.law.reference for t in torques]
    if (not tabs or any(r is None or r.interpolation != "cubic" or len(r.phase_rad) < 3
                        or r.phase_rad != tabs[0].phase_rad for r in tabs)):
        return None
    from scipy.interpolate import CubicSpline

    s = np.asarray(tabs[0].phase_rad, float)
    cs = CubicSpline(s, np.array([r.values_rad for r in tabs], float).T, bc_type="not-a-knot",
                     extrapolate=False)
    d1, d2 = cs.derivative(), cs.derivative(2)
    memo: dict = {}

    def at(u):  # (h (k,), dh (k,)) at the phase u
        key = (bool(np.iscomplexobj(u)), complex(u))  # a real call never reads a complex
        if key not in memo:
            memo.clear()
            r = min(max(float(np.real(u)), s[0]), s[-1])
            inside = float(s[0] < np.real(u) < s[-1])
            h, dh = cs(r), d1(r) * inside
            if np.iscomplexobj(u):
                h = h + 1j * np.imag(u) * dh
                dh = dh + 1j * np.imag(u) * d2(r) * inside
            memo[key] = (h, dh)
        return memo[key]

    return [((lambda u, i=i: at(u)[0][i]), (lambda u, i=i: at(u)[1][i]))
            for i in range(len(tabs))]


def _table_coefficients(table) -> tuple[np.ndarray, np.ndarray]:
    """Knots (n,) and cubic coefficients (4, n - 1) of a table as :func:`phase_reference`
    interpolates it (highest degree first; piecewise linear: ``0, 0, slope, value``)."""
    s, y = np.asarray(table.phase_rad, float), np.asarray(table.values_rad, float)
    if table.interpolation == "cubic" and len(s) >= 3:
        from scipy.interpolate import CubicSpline

        return s, CubicSpline(s, y, bc_type="not-a-knot").c
    slope = np.diff(y) / np.diff(s)
    return s, np.vstack([np.zeros_like(slope), np.zeros_like(slope), slope, y[:-1]])


def saturate(tau, limit):
    """``tau`` clipped to ``[-limit, limit]`` [N m] (None: unchanged); complex-safe."""
    if limit is None:
        return tau
    re = np.real(tau)
    return np.where(re > limit, limit, np.where(re < -limit, -limit, tau))


class TorqueLaws:
    """The hip-torque laws of one walker's ``walker.actuation.torques``.

    Parameters
    ----------
    torques : list of walkerlab.config.actuation.JointTorque
    """

    def __init__(self, torques):
        self.torques = list(torques)
        self.refs = [(phase_reference(t.law.reference) if t.law.reference is not None
                      else None) for t in self.torques]
        self.time_refs = [(phase_reference(t.law.time_reference)
                           if t.law.time_reference is not None else None)
                          for t in self.torques]

    @property
    def timed(self) -> bool:
        """Some law reads the time since the step began."""
        return any(r is not None for r in self.time_refs)

    def __bool__(self) -> bool:
        return bool(self.torques)

    def packed(self) -> np.ndarray:
        """The laws as the law block of compiled flows
        (:func:`walkerlab.codegen.torque_law.pack_laws`): the same tables (the not-a-knot
        :class:`scipy.interpolate.CubicSpline`'s coefficients, or the piecewise-linear
        slopes), gains and saturations as :meth:`each` evaluates."""
        from walkerlab.codegen.torque_law import PHASE, PLAIN, TIME, pack_laws  # light

        rows = []
        for act in self.torques:
            law = act.law
            table = law.reference if law.reference is not None else law.time_reference
            kind = PLAIN if table is None else (PHASE if law.reference is not None else TIME)
            knots = coefs = None
            if table is not None:
                knots, coefs = _table_coefficients(table)
            rows.append((kind, law.constant_n_m, law.stiffness_n_m_per_rad,
                         law.damping_n_m_s_per_rad, law.rest_angle_rad, act.max_torque_n_m,
                         knots, coefs))
        return pack_laws(rows)

    def __call__(self, delta, ddelta, s, ds, t_step=0.0) -> np.ndarray:
        """Torque of each actuator, shape (k,) [N m; N m/kg when ``scaled_by: foot_mass``].

        Parameters
        ----------
        delta, ddelta : float or complex
            Hip angle (swing minus stance leg angle) [rad] and its rate [rad/s].
        s, ds : float or complex
            Phase variable (the stance leg's absolute angle) [rad] and its rate [rad/s].
        t_step : float
            Time since the step's heel strike [s] (read by ``time_reference`` laws).
        """
        k = len(self.torques)
        return self.each([delta] * k, [ddelta] * k, s, ds, t_step)

    def each(self, deltas, ddeltas, s, ds, t_step=0.0) -> np.ndarray:
        """Torque of each actuator (k,) [N m] with its own joint angle: ``deltas[i]``,
        ``ddeltas[i]`` [rad, rad/s] are actuator ``i``'s joint angle and rate (a five-link
        biped's joints, :data:`walkerlab.config.actuation.FIVE_LINK_JOINTS`); ``s, ds``,
        ``t_step`` as in :meth:`__call__`."""
        out = []
        for act, ref, tref, delta, ddelta in zip(self.torques, self.refs, self.time_refs,
                                                 deltas, ddeltas):
            law = act.law
            if ref is not None:
                h, dh = ref
                err, derr = delta - h(s), ddelta - dh(s) * ds
            elif tref is not None:
                h, dh = tref
                err, derr = delta - h(t_step), ddelta - dh(t_step)
            else:
                err, derr = delta - law.rest_angle_rad, ddelta
            tau = law.constant_n_m - law.stiffness_n_m_per_rad * err \
                - law.damping_n_m_s_per_rad * derr
            out.append(saturate(tau, act.max_torque_n_m))
        return np.array(out)


class TorqueOfTime:
    """One hip torque of the time since the step's heel strike alone: an optimised step's
    torque replayed (Hermite-Simpson collocation's control, a quadratic on each interval
    through its three nodes, held at its end values outside the step), as data of the
    compiled contact run (:meth:`packed`, the law kind
    :data:`walkerlab.codegen.torque_law.TIME_FEEDFORWARD`) and as a Python law (``tau``,
    the callable it was made from, for the ``solve_ivp`` runs).

    Parameters
    ----------
    tau : callable
        ``tau(t) -> float`` [N m] of the time since the heel strike [s].
    pieces : sequence of (ndarray, ndarray) or None
        Each phase's collocation nodes ``t`` (2 m + 1,) [s] (since the heel strike,
        increasing, phase after phase) and controls ``u`` (2 m + 1,) [N m]; None: ``tau``
        alone (no law block: :meth:`packed` answers None).
    """

    def __init__(self, tau, pieces):
        self.tau = tau
        self.knots = self.coefs = None
        if pieces is None:
            return
        knots, coefs = [], []
        for t, u in pieces:
            t, u = np.asarray(t, float), np.asarray(u, float)
            for i in range(0, len(t) - 2, 2):
                x = t[i:i + 3] - t[i]
                a2, a1, a0 = np.polyfit(x, u[i:i + 3], 2)  # through the three nodes
                knots.append(t[i])
                coefs.append((0.0, a2, a1, a0))
        knots.append(float(np.asarray(pieces[-1][0], float)[-1]))
        self.knots, self.coefs = np.array(knots), np.array(coefs).T

    def __bool__(self) -> bool:
        return True

    def __call__(self, delta, ddelta, s, ds, t=0.0) -> np.ndarray:
        """The torque (1,) [N m] at the time ``t`` [s] since the heel strike (the other
        arguments, a torque law's, are not read)."""
        return np.array([self.tau(float(t))])

    def packed(self) -> np.ndarray | None:
        """The law block (:func:`walkerlab.codegen.torque_law.pack_laws`) of this torque
        (None without its pieces)."""
        from walkerlab.codegen.torque_law import TIME_FEEDFORWARD, pack_laws  # light

        if self.knots is None:
            return None
        return pack_laws([(TIME_FEEDFORWARD, 0.0, 0.0, 0.0, 0.0, None, self.knots,
                           self.coefs)])


def push_off_impulse(push_off, hip_speed):
    """Push-off impulse ``P`` [N s] (>= 0: a foot can only push) of the law
    :class:`walkerlab.config.actuation.PushOff` at the pre-impact hip speed [m/s]:
    ``P = impulse_n_s + speed_gain_n_s2_per_m (reference_speed_m_per_s - v)`` (complex-safe).
    None: 0."""
    if push_off is None:
        return 0.0
    if push_off.speed_gain_n_s2_per_m == 0.0:
        return push_off.impulse_n_s
    p = push_off.impulse_n_s + push_off.speed_gain_n_s2_per_m * (
        push_off.reference_speed_m_per_s - hip_speed)
    return np.where(np.real(p) > 0.0, p, 0.0 * p)


class JointMap:
    """The joint torques of a walker whose every coordinate is a link's absolute angle (a
    free-jointed biped), in the rigid view's role order: each joint's links
    (:func:`walkerlab.walker.joints.joint_links`), its column of ``B``
    (:func:`walkerlab.walker.joints.joint_columns`) and the laws (one spline for laws
    sharing a phase table, :func:`shared_phase_table`) - what both views evaluate.

    Parameters
    ----------
    spec : walkerlab.config.actuation.Actuation
    leg_angles : callable
        The walker's generated ``leg_angles`` (``x (2n,) -> {<link>_angle, <link>_rate}``).
    n : int
        Number of generalised coordinates (role order).

    Raises
    ------
    ValueError
        A joint the walker does not have (naming the joints it has) or a torque per foot
        mass (one line, naming the field).
    """

    def __init__(self, spec, leg_angles, n: int):
        for i, t in enumerate(spec.torques):
            if t.scaled_by != "none":
                raise ValueError(f"walker.actuation.torques.{i}.scaled_by: foot_mass is for "
                                 "walkers whose legs are massless")
        self.spec = spec
        self._angles = lambda x: link_angles(leg_angles(x))
        z = np.zeros(n)
        names = self._angles(np.concatenate([z, z]))
        self.links = [joint_links(names, t.joint, f"walker.actuation.torques.{i}.joint")
                      for i, t in enumerate(spec.torques)]
        #: (n, k) each joint's generalised-force column
        self.B = joint_columns(self._angles, n, self.links)
        self.laws = TorqueLaws(spec.torques)
        shared = shared_phase_table(spec.torques)
        if shared is not None:  # one spline for every law's reference: 2 calls, not 2k
            self.laws.refs = shared

    def joint_angles(self, x):
        """``(deltas, ddeltas, s, ds)`` at the role state ``x`` (2n,): each joint's angle
        [rad] and rate [rad/s], the phase variable (the virtual stance leg's angle) [rad] and
        its rate [rad/s] (:func:`walkerlab.walker.joints.joint_angles`)."""
        return joint_angles(self._angles(x), self.links, "stance")


def torque_feature(joint: str) -> str:
    """The capability table's feature of a torque at ``joint`` (``hip``: the hip torque;
    ``stance_hip``/``swing_hip``: between a torso and a leg; a knee's, an ankle's)."""
    for part in ("knee", "ankle"):
        if part in joint:
            return f"{part}_torque"
    return "hip_torque" if joint == "hip" else "torso_torque"


def refuse_actuators(kind, spec, view: str) -> None:
    """Refuse the first actuator ``spec`` (a ``walker.actuation`` section) asks for that
    ``kind`` does not have in ``view``, in the table's one line naming its field (both
    views' and the exports' check: it lies below them).

    Raises
    ------
    walkerlab.walker.kinds.KindRefused
    """
    for i, t in enumerate(spec.torques):
        kind.require(torque_feature(t.joint), view, f"walker.actuation.torques.{i}.joint")
    for name in ("push_off", "ankle_push_off", "virtual_constraints"):
        if getattr(spec, name, None) is not None:
            kind.require(name, view, f"walker.actuation.{name}")
