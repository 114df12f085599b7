"""The compliant-contact walker's own periodic gait: fixed point of a mid-stance step map.

The step map, its section coordinates and the footfall-relative terrain live in
:mod:`walkerlab.analysis.contact.step_map`.

Floquet multipliers
-------------------
Eigenvalues of the n x n Jacobian of ``P`` (n = 6, kneed 10) at the fixed point, by central
finite differences in scaled coordinates: step ``h = fd_step`` (default 1e-4) times the
coordinate scale (:data:`SCALES`: 1 rad, 1 rad/s, 1 rad/s, static penetration ~6e-5 m, 1
mm/s, 1 mm/s; kneed: every angle 1 rad, every rate 1 rad/s), with the map integrated at rtol
1e-12 / atol 1e-14 (CyRK's BDF over the compiled RHS; the step map's Jacobian from the
variational equations agrees to ~1e-5 scaled, :mod:`walkerlab.analysis.contact.variational`).
Measured on the paper's contact: the map's noise (adaptive-step jitter)
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
:func:`walkerlab.analysis.contact.rigid_limit.convergence` follows this gait along it.
"""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import root

from walkerlab.analysis.contact.sim import scene_start, simulate_contact
from walkerlab.analysis.contact.step_map import (
    PeriodicGaitError,
    SearchBudget,
    StepMap,
    section_guess_from_ideal,
)
from walkerlab.analysis.gait.zero_dynamics import zero_dynamics
from walkerlab.config import FixedPointSettings
from walkerlab.integrate.contact_grid import GRID_METHODS
from walkerlab.integrate.solver import Solver
from walkerlab.io.schemas.continuation import initial_state
from walkerlab.models.contact.model import ContactWalker
from walkerlab.models.contact.parts import contact_part
from walkerlab.models.contact.powered_data import powered_data
from walkerlab.numerics import fd_jacobian, sort_multipliers

#: the step map's integrator while root finding and for the final Jacobian (CyRK's BDF over
#: the compiled right-hand side, :func:`walkerlab.integrate.contact_grid.contact_grid`)
MAP_SOLVER = Solver("cyrk_bdf", 1e-12, 1e-14)
#: the cheap map of the two-fidelity search
COARSE_SOLVER = Solver("cyrk_bdf", 1e-10, 1e-12)

#: the map of a walker whose torque laws are no compiled data (a replay's Python callables:
#: the powered contact integrator on solve_ivp with a Python right-hand side, looser than
#: the passive map's) and its cheap map; laws that are data run on :data:`MAP_SOLVER`
POWERED_MAP_SOLVER = Solver("LSODA", 1e-10, 1e-12)
POWERED_COARSE_SOLVER = Solver("LSODA", 1e-8, 1e-10)

