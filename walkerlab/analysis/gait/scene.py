"""The period-1 gait of a scene's rigid walker: the scene's solver and fixed-point settings
applied to :func:`walkerlab.analysis.gait.search.find_gaits`, and the other equation variants
of a compass gait compared with published numbers (what the ``fixedpoint`` stage stores).
"""

from __future__ import annotations

import math

from walkerlab.analysis.gait.checks import ground_contact
from walkerlab.analysis.gait.failure_text import no_energy_reason
from walkerlab.analysis.gait.friction import scene_friction
from walkerlab.analysis.gait.planar_start import planar_fallback
from walkerlab.analysis.gait.poincare import FixedPointNotFound, find_fixed_point
from walkerlab.analysis.gait.search import GaitNotFound, find_gaits
from walkerlab.analysis.gait.zero_dynamics import compare_full_order, zero_dynamics
from walkerlab.config import FixedPointSettings, Scene
from walkerlab.integrate.solver import Solver
from walkerlab.io.schemas.continuation import initial_state
from walkerlab.io.schemas.fixedpoint import FixedPointRun
from walkerlab.models.hybrid.printed_equations import VARIANTS
from walkerlab.models.hybrid.rolling_polygon import cannot_roll
from walkerlab.models.registry import build_walker
from walkerlab.units import for_scene
from walkerlab.walker.plant import Plant


def _settings(scene: Scene):
    """The scene's ``fixedpoint`` section; left out, its defaults (every field is optional:
    the gait is then found from scale-free seeds)."""
    return scene.fixedpoint if scene.fixedpoint is not None else FixedPointSettings()


def variants_for(scene: Scene, compare: bool) -> tuple[str, ...]:
    """The scene's own equation variant first, then (``compare``, for a compass gait compared
    with published numbers) the other variants: they explain the difference from Eq. 11."""
    own = (scene.ideal.variant,)
    if scene.walker.actuation is not None:  # the printed ones are passive
        return own
    if scene.terrain is not None and not scene.terrain.is_slope:  # ... and on the slope
        return own
    if compare and scene.walker.model == "compass_gait" and scene.published is not None:
        return own + tuple(v for v in VARIANTS if v != scene.ideal.variant)
    return own


def initial_guess(scene: Scene, walker):
    """The scene's initial guess by state name, or None (found automatically).

    Raises
    ------
    ValueError
        The guess does not name the walker's states, or is no walking state
        (:func:`check_walking_state`) (one line naming the field).
    """
    fp = _settings(scene)
    if fp.initial_guess is None:
        return None
    try:
        guess = initial_state(fp.initial_guess, walker.state_names())
    except ValueError as exc:
        raise ValueError(f"fixedpoint.initial_guess: {exc}") from None
    check_walking_state(guess, walker, scene)
    return guess


#: largest leg angular rate of an initial guess, in units of sqrt(g/l)
MAX_GUESS_RATE = 20.0


def check_walking_state(x, walker, scene: Scene) -> None:
    """Refuse a guess no walking gait is near, before the root finder spends minutes on it.

    A leg turning at ``omega`` needs a centripetal acceleration ``omega^2 l`` at its far end;
    above ``g`` the stance foot would leave the ground, so a walking gait has rates of the
    order of ``sqrt(g/l)`` (paper walker: 3.1 rad/s; its fixed point 0.86 rad/s).  Rates above
    :data:`MAX_GUESS_RATE` ``sqrt(g/l)`` (or angles beyond pi) send the map's integration
    into spinning legs (1e6 rad/s: a long run, then ``OverflowError``).

    Raises
    ------
    ValueError
        One line naming the field, its value and the bound.
    """
    g = walker.params.get("gravity_m_per_s2")
    length = walker.params.get("leg_length_m")
    if not g or not length:
        return
    max_rate = MAX_GUESS_RATE * math.sqrt(g / length)
    for name, v in zip(walker.state_names(), x, strict=True):
        if name.endswith("_rate") and abs(v) > max_rate:
            raise ValueError(
                f"fixedpoint.initial_guess.{name}_rad_per_s: {v:g} is not a walking state: "
                f"give at most {max_rate:.3g} {for_scene(scene).rate} ({MAX_GUESS_RATE:g} "
                "sqrt(g/l); a leg this fast would leave the ground)")
        if name.endswith("_angle") and abs(v) > math.pi:
            raise ValueError(f"fixedpoint.initial_guess.{name}_rad: {v:g} rad is more than "
                             "half a turn: give an angle within [-pi, pi]")


def with_variant(scene: Scene, variant: str) -> Scene:
    """The scene with ``ideal.variant`` set to ``variant``."""
    return scene.model_copy(update={"ideal": scene.ideal.model_copy(update={"variant": variant})})


