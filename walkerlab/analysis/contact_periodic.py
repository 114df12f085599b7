"""The compliant-contact walker's own periodic gait: fixed point of a mid-stance step map.

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
four link rates (swing leg first), then the three stance-foot coordinates.
``theta_swing = theta_stance`` on the section [rad]; rates [rad/s]; ``delta_stance`` is the
stance foot's penetration [m] (along -n), ``v_t_stance`` its down-slope slip velocity [m/s],
``ddelta_stance`` its penetration rate [m/s].  The along-slope position of the stance foot is
dropped (the dynamics are invariant under translation along the slope, see *Terrain*).

Step map
--------
``P(z)``: build the full state with the stance foot at along-slope ``s = 0`` (leg2 = stance,
leg1 = swing: the legs are identical, so one orientation suffices), integrate with
``solve_ivp`` (LSODA or Radau with the analytic numba Jacobian; through
:func:`walkerlab.integrate.events.run_to_event`, or odeint on a grid with
:func:`~walkerlab.integrate.events.odeint_grid`) until the next upward zero
of ``theta2 - theta1`` (proximal links; mid-stance of the other leg), located by
``solve_ivp``'s event root-finding on the dense output; swap the leg roles and express the
state relative to the new stance foot (leg1).  Outputs besides ``P(z)``: the step period
``T`` [s] and the step length (along-slope displacement of the stance foot from one
mid-stance to the next) [m].

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
whose patches are spaced by the gait's own step length.

Floquet multipliers
-------------------
Eigenvalues of the n x n Jacobian of ``P`` (n = 6, kneed 10) at the fixed point, by central
finite differences in scaled coordinates: step ``h = fd_step`` (default 1e-4) times the
coordinate scale (:data:`SCALES`: 1 rad, 1 rad/s, 1 rad/s, static penetration ~6e-5 m, 1
mm/s, 1 mm/s; kneed: every angle 1 rad, every rate 1 rad/s), with the map integrated at rtol
1e-12 / atol 1e-14.  Measured on the paper's contact: the map's noise (adaptive-step jitter)
is ~1e-9 (scaled) at rtol 1e-11 and ~1e-10 at 1e-12, so the FD noise is ~1e-10 / h ~ 1e-6,
and the truncation error O(h^2) is ~1e-8; the multipliers agree to ~1e-5 between h = 1e-3,
1e-4 and 1e-5 (``multiplier_fd_spread`` reports the change for h*3 and h/3).  The three
"fast" multipliers (normal contact mode, tangential creep of the stance foot, both damped
within milliseconds) are ~1e-5..1e-8, i.e. zero within the FD noise; the three slow ones
belong to the swing dynamics and correspond to the ideal model's nonzero multipliers
(section-independent for a periodic orbit).  Kneed walker (``configs/kneed.yaml``): the same
three slow ones (0.469 +- 0.498j, 0.113; rigid 0.548 +- 0.499j, 0.108), the seven others
(contact and knee-stop modes) < 1e-4.

Rigid limit
-----------
The one rigid-limit family of the contact is :mod:`walkerlab.models.contact.rigid_limit`
(:func:`~walkerlab.models.contact.rigid_limit.scale_walker`);
:func:`walkerlab.analysis.rigid_limit.convergence` follows this gait along it.
"""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import brentq, root

from walkerlab.integrate.contact import StateIndex
from walkerlab.integrate.ends import RunEnd
from walkerlab.integrate.events import Event, EventRun, odeint_grid, run_to_event
from walkerlab.integrate.solver import Solver
from walkerlab.models.contact.model import ContactWalker, footprint_offsets

__all__ = ["SECTION_NAMES", "SECTION_UNITS", "StepMap", "ContactPeriodicGait", "PeriodicGaitError",
           "find_contact_periodic_gait", "section_guess_from_ideal"]

SECTION_NAMES = ("theta_stance", "dtheta_swing", "dtheta_stance", "delta_stance",
                 "v_t_stance", "ddelta_stance")
