"""The compliant-contact walker's mid-stance step map: its Poincaré section, section
coordinates and the footfall-relative terrain it integrates on.

Poincaré section
----------------
Mid-stance single support: the legs' proximal links are aligned (straight legs: the legs;
kneed legs: the thighs), ``theta_swing - theta_stance`` of those links crosses zero upward
(the links are found by name, ``walker.leg_angle_states(leg)[0]``).  In the compliant
model a heel strike is not an instant but a double-support phase
(both feet loaded for ~10 ms), so a touchdown section would cut through an impact transient;
at mid-stance only the stance foot is loaded and the state is smooth.

Section coordinates (all states - section constraint - translation along the slope, by
name, :func:`section_coordinates`); straight legs (6 = 8 - 2)::

    z = [theta_stance, dtheta_swing, dtheta_stance,
         delta_stance, v_t_stance, ddelta_stance]

kneed legs (10 = 12 - 2): ``theta_stance_thigh, theta_stance_shank, theta_swing_shank``, the
four link rates (swing leg first), then the three stance-foot coordinates.  Straight legs
in 3D (15 = 18 - 1 - 2, the translations along the slope and across it dropped)::

    z = [theta_stance, heading, phi2, phi_pelvis, phi1,
         dtheta_swing, dtheta_stance, dheading, dphi2, dphi_pelvis, dphi1,
         delta_stance, v_t_stance, v_lat_stance, ddelta_stance]

``theta_swing = theta_stance`` on the section [rad]; rates [rad/s]; ``delta_stance`` is the
stance foot's penetration [m] (along -n), ``v_t_stance`` its down-slope slip velocity [m/s],
``ddelta_stance`` its penetration rate [m/s].  The along-slope position of the stance foot is
dropped (the dynamics are invariant under translation along the slope, see *Terrain*).

Step map
--------
``P(z)``: build the full state with the stance foot at along-slope ``s = 0`` (leg2 = stance,
leg1 = swing: the legs are identical, so one orientation suffices), integrate until the next
upward zero of ``theta2 - theta1`` (proximal links; mid-stance of the other leg), swap the leg
roles and express the state relative to the new stance foot (leg1).  A walker whose two
steps are not the same state with the roles swapped maps a **stride**
(:attr:`~walkerlab.models.contact.model.ContactWalker.steps_per_map` 2): a walker in 3D,
whose steps mirror each other across the sagittal plane and whose floating base is leg2's
foot, and legs that differ; the map then runs on through leg1's mid-stance to leg2's next
(each footfall on a patch of its own, leg2's two a stride apart), its period and step
length are the stride's means, and its Floquet multipliers are the stride's (a symmetric
gait's reflected step map's squared, as the rigid view's).  The search's map runs
on the compiled integrator (``"cyrk_bdf"``: CyRK's BDF over the generated right-hand side on
a 2 ms grid, :func:`walkerlab.integrate.contact_grid.contact_grid`; no Python per RHS call),
the crossing bracketed on the samples and located by brentq on short compiled runs from the
sample before it; ``"odeint"`` does the same through scipy's odeint, a ``solve_ivp`` method
locates it as an event (:func:`walkerlab.integrate.events.run_to_event`).  A powered walker
(``actuators``: straight legs, point feet) passes its heel strike inside the step: the
push-off pulse along the trailing leg, ending at the swing foot's predicted touchdown on its
patch ahead, on the powered contact integrator (:mod:`walkerlab.integrate.contact_powered`),
the touchdown and the roles swap; with
push-off alone the flow between is passive and compiled, with hip torques the whole step
runs on the powered integrator (with ``"cyrk_bdf"`` its compiled segments: no Python per
right-hand side either).  Outputs besides ``P(z)``: the step period ``T`` [s] and the
step length (along-slope displacement of the stance foot from one mid-stance to the next)
[m].

Terrain (the choice made here, and why)
---------------------------------------
Kneed walkers keep their scene's *continuous ground*: at the section the swing knee is
flexed (~0.5 rad on ``configs/kneed.yaml``) and the swing foot ~5 cm above the ground.
For straight legs, *continuous ground* is not usable at this section: with rigid legs of
equal length the swing foot is exactly at stance-foot depth when the legs are aligned, i.e.
it penetrates the ground (foot scuffing) precisely on the section.  *Checkerboard at fixed
positions* breaks the translation invariance (the gait's steps are ~12 mm shorter than the
ideal ones, so footfalls drift across the patches).  We therefore use **checkerboard lanes
placed relative to the current footfall**: during each step the stance lane has one patch
centred on the stance foot's section position (s = 0) and the swing lane one patch centred
one *ideal* step length ``l`` ahead (the paper's rule: patches around the footfalls of the
ideal gait).  The swing foot passes over a gap at mid-stance exactly as in the ADAMS model.
The re-centring is physically invisible as long as each foot stays inside its patch during
its stance (the IMPACT force only depends on the patch membership, not on the distance to
the centre): :func:`find_contact_periodic_gait` reports the worst margin to a patch edge
(``patch_margin_m``), and the fixed point is then a true periodic gait of a checkerboard
whose patches are spaced by the gait's own step length.  On stairs and footholds of one
height (patches a riser apart, :func:`walkerlab.models.contact.terrain.terrain_ground`) the
swing patch lies the step's rise (:func:`~walkerlab.analysis.contact.section.step_rise`)
above the stance patch, and the new stance foot's penetration is measured from its own
patch: each step on the same ground.

"""

