"""The rigid view of the Gymnasium environment: the scene's hybrid walker advanced one
control period at a time, resumable inside a step.

Each control period integrates the walker's present phase with the library's integrator
(:func:`walkerlab.integrate.rigid_phase.integrate_phase`: ``solve_ivp`` or CyRK, the scene's
``solver`` section), its guards as terminal events; a guard inside the period is handled as
:func:`walkerlab.integrate.rigid.integrate_step` handles it (a knee strike's reset and the
next phase; a heel strike's reset map - with the scene's push-off - the roles swapped and
the next step begun; a fall ends the episode) and the integration goes on to the period's
end from the event's state.  So the heel strike's time is the event's own, located by the
integrator inside the period (not rounded to the control grid), and with a zero action the
walk is the scene's own walk (the period boundaries only restart the integrator).

The ground is stepped as ``walkerlab simulate`` steps it
(:func:`walkerlab.analysis.gait.rigid_run.walk_scene`): each step's walker is
:func:`walkerlab.integrate.rigid.walker_of_step`'s (footholds of several heights or slopes:
the step's landing in the walker's cycle), or on a height profile the walker landing on the
segment under the swing foot (:class:`walkerlab.analysis.gait.profile_walk.ProfileGround`);
a heel strike off that segment walks the step again from its start on the segment the
foot landed on, each of its control periods with the action it had (the step's start and
periods are kept), so the landing is the one ``simulate`` finds.  A finite foothold list
or a landing past the profile's end ends the episode (``ground_end``).  On a profile the
step's swing-foot path is checked against it at the heel strike, as ``simulate`` checks it
(:func:`walkerlab.analysis.gait.profile_walk.swing_clearance`): a swing foot that went into
the profile ends the episode as a ``trip`` there (the heel strike not made; :attr:`RigidView.
trip` says when and where the foot met the profile).

The compiled control step (``compiled``, the default): a phase of a step walker without
torque laws of its own (the passive walker, or one powered by a push-off alone) runs its
flow with the action's torques compiled in (:func:`walkerlab.models.hybrid.actuated.
compiled_with`: an :class:`walkerlab.models.compiled_flows.ActuatedFlow` whose laws are constant
torques, the action written into its law block each period), integrated by DOP853 at the
scene solver's tolerances in compiled code: no Python per right-hand-side call.  It is the
native vector environment's step of one walker (:meth:`RigidView.advance`:
:func:`walkerlab.gym.rigid_rows.advance_rows`, the kernel
:func:`walkerlab.integrate.rows_dop853.period_rows` with a batch of one, guards as the
cfunc's extra outputs located on each step's dense output), so one environment and the
vector environment with one walker are the same numbers bit for bit; CyRK's DOP853
(:mod:`walkerlab.integrate._compiled`, the same steps to round-off) runs only a profile's
compiled pieces (their dense output kept for the swing foot's check), a compiled phase
without guard outputs, and the dense output the kernel does not keep, made again when read
(a failed step's piece; the ledger of joints not affine in the coordinates).  Its
work ledger is the held torques' exact work ``sum_k u_k Delta delta_k`` where the action's
power keeps one sign over the period's piece (else the Gauss-Legendre nodes below).  Other
phases (flat feet's modes, a walker with torque laws) run the scene's solver on Python
flows, as ``compiled=False`` runs every phase.

The action adds ``M^-1 B u`` to every phase's flow (:class:`walkerlab.gym.action.
ActionTorques`); a zero action adds nothing (the scene's flows are called as they are).

Energy ledger (the episode's sums, [J]): ``action_work_positive``, ``action_work_negative``
(the action torques' power ``sum_k u_k ddelta_k`` integrated by 4-point Gauss-Legendre over
each integrated piece), ``scene_torque_work`` (the scene's own torque laws), ``push_off_work``
(kinetic energy the push-off adds, Kuo 2002), ``heel_strike_loss`` (kinetic energy change of
the heel strike's collision, <= 0).
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from walkerlab.codegen.torque_law import HEAD
from walkerlab.integrate.rigid import MIN_STEP_TIME_S, walker_of_step
from walkerlab.integrate.rigid_phase import integrate_phase
from walkerlab.integrate.solver import Solver, available_backends

from .action import GL_W, GL_X, action_torques, flat_action_walker

__all__ = ["LEDGER_TERMS", "RigidView"]

#: most lanes a view keeps (:meth:`RigidView.lane_at`)
LANES_KEPT = 64

#: the ledger's terms (:mod:`walkerlab.gym.rigid_view` docstring) [J]
LEDGER_TERMS = ("action_work_positive", "action_work_negative", "scene_torque_work",
                "push_off_work", "heel_strike_loss")

#: the compiled control step's integrator: CyRK's DOP853 (Hairer's 8(5,3) pair, the stepping
#: in C++) on the numba-compiled flow, at the scene solver's tolerances
COMPILED_METHOD = "DOP853"
#: the first actuator's constant torque in a law block (:mod:`walkerlab.codegen.torque_law`:
#: ``b[3 + HEAD i + 1]``, ``constant_n_m``; actuator ``i``'s ``HEAD i`` further on)
_CONSTANT_0 = 3 + 1


_ADVANCE_ROWS = None


def _advance_rows():
    """:func:`walkerlab.gym.rigid_rows.advance_rows`, imported on first use (the kernels'
    module it reads is not needed to build a view), kept."""
    global _ADVANCE_ROWS
    from .rigid_rows import advance_rows  # light: read on the first step

    _ADVANCE_ROWS = advance_rows
    return advance_rows


class RigidView:
    """The scene's rigid hybrid walker stepped by control periods.

    Parameters
    ----------
    model : walkerlab.models.hybrid.HybridWalker
        The scene's walker with its own actuators
        (:attr:`walkerlab.rigid_walker.SceneWalker.model`).
    solver : walkerlab.integrate.solver.Solver
    data : walkerlab.walker.description.WalkerData
        The walker's description (the action's actuators are built from it).
    joints : list of str
        The action's joints (:func:`walkerlab.gym.action.action_joints`).
    max_step_time : float
        A step longer than this [s] ends the episode (the walker stalled).
    ground : walkerlab.analysis.gait.profile_walk.ProfileGround, optional
        A height profile's steps (:func:`walkerlab.analysis.gait.rigid_run.profile_ground`);
        None: the model's own ground (slope, stairs, footholds).
    actuation : walkerlab.config.actuation.Actuation, optional
        The scene's actuation (a flat foot's twins carry its laws).
    compiled : bool
        Run the compiled control step where a phase has one (module docstring); False:
        the scene's ``solver`` on Python flows throughout.

    Raises
    ------
    ValueError
        A walker the action cannot drive (:func:`walkerlab.gym.action.action_torques`).
    """

    def __init__(self, model, solver, data, joints, max_step_time: float, ground=None,
                 actuation=None, compiled: bool = True):
        self.model = model
        self.ground = ground
        self.solver = solver
        backend = solver.resolved_backend()
        # the scene's compiled flows carry the scene's laws only: the action's Python flow,
        # unless the compiled control step runs (below)
        self.backend = "cyrk" if backend == "cyrk_compiled" else backend
        #: the compiled control step's integrator (:data:`COMPILED_METHOD` at the scene's
        #: tolerances, flows compiled with the action in them), or None: the scene's solver
        self.compiled_solver = (Solver(COMPILED_METHOD, solver.rtol, solver.atol,
                                       solver.max_step_s, "cyrk_compiled")
                                if compiled and "cyrk_compiled" in available_backends()
                                else None)
        self._compiled: dict = {}
        #: :meth:`next_piece`'s memo of the present walker, phase and leg (:meth:`_lane_of`)
        self._lane: tuple | None = None
        self._lanes: dict = {}  # every lane made, by walker, phase and leg (lane_at)
        #: ``(compiled phase, torques' bytes)``: what its law block holds, as last written
        self._held: tuple = (None, b"")
        #: what a compiled phase shares with other walkers' in a batched step
        #: (:mod:`walkerlab.gym.rigid_rows`), by the phase's id (it lives in ``_compiled``),
        #: and the action's joint map by its actuators' (they live in ``acts``)
        self.row_keys: dict = {}
        self._joints_at: tuple = (b"", None, None, None)  # (state bytes, delta, ddelta, acts)
        n = model.n_coordinates
        self.n = n
        # the action's actuators of each stance leg (legs that differ: the leg's own
        # numbers, as its step's walker; a profile's walkers are all the first leg's)
        own = action_torques(data, n, joints)
        self.acts = {leg: own for leg in model.legs}
        if model.mirror is not None and ground is None:
            self.acts[model.legs[0]] = action_torques(data.mirror, n, joints)
        self.max_step_time = float(max_step_time)
        self.state_names = list(model.state_names())
        # feet whose stance modes each have a mass matrix of their own (a flat foot's: heel
        # or toe pinned, the foot locked flat): the action acts through a twin of each
        # step's walker whose phases have M_mode^-1 B u in each flow and in its guards'
        # ground forces (flat_action_walker), built on first use; the other kinds' flows
        # gain the generic M^-1 B u
        self._twin_of = flat_action_walker if data.structure.kind.feet_have_modes else None
        self._twins: dict = {}
        self._data, self._joints, self._actuation = data, list(joints), actuation
        if self._twin_of is not None:
            self.compiled_solver = None  # a mode's own M^-1 B u: the twins' Python flows
        if self._twin_of is not None:  # the first step's now (a bad walker says so here)
            self._twins[id(model)] = self._twin_of(model, replace(data, mirror_params=None),
                                                   self._joints, actuation)

    def _step_data(self, w):
        """The walker data of the step walker ``w``: the scene's, or its mirror's for a
        mirrored leg (legs that differ: the step walker itself, or on a ground that
        differs from step to step, the present stance's, as :attr:`acts` reads it)."""
        mirror = self._data.mirror
        if w is self.model or mirror is None:
            return self._data
        if w is self.model.mirror:
            return mirror
        return mirror if self.leg == self.model.legs[0] else self._data

    def _twin(self, w):
        """``(walker, actuators)``: the twin of the step's walker ``w`` with the action in
        its modes (:func:`walkerlab.gym.action.flat_action_walker`), its actuators' clock
        at the step's start."""
        key = id(w)
        if key not in self._twins:
            d = self._step_data(w)
            self._twins[key] = self._twin_of(w, replace(d, mirror_params=None),
                                             self._joints, self._actuation)
        tw, tacts = self._twins[key]
        tacts.t_origin = self.t_step
        return tw, tacts

    # ------------------------------------------------------------------ state
    def reset(self, x0: np.ndarray) -> None:
        """Start at the post-impact state ``x0`` (2n,), ``leg1`` swinging, at t = 0."""
        self.t = 0.0
        self.t_step = 0.0
        self.leg = self.model.legs[-1]
        self.x = np.array(x0, dtype=float)
        self.foot = (np.zeros(np.size(self.model.points(self.x)["stance_foot"]))  # its
                     if self.ground is None else self.ground.start.copy())  # world's axes
        self.advance_x = 0.0  # the last step's advance along x [m] (a profile's segment)
        self.ended = ""
        #: ``(t [s], x [m], y [m])`` where the swing foot met a profile (a ``trip``), or None
        self.trip = None
        self.ledger = dict.fromkeys(LEDGER_TERMS, 0.0)
        self.steps = 0
        self._period = (np.zeros(0), 0.0)
        self._begin_step()

    def _begin_step(self) -> None:
        """The step's walker (:func:`walkerlab.integrate.rigid.walker_of_step`, or on a
        profile the walker landing on the segment it is first tried on), entered; the
        step's start kept (a profile's step is walked again from it on another segment)."""
        self._choose_walker()
        self._start_step()

    def _choose_walker(self) -> None:
        if self.ground is None:
            self.walker = walker_of_step(self.model, self.steps, self.leg)
        else:
            self.j = self.ground.first_segment(self.foot, self.advance_x)
            self.tried: set = set()
            self.walker = self.ground.walker(self.j, self.foot)

    def _start_step(self) -> None:
        self._step_start = (self.t, self.x.copy(), dict(self.ledger))
        self._log = [self._period]  # this step's periods (kept on a profile: _again)
        self._pieces: list = []  # on a profile: the step's dense output, piece by piece
        self._enter()

    def _enter(self) -> None:
        w = self.walker
        if w.actuators is not None:
            w.actuators.begin_step(self.t)
        self.k = 0
        u = self._period[0]
        if self._twin_of is not None and np.any(u):  # the trailing toe's force with the
            w, acts = self._twin(w)                   # action's torque in it
            acts.u = np.asarray(u, dtype=float)
        if w.step_entry is not None:
            x_new, name = w.step_entry(self.x)
            self.x = np.asarray(x_new, float)
            self.k = 0 if name is None else [p.name for p in w.phases].index(name)

    def hip_x(self) -> float:
        """World position of the hip along x (horizontal, downhill) [m]."""
        w = self.walker
        if w.hip_x is None:
            return float(self.foot[0] + w.points(self.x)["hip"][0])
        return float(self.foot[0] + w.hip_x(self.x))

    def points(self) -> dict:
        """World positions [m] of the walker's named points, by role (x, y; 3D: z)."""
        return {k: self.foot + np.asarray(v, float)
                for k, v in self.walker.points(self.x).items()}

    # ------------------------------------------------------------------ stepping
    def _compiled_phase(self, w, phase, acts):
        """``phase`` with its flow compiled with the action's torques in it (an
        :class:`walkerlab.models.compiled_flows.ActuatedFlow` whose laws are the action's
        actuators, each a constant torque: :attr:`ActionTorques.u` written into the law
        block before each period), or None where the compiled step does not run: a step
        walker with torque laws of its own (their Python flows), a phase without a compiled
        flow, or actuators acting on a massless limit's rows.  Built once per phase."""
        key = (id(phase), id(acts))
        if key in self._compiled:
            return self._compiled[key]
        from walkerlab.models.compiled_flows import CompiledFlow
        from walkerlab.models.hybrid.actuated import compiled_with

        own, comp = w.actuators, phase.compiled
        passive = own is None or (not own.spec.torques and getattr(
            own.spec, "virtual_constraints", None) is None)
        # the walker's own phase (no ground of a step in its guards) or a compiled phase
        # (its guards' outputs and offsets carried by the compiled flow)
        own_walker = w is self.model or (self.model.mirror is not None
                                         and w is self.model.mirror)
        data = self._step_data(w) if own_walker else None
        if comp is not None and type(comp) is CompiledFlow:
            data = replace(self._step_data(w), params=comp.params, mirror_params=None)
        flow = None
        if passive and data is not None and (comp is None or type(comp) is CompiledFlow):
            flow = compiled_with(phase, data, acts)  # (the phase's own guards, offsets)
            if flow is not None and comp is not None:
                flow = replace(flow, first_chunk_steps=comp.first_chunk_steps,
                               chunk_rtol=comp.chunk_rtol, _memo={})
        # (the phase itself kept with it: its id stays its own while the entry lives)
        out = None if flow is None else (replace(phase, compiled=flow), flow.laws, phase)
        self._compiled[key] = out
        return out

    def _flow(self, phase, acts, act_on: bool):
        if not act_on:
            return phase.flow
        n, flow, cons = self.n, phase.flow, phase.constraint

        def f(t, x):
            out = np.array(flow(t, x), dtype=float)
            out[n:] += acts.added_acceleration(t, x, cons)
            return out
        return f

    def _work(self, dense, ta: float, tb: float, acts, act_on: bool) -> None:
        """Add the action's and the scene's torque work over ``[ta, tb]`` to the ledger."""
        scene = self.walker.actuators
        scene_on = scene is not None and bool(scene.spec.torques)
        if tb <= ta or not (act_on or scene_on):
            return
        ts = 0.5 * (tb - ta) * GL_X + 0.5 * (ta + tb)
        X = np.atleast_2d(dense(ts))[:2 * self.n]
        h = 0.5 * (tb - ta)
        if act_on and not acts.first and acts.affine is not None:  # the nodes' power at once
            for w, p in zip(GL_W, acts.rate_power(X)):
                key = "action_work_positive" if p > 0 else "action_work_negative"
                self.ledger[key] += h * w * p
            act_on = False
        for j, tj in enumerate(ts):
            xj = X[:, j]
            if act_on:
                p = acts.power(tj, xj)
                key = "action_work_positive" if p > 0 else "action_work_negative"
                self.ledger[key] += h * GL_W[j] * p
            if scene_on:
                self.ledger["scene_torque_work"] += h * GL_W[j] * scene.power(tj, xj)

    def _held_work(self, run, acts, act_on: bool) -> None:
        """The compiled step's ledger over ``[self.t, run.t_last]`` (the action alone: the
        step's walker has no torque laws of its own there): where the action's power has
        one sign at both ends, the exact work of the held torques
        (:meth:`walkerlab.gym.action.ActionTorques.held_work`, no dense output needed) on
        that sign's side; else :meth:`_work`'s Gauss-Legendre nodes on the dense output."""
        if not act_on or run.t_last <= self.t or acts.limit:
            return
        xb = np.asarray(run.y_last[:2 * self.n], float)
        key = self.x.tobytes()  # the last period's end state's joint angles, kept
        da, dda = (self._joints_at[1:3] if self._joints_at[0] == key and
                   self._joints_at[3] is acts else acts.joint_state(self.x))
        db, ddb = acts.joint_state(xb)
        self._joints_at = (xb.tobytes(), db, ddb, acts)
        pa, pb = float(acts.u @ dda), float(acts.u @ ddb)  # the power at both ends [W]
        if pa * pb > 0.0:
            key = "action_work_positive" if pa > 0 else "action_work_negative"
            self.ledger[key] += float(acts.u @ (db - da))
        else:
            self._work(run.dense, self.t, run.t_last, acts, act_on)

    def advance(self, u: np.ndarray, t_end: float) -> list[float]:
        """Integrate to ``t_end`` [s] with the action torques ``u`` (k,) [N m] held: the
        native vector environment's step of one walker
        (:func:`walkerlab.gym.rigid_rows.advance_rows`), so the compiled control step's
        pieces run on its kernel (``rows_dop853``) as a batch of one, and one environment
        is the vector environment with one walker, bit for bit.

        Returns
        -------
        list of float
            The heel-strike times inside the period [s] (the events' own times).
            :attr:`ended` is set when the episode ended inside it (``fall``, ``stall``,
            ``ground_end``, ``solver_failure``).
        """
        return (_ADVANCE_ROWS or _advance_rows())([self], (u,), (t_end,))[0]

    def open_period(self, u: np.ndarray, t_end: float) -> None:
        """A control period to ``t_end`` [s] with the torques ``u`` (k,) [N m] begins: kept
        with the step's periods on a height profile (replayed by :meth:`_again`)."""
        self._period = (np.asarray(u, dtype=float), float(t_end))
        if self.ground is not None:  # (read only where the step is walked again)
            self._log.append(self._period)

    def _again(self, j: int) -> list[float]:
        """Walk the present step again from its start on a profile's segment ``j`` (the
        last heel strike landed off the segment it was walked on), its control periods'
        actions as they were, up to the present period's start; returns the heel-strike
        times met on the way [s]."""
        period, log = self._period, self._log  # log[0]: the period the step began in
        self.t, x, ledger = self._step_start
        self.x, self.ledger = x.copy(), dict(ledger)
        self.j, self.walker = j, self.ground.walker(j, self.foot)
        self._log = [log[0]]
        self._pieces = []
        self._enter()
        strikes: list[float] = []
        if len(log) == 1:  # the step began in the present period: it goes on from there
            return strikes
        for i, (u, t_end) in enumerate(log[:-1]):
            if self.ended:
                break
            if i == 0:  # from the step's start to the end of the period it began in
                self._period = log[0]
                strikes += self._run(u, t_end)
            else:
                strikes += self.advance(u, t_end)
        self._period = period
        self._log.append(period)
        return strikes

    def _run(self, u: np.ndarray, t_end: float) -> list[float]:
        strikes: list[float] = []
        while self.t < t_end and not self.ended:
            piece = self.next_piece(u, t_end)
            if piece is None:
                break
            run, phase = self.integrate_piece(piece)
            strikes += self.absorb(piece, run, phase)
        return strikes

    def next_piece(self, u: np.ndarray, t_end: float):
        """The period's next piece to integrate, from the present phase with the action
        ``u`` (k,) [N m] held: ``(walker, actuators, action on, phase, t_stop [s], fast)``,
        ``fast`` the compiled phase (:meth:`_compiled_phase`, its law block holding ``u``)
        or None; None when the phase's fall guard is already violated (:attr:`ended` set)."""
        w = self.walker
        lane = self._lane
        if lane is None or lane[0] is not w or lane[1] != self.k or lane[2] != self.leg:
            lane = self._lane = self.lane_at(w)
        _, _, _, acts, phase, falls, fast = lane
        u = acts.u = np.asarray(u, dtype=float)
        act_on = any(u.tolist())
        for g in falls:  # a fall guard already violated as the phase begins
            if g.direction * float(g.function(self.t, self.x)) > 0:
                self.ended = "fall"
        if self.ended:
            return None
        t_stop = self.t_step + self.max_step_time
        if not t_stop < t_end:  # (min(t_end, t_stop): t_end unless t_stop is below it)
            t_stop = t_end
        if fast is not None:  # the compiled control step: the action's torques held in
            # the law block (each actuator's constant), written where they are not the
            # very numbers it holds (this phase's last ones, bit for bit: -0.0 is written)
            held, bits = self._held, u.tobytes()
            if held[0] is not fast or held[1] != bits:
                fast[1][_CONSTANT_0:_CONSTANT_0 + HEAD * u.size:HEAD] = u
                self._held = (fast, bits)
        return w, acts, act_on, phase, t_stop, fast

    def lane_at(self, w) -> tuple:
        """:meth:`_lane_of` the step walker ``w`` at the present phase and stance leg, made
        once (kept by the walker's id, phase and leg, the walker with it: its id stays its
        own; at most :data:`LANES_KEPT`, cleared when full: a profile's walkers are many)."""
        key = (id(w), self.k, self.leg)
        lane = self._lanes.get(key)
        if lane is None:
            if len(self._lanes) >= LANES_KEPT:
                self._lanes.clear()
            lane = self._lanes[key] = self._lane_of(w)
        return lane

    def _lane_of(self, w) -> tuple:
        """What :meth:`next_piece` reads of the present step walker ``w``, phase and
        stance leg (kept while they stay: :attr:`_lane`): ``(w, k, leg, actuators, phase,
        its fall guards checked at entry, the compiled phase or None)``."""
        acts = self.acts[self.leg]
        phase = w.phases[self.k]
        falls = tuple(g for g in phase.guards if g.at_entry and g.outcome == "fall")
        fast = (self._compiled_phase(w, phase, acts) if self.compiled_solver is not None
                else None)
        return (w, self.k, self.leg, acts, phase, falls, fast)

    def integrate_piece(self, piece):
        """``(run, phase)``: :meth:`next_piece`'s piece integrated from the present state
        (the compiled step, or the scene's solver on Python flows), and the phase that ran
        (a flat foot's twin's under an action)."""
        w, acts, act_on, phase, t_stop, fast = piece
        n = self.n
        if fast is not None:
            return integrate_phase(fast[0], self.t, self.x, None, t_stop, 2 * n,
                                   self.compiled_solver, "cyrk_compiled", None, None,
                                   False), phase
        if self._twin_of is not None and act_on:  # the mode's own M^-1 B u: the twin's
            tw, tacts = self._twin(w)
            tacts.u = acts.u
            phase = tw.phases[self.k]
            rhs = phase.flow
        else:
            rhs = self._flow(phase, acts, act_on)
        jac = phase.jacobian if phase.jacobian is not None else w.variational
        return integrate_phase(phase, self.t, self.x, None, t_stop, 2 * n, self.solver,
                               self.backend, rhs, jac, False), phase

    def absorb(self, piece, run, phase) -> list[float]:
        """Take the integrated ``run`` of :meth:`next_piece`'s ``piece`` (``phase``: the
        one that ran): the ledger, the state, and the guard that ended it (a knee strike,
        a heel strike with the next step begun, a fall, a stall); returns the heel-strike
        times met [s] (a profile's step walked again included)."""
        w, acts, act_on, _, _, fast = piece
        n = self.n
        strikes: list[float] = []
        if fast is not None:
            self._held_work(run, acts, act_on)
        else:
            self._work(run.dense, self.t, run.t_last, acts, act_on)
        if self.ground is not None:
            self._pieces.append((phase, run.dense, (self.t, run.t_last)))
        x = np.array(run.y_last[:2 * n], float)
        finite = not run.failed and all(map(math.isfinite, x.tolist()))
        if run.event is None or not finite:
            self.settle(run.t_last, x, finite)
            return strikes
        self.t, self.x = run.t_last, x
        # the walker's own guard (a twin's are the same, in order; the heel strike's
        # reset, a push-off's, is the scene walker's)
        guard = w.phases[self.k].guards[run.event]
        if guard.outcome == "fall":
            self.ended = "fall"
        elif guard.outcome == "next_phase":
            target = guard.next_phase
            self.k = (self.k + 1 if target is None
                      else [p.name for p in w.phases].index(target))
            if guard.reset is not None:
                self.x = np.asarray(guard.reset(self.x), float)
            if self.k >= len(w.phases):
                self.ended = "fall"
        elif self.t - self.t_step <= MIN_STEP_TIME_S:
            self.ended = "stall"  # a heel strike at the step's start: no step
        else:
            if self.ground is not None:  # a profile: the step's landing segment
                land = self.foot[0] + float(w.points(self.x)["swing_foot"][0])
                j2 = self.ground.retry(self.j, land, self.tried)
                if j2 is not None:
                    return self._again(j2)
                on = self.ground.goes_on(self.j, land)
                self.trip = self._swing_trip(w)
                if self.trip is not None:
                    self.ended = "trip"
                    return strikes
            self._heel_strike(guard)
            strikes.append(self.t)
            ends = self.model.ground_steps
            if (self.ground is not None and not on) or (
                    ends is not None and self.steps >= ends):
                self.ended = "ground_end"  # the walk left the ground's end
        return strikes

    def settle(self, t_last: float, x: np.ndarray, finite: bool) -> None:
        """A piece that ended without a guard crossing (:meth:`absorb`): the walker at
        ``(t_last [s], x (2n,))`` (``x`` kept, not copied), ``finite`` False for a failed
        integration or a state not finite (the episode ends: ``solver_failure``); a step
        that has lasted ``max_step_time`` ends it as a ``stall``."""
        self.t, self.x = t_last, x
        if not finite:
            self.ended = "solver_failure"
        elif self.t >= self.t_step + self.max_step_time:
            self.ended = "stall"

    def _swing_trip(self, w):
        """Where the swing foot of the step just ended met the profile (``(t, x, y)``), or
        None (:func:`walkerlab.analysis.gait.profile_walk.swing_clearance` on the step's
        pieces of dense output, as ``simulate`` checks it)."""
        from walkerlab.analysis.gait.profile_walk import swing_clearance  # light
        from walkerlab.integrate.rigid import Segment

        t0, x0, _ = self._step_start
        seg = Segment(self.steps, self.leg, t0, self.t, x0, self.x.copy(), None, "", "", {},
                      0, "", pieces=list(self._pieces))
        return swing_clearance(w, seg, self.foot, self.ground.P, self.j).trip

    def _heel_strike(self, guard) -> None:
        """The reset map (push-off and collision, roles swapped), the next step begun."""
        w = self.walker
        x_minus = self.x
        ke_minus = float(np.real(w.energies(x_minus)[0]))
        push = 0.0
        if guard.reset is not None:
            x_plus = guard.reset(x_minus)
        elif w.actuators is not None and w.actuators.spec.push_off is not None:
            tr = w.actuators.transition(x_minus)
            x_plus = tr["x_plus"]
            push = float(tr["ke_push_off"] - tr["ke_minus"])
        else:
            x_plus = w.reset(x_minus)
        step = np.asarray(w.points(x_minus)["swing_foot"], float)
        self.foot = self.foot + step
        self.advance_x = float(step[0])
        self.leg = [g for g in self.model.legs if g != self.leg][0]
        self.x = np.asarray(x_plus, float)
        self.steps += 1
        self._choose_walker()  # the next step's
        ke_plus = float(np.real(self.walker.energies(self.x)[0]))
        self.ledger["push_off_work"] += push
        self.ledger["heel_strike_loss"] += ke_plus - ke_minus - push
        self.t_step = self.t
        self._start_step()