SECTION_UNITS = ("rad", "rad/s", "rad/s", "m", "m/s", "m/s")


@dataclass
class ContactPeriodicGait:
    """Periodic gait of the contact walker (fixed point of the mid-stance step map).

    Attributes
    ----------
    z : ndarray (n,)
        Fixed point in the section's order (:func:`section_coordinates`; straight legs
        :data:`SECTION_NAMES`, units :data:`SECTION_UNITS`; n = 6, kneed 10).
    fixed_point : dict[str, float]
        The same, named.
    period_s : float
        Step period [s] (mid-stance to mid-stance; equals the heel-strike-to-heel-strike
        period on a periodic orbit).
    step_length_m : float
        Along-slope advance of the stance foot per step [m].
    residual : float
        max |(P(z) - z) / scale| (scaled, see :data:`SCALES`) [-].
    residual_si : ndarray (n,)
        P(z) - z in SI units.
    jacobian : ndarray (n, n)
        dP/dz in SI (rows/cols in the section's order).
    multipliers : ndarray (n,) complex
        Floquet multipliers, sorted by decreasing modulus.
    multiplier_fd_spread : float
        max change of the slow (|lambda| > 1e-3) sorted multipliers when the FD step is
        multiplied or divided by 3.
    stable : bool
        All |multipliers| < 1.
    converged : bool
    message : str
    nfev : int
        Step-map evaluations (root finding + Jacobian).
    patch_margin_m : float
        Smallest distance [m] of a loaded foot to the edge of its patch on the orbit (inf on
        continuous ground).
    full_state : ndarray (2 nq,)
        Full state at the section (leg2 stance at s = 0).
    wall_time_s : float
    info : dict
        Extra diagnostics (warm-up history, solver settings).
    """

    z: np.ndarray
    fixed_point: dict
    period_s: float
    step_length_m: float
    residual: float
    residual_si: np.ndarray
    jacobian: np.ndarray
    multipliers: np.ndarray
    multiplier_fd_spread: float
    stable: bool
    converged: bool
    message: str
    nfev: int
    patch_margin_m: float
    full_state: np.ndarray
    wall_time_s: float
    info: dict = field(default_factory=dict)

    @property
    def max_multiplier(self) -> float:
        """Largest |multiplier| [-]."""
        return float(np.max(np.abs(self.multipliers)))


