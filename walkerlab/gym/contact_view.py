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
:attr:`~walkerlab.models.contact.model.ContactWalker.heights1`), all but the starting stance
foot's patch (the walker starts on the scene's own ground, not inside a raised patch).  The
patches are laid out for :data:`LAYOUT_STEPS` steps at a time and laid out again for twice
as many as the walk nears their end (memory and each contact evaluation's patch search stay
proportional to the walk so far, not to ``max_episode_steps``); a patch's height depends on
the seed and its place only, so the ground a walker meets does not depend on when it was laid.

A third terminal event ends the episode as ``launch``: the hip more than
:data:`LAUNCH_HIP_FACTOR` leg lengths above the ground line (plus the highest ground laid out).
No walker with a foot on the ground gets there; a foot that meets a raised patch's side below
its top does (the contact law measures the penetration below the patch's top, so the foot is
pushed out at once as from that depth: the walker is thrown into the air).

A control period whose heel-strike event cannot be located (``solve_ivp``'s root bracketing
fails: the swing foot's touchdown test jumps where a foot meets a patch's side below its top)
ends the episode as ``solver_failure``, with the solver's message in :attr:`ContactView.failure`.
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
#: the hip this many leg lengths above the ground line (plus the highest ground laid out)
#: ends the episode as ``launch`` (a walking hip is at most one leg length above its foot)
LAUNCH_HIP_FACTOR = 1.5
#: steps the patches are laid out for at a time (the layout doubles as the walk nears its end)
LAYOUT_STEPS = 32
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
        Steps the episode may take (the patches are first laid out for at most
        :data:`LAYOUT_STEPS` of them, then for more as the walk goes).

    Raises
    ------
    ValueError
        A scene actuation the view does not carry (an ankle push-off), or an action link
        with no floating coordinate (a torso that bisects the legs), one line.
    """

    def __init__(self, setup, links, x_gait, n_steps: int):
        acts = setup.actuators
        if acts is not None and getattr(acts, "ankle", None) is not None:
            raise ValueError("walkerlab.gym: the contact view does not carry the scene's "
                             "ankle push-off yet; use view='rigid'")
        self._setup, self._x_gait = setup, np.asarray(x_gait, float)
        self._first_layout = max(1, min(int(n_steps), LAYOUT_STEPS))
        self._roughness, self._seed = 0.0, 0
        self.x_start, self.limits, self.step_length = self._lay_out(self._first_layout)
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

    def _lay_out(self, n_steps: int):
        """Patches for ``n_steps`` steps (:func:`walkerlab.analysis.contact.sim.scene_start`),
        the episode's roughness on them; returns the scene's start, limits, step length."""
        from walkerlab.analysis.contact.sim import scene_start

        walker, x0, limits, step_length = scene_start(self._setup, self._x_gait,
                                                      n_steps // 2 + 1)
        self._laid = n_steps
        self._lanes = (walker.lane1.copy(), walker.lane2.copy())
        # the scene's own patch heights (stairs, footholds; None on the slope): roughness adds
        self._heights = (walker.heights1, walker.heights2)
        self._scene_walker = walker
        self._roughen()
        w = self.walker
        ground = [0.0] + [float(np.max(h)) for h in (w.heights1, w.heights2)
                          if h is not None and np.size(h)]
        if w.ground_line is not None:
            ground.append(float(np.max(w.ground_line[:, 0] * np.sin(w.phi)
                                       + w.ground_line[:, 1] * np.cos(w.phi))))
        self._launch_height = LAUNCH_HIP_FACTOR * float(w.L) + max(ground)
        return x0, limits, step_length

    def _roughen(self) -> None:
        w, base, r = self._scene_walker, self._heights, self._roughness
        if r <= 0.0:
            self.walker = w
            return
        h = []
        for k, (lane, b) in enumerate(zip(self._lanes, base)):
            d = np.random.default_rng([self._seed, k]).uniform(-r, r, lane.size)
            if k == 1:
                d[0] = 0.0  # leg2's first patch: the starting stance foot's ground
            h.append(d if b is None else np.asarray(b, float) + d)
        self.walker = dataclasses.replace(w, heights1=h[0], heights2=h[1])

    def set_terrain(self, roughness_m: float, seed: int) -> None:
        """The scene's patch heights (its stairs' or footholds'; none on the slope) plus
        heights drawn from ``[-roughness_m, roughness_m]`` [m] by ``seed`` (0: the scene's
        ground as it is), the starting stance foot's patch (leg2's first) left as the scene
        has it; the patches laid out afresh for :data:`LAYOUT_STEPS` steps."""
        self._roughness, self._seed = float(roughness_m), int(seed)
        self._lay_out(self._first_layout)

    def reset(self, x0: np.ndarray | None = None) -> None:
        """Start at the contact state ``x0`` (N,) (default: the scene's start), leg2 in
        stance, at t = 0."""
        self.t = 0.0
        self.t_step = 0.0
        self.stance = 1
        self.x = np.array(self.x_start if x0 is None else x0, dtype=float)
        self.ended = ""
        self.failure = ""
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

        def launch(t, y):
            return self._launch_height - float(w.hip_height(y[:n])[0])
        launch.terminal, launch.direction = True, -1
        return [touch, fall, launch]

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
            when the episode ended inside it (``fall``, ``launch``, ``solver_failure``).
        """
        from scipy.integrate import solve_ivp

        strikes: list[float] = []
        while self.t < t_end and not self.ended:
            f, Q = self._rhs(u)
            jac = self.walker.jac if self.method in ("Radau", "BDF", "LSODA") else None
            kw = {"jac": jac} if jac is not None else {}
            try:
                sol = solve_ivp(f, (self.t, t_end), self.x, method=self.method,
                                rtol=self.rtol, atol=self.atol, events=self._events(),
                                dense_output=True, **kw)
            except ValueError as err:  # an event's root not bracketed (module docstring)
                self.ended, self.failure = "solver_failure", str(err)
                break
            if sol.status == -1 or not np.all(np.isfinite(sol.y[:, -1])):
                self.ended, self.failure = "solver_failure", str(sol.message)
                break
            fired = [(te[0], i) for i, te in enumerate(sol.t_events) if len(te)]
            if fired:
                te, i = min(fired)
                self._work(sol.sol, self.t, te, Q)
                self.t, self.x = float(te), np.array(sol.y_events[i][0], float)
                if i > 0:
                    self.ended = "fall" if i == 1 else "launch"
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
        if self.steps + 4 >= self._laid:  # the walk nears the patches' end: lay out more
            self._lay_out(2 * self._laid)