from __future__ import annotations

import dataclasses
import time

import numpy as np

from walkerlab.analysis.contact.sim import initial_state_from_ideal
from walkerlab.freshstack import import_on_fresh_stack
from walkerlab.integrate.contact import ContactLimits, run_powered
from walkerlab.integrate.contact_grid import GRID_METHODS, contact_grid
from walkerlab.integrate.contact_powered_step import powered_to_section, push_off
from walkerlab.integrate.ends import RunEnd, solver_words
from walkerlab.integrate.events import Event, EventRun, run_to_event
from walkerlab.integrate.powered_events import pulse_lead, pulse_lead_s
from walkerlab.integrate.solver import Solver
from walkerlab.models.contact.model import ContactWalker, footprint_offsets
from walkerlab.models.ground import FALL_HIP_FRACTION
from walkerlab.walker.layout import StateIndex

from .search_budget import PeriodicGaitError, SearchBudget
from .section import (
    SCALES,
    SECTION_NAMES,
    SECTION_UNITS,
    other_coordinates,
    section_coordinates,
    step_rise,
)

brentq = import_on_fresh_stack("scipy.optimize").brentq  # see walkerlab.freshstack

__all__ = ["SCALES", "SECTION_NAMES", "SECTION_UNITS", "PeriodicGaitError", "SearchBudget",
           "StepMap",
           "section_coordinates", "section_guess_from_ideal"]


#: what to try when a step of the map falls: the search starts from the rigid gait's state
#: (placed on the contact model) and iterates the map from it
FELL_ADVICE = ("the contact gait, if there is one, is far from the rigid gait the search "
               "starts from; check that walkerlab contact-sim walks from the rigid gait (its "
               "outcome says why not), move the contact law toward the rigid model along "
               "its rigid-limit family (stiffness, damping and stiction velocity scaled "
               "together: walkerlab compare --rigid-limit; a stiffer law alone makes the heel "
               "strike elastic: restitution 0.03 at the paper's stiffness, 0.99 at 1e4 times "
               "it), or start the search elsewhere (ContactWalker.periodic_gait(x0))")
#: a step of the map that fell
FELL = f"step map: the walker fell (hip below L/2): {FELL_ADVICE}"

#: the step map's default integrator (LSODA with the analytic Jacobian)
DEFAULT_SOLVER = Solver("LSODA", 1e-11, 1e-13)