class PeriodicGaitError(RuntimeError):
    """The step map or the search failed; ``kind`` is one of "fall", "no_mid_stance",
    "time_limit", "solver_failure"."""

    def __init__(self, kind: str, message: str):
        super().__init__(message)
        self.kind = kind


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
    method : {"LSODA", "Radau", "BDF"}
    rtol, atol : float
        Integrator tolerances (``atol`` well below the penetration ~6e-5 m).
    t_max : float
        Give up a step after this time [s].
    """

    def __init__(self, walker: ContactWalker, patch_spacing: float | None = None,
                 method: str = "LSODA", rtol: float = 1e-11, atol: float = 1e-13,
                 t_max: float = 3.0, deadline: float | None = None):
        if patch_spacing is None:
            if walker.lane1.size and walker.lane2.size:
                patch_spacing = float(walker.lane1[0] - walker.lane2[0])
            else:
                patch_spacing = 0.372
        self.spacing = float(patch_spacing)
        # straight legs scuff the ground at mid-stance: footfall-relative lanes (module doc);
        # a kneed swing leg is flexed there, so its continuous ground is kept
        keep_ground = walker.continuous and walker.structure.knee
        # each patch centred on its foot's footprint (a flat foot's lies ahead of its heel)
        o2 = footprint_offsets(walker.data)[1]
        self.walker = dataclasses.replace(walker, lane1=np.array([self.spacing + o2]),
                                          lane2=np.array([o2]), continuous=keep_ground)
        self.method, self.t_max = method, t_max
        self.solver = Solver(method, rtol, atol)  # the step map's integrator
        self.deadline = np.inf if deadline is None else deadline
        self.nfev = 0
        w = self.walker
        kern = w.kernels
        args = (w.contact_params, w.walker_params, *w.kernel_lanes)
        self._f = lambda x: kern.rhs(x, *args)  # noqa: E731
        self._fj = lambda x: kern.jac(x, *args)  # noqa: E731
        self.n, self.t = w.normal, w.tangent
        self.idx = StateIndex(w)
        # every column by name (leg1 = 0, leg2 = 1), never by row: each leg's link angles,
        # proximal first (the section is the crossing of the two proximal links)
        self._links = [w.leg_angle_states("leg1"), w.leg_angle_states("leg2")]
        self._angle = [self.idx[a[0]] for a in self._links]
        self._rate = [self.idx.rate_of(a[0]) for a in self._links]
        self.names, self.units, self.scale = section_coordinates(w)

    def _columns(self, stance: int) -> list[int]:
        """State columns of the link coordinates in section order, with foot ``stance``."""
        ix, st, sw = self.idx, self._links[stance], self._links[1 - stance]
        return ([ix[a] for a in st] + [ix[a] for a in sw[1:]]
                + [ix.rate_of(a) for a in sw] + [ix.rate_of(a) for a in st])

    # ------------------------------------------------------------------ coordinates
    def to_state(self, z) -> np.ndarray:
        """Full state (2 nq,) from section coordinates (leg2 stance, stance foot at s = 0)."""
        z = np.asarray(z, float)
        nl = len(z) - 3
        d, vt, dd = z[nl:]
        p = -d * self.n
        v = vt * self.t - dd * self.n
        # link state by name: the swing leg's proximal link aligned with the stance one's
        val = dict(zip(self._columns(1), z[:nl]))
        val[self._angle[0]] = val[self._angle[1]]
        ix = self.idx
        cols = [ix[c] for c in ix.names[ix.coordinates] if c not in ("hip_x", "hip_y")]
        zp = np.array([val[c] for c in cols] + [val[ix.rate_of(ix.names[c])] for c in cols])
        # stance foot at p and at rest, then the whole walker translated at v
        x = self.walker.pinned_to_full(zp, p)
        x[[ix.rate_of("hip_x"), ix.rate_of("hip_y")]] += v
        return x

    def to_section(self, x, stance: int) -> tuple[np.ndarray, float]:
        """Section coordinates (:attr:`names`) and along-slope position s [m] of foot
        ``stance`` (0/1)."""
        x = np.asarray(x, float)
        px, py, vx, vy = self.walker.foot_state(x, stance)
        p, v = np.array([px, py]), np.array([vx, vy])
        z = np.concatenate([x[self._columns(stance)], [-p @ self.n, v @ self.t, -v @ self.n]])
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
        (hip below L/2; :func:`walkerlab.integrate.events.run_to_event`)."""
        ist, isw = self._angle[stance_to_come], self._angle[1 - stance_to_come]
        hth = 0.5 * self.walker.L
        events = [Event("mid_stance", lambda t, x: x[isw] - x[ist], 1.0),
                  Event("fall", lambda t, x: self.walker.fall_margin(x, hth), -1.0,
                        RunEnd.FALL)]
        run = run_to_event(self._rhs, x0, self.t_max, self.solver, events, jac=self._jac,
                           dense=dense)
        self.nfev += 1
        return run

    def _step_odeint(self, x0, stance_to_come: int = 0, dt: float = 2e-3,
                     chunk_s: float = 0.25):
        """``method="odeint"``: (t_e, x_e) of the next upward zero of theta_sw - theta_st.

        scipy's odeint (LSODA without per-step Python overhead) on a ``dt`` grid in chunks;
        the crossing is bracketed on the samples and located by ``scipy.optimize.brentq``
        on short odeint integrations from the sample before it, so the section state
        carries the integrator's accuracy, not an interpolant's.
        """
        ist, isw = self._angle[stance_to_come], self._angle[1 - stance_to_come]
        hth = 0.5 * self.walker.L
        frhs, fjac = self._f, self._fj

        def f(t, x):
            return frhs(x)

        def jf(t, x):
            return fjac(x)

        def run(x, tg):
            X, end, message = odeint_grid(f, x, tg, self.solver, jac=jf)
            if end is RunEnd.SOLVER_FAILURE:
                raise PeriodicGaitError("solver_failure", f"step map: {message}")
            return X

        ta, xa = 0.0, np.asarray(x0, float)
        self.nfev += 1
        while ta < self.t_max:
            if time.perf_counter() > self.deadline:
                raise PeriodicGaitError("time_limit", "periodic-gait search: wall-time limit "
                                        "reached")
            tg = ta + dt * np.arange(int(round(chunk_s / dt)) + 1)
            X = run(xa, tg)
            g = X[:, isw] - X[:, ist]
            hh = self.walker.hip_height(X)
            up = np.flatnonzero((g[:-1] < 0) & (g[1:] >= 0)) + 1
            down = np.flatnonzero(hh < hth)
            if down.size and (not up.size or down[0] <= up[0]):
                raise PeriodicGaitError("fall", "step map: the walker fell (hip below L/2)")
            if up.size:
                k = int(up[0])
                xk = X[k - 1]

                def gap(t, k=k, xk=xk, tg=tg, g=g):
                    if t <= tg[k - 1]:
                        return g[k - 1]
                    x = run(xk, np.array([tg[k - 1], t]))[-1]
                    return x[isw] - x[ist]

                te = brentq(gap, tg[k - 1], tg[k], xtol=1e-13, rtol=1e-14)
                xe = run(xk, np.array([tg[k - 1], te]))[-1] if te > tg[k - 1] else xk
                return float(te), xe
            ta, xa = tg[-1], X[-1]
        raise PeriodicGaitError("no_mid_stance", f"step map: no mid-stance within "
                                f"{self.t_max:g} s")

    def __call__(self, z):
        """One step: returns (P(z) (n,), period [s], step length [m]).

        Raises
        ------
        PeriodicGaitError
            The walker fell, did not reach the next mid-stance within ``t_max``, the solver
            failed or the wall-time limit ran out.
        """
        if self.method == "odeint":
            te, xe = self._step_odeint(self.to_state(z))
            z1, s1 = self.to_section(xe, 0)
            return z1, te, s1
        run = self.integrate(self.to_state(z))
        if run.event != "mid_stance":
            if run.end is RunEnd.FALL:
                raise PeriodicGaitError("fall", "step map: the walker fell (hip below L/2)")
            if run.end is RunEnd.SOLVER_FAILURE:
                raise PeriodicGaitError("solver_failure", f"step map: {run.message}")
            raise PeriodicGaitError("no_mid_stance", f"step map: no mid-stance within "
                                    f"{self.t_max:g} s")
        z1, s1 = self.to_section(run.y_event, 0)
        return z1, run.t_event, s1

    def patch_margin(self, z) -> float:
        """Smallest distance [m] of a loaded foot to its patch edge over one step."""
        if self.method == "odeint":
            x0 = self.to_state(z)
            te = self._step_odeint(x0)[0]
            tt = np.linspace(0.0, te, 2001)
            X = odeint_grid(lambda t, x: self._f(x), x0, tt, self.solver,
                            jac=lambda t, x: self._fj(x))[0]
        else:
            run = self.integrate(self.to_state(z), dense=True)
            te = run.t_event if run.event == "mid_stance" else run.t[-1]
            tt = np.linspace(0.0, te, 2001)
            X = run.dense(tt).T
        if self.walker.continuous:
            return np.inf  # continuous ground: no patch edges
        cq = self.walker.contact_quantities(X)
        hw = self.walker.patch_half_width
        margin = np.inf
        for name, q in cq.items():  # every contact point on its leg's patch
            c = float(self.walker.lane(name)[0])
            loaded = q["penetration"] > 0
            near = np.abs(q["s"] - c) <= 2 * hw  # in or next to this leg's patch
            sel = loaded & near
            if sel.any():
                margin = min(margin, float(np.min(hw - np.abs(q["s"][sel] - c))))
        return margin