__all__ = ["COARSE_SOLVER", "MAP_SOLVER", "POWERED_COARSE_SOLVER", "POWERED_MAP_SOLVER",
           "ContactPeriodicGait", "converged_gait", "find_contact_periodic_gait",
           "ideal_gait", "search_bounds", "simulate_from_periodic_gait"]


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
        period on a periodic orbit; a stride map's mean step).
    step_length_m : float
        Along-slope advance of the stance foot per step [m] (a stride map's mean step).
    residual : float
        max ``|(P(z) - z) / scale|`` (scaled, see :data:`SCALES`) [-].
    residual_si : ndarray (n,)
        P(z) - z in SI units.
    jacobian : ndarray (n, n)
        dP/dz in SI (rows/cols in the section's order).
    multipliers : ndarray (n,) complex
        Floquet multipliers of the map (:attr:`steps_per_map` steps), sorted by decreasing
        modulus.
    multiplier_fd_spread : float
        max change of the slow (``|lambda|`` > 1e-3) sorted multipliers when the FD step is
        multiplied or divided by 3.
    stable : bool
        All ``|multipliers|`` < 1.
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
    steps_per_map : int
        Steps of the map (:attr:`walkerlab.models.contact.model.ContactWalker.steps_per_map`:
        1, a step with the legs' roles swapped; 2, a stride, in 3D).
    multiplier_modes : tuple of str
        For each multiplier, the section coordinate its eigenvector moves most (scaled by
        :data:`SCALES`): ``"heading"`` for a walker in 3D's near-neutral heading mode.
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
    steps_per_map: int = 1
    multiplier_modes: tuple = ()

    @property
    def max_multiplier(self) -> float:
        """Largest ``|multiplier|`` [-]."""
        return float(np.max(np.abs(self.multipliers)))


def converged_gait(gait: ContactPeriodicGait) -> ContactPeriodicGait:
    """``gait`` if its search converged (scaled residual below the search's
    ``residual_tol``), for the callers that start from the gait or hand it on as found
    (``contact_sim.start: periodic_gait``, ``periodic_gait: true``,
    :meth:`walkerlab.api.walker.ContactWalker.periodic_gait`, the rough-ground start): an
    unconverged state's period and Floquet multipliers (the finite-difference Jacobian of
    the map away from its fixed point) are no gait's.

    Raises
    ------
    walkerlab.analysis.contact.step_map.PeriodicGaitError
        ``kind`` "not_converged": one line with the residual, the tolerance and the root
        finder's message.
    """
    if gait.converged:
        return gait

    tol = gait.info.get("residual_tol", float("nan"))
    # the root finder's message, to its first clause ("The iteration is not making good
    # progress, as measured by ..."): the line stays whole on the terminal
    why = " ".join(str(gait.info.get("root_message", gait.message)).split()).split(",")[0]
    raise PeriodicGaitError("not_converged", f"the fixed-point search did not converge "
                            f"(scaled residual {gait.residual:.3g} > {tol:g}: {why})")


def ideal_gait(scene, plant):
    """The rigid (derived) periodic gait of ``scene`` from its ``fixedpoint`` section
    (``plant``: the scene's :class:`~walkerlab.walker.plant.Plant`, from the caller).

    Returns
    -------
    walkerlab.analysis.gait.search result (``x`` role-order post-impact state, ``period_s``, ...)

    Raises
    ------
    GaitNotFound
        No ideal gait (a scene without a ``fixedpoint`` section searches from scale-free
        seeds).
    """
    from walkerlab.analysis.gait.search import find_gaits
    from walkerlab.models.registry import build_walker

    sc = scene.model_copy(update={"ideal": scene.ideal.model_copy(update={"variant": "derived"})})

    fp = sc.fixedpoint or FixedPointSettings()  # every field optional: the defaults
    iw = build_walker(plant.with_(sc))  # the variant changes the equations, not the description
    guess = None if fp.initial_guess is None else initial_state(fp.initial_guess,
                                                                iw.state_names())
    ctrl = getattr(getattr(iw, "actuators", None), "controller", None) if guess is None \
        else None
    if ctrl is not None:  # virtual constraints: from their zero dynamics' orbit, as
        # walkerlab fixedpoint starts (seeds off the constraint surface can leave the
        # controller's domain: a math domain error in its flow)
        zd = zero_dynamics(ctrl)
        guess = zd.x_plus if zd.exists else None
    return find_gaits(iw, Solver.from_settings(sc.solver), guess,
                      policy=fp.gait, other_gait=False, partner_if_needed=fp.other_gait,
                      xtol=fp.tolerance,
                      fd_step=fp.fd_step, max_step_time=fp.max_step_time_s).result


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


def search_bounds(sim) -> dict:
    """The bounds a scene's ``contact_sim`` section (``sim``,
    :class:`walkerlab.config.contact_sim.ContactSimSettings`) sets on its periodic-gait
    search, as :func:`find_contact_periodic_gait`'s keywords: ``max_step_maps``
    (``periodic_max_step_maps``, work) and ``time_limit_s`` (``periodic_time_limit_s``, an
    optional wall-clock limit)."""
    return {"max_step_maps": getattr(sim, "periodic_max_step_maps", None),
            "time_limit_s": getattr(sim, "periodic_time_limit_s", None)}


def find_contact_periodic_gait(walker: ContactWalker, guess, *, rate_scale=(1.0, 1.0),
                               warmup_steps: int = 8, xtol: float = 1e-8,
                               residual_tol: float = 1e-8, fd_step: float = 1e-4,
                               check_fd: bool = True, solver: Solver = MAP_SOLVER,
                               jacobian_solver: Solver = MAP_SOLVER,
                               coarse_solver: Solver | None = COARSE_SOLVER,
                               coarse_xtol: float = 1e-6,
                               patch_spacing: float | None = None,
                               time_limit_s: float | None = None,
                               max_step_maps: int | None = None) -> ContactPeriodicGait:
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
    solver : walkerlab.integrate.solver.Solver
        The map's integrator while root finding (:data:`MAP_SOLVER`: ``"cyrk_bdf"``, CyRK's
        BDF over the compiled right-hand side with the section crossing found by brentq;
        ``"odeint"`` the same through scipy's odeint and a Python RHS;
        the ``solve_ivp`` methods "LSODA", "Radau", "BDF" locate it as an event).  A
        powered walker's step runs on compiled segments with ``"cyrk_bdf"``
        (:mod:`walkerlab.integrate.contact_powered_step`); one whose torque laws are no
        compiled data (a replay's Python callables) defaults to :data:`POWERED_MAP_SOLVER`
        (its map is Python throughout).
    jacobian_solver : walkerlab.integrate.solver.Solver
        The map's integrator for the final FD Jacobian (same method as ``solver``).
    coarse_solver : walkerlab.integrate.solver.Solver or None
        Two-fidelity search (used only when its ``rtol`` is looser than ``solver``'s; None:
        off).  The warm-up and a first hybr solve (``xtol = coarse_xtol``,
        forward-difference Jacobian) run on the map at its tolerances; the final hybr
        solve at ``solver.rtol`` starts from that fixed point with
        its Jacobian (a Newton direction accurate to the FD step, ~1e-3), so it needs only
        a few map evaluations at the tight tolerance.
    patch_spacing : float, optional
        Swing-patch distance ahead of the stance foot [m]; default the walker's lane spacing.
    time_limit_s : float, optional
        Wall-clock limit of the whole search [s] (a search it ends depends on the machine's
        speed: kind ``time_limit``).
    max_step_maps : int, optional
        Work bound of the whole search: the most step-map integrations
        (:class:`~walkerlab.analysis.contact.step_map.SearchBudget`; kind ``work_limit``).

    Returns
    -------
    ContactPeriodicGait

    Raises
    ------
    PeriodicGaitError
        A step of the map fell, found no mid-stance, the solver failed, the work bound or
        the wall-clock limit ran out (``kind`` says which).
    """
    wall = time.perf_counter()
    budget = SearchBudget(max_step_maps, np.inf if time_limit_s is None else wall + time_limit_s)
    solver, jacobian_solver, coarse_solver = _map_solvers(walker, solver, jacobian_solver,
                                                          coarse_solver)
    P, PC, coarse = _step_maps(walker, patch_spacing, solver, coarse_solver, budget)
    z, hist = _warm_up_guess(walker, P, PC, guess, rate_scale, warmup_steps)
    sol, root_nfev = _solve_fixed_point(P, PC, coarse, z, solver.method, fd_step, xtol,
                                        coarse_xtol, residual_tol)
    return _periodic_gait_result(
        walker, P, PC, coarse, sol, root_nfev, hist, solver=solver,
        coarse_solver=coarse_solver, jacobian_solver=jacobian_solver,
        patch_spacing=patch_spacing, budget=budget, fd_step=fd_step, check_fd=check_fd,
        residual_tol=residual_tol, wall=wall)


def _map_solvers(walker: ContactWalker, solver, jacobian_solver, coarse_solver):
    """The map's solvers (:func:`find_contact_periodic_gait`): a walker with torque laws that
    are no compiled data (:func:`~walkerlab.models.contact.powered_data.powered_data`: a
    replay's Python callables) has the whole map in Python, so the defaults become the
    looser :data:`POWERED_MAP_SOLVER` and :data:`POWERED_COARSE_SOLVER`; laws that are data
    run on the compiled map (:mod:`walkerlab.integrate.contact_powered_step`) at the passive
    map's tolerances; a kind whose map has tolerances of its own
    (:attr:`walkerlab.models.contact.parts.ContactPart.map_tolerances`: a walker in 3D) has
    them in place of :data:`MAP_SOLVER`'s; a solver given stays."""
    tol = contact_part(walker.structure).map_tolerances  # the kind's map (a walker in 3D)
    if tol != (MAP_SOLVER.rtol, MAP_SOLVER.atol):
        own = dataclasses.replace(MAP_SOLVER, rtol=tol[0], atol=tol[1])
        solver = own if solver is MAP_SOLVER else solver
        jacobian_solver = own if jacobian_solver is MAP_SOLVER else jacobian_solver
    acts = getattr(walker, "actuators", None)
    if acts is not None and acts.laws and powered_data(walker) is None:  # Python laws
        solver = POWERED_MAP_SOLVER if solver is MAP_SOLVER else solver
        jacobian_solver = POWERED_MAP_SOLVER if jacobian_solver is MAP_SOLVER else jacobian_solver
        coarse_solver = (POWERED_COARSE_SOLVER if coarse_solver is COARSE_SOLVER
                         else coarse_solver)
    return solver, jacobian_solver, coarse_solver


def _step_maps(walker: ContactWalker, patch_spacing, solver, coarse_solver,
               budget: SearchBudget):
    """The step map on ``solver`` and the cheap one on ``coarse_solver`` (the same method) when
    its ``rtol`` is looser (else the map itself): ``(P, PC, coarse)``, both charged to the
    search's ``budget``."""
    method = solver.method
    P = StepMap(walker, patch_spacing, solver, budget=budget)
    coarse = coarse_solver is not None and coarse_solver.rtol > solver.rtol
    # the cheap map (coarse) brings the guess to ~its noise floor; the tight map polishes it
    PC = StepMap(walker, patch_spacing, dataclasses.replace(coarse_solver, method=method),
                 budget=budget) if coarse else P
    return P, PC, coarse


def _warm_up_guess(walker: ContactWalker, P: StepMap, PC: StepMap, guess, rate_scale,
                   warmup_steps: int) -> tuple[np.ndarray, list[float]]:
    """The warm-up of :func:`find_contact_periodic_gait`: the guess as a section state (a
    section state as given, an ideal post-impact state through
    :func:`section_guess_from_ideal` on the cheap map ``PC``), then ``warmup_steps`` steps of
    ``PC`` from it; returns the state reached and the scaled change of each step (the
    ``warmup_history``).  Raises ValueError for a guess of neither size."""
    scale = P.scale
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
    return z, hist


def _scaled_residual(M: StepMap, scale: np.ndarray):
    """``G(u) = (M(u * scale) - u * scale) / scale``, the scaled fixed-point residual of the
    step map ``M`` that ``scipy.optimize.root`` zeroes (memoised on its last argument, see
    :func:`_last_call_memo`)."""
    return _last_call_memo(lambda u: (M(u * scale)[0] - u * scale) / scale)


def _scaled_residual_jacobian(M: StepMap, scale: np.ndarray, fd_step: float, method: str):
    """dG/du of :func:`_scaled_residual` by finite differences of step ``10 * fd_step`` times
    ``scale`` (forward differences when ``method`` is a grid method, ``"cyrk_bdf"`` or
    ``"odeint"``, central otherwise), the root finder's Jacobian; memoised on its last
    argument, its last value kept as ``.last``."""
    return _last_call_memo(
        lambda u: fd_jacobian(lambda v: M(v)[0], u * scale, 10 * fd_step * scale,
                              central=method not in GRID_METHODS)
        * scale[None, :] / scale[:, None] - np.eye(len(scale)))


def _solve_fixed_point(P: StepMap, PC: StepMap, coarse: bool, z: np.ndarray, method: str,
                       fd_step: float, xtol: float, coarse_xtol: float,
                       residual_tol: float = np.inf):
    """The two-fidelity root solve of :func:`find_contact_periodic_gait` from the warmed-up
    state ``z``: with ``coarse``, a hybr solve on the cheap map ``PC`` to ``coarse_xtol``
    whose last Jacobian then steers every step of the tight solve on ``P`` (a Newton step
    lands at the tight map's noise floor with no Jacobian at the tight tolerance); without
    it, one hybr solve on ``P`` with its own FD Jacobians; then, while the scaled residual
    is above ``residual_tol``, up to three Newton steps with the last Jacobian.  Returns
    the tight solve's ``OptimizeResult`` (``x`` in scaled coordinates) and the function
    evaluations of both (``method``: the maps' integrator, which picks the FD Jacobians'
    differences)."""
    scale = P.scale
    root_nfev = 0
    jac = _scaled_residual_jacobian(P, scale, fd_step, method)
    if coarse:
        dGc = _scaled_residual_jacobian(PC, scale, fd_step, method)
        solc = root(_scaled_residual(PC, scale), z / scale, jac=dGc, method="hybr",
                    options={"xtol": coarse_xtol})
        root_nfev += solc.nfev
        z = solc.x * scale
        # the last Jacobian hybr asked for (near the coarse fixed point; the tight one is
        # ~1e-7 from it) steers every step of the tight solve: a Newton step then lands at
        # the tight map's noise floor, with no Jacobian at the tight tolerance
        Jc = dGc.last
        jac = lambda u: Jc  # noqa: E731

    G = _scaled_residual(P, scale)
    sol = root(G, z / scale, jac=jac, method="hybr", options={"xtol": xtol})
    root_nfev += sol.nfev
    # hybr's step test (xtol) may stop above the residual asked for: up to three Newton
    # steps with the same Jacobian, each kept only if it lowers the residual
    for _ in range(3):
        r = G(sol.x)
        if np.max(np.abs(r)) < residual_tol:
            break
        u = sol.x - np.linalg.solve(jac(sol.x), r)
        root_nfev += 1
        if np.max(np.abs(G(u))) >= np.max(np.abs(r)):
            break
        sol.x = u
    return sol, root_nfev


def _floquet_multipliers(walker: ContactWalker, P: StepMap, zs: np.ndarray, solver: Solver,
                         jacobian_solver: Solver, patch_spacing, budget: SearchBudget,
                         fd_step: float,
                         check_fd: bool):
    """The final Jacobian of :func:`find_contact_periodic_gait` at the fixed point ``zs``:
    central differences of step ``fd_step * scale`` on the map at ``jacobian_solver``'s
    tolerances (``P`` itself when they equal ``solver``'s), its sorted eigenvalues (the
    Floquet multipliers) and, with ``check_fd``, the largest change of the slow (``|lambda|`` >
    1e-3) multipliers for the step times 3 and over 3 (NaN without).  Returns
    ``(PJ, J, multipliers, spread)``, ``PJ`` the map the Jacobian used."""
    scale = P.scale
    jac_solver = dataclasses.replace(jacobian_solver, method=solver.method)
    PJ = P if (jac_solver.rtol, jac_solver.atol) == (solver.rtol, solver.atol) else \
        StepMap(walker, patch_spacing, jac_solver, budget=budget)
    FJ = lambda v: PJ(v)[0]  # noqa: E731
    J = fd_jacobian(FJ, zs, fd_step * scale)
    ev = sort_multipliers(np.linalg.eigvals(J))
    spread = np.nan
    if check_fd:
        ev_lo = sort_multipliers(np.linalg.eigvals(fd_jacobian(FJ, zs, fd_step / 3 * scale)))
        ev_hi = sort_multipliers(np.linalg.eigvals(fd_jacobian(FJ, zs, fd_step * 3 * scale)))
        # compare the slow (|lambda| > 1e-3) multipliers; the fast ones are FD noise
        slow = np.abs(ev) > 1e-3
        spread = float(max(np.max(np.abs(ev_lo - ev)[slow], initial=0.0),
                           np.max(np.abs(ev_hi - ev)[slow], initial=0.0)))
    return PJ, J, ev, spread


def _periodic_gait_result(walker: ContactWalker, P: StepMap, PC: StepMap, coarse: bool, sol,
                          root_nfev: int, hist: list[float], *, solver: Solver,
                          coarse_solver: Solver | None, jacobian_solver: Solver,
                          patch_spacing, budget: SearchBudget, fd_step: float,
                          check_fd: bool,
                          residual_tol: float, wall: float) -> ContactPeriodicGait:
    """The result of :func:`find_contact_periodic_gait` from its root solve ``sol``: one step
    of the tight map from the fixed point (period, step length, residual), the Floquet
    multipliers (:func:`_floquet_multipliers`), the patch margin and the diagnostics
    (``info``), packed as a :class:`ContactPeriodicGait` (``wall`` is the search's start on
    ``time.perf_counter``; the keywords are the search's own arguments)."""
    scale, method = P.scale, solver.method
    zs = sol.x * scale
    z1, T, ell = P(zs)
    res_si = z1 - zs
    margin = P.patch_margin(zs)  # from the step just taken (the map keeps its last one)
    PJ, J, ev, spread = _floquet_multipliers(walker, P, zs, solver, jacobian_solver,
                                             patch_spacing, budget, fd_step, check_fd)
    info = {"warmup_history": hist, "root_message": sol.message, "root_nfev": root_nfev,
            "fd_step": fd_step, "scales": scale, "method": method, "rtol": solver.rtol,
            "atol": solver.atol, "coarse_rtol": coarse_solver.rtol if coarse else None,
            "coarse_map_evaluations": PC.nfev if coarse else 0, "patch_spacing_m": P.spacing,
            "residual_tol": residual_tol}
    resid = float(np.max(np.abs(res_si / scale)))
    return ContactPeriodicGait(
        z=zs, fixed_point=dict(zip(P.names, map(float, zs))), period_s=T,
        step_length_m=ell, residual=resid, residual_si=res_si, jacobian=J, multipliers=ev,
        multiplier_fd_spread=spread, stable=bool(np.all(np.abs(ev) < 1)),
        converged=bool(resid < residual_tol), message=sol.message,
        nfev=P.nfev + (PJ.nfev if PJ is not P else 0) + (PC.nfev if coarse else 0),
        patch_margin_m=margin, full_state=P.to_state(zs),
        wall_time_s=time.perf_counter() - wall, info=info, steps_per_map=P.steps,
        multiplier_modes=multiplier_modes(J, ev, P.names[:len(P.names) - P.walker.dim - 1]))


def multiplier_modes(J: np.ndarray, multipliers: np.ndarray, names) -> tuple:
    """The link coordinate (angle [rad] or rate [rad/s]) each Floquet multiplier's
    eigenvector moves most.

    Parameters
    ----------
    J : ndarray (n, n)
        The map's Jacobian in SI section coordinates (the link angles and rates first).
    multipliers : ndarray (n,) complex
        Its eigenvalues in the order wanted (sorted).
    names : sequence of str (k,)
        The names of the section's first k coordinates, the link angles and rates (the
        stance foot's penetration and velocities after them are left out: their fast modes
        are the contact's, and a slow mode moves them in other units).

    Returns
    -------
    tuple of str (n,)
    """
    w, V = np.linalg.eig(J)
    out = []
    for lam in multipliers:
        j = int(np.argmin(np.abs(w - lam)))
        out.append(str(names[int(np.argmax(np.abs(V[:len(names), j])))]))
    return tuple(out)

def simulate_from_periodic_gait(setup, x_ideal: np.ndarray, strides: int | None = None,
                                solver=None):  # setup: ContactSetup, solver: SolverSettings
    """Run the contact walker of a scene (its ``setup``,
    :func:`walkerlab.models.contact.scene.contact_setup`) from its own periodic gait
    (``contact_sim.start: periodic_gait``): steady state, no start-up transient.

    The gait is found from the ideal fixed point ``x_ideal``
    (:func:`walkerlab.analysis.contact.periodic.find_contact_periodic_gait`, within
    ``contact_sim.periodic_max_step_maps``, :func:`search_bounds`); the run starts at its
    mid-stance section (leg2 stance, stance foot at s = 0) on patches spaced by the gait's
    step length, so every footfall lands where the gait's does, and runs
    ``(2 strides + 1)`` gait periods.

    ``x_ideal`` (2n,): the rigid walker's post-impact fixed point (its ``state_names()``,
    [rad, rad/s]); the returned ``x0`` is the contact walker's full state (2 nq,)
    (``ContactWalker.state_names()``, [m, rad, m/s, rad/s]), ``step_length`` in [m].

    Returns
    -------
    walker, result, x0, step_length, gait
        As :func:`walkerlab.analysis.contact.sim.simulate_from`, plus the
        :class:`ContactPeriodicGait` started from.

    Raises
    ------
    walkerlab.analysis.contact.periodic.PeriodicGaitError
        The periodic gait was not found (fell, no mid-stance, solver failure, work bound,
        time limit, not converged: :func:`converged_gait`).
    """
    cs, sv = setup.sim, solver or setup.solver
    n_strides = strides or cs.n_strides
    probe, _, limits, _ = scene_start(setup, x_ideal, n_strides)
    gait = converged_gait(find_contact_periodic_gait(probe, x_ideal, **search_bounds(cs)))
    walker, step_length = setup.build(x_ideal, 2 * n_strides, step_length_m=gait.step_length_m)
    x0 = np.asarray(gait.full_state, float)
    t_final = cs.t_final_s or (2 * n_strides + 1) * gait.period_s
    res = simulate_contact(walker, x0, t_final, sv, limits,
                           max_heel_strikes=2 * n_strides + 1 if cs.stop_after_strides else None)
    return walker, res, x0, step_length, gait