class StepMap:
    """Mid-stance-to-mid-stance step map of a :class:`ContactWalker`.

    Parameters
    ----------
    walker : ContactWalker
        Parameters and contact law; its lanes are replaced by footfall-relative lanes
        (kneed walkers on continuous ground keep it).  Any walker the contact model builds.
    patch_spacing : float, optional
        Distance [m] ahead of the stance foot of the swing lane's patch (default: the
        walker's lane spacing ``lane1[0] - lane2[0]`` if it has lanes, else 0.372 m).
    solver : walkerlab.integrate.solver.Solver
        The map's integrator: ``"cyrk_bdf"`` (CyRK's BDF over the compiled RHS on a grid,
        the crossing found by brentq), ``"odeint"`` (the same through scipy's odeint) or a
        ``solve_ivp`` method (``"LSODA"``, ``"Radau"``, ``"BDF"``; the crossing located as
        an event); ``atol`` well below the penetration ~6e-5 m.  A powered walker's pulse
        (and, with hip torques, its whole step) runs on the powered contact integrator: on
        compiled segments with ``"cyrk_bdf"`` (laws that are data), on ``solve_ivp`` with
        this method if it is a ``solve_ivp`` one, else LSODA
        (:mod:`walkerlab.integrate.contact_powered_step`).
    t_max : float
        Give up a step after this time [s].
    deadline : float, optional
        ``time.perf_counter()`` value past which a map evaluation raises ``time_limit``
        (None: none); ignored when ``budget`` is given (its own deadline).
    budget : SearchBudget, optional
        The search's bounds, shared with its other maps (each integration is charged to
        it); default a budget of this map's own with no work bound.
    """

    def __init__(self, walker: ContactWalker, patch_spacing: float | None = None,
                 solver: Solver = DEFAULT_SOLVER, t_max: float = 3.0,
                 deadline: float | None = None, budget: SearchBudget | None = None):
        acts = getattr(walker, "actuators", None)
        if acts is not None and any(r is not None for r in acts.laws.time_refs):
            raise ValueError("walker.actuation: a torque law on time since the heel strike "
                             "has no mid-stance step map (the time is not a state of the "
                             "section): the contact periodic gait needs state-based laws")
        #: a powered walker (actuators): its map runs on the powered contact integrator
        self.powered = acts is not None
        if patch_spacing is None:
            if walker.lane1.size and walker.lane2.size:
                patch_spacing = float(walker.lane1[0] - walker.lane2[0])
            else:
                patch_spacing = 0.372
        self.spacing = float(patch_spacing)
        # straight legs scuff the ground at mid-stance: footfall-relative lanes (module doc);
        # a kneed swing leg (knees that lock or free knees) is flexed there, so its
        # continuous ground is kept
        keep_ground = walker.continuous and walker.structure.kind.has_knees
        # each patch centred on its foot's footprint (a flat foot's lies ahead of its heel)
        o2 = footprint_offsets(walker.data)[1]
        #: height [m] of the swing lane's patch above the stance patch (stairs, footholds)
        self.rise = step_rise(walker)
        #: steps per map (:attr:`ContactWalker.steps_per_map`): 2, a stride, for a walker
        #: whose section is leg2's mid-stance only; each footfall of the map has a patch
        self.steps = int(walker.steps_per_map)
        k1 = np.arange(1, self.steps + 1, 2)  # leg1's footfalls (leg2's at 0, 2, ...)
        k2 = np.arange(0, self.steps + 1, 2)
        heights = {} if walker.heights1 is None and walker.heights2 is None else {
            "heights1": self.rise * k1, "heights2": self.rise * k2}
        self.walker = dataclasses.replace(walker, lane1=self.spacing * k1 + o2,
                                          lane2=self.spacing * k2 + o2,
                                          continuous=keep_ground, **heights)
        self.method, self.t_max = solver.method, t_max
        self.solver = solver  # the step map's integrator
        #: the search's shared bounds (its work, its wall-clock deadline)
        self.budget = SearchBudget(deadline=np.inf if deadline is None else deadline) \
            if budget is None else budget
        self.deadline = self.budget.deadline
        self.nfev = 0
        self._last_section = (None, None)  # next_section's last (arguments, answer)
        w = self.walker
        kern = w.kernels
        args = (w.contact_params, w.walker_params, *w.kernel_lanes)
        self._f = lambda x: kern.rhs(x, *args)  # noqa: E731
        self._fj = lambda x: kern.jac(x, *args)  # noqa: E731
        self._data = w.pack() if solver.method != "odeint" else None  # compiled RHS data
        self.n, self.t = w.normal, w.tangent
        self.idx = StateIndex(w)
        # every column by name (leg1 = 0, leg2 = 1), never by row: each leg's link angles,
        # proximal first (the section is the crossing of the two proximal links)
        self._links = [w.leg_angle_states("leg1"), w.leg_angle_states("leg2")]
        self._angle = [self.idx[a[0]] for a in self._links]
        self._rate = [self.idx.rate_of(a[0]) for a in self._links]
        self._others = other_coordinates(w)  # in 3D the heading and the rolls
        self.names, self.units, self.scale = section_coordinates(w)
        self._last_map = (None, None)  # _run_map's last (section state, answer)

    def _columns(self, stance: int) -> list[int]:
        """State columns of the link coordinates in section order, with foot ``stance``."""
        ix, st, sw = self.idx, self._links[stance], self._links[1 - stance]
        return ([ix[a] for a in st] + [ix[a] for a in sw[1:]] + [ix[a] for a in self._others]
                + [ix.rate_of(a) for a in sw] + [ix.rate_of(a) for a in st]
                + [ix.rate_of(a) for a in self._others])

    # ------------------------------------------------------------------ coordinates
    def to_state(self, z) -> np.ndarray:
        """Full state (2 nq,) from section coordinates (leg2 stance, stance foot at s = 0).

        ``z`` has shape (m,) in :attr:`names` order (units :attr:`units`: link angles [rad],
        rates [rad/s], the stance foot's penetration [m] and velocities [m/s]); the state
        follows ``walker.state_names()`` [m, rad, m/s, rad/s].
        """
        z = np.asarray(z, float)
        dim = self.walker.dim
        nl = len(z) - dim - 1
        d, *slips, dd = z[nl:]  # penetration, slip along each tangent, penetration rate
        p = -d * self.n
        v = np.array(slips) @ self.walker.tangents - dd * self.n
        # link state by name: the swing leg's proximal link aligned with the stance one's
        val = dict(zip(self._columns(1), z[:nl]))
        val[self._angle[0]] = val[self._angle[1]]
        ix = self.idx
        names = ix.names[ix.coordinates]
        cols = [ix[c] for c in names[dim:]]  # after the base's slides
        zp = np.array([val[c] for c in cols] + [val[ix.rate_of(ix.names[c])] for c in cols])
        # stance foot at p and at rest, then the whole walker translated at v
        x = self.walker.pinned_to_full(zp, p)
        x[[ix.rate_of(c) for c in names[:dim]]] += v
        return x

    def to_section(self, x, stance: int, footfall: int | None = None
                   ) -> tuple[np.ndarray, float]:
        """Section coordinates (:attr:`names`) and along-slope position s [m] of foot
        ``stance`` (0/1), standing on the map's footfall ``footfall`` (0: leg2's at s = 0,
        1: leg1's next, ...; default ``1 - stance``, the step's).

        ``x`` (2 nq,): full state (``walker.state_names()``); returns ``(z, s)`` with ``z``
        of shape (m,) (units :attr:`units`).
        """
        x = np.asarray(x, float)
        p, v = self.walker.foot_state(x, stance)
        # the penetration below the foot's own patch: each footfall lies ``rise`` above the
        # last on stairs and footholds, the next step's ground as the last one
        h = self.rise * (1 - stance if footfall is None else footfall)
        z = np.concatenate([x[self._columns(stance)], [h - p @ self.n],
                            self.walker.tangents @ v, [-v @ self.n]])
        return z, float(p @ self.t)

    # ------------------------------------------------------------------ the map
    def _rhs(self, t, x):
        if time.perf_counter() > self.deadline:
            raise PeriodicGaitError("time_limit", "periodic-gait search: wall-time limit "
                                    "reached")
        return self._f(x)

    def _jac(self, t, x):
        return self._fj(x)

    def integrate(self, x0, stance_to_come: int = 0, dense: bool = False) -> EventRun:
        """Integrate from ``x0`` to the next upward zero of theta_sw - theta_st where the
        new stance leg is ``stance_to_come`` (0 = leg1): event ``mid_stance``, or ``fall``
        (hip below L/2; :func:`walkerlab.integrate.events.run_to_event`).

        ``x0`` (2 nq,): full state (``walker.state_names()``, [m, rad, m/s, rad/s]); the
        run's times are in [s].

        Raises
        ------
        PeriodicGaitError
            ``time_limit``: the search's wall-time deadline passed during the integration.
        """
        ist, isw = self._angle[stance_to_come], self._angle[1 - stance_to_come]
        hth = FALL_HIP_FRACTION * self.walker.L
        events = [Event("mid_stance", lambda t, x: x[isw] - x[ist], 1.0),
                  Event("fall", lambda t, x: self.walker.fall_margin(x, hth), -1.0,
                        RunEnd.FALL)]
        self._spend()
        return run_to_event(self._rhs, x0, self.t_max, self.solver, events, jac=self._jac,
                            dense=dense)

    def _spend(self) -> None:
        """Count one integration of the map (:attr:`nfev`) and charge it to the search's
        :class:`SearchBudget` (raises its ``work_limit``)."""
        self.budget.spend()
        self.nfev += 1

    def next_section(self, x0, stance_to_come: int = 0, dt: float = 2e-3,
                     chunk_s: float = 0.25, passive: bool = False):
        """(t_e [s], x_e (2 nq,)) of the next upward zero of theta_sw - theta_st from the
        full state ``x0`` (2 nq,) at t = 0, the new stance leg ``stance_to_come`` (0 = leg1);
        for a grid method (``"cyrk_bdf"``, ``"odeint"``), or a powered walker (through its
        next heel strike, on the powered contact integrator; ``passive``: its actuators
        left out, on CyRK's BDF at the map's tolerances).

        The walker on a ``dt`` grid in chunks (:func:`walkerlab.integrate.contact_grid.
        contact_grid`: CyRK's BDF over the compiled RHS, or scipy's odeint); the crossing is
        bracketed on the samples and located by ``scipy.optimize.brentq`` on short
        integrations from the sample before it, so the section state carries the
        integrator's accuracy, not an interpolant's.

        The last call's answer is kept: the same arguments again (the root finder's
        forward-difference Jacobian evaluates the map where it has just evaluated it, the
        fixed point's last step and its patch margin start from the same state) return it
        without integrating, a copy of what the integration (deterministic) gives.
        """
        x0 = np.asarray(x0, float)
        key = (x0.tobytes(), stance_to_come, dt, chunk_s, passive)
        if self._last_section[0] != key:
            self._last_section = (key, self._section(x0, stance_to_come, dt, chunk_s,
                                                     passive))
        te, xe = self._last_section[1]
        return te, xe.copy()

    def _section(self, x0, stance_to_come: int, dt: float, chunk_s: float, passive: bool):
        """:meth:`next_section` without its memory of the last call."""
        ist, isw = self._angle[stance_to_come], self._angle[1 - stance_to_come]
        hth = FALL_HIP_FRACTION * self.walker.L
        if self.powered and not passive:
            return self._powered_section(x0, stance_to_come, ist, isw, hth)
        return self._grid_crossing(x0, lambda X: X[:, isw] - X[:, ist], 0.0, dt, chunk_s,
                                   hth, "no_mid_stance", "mid-stance")

    def _grid_crossing(self, x0, gfun, t0: float, dt: float, chunk_s: float, hth: float,
                       kind: str, what: str):
        """(t_e, x_e) of the first upward zero of ``gfun`` (rows of states -> values) from
        ``x0`` at ``t0`` on the passive flow, on the grid integrator (module doc of
        :meth:`next_section`); a fall (hip below ``hth``) first raises ``fall``, no crossing
        by ``t_max`` raises ``kind``."""
        solver = self.solver
        if solver.method not in GRID_METHODS:
            solver = dataclasses.replace(solver, method=GRID_METHODS[0])

        def run(x, tg):
            X, end, message, _ = contact_grid(self.walker, x, tg, solver, self._data)
            if end is RunEnd.SOLVER_FAILURE:
                raise PeriodicGaitError("solver_failure", f"step map: {solver_words(message)}")
            return X

        ta, xa = t0, np.asarray(x0, float)
        self._spend()
        while ta < self.t_max:
            if time.perf_counter() > self.deadline:
                raise PeriodicGaitError("time_limit", "periodic-gait search: wall-time limit "
                                        "reached")
            tg = ta + dt * np.arange(int(round(chunk_s / dt)) + 1)
            X = run(xa, tg)
            g = gfun(X)
            hh = self.walker.hip_height(X)
            up = np.flatnonzero((g[:-1] < 0) & (g[1:] >= 0)) + 1
            down = np.flatnonzero(hh < hth)
            if down.size and (not up.size or down[0] <= up[0]):
                raise PeriodicGaitError("fall", FELL)
            if up.size:
                k = int(up[0])
                xk = X[k - 1]
                ends = {}  # brentq's evaluations, t -> state (the root is one of them)

                def gap(t, k=k, xk=xk, tg=tg, g=g, ends=ends):
                    if t <= tg[k - 1]:
                        return g[k - 1]
                    ends[t] = run(xk, np.array([tg[k - 1], t]))[-1:]
                    return gfun(ends[t])[0]

                te = brentq(gap, tg[k - 1], tg[k], xtol=1e-13, rtol=1e-14)
                if te <= tg[k - 1]:
                    return float(te), xk
                # brentq answers a point it evaluated: that short run's end, not a new run
                xe = ends[te][-1] if te in ends else run(xk, np.array([tg[k - 1], te]))[-1]
                return float(te), xe
            ta, xa = tg[-1], X[-1]
        raise PeriodicGaitError(kind, f"step map: no {what} within {self.t_max:g} s")

    def _powered_section(self, x0, stance_to_come, ist, isw, hth):
        """:meth:`next_section` of a powered walker: the heel strike, push-off and roles
        swap.  Push-off alone: the passive flow (compiled, :meth:`_grid_crossing`) to the
        pulse's start (``pulse_s`` before the predicted touchdown of the swing foot on its
        patch ahead; the touchdown itself for an impulse), the pulse on the powered contact
        integrator (:func:`walkerlab.integrate.contact_powered_step.push_off`), the passive flow
        to mid-stance; with hip torques the whole step on the powered contact integrator
        (:func:`walkerlab.integrate.contact_powered_step.powered_to_section`)."""
        acts = self.walker.actuators
        if not acts.laws:
            return self._push_off_section(x0, stance_to_come, ist, isw, hth)
        self._spend()
        te, xe, end = powered_to_section(self.walker, np.asarray(x0, float),
                                         1 - stance_to_come,
                                         lambda x: x[..., isw] - x[..., ist],
                                         self.solver, self.t_max, self.deadline, hth)
        return self._powered_end(te, xe, end)

    def _push_off_section(self, x0, stance_to_come, ist, isw, hth):
        """:meth:`_powered_section` of a walker powered by push-off alone."""
        w, acts = self.walker, self.walker.actuators
        trailing = 1 - stance_to_come
        sw, st = f"leg{stance_to_come + 1}", f"leg{trailing + 1}"
        lead = pulse_lead_s(acts)  # the pulse ends at the predicted touchdown

        def touch(X):  # the swing foot's penetration on its patch ahead, else -1; with a
            # pulse: extrapolated pulse_s ahead (the pulse ends at the predicted touchdown)
            fq = w.foot_quantities(X)
            ok = (fq[sw]["on_ground"] > 0.5) & (fq[sw]["s"] - fq[st]["s"] >= acts.min_step_m)
            pen = fq[sw]["penetration"]
            if lead > 0.0:
                pen = pulse_lead(pen, fq[sw]["penetration_rate"], lead)
            return np.where(ok, pen, -1.0)

        t1, x1 = self._grid_crossing(x0, touch, 0.0, 2e-3, 0.25, hth, "no_mid_stance",
                                     "heel strike" if lead == 0.0 else
                                     "push-off before a heel strike")
        t2, x2, end = push_off(w, x1, t1, trailing, self.solver, self.deadline, hth)
        if end is not RunEnd.T_FINAL:
            return self._powered_end(t2, x2, end)
        self.nfev -= 1  # one map evaluation in three pieces
        return self._grid_crossing(x2, lambda X: X[:, isw] - X[:, ist], t2, 2e-3, 0.25, hth,
                                   "no_mid_stance", "mid-stance")

    def _powered_end(self, te, xe, end):
        """(t_e, x_e) of a powered section run that ended at the section, else the
        :class:`PeriodicGaitError` its ``end`` (:class:`RunEnd`) means."""
        if end is RunEnd.T_FINAL:
            return float(te), xe
        if end is RunEnd.FALL:
            raise PeriodicGaitError("fall", FELL)
        if end is RunEnd.TIME_LIMIT:
            raise PeriodicGaitError("time_limit", "periodic-gait search: wall-time limit "
                                    "reached")
        if end is RunEnd.SOLVER_FAILURE or end is RunEnd.TRIP:
            raise PeriodicGaitError("solver_failure", f"step map: the powered run ended "
                                    f"({end.value}) at t = {te:.4g} s")
        raise PeriodicGaitError("no_mid_stance", f"step map: no heel strike and mid-stance "
                                f"within {self.t_max:g} s")

    def __call__(self, z):
        """One map (:attr:`steps` steps): returns (P(z) (n,), the mean step period [s], the
        mean step length [m]) over its steps.

        Raises
        ------
        PeriodicGaitError
            The walker fell, did not reach the next mid-stance within ``t_max``, the solver
            failed or the wall-time limit ran out.
        """
        te, xe = self._run_map(z)
        stance = (self.steps - 1) % 2  # the last step's new stance leg (0 = leg1)
        z1, s1 = self.to_section(xe, stance, self.steps)
        return z1, te / self.steps, s1 / self.steps

    def _run_map(self, z) -> tuple[float, np.ndarray]:
        """(t [s], x (2 nq,)): the time to and the full state at the map's section
        (:attr:`steps` mid-stances on) from the section state ``z``; the last call's
        answer is kept (:meth:`patch_margin` integrates over the map just taken)."""
        key = np.asarray(z, float).tobytes()
        if self._last_map[0] != key:
            self._last_map = (key, self._map_steps(self.to_state(z)))
        te, xe = self._last_map[1]
        return te, xe.copy()

    def _map_steps(self, x) -> tuple[float, np.ndarray]:
        """:meth:`_run_map` without its memory: each step to the next mid-stance, the new
        stance leg alternating (leg1 first)."""
        t = 0.0
        for k in range(self.steps):
            if self.method in GRID_METHODS or self.powered:
                te, x = self.next_section(x, stance_to_come=k % 2)
            else:
                run = self.integrate(x, stance_to_come=k % 2)
                if run.event != "mid_stance":
                    if run.end is RunEnd.FALL:
                        raise PeriodicGaitError("fall", FELL)
                    if run.end is RunEnd.SOLVER_FAILURE:
                        raise PeriodicGaitError("solver_failure",
                                                f"step map: {solver_words(run.message)}")
                    raise PeriodicGaitError("no_mid_stance", f"step map: no mid-stance "
                                            f"within {self.t_max:g} s")
                te, x = run.t_event, run.y_event
            t += te
        return t, x

    def patch_margin(self, z) -> float:
        """Smallest distance [m] of a loaded foot to its patch edge over one step from the
        section coordinates ``z`` (m,) (:attr:`names`); inf on continuous ground."""
        x0 = self.to_state(z)
        if self.powered:
            te = self._run_map(z)[0]
            X = run_powered(self.walker, x0, 0.0, te, self.solver,
                            ContactLimits(sample_rate_hz=2000 / te), self.deadline, None)[1]
        elif self.method in GRID_METHODS or self.steps > 1:
            te = self._run_map(z)[0]
            tt = np.linspace(0.0, te, 2000 * self.steps + 1)
            solver = self.solver if self.method in GRID_METHODS else \
                dataclasses.replace(self.solver, method=GRID_METHODS[0])
            X = contact_grid(self.walker, x0, tt, solver, self._data)[0]
        else:
            run = self.integrate(x0, dense=True)
            te = run.t_event if run.event == "mid_stance" else run.t[-1]
            tt = np.linspace(0.0, te, 2001)
            X = run.dense(tt).T
        if self.walker.continuous:
            return np.inf  # continuous ground: no patch edges
        cq = self.walker.contact_quantities(X)
        hw = self.walker.patch_half_width
        margin = np.inf
        for name, q in cq.items():  # every contact point on its leg's patches
            loaded = q["penetration"] > 0
            for c in map(float, self.walker.lane(name)):
                near = np.abs(q["s"] - c) <= 2 * hw  # in or next to this patch
                sel = loaded & near
                if sel.any():
                    margin = min(margin, float(np.min(hw - np.abs(q["s"][sel] - c))))
        return margin