#: coordinate scales (SI) of the straight-legged section (:data:`SECTION_NAMES`) used for
#: the root finder, the residual and the FD steps; the penetration scale is replaced by the
#: walker's static penetration at run time (:func:`section_coordinates` for any walker).
SCALES = np.array([1.0, 1.0, 1.0, 6e-5, 1e-3, 1e-3])


def _role_name(state: str, role: str) -> str:
    """``theta1_thigh`` -> ``theta_<role>_thigh``, ``dtheta2`` -> ``dtheta_<role>``."""
    head, _, tail = state.partition("_")
    return head.rstrip("12") + f"_{role}" + (f"_{tail}" if tail else "")


def section_coordinates(walker: ContactWalker) -> tuple[tuple, tuple, np.ndarray]:
    """Names, units and scales of the mid-stance section coordinates of ``walker``.

    All states minus the section constraint (the swing leg's proximal link aligned with the
    stance leg's) minus the along-slope translation, the hip position replaced by the stance
    foot's contact: the stance leg's link angles, the swing leg's other link angles, the
    swing leg's link rates, the stance leg's link rates, then ``delta_stance`` [m],
    ``v_t_stance`` [m/s], ``ddelta_stance`` [m/s].  Straight legs: :data:`SECTION_NAMES`
    (6); kneed legs: 10.

    Returns
    -------
    names : tuple of str
    units : tuple of str
    scale : ndarray (n,)
        1 rad, 1 rad/s, the static penetration, 1 mm/s, 1 mm/s (:data:`SCALES`).
    """
    st, sw = walker.leg_angle_states("leg2"), walker.leg_angle_states("leg1")
    angles = [_role_name(a, "stance") for a in st] + [_role_name(a, "swing") for a in sw[1:]]
    rates = ([_role_name("d" + a, "swing") for a in sw]
             + [_role_name("d" + a, "stance") for a in st])
    names = tuple(angles + rates) + SECTION_NAMES[-3:]
    units = ("rad",) * len(angles) + ("rad/s",) * len(rates) + SECTION_UNITS[-3:]
    scale = np.array([1.0] * (len(angles) + len(rates))
                     + [walker.static_penetration(), 1e-3, 1e-3])
    return names, units, scale


