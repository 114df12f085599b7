"""The contact view of the Gymnasium environment: the scene's floating walker with compliant
feet (:class:`walkerlab.models.contact.model.ContactWalker`, its IMPACT contact law and
terrain) advanced one control period at a time.

The walker, its terrain's patches and its start are those of ``walkerlab contact-sim``
(:func:`walkerlab.analysis.contact.sim.scene_start`: the stance foot at its static
penetration, the rigid gait's rates times ``contact_sim.initial_rate_scale``), the patches
laid out for the episode's longest walk.  Each control period runs ``solve_ivp`` (LSODA
unless ``contact_solver.method`` is one of its methods, with the scene's tolerances and the
model's analytic Jacobian) with two terminal events: the swing foot's touchdown on ground at
least ``min_step_m`` ahead of the stance foot (the heel strike: the stance leg switches
there, as in :mod:`walkerlab.integrate.contact_powered`) and the hip's fall below
``contact_sim.fall_hip_height_m`` (the contact model's fall test,
:meth:`~walkerlab.models.contact.model.ContactWalker.fall_margin`).

The scene's own actuation acts as in the contact view's powered run
(:func:`walkerlab.models.contact.actuation.powered_rhs`: its torque laws); its push-off is
applied as an impulse at the touchdown (the pulse's limit ``T -> 0``,
:func:`walkerlab.integrate.contact_powered.impulse_jump`).  The action's torques act ``+tau``
on the second link of their joint and ``-tau`` on the first, on the floating coordinates
(absolute link angles, the same convention as the rigid view's).

Seeded terrain: with ``terrain_roughness_m > 0`` each patch is raised or lowered by a height
drawn uniformly from ``[-r, r]`` by the episode's terrain seed (rough ground as geometry,
:attr:`~walkerlab.models.contact.model.ContactWalker.heights1`).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from walkerlab.models.contact.actuation import ContactRows

__all__ = ["CONTACT_LEDGER_TERMS", "ContactView"]

#: the contact view's ledger terms [J] (the episode's sums)
CONTACT_LEDGER_TERMS = ("action_work_positive", "action_work_negative", "scene_torque_work",
                        "push_off_work")
#: a touchdown is a heel strike only this far [m] ahead of the stance foot (as the contact
#: view's powered run, ``ContactActuators.min_step_m``)
MIN_STEP_M = 0.05
_IVP_METHODS = ("RK45", "RK23", "DOP853", "Radau", "BDF", "LSODA")
_GL_X, _GL_W = np.polynomial.legendre.leggauss(4)


def _link_coordinate(link: str, leg: dict, names: tuple) -> int:
    """Index of a rigid role link (``stance``, ``swing_thigh``, ``torso``, ...) among the
    floating coordinates ``names`` with ``leg`` = ``{"stance": legX, "swing": legY}``."""
    role, _, part = link.partition("_")
    if role in leg:
        name = f"{leg[role]}_{part}_angle" if part else f"{leg[role]}_angle"
    else:
        name = f"{link}_angle"
    if name not in names:
        raise ValueError(f"walkerlab.gym: the contact view has no coordinate {name} for the "
                         f"action's link {link} (its coordinates: {', '.join(names)})")
    return names.index(name)


class ContactView:
    """The scene's contact walker stepped by control periods.

    Parameters
    ----------
    setup : walkerlab.models.contact.scene.ContactSetup
    links : list of (str, str)
        The action's joints as their (first, second) rigid links
        (:attr:`walkerlab.gym.action.ActionTorques.links`).
    x_gait : ndarray (2n,)
        The rigid gait's post-impact state (the start).
    n_steps : int
        Steps the episode may take (the patches laid out).

    Raises
    ------
    ValueError
        A scene actuation the view does not carry (an ankle push-off), or an action link
        with no floating coordinate (a torso that bisects the legs), one line.
    """

    def __init__(self, setup, links, x_gait, n_steps: int):
        from walkerlab.analysis.contact.sim import scene_start

        acts = setup.actuators
        if acts is not None and getattr(acts, "ankle", None) is not None:
            raise ValueError("walkerlab.gym: the contact view does not carry the scene's "
                             "ankle push-off yet; use view='rigid'")
        self.walker, self.x_start, self.limits, self.step_length = scene_start(
            setup, np.asarray(x_gait, float), max(1, n_steps // 2 + 1))
        names = tuple(self.walker.coordinate_names())
        self.nq = len(names)
        self.index = []  # per stance leg (0: leg1, 1: leg2): (first, second) coordinates
        for stance in (0, 1):
            leg = {"stance": f"leg{stance + 1}", "swing": f"leg{2 - stance}"}
            self.index.append([(_link_coordinate(a, leg, names),
                                _link_coordinate(b, leg, names)) for a, b in links])
        s = setup.solver
        self.method = s.method if s.method in _IVP_METHODS else "LSODA"
        self.rtol, self.atol = s.rtol, s.atol
        self.rows = acts if acts is not None else ContactRows()
        self.acts = acts
        self.state_names = list(self.walker.state_names())
        self._lanes = (self.walker.lane1.copy(), self.walker.lane2.copy())
        # the scene's own patch heights (stairs, footholds; None on the slope): roughness adds
        self._heights = (self.walker.heights1, self.walker.heights2)

    def set_terrain(self, roughness_m: float, seed: int) -> None:
        """The scene's patch heights (its stairs' or footholds'; none on the slope) plus
        heights drawn from ``[-roughness_m, roughness_m]`` [m] by ``seed`` (0: the scene's
        ground as it is)."""
        w = self.walker
        base = self._heights
        if roughness_m > 0.0:
            rng = np.random.default_rng(seed)
            h = [rng.uniform(-roughness_m, roughness_m, lane.size) for lane in self._lanes]
            h = [d if b is None else np.asarray(b, float) + d for b, d in zip(base, h)]
            self.walker = dataclasses.replace(w, heights1=h[0], heights2=h[1])
        elif w.heights1 is not base[0] or w.heights2 is not base[1]:
            self.walker = dataclasses.replace(w, heights1=base[0], heights2=base[1])

    def reset(self, x0: np.ndarray | None = None) -> None:
        """Start at the contact state ``x0`` (N,) (default: the scene's start), leg2 in
        stance, at t = 0."""
        self.t = 0.0
        self.t_step = 0.0
        self.stance = 1
        self.x = np.array(self.x_start if x0 is None else x0, dtype=float)
        self.ended = ""
        self.ledger = dict.fromkeys(CONTACT_LEDGER_TERMS, 0.0)
        self.steps = 0

    def hip_x(self) -> float:
        """World position of the hip along x (horizontal, downhill) [m]."""
        return float(self.walker.points(self.x)["hip"][0, 0])

    def points(self) -> dict:
        """World positions (2,) [m] of the walker's named points."""
        return {k: np.asarray(v, float)[:, 0] for k, v in self.walker.points(self.x).items()}

    # ------------------------------------------------------------------ stepping
    def _action_force(self, u):
        Q = np.zeros(self.nq)
        for tau, (a, b) in zip(u, self.index[self.stance]):
            Q[b] += tau
            Q[a] -= tau
        return Q

    def _rhs(self, u):
        w, n, acts = self.walker, self.nq, self.acts
        Q = self._action_force(u)
        act_on = bool(np.any(Q))
        stance, t_step = self.stance, self.t_step

        def f(t, x):
            if acts is None:
                dx = np.array(w.rhs(t, x), float)
            else:
                from walkerlab.models.contact.actuation import powered_rhs

                dx = powered_rhs(w, x, stance, None, t - t_step)[0]
            if act_on:
                dx[n:] += np.linalg.solve(w.mass_matrix(x), Q)
            return dx
        return f, Q

    def _events(self):
        w, rows, stance, n = self.walker, self.rows, self.stance, 2 * self.nq

        def touch(t, y):
            r = rows.leg_contacts(w, y[:n])
            sw, st = r[1 - stance], r[stance]
            if sw[7] < 0.5 or sw[3] - st[3] < MIN_STEP_M:
                return 1.0
            return -float(sw[0])
        touch.terminal, touch.direction = True, -1

        def fall(t, y):
            return w.fall_margin(y[:n], self.limits.fall_hip_height_m)
        fall.terminal, fall.direction = True, -1
        return [touch, fall]

    def _work(self, sol, ta, tb, Q) -> None:
        acts = self.acts
        if tb <= ta:
            return
        ts = 0.5 * (tb - ta) * _GL_X + 0.5 * (ta + tb)
        X = np.atleast_2d(sol(ts))
        h, n = 0.5 * (tb - ta), self.nq
        for j, tj in enumerate(ts):
            xj = X[:, j]
            if np.any(Q):
                p = float(Q @ xj[n:])
                key = "action_work_positive" if p > 0 else "action_work_negative"
                self.ledger[key] += h * _GL_W[j] * p
            if acts is not None and acts.spec.torques:
                p_sc = acts.hip_torque(xj, self.stance, tj - self.t_step)[1]
                self.ledger["scene_torque_work"] += h * _GL_W[j] * p_sc

    def advance(self, u: np.ndarray, t_end: float) -> list[float]:
        """Integrate to ``t_end`` [s] with the action torques ``u`` (k,) [N m] held.

        Returns
        -------
        list of float
            The heel-strike (touchdown) times inside the period [s]; :attr:`ended` is set
            when the episode ended inside it (``fall``, ``solver_failure``).
        """
        from scipy.integrate import solve_ivp

        strikes: list[float] = []
        while self.t < t_end and not self.ended:
            f, Q = self._rhs(u)
            jac = self.walker.jac if self.method in ("Radau", "BDF", "LSODA") else None
            kw = {"jac": jac} if jac is not None else {}
            sol = solve_ivp(f, (self.t, t_end), self.x, method=self.method, rtol=self.rtol,
                            atol=self.atol, events=self._events(), dense_output=True, **kw)
            if sol.status == -1:
                self.ended = "solver_failure"
                break
            fired = [(te[0], i) for i, te in enumerate(sol.t_events) if len(te)]
            if fired:
                te, i = min(fired)
                self._work(sol.sol, self.t, te, Q)
                self.t, self.x = float(te), np.array(sol.y_events[i][0], float)
                if i == 1:
                    self.ended = "fall"
                    break
                self._touchdown()
                strikes.append(self.t)
                continue
            self._work(sol.sol, self.t, float(sol.t[-1]), Q)
            self.t, self.x = float(sol.t[-1]), np.array(sol.y[:, -1], float)
        return strikes

    def _touchdown(self) -> None:
        """Heel strike: the scene's push-off impulse at the trailing foot, then the stance
        leg switches to the leg that touched down."""
        acts = self.acts
        trailing = self.stance
        if acts is not None and getattr(acts.spec, "push_off", None) is not None:
            from walkerlab.integrate.contact_powered import impulse_jump

            P = acts.impulse(self.x)
            if P > 0:
                self.x, work = impulse_jump(self.walker, self.x, trailing, P)
                self.ledger["push_off_work"] += work
        self.stance = 1 - trailing
        self.t_step = self.t
        self.steps += 1