def section_guess_from_ideal(step_map: StepMap, x_ideal, rate_scale=(1.0, 1.0)) -> np.ndarray:
    """Section state from an ideal-model post-impact state (the rigid walkers
    ``state_names()`` order, e.g. ``[th_sw, th_st, w_sw, w_st]``).

    The ideal state is placed as :func:`initial_state_from_ideal` does (stance foot leg2 at
    its static penetration, ``rate_scale`` on the rates) and integrated to the first
    mid-stance of leg2, where the section coordinates are read.

    Parameters
    ----------
    step_map : StepMap
    x_ideal : array_like, shape (2n,)
        The rigid walker's post-impact state [rad, rad/s].
    rate_scale : (float, float)
        Multipliers [-] on leg1's and leg2's rates.

    Returns
    -------
    ndarray, shape (m,)
        Section coordinates (``step_map.names``, units ``step_map.units``; m = 6 for
        straight legs).

    Raises
    ------
    PeriodicGaitError
        ``fall`` or ``no_mid_stance``: the placed state does not reach mid-stance;
        ``time_limit`` when the step map's wall-time deadline passes.
    """
    w = step_map.walker
    x0 = initial_state_from_ideal(w, *np.asarray(x_ideal, float), rate_scale=rate_scale)
    if step_map.method in GRID_METHODS or step_map.powered:
        try:
            # from the post-impact state to the first mid-stance: no heel strike between
            xe = step_map.next_section(x0, stance_to_come=1, passive=True)[1]
        except PeriodicGaitError as e:
            if e.kind in ("time_limit", "work_limit"):
                raise
            raise PeriodicGaitError("fall" if e.kind == "fall" else "no_mid_stance",
                                    "the ideal state does not reach mid-stance on the "
                                    "contact model" + (f" (it falls): {FELL_ADVICE}"
                                                       if e.kind == "fall" else "")) from None
        return step_map.to_section(xe, 1, 0)[0]
    run = step_map.integrate(x0, stance_to_come=1)
    if run.event != "mid_stance":
        fell = run.end is RunEnd.FALL
        raise PeriodicGaitError("fall" if fell else "no_mid_stance",
                                "the ideal state does not reach mid-stance on the contact model"
                                + (f" (it falls): {FELL_ADVICE}" if fell else ""))
    return step_map.to_section(run.y_event, 1, 0)[0]