def section_guess_from_ideal(step_map: StepMap, x_ideal, rate_scale=(1.0, 1.0)) -> np.ndarray:
    """Section state from an ideal-model post-impact state (the rigid walkers
    ``state_names()`` order, e.g. ``[th_sw, th_st, w_sw, w_st]``).

    The ideal state is placed as :func:`initial_state_from_ideal` does (stance foot leg2 at
    its static penetration, ``rate_scale`` on the rates) and integrated to the first
    mid-stance of leg2, where the section coordinates are read.
    """
    from walkerlab.analysis.contact_sim import initial_state_from_ideal

    w = step_map.walker
    x0 = initial_state_from_ideal(w, *np.asarray(x_ideal, float), rate_scale=rate_scale)
    run = step_map.integrate(x0, stance_to_come=1)
    if run.event != "mid_stance":
        raise PeriodicGaitError("fall" if run.end is RunEnd.FALL else "no_mid_stance",
                                "the ideal state does not reach mid-stance on the contact model")
    return step_map.to_section(run.y_event, 1)[0]


def ideal_gait(scene):
    """The rigid (derived) periodic gait of ``scene`` from its ``fixedpoint`` section.

    Returns
    -------
    walkerlab.analysis.gaits result (``x`` role-order post-impact state, ``period_s``, ...)

    Raises
    ------
    GaitNotFound
        No ideal gait (a scene without a ``fixedpoint`` section searches from scale-free
        seeds).
    """
    from walkerlab.analysis.gaits import find_gaits
    from walkerlab.integrate.solver import Solver
    from walkerlab.models.registry import build_walker

    sc = scene.model_copy(update={"ideal": scene.ideal.model_copy(update={"variant": "derived"})})
    from walkerlab.config import FixedPointSettings

    fp = sc.fixedpoint or FixedPointSettings()  # every field optional: the defaults
    iw = build_walker(sc)
    return find_gaits(iw, Solver.from_settings(sc.solver),
                      None if fp.initial_guess is None
                      else fp.initial_guess.as_array(iw.state_names()),
                      policy=fp.gait, other_gait=False, xtol=fp.tolerance,
                      fd_step=fp.fd_step, max_step_time=fp.max_step_time_s).result