def solve_scene(scene: Scene, fd_check: bool = True, guess=None, walker=None, solver=None,
                ground: bool = False, other_gait: bool | None = None,
                partner_off_ground: bool = False, nearby=None, *, plant: Plant):
    """The period-1 gait(s) of the scene's walker, chosen by ``fixedpoint.gait``, from
    ``guess`` (a state (2n,), e.g. a known gait carried here by homotopy) or else the
    scene's initial guess; ``walker`` (default: the scene's, ``build_walker``) another
    rigid model of it (a flat foot's without its double support).

    ``walker`` (a :class:`HybridWalker`) and ``solver`` (a
    :class:`~walkerlab.integrate.solver.Solver`) are the scene's model and integrator when
    the caller holds them already (the in-memory :class:`walkerlab.api.walker.Walker`);
    default: built here from the scene (:func:`build_walker`, ``Solver.from_settings``).
    ``plant`` (a :class:`~walkerlab.walker.plant.Plant`): the scene's walker described once,
    by the caller that holds it (a stage, the API, or one that has just made ``scene``).
    ``ground``: check every gait found for a ground that only pushes
    (:func:`gait_ground_contact`; each :class:`~walkerlab.analysis.gait.search.Gait` carries
    its verdict and the selection prefers the gaits that need no pull).  ``other_gait``
    (default ``fixedpoint.other_gait``): look for the other gait of the pair even when the
    choice does not need it (the scene's ``fixedpoint.other_gait: false``: not even when it
    does, :func:`~walkerlab.analysis.gait.search.find_gaits` ``partner_if_needed``);
    ``partner_off_ground``: without it, still when the first gait
    needs a pull or more friction than the ground has
    (:func:`~walkerlab.analysis.gait.search.find_gaits`).

    Without ``guess``, when the scene's initial guess does not converge (it may be the gait
    of other parameters) or the scene has none, the root finder is started, before the
    scale-free seeds, from ``nearby`` (a
    :class:`~walkerlab.analysis.gait.starts.FallbackStart`, e.g. a stored gait of a walker
    nearby carried here: :func:`walkerlab.studies.warm_start.stored_gait_start`) and then,
    for a 3D walker, from its planar twin's gait carried in hip width
    (:func:`~walkerlab.analysis.gait.planar_start.planar_fallback`).  A guess that
    converges takes the search as before: no fallback is built further than its label.

    Returns
    -------
    walker : HybridWalker
    search : walkerlab.analysis.gait.search.GaitSearch

    Raises
    ------
    GaitNotFound
        No gait (one line: what was tried, what to try next).
    ValueError
        A malformed initial guess or gait choice, or no ``fixedpoint`` section (one line).
    """
    fp = _settings(scene)
    if scene.terrain is None or scene.terrain.is_slope:  # a wheel that cannot roll: at once
        why = cannot_roll(plant.data)
        if why is not None:
            raise GaitNotFound(why, math.nan)
    walker = build_walker(plant.with_(scene)) if walker is None else walker
    solver = Solver.from_settings(scene.solver) if solver is None else solver
    start = initial_guess(scene, walker) if guess is None else guess
    if start is None:  # virtual constraints: the zero dynamics' periodic orbit, if any
        start = hzd_start(walker)

    def search_from(x, fallbacks):
        return find_gaits(walker, solver, x, policy=fp.gait,
                          other_gait=fp.other_gait if other_gait is None else other_gait,
                          xtol=fp.tolerance, fd_step=fp.fd_step,
                          max_step_time=fp.max_step_time_s, fd_check=fd_check,
                          ground_check=(lambda x: gait_ground_contact(scene, walker, x, plant))
                          if ground else None, partner_off_ground=partner_off_ground,
                          partner_if_needed=fp.other_gait, fallbacks=fallbacks)

    fallbacks = []  # when the scene's own guess fails (or it has none), before the seeds
    if guess is None and not no_energy_reason(walker):  # (none where no gait can be)
        if nearby is not None:  # a gait stored nearby, carried here
            fallbacks.append(nearby)
        planar = planar_fallback(scene, walker, solver,
                                 plant=plant)  # a 3D walker: from its planar twin
        if planar is not None:
            fallbacks.append(planar)
    return walker, search_from(start, fallbacks)


def controller(walker):
    """The walker's virtual-constraint controller
    (:class:`walkerlab.models.hybrid.virtual_constraints.VirtualConstraintController`), or
    None."""
    return getattr(getattr(walker, "actuators", None), "controller", None)