def fd_jacobian(F, z, scale, h, central: bool = True, F0=None):
    """Finite-difference Jacobian dF/dz (SI) with steps ``h * scale``: central, or forward
    from ``F0 = F(z)`` (n calls instead of 2n; used only for the root finder's Newton
    directions, never for the reported multipliers)."""
    n = len(z)
    J = np.empty((n, n))
    if not central and F0 is None:
        F0 = F(z)
    for j in range(n):
        dz = np.zeros(n)
        dz[j] = h * scale[j]
        J[:, j] = ((F(z + dz) - F(z - dz)) / (2 * dz[j]) if central
                   else (F(z + dz) - F0) / dz[j])
    return J


def _last_call_memo(f):
    """``f`` that returns its previous result when called again with the same array
    (``scipy.optimize.root`` evaluates the function and the Jacobian at the starting point
    twice, a shape check and MINPACK's own call: here each is one step map or six).  The
    last result is also kept as ``.last``."""
    def g(u):
        key = np.asarray(u, float).tobytes()
        if g.key != key:
            g.key, g.last = key, f(u)
        return g.last

    g.key, g.last = None, None
    return g


def _sorted_eig(J):
    ev = np.linalg.eigvals(J)
    return ev[np.argsort(-np.abs(ev), kind="stable")]


def find_contact_periodic_gait(walker: ContactWalker, guess, *, rate_scale=(1.0, 1.0),
                               warmup_steps: int = 8, xtol: float = 1e-8,
                               residual_tol: float = 1e-8, fd_step: float = 1e-4,
                               check_fd: bool = True, method: str = "odeint",
                               rtol: float = 1e-12, atol: float = 1e-14,
                               jac_rtol: float = 1e-12, jac_atol: float = 1e-14,
                               coarse_rtol: float | None = 1e-10, coarse_atol: float = 1e-12,
                               coarse_xtol: float = 1e-6,
                               patch_spacing: float | None = None,
                               time_limit_s: float | None = None) -> ContactPeriodicGait:
    """Periodic gait of the compliant-contact walker and its Floquet multipliers.

    Parameters
    ----------
    walker : ContactWalker
        The contact walker (:meth:`walkerlab.models.contact.scene.ContactSetup.build`).
    guess : array_like
        Either a section state (n,) (:func:`section_coordinates`) or an ideal post-impact
        state (role order of the rigid walker, as ``solve_variant``; compass gait
        ``[th_swing, th_stance, w_swing, w_stance]``).
    rate_scale : (float, float)
        Multipliers on the swing and stance legs' rates of an ideal-state guess.
    warmup_steps : int
        Steps of the map iterated from the guess before root finding (the gait is stable,
        so this brings the guess into the Newton basin).
    xtol : float
        Relative tolerance of ``scipy.optimize.root`` (hybr) in scaled coordinates.
    residual_tol : float
        ``converged`` means the scaled residual is below this [-] (hybr may stop with "not
        making good progress" once it reaches the map's noise floor: ~2e-8 at rtol 1e-11,
        ~2e-10 at rtol 1e-12, measured on the paper's contact).
    fd_step : float
        Relative central-difference step (times :data:`SCALES`) of the final Jacobian [-]
        (the root finder's own Jacobians use ``10 * fd_step`` on the cheaper map).
    check_fd : bool
        Also compute the multipliers with ``fd_step * 3`` and ``/ 3`` (``multiplier_fd_spread``).
    method, rtol, atol : integrator settings of the map while root finding (``"odeint"``:
        scipy odeint with the section crossing found by brentq, 3-10x faster than the
        ``solve_ivp`` methods "LSODA", "Radau", "BDF", which locate it as an event).
    jac_rtol, jac_atol : tolerances of the map for the final FD Jacobian.
    coarse_rtol, coarse_atol, coarse_xtol : two-fidelity search (used only when
        ``coarse_rtol`` is looser than ``rtol``; None: off).  The warm-up and a first hybr
        solve (``xtol = coarse_xtol``, forward-difference Jacobian) run on the map at
        ``coarse_rtol``; the final hybr solve at ``rtol`` starts from that fixed point with
        its Jacobian (a Newton direction accurate to the FD step, ~1e-3), so it needs only
        a few map evaluations at the tight tolerance.  Measured on the paper's contact
        (odeint, median CPU per map): 31 ms at rtol 1e-10, 130 ms at 1e-11, 114 ms at 1e-12.
    patch_spacing : float, optional
        Swing-patch distance ahead of the stance foot [m]; default the walker's lane spacing.
    time_limit_s : float, optional
        Wall-time limit of the whole search [s].

    Returns
    -------
    ContactPeriodicGait

    Raises
    ------
    PeriodicGaitError
        A step of the map fell, found no mid-stance, the solver failed, or the wall-time
        limit ran out (``kind`` says which).
    """
    wall = time.perf_counter()
    deadline = None if time_limit_s is None else wall + time_limit_s
    P = StepMap(walker, patch_spacing, method=method, rtol=rtol, atol=atol, deadline=deadline)
    scale = P.scale
    coarse = coarse_rtol is not None and coarse_rtol > rtol
    # the cheap map (coarse) brings the guess to ~its noise floor; the tight map polishes it
    PC = StepMap(walker, patch_spacing, method=method, rtol=coarse_rtol, atol=coarse_atol,
                 deadline=deadline) if coarse else P
    guess = np.asarray(guess, float)
    if guess.size == len(P.names):
        z = guess.copy()
    elif guess.size == walker.rigid_layout().size:
        z = section_guess_from_ideal(PC, guess, rate_scale)
    else:
        raise ValueError(f"guess must be a section state ({len(P.names)},) or an ideal state "
                         f"({walker.rigid_layout().size},)")
    hist = []
    for _ in range(warmup_steps):
        z1 = PC(z)[0]
        hist.append(float(np.max(np.abs((z1 - z) / scale))))
        z = z1

    def G_of(M):
        return _last_call_memo(lambda u: (M(u * scale)[0] - u * scale) / scale)

    def dG_of(M):
        return _last_call_memo(
            lambda u: fd_jacobian(lambda v: M(v)[0], u * scale, scale, 10 * fd_step,
                                  central=method != "odeint")
            * scale[None, :] / scale[:, None] - np.eye(len(scale)))

    root_nfev = 0
    jac = dG_of(P)
    if coarse:
        dGc = dG_of(PC)
        solc = root(G_of(PC), z / scale, jac=dGc, method="hybr", options={"xtol": coarse_xtol})
        root_nfev += solc.nfev
        z = solc.x * scale
        # the last Jacobian hybr asked for (near the coarse fixed point; the tight one is
        # ~1e-7 from it) steers every step of the tight solve: a Newton step then lands at
        # the tight map's noise floor, with no Jacobian at the tight tolerance
        Jc = dGc.last
        jac = lambda u: Jc  # noqa: E731

    sol = root(G_of(P), z / scale, jac=jac, method="hybr", options={"xtol": xtol})
    root_nfev += sol.nfev
    zs = sol.x * scale
    z1, T, ell = P(zs)
    res_si = z1 - zs
    PJ = P if (jac_rtol, jac_atol) == (rtol, atol) else \
        StepMap(walker, patch_spacing, method=method, rtol=jac_rtol, atol=jac_atol,
                deadline=deadline)
    FJ = lambda v: PJ(v)[0]  # noqa: E731
    J = fd_jacobian(FJ, zs, scale, fd_step)
    ev = _sorted_eig(J)
    spread = np.nan
    if check_fd:
        ev_lo = _sorted_eig(fd_jacobian(FJ, zs, scale, fd_step / 3))
        ev_hi = _sorted_eig(fd_jacobian(FJ, zs, scale, fd_step * 3))
        # compare the slow (|lambda| > 1e-3) multipliers; the fast ones are FD noise
        slow = np.abs(ev) > 1e-3
        spread = float(max(np.max(np.abs(ev_lo - ev)[slow], initial=0.0),
                           np.max(np.abs(ev_hi - ev)[slow], initial=0.0)))
    margin = P.patch_margin(zs)
    info = {"warmup_history": hist, "root_message": sol.message, "root_nfev": root_nfev,
            "fd_step": fd_step, "scales": scale, "method": method, "rtol": rtol, "atol": atol,
            "coarse_rtol": coarse_rtol if coarse else None, "coarse_map_evaluations": PC.nfev
            if coarse else 0, "patch_spacing_m": P.spacing}
    resid = float(np.max(np.abs(res_si / scale)))
    return ContactPeriodicGait(
        z=zs, fixed_point=dict(zip(P.names, map(float, zs))), period_s=T,
        step_length_m=ell, residual=resid, residual_si=res_si, jacobian=J, multipliers=ev,
        multiplier_fd_spread=spread, stable=bool(np.all(np.abs(ev) < 1)),
        converged=bool(resid < residual_tol), message=sol.message,
        nfev=P.nfev + (PJ.nfev if PJ is not P else 0) + (PC.nfev if coarse else 0),
        patch_margin_m=margin, full_state=P.to_state(zs),
        wall_time_s=time.perf_counter() - wall, info=info)