def hzd_start(walker):
    """The post-impact state of the hybrid zero dynamics' periodic orbit (a walker under
    virtual constraints whose restricted map has a fixed point), else None."""
    ctrl = controller(walker)
    if ctrl is None:
        return None

    zd = zero_dynamics(ctrl)
    return zd.x_plus.copy() if zd.exists else None


def solve_variant(scene: Scene, variant: str, guess=None, *, plant: Plant):
    """Fixed point of one equation variant of the scene's walker, from ``guess`` (default:
    the scene's initial guess) - for the comparison of printed equations.  ``plant``: the
    scene's :class:`~walkerlab.walker.plant.Plant` (the variant does not change it).

    Raises
    ------
    FixedPointNotFound
        No fixed point from the guess (or no guess).
    """
    sc = with_variant(scene, variant)
    walker = build_walker(plant.with_(sc))
    fp = _settings(scene)
    g = initial_guess(scene, walker) if guess is None else guess
    if g is None:
        raise FixedPointNotFound("no initial guess for this equation variant", math.nan)
    res = find_fixed_point(walker, g, Solver.from_settings(scene.solver),
                           xtol=fp.tolerance, fd_step=fp.fd_step, max_step_time=fp.max_step_time_s)
    return walker, res


def fixed_point_run(scene: Scene, compare_variants: bool = True, guess=None,
                    note: str | None = None, nearby=None, *, plant: Plant):
    """The period-1 gait of the scene's own equation variant and, with ``compare_variants``
    (a compass gait compared with published numbers), the fixed points of the other
    variants from the same start - what the ``fixedpoint`` artifact stores.

    Parameters
    ----------
    guess : ndarray (2n,), optional
        Start of the root finder (a known gait carried here by homotopy,
        :func:`walkerlab.studies.continuation.homotopy_start`); default the scene's initial
        guess or the scale-free seeds.
    note : str, optional
        How ``guess`` was found, added to the search's notes.
    nearby : FallbackStart, optional
        A start tried when the scene's own guess fails (:func:`solve_scene`).
    plant : walkerlab.walker.plant.Plant
        The scene's walker described once (by the stage).

    Returns
    -------
    run : walkerlab.io.schemas.fixedpoint.FixedPointRun
        The writer's input; a variant without a fixed point holds its
        :class:`~walkerlab.analysis.gait.poincare.FixedPointNotFound`.
    summary : dict
        ``walker``, ``result`` (the selected gait), ``gaits`` (the search), ``variants``,
        ``ground_contact`` (:func:`gait_ground_contact` of the selected gait).

    Raises
    ------
    GaitNotFound
        No gait for the scene's own variant (one line).
    ValueError
        A malformed initial guess or gait choice (one line).
    """
    walker, search = solve_scene(scene, guess=guess, ground=True, nearby=nearby, plant=plant)
    if note:
        search.notes.append(note)
    main = search.result
    results = {scene.ideal.variant: (walker, main)}
    init = initial_guess(scene, walker)
    other_guess = main.x if init is None else init
    for variant in variants_for(scene, compare_variants)[1:]:
        try:
            results[variant] = solve_variant(scene, variant, other_guess, plant=plant)
        except FixedPointNotFound as exc:
            results[variant] = exc
    ground = search.gait.ground  # every gait found carries its check (solve_scene)
    treads = None
    if scene.terrain is not None and scene.terrain.kind == "stairs":
        from walkerlab.analysis.gait.treads import tread_landing  # light

        treads = tread_landing(walker, main.x, scene.terrain, Solver.from_settings(scene.solver))
    hzd = None
    if controller(walker) is not None:  # virtual constraints: the restricted map too

        hzd = zero_dynamics(controller(walker))
        compare_full_order(hzd, controller(walker), walker, main,
                           Solver.from_settings(scene.solver))
    run = FixedPointRun(walker, search, results, scene.ideal.variant, other_guess, ground,
                        treads, hzd)
    summary = {"walker": walker, "result": main, "gaits": search, "variants": dict(results),
               "ground_contact": ground, "footholds": treads, "zero_dynamics": hzd}
    return run, summary


def gait_ground_contact(scene: Scene, walker, x, plant: Plant):
    """Whether the gait from ``x`` (the scene's walker's fixed point) needs only a ground that
    pushes, and the friction it needs against the scene's ``mu``
    (:func:`walkerlab.analysis.gait.checks.ground_contact`, with the scene's solver;
    :func:`walkerlab.analysis.gait.friction.scene_friction`).

    ``plant``: the scene's :class:`~walkerlab.walker.plant.Plant`.

    Returns
    -------
    walkerlab.analysis.gait.checks.GroundContact
    """
    mu, mu_source = scene_friction(scene)
    return ground_contact(walker, plant.data, x,
                          Solver.from_settings(scene.solver), mu=mu, mu_source=mu_source)