def simulate_from_periodic_gait(setup, x_ideal: np.ndarray, strides: int | None = None,
                                solver=None):  # setup: ContactSetup, solver: SolverSettings
    """Run the contact walker of a scene (its ``setup``,
    :func:`walkerlab.models.contact.scene.contact_setup`) from its own periodic gait
    (``contact_sim.start: periodic_gait``): steady state, no start-up transient.

    The gait is found from the ideal fixed point ``x_ideal``
    (:func:`walkerlab.analysis.contact_periodic.find_contact_periodic_gait`, within
    ``contact_sim.periodic_time_limit_s``); the run starts at its mid-stance section (leg2
    stance, stance foot at s = 0) on patches spaced by the gait's step length, so every
    footfall lands where the gait's does, and runs ``(2 strides + 1)`` gait periods.

    Returns
    -------
    walker, result, x0, step_length, gait
        As :func:`walkerlab.analysis.contact_sim.simulate_from`, plus the
        :class:`ContactPeriodicGait` started from.

    Raises
    ------
    walkerlab.analysis.contact_periodic.PeriodicGaitError
        The periodic gait was not found (fell, no mid-stance, solver failure, time limit).
    """
    from walkerlab.analysis.contact_sim import scene_start, simulate_contact

    cs, sv = setup.sim, solver or setup.solver
    n_strides = strides or cs.n_strides
    probe, _, limits, _ = scene_start(setup, x_ideal, n_strides)
    gait = find_contact_periodic_gait(probe, x_ideal, time_limit_s=cs.periodic_time_limit_s)
    walker, step_length = setup.build(x_ideal, 2 * n_strides, step_length_m=gait.step_length_m)
    x0 = np.asarray(gait.full_state, float)
    t_final = cs.t_final_s or (2 * n_strides + 1) * gait.period_s
    res = simulate_contact(walker, x0, t_final, sv, limits,
                           max_heel_strikes=2 * n_strides + 1 if cs.stop_after_strides else None)
    return walker, res, x0, step_length, gait
