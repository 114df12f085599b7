"""Map a scene's ``walker`` section to a hybrid walker (the only place that knows the list)."""

from __future__ import annotations

from dataclasses import replace

from walkerlab.models.hybrid.actuated import actuate
from walkerlab.models.hybrid.base import HybridWalker
from walkerlab.models.hybrid.ground import foothold_steps, landing_drop, on_footholds, on_landing
from walkerlab.models.hybrid.printed_equations import make_compass_gait
from walkerlab.models.hybrid.rigid import make_rigid_walker
from walkerlab.walker.description import state_names, state_units
from walkerlab.walker.plant import Plant


def state_layout(plant: Plant) -> tuple[list[str], list[str]]:
    """State names and units of the rigid walker of the plant's scene, from its description
    alone (no equations derived, no code loaded): what :func:`build_walker` ``(plant)``'s
    ``state_names()`` and ``state_units()`` return.

    Parameters
    ----------
    plant : walkerlab.walker.plant.Plant
        The scene's walker, described once by the caller.

    Returns
    -------
    names, units : list of str, length 2n
    """
    roles = plant.structure.roles
    return state_names(roles), state_units(roles)


def build_walker(plant: Plant) -> HybridWalker:
    """Build the rigid hybrid walker of a plant's scene (its
    :attr:`~walkerlab.walker.plant.Plant.scene`, a :class:`~walkerlab.config.Scene`).

    ``model: compass_gait`` (paper Table 1) supports the printed-equation variants
    (``ideal.variant``); ``model: biped`` is any walker described as data, derived
    symbolically (variant ``derived`` only), as is ``model: rimless_wheel``: each reached
    through its kind (:data:`walkerlab.models.hybrid.rigid.BUILDERS`; a spoked wheel is the
    rolling polygon, :mod:`walkerlab.models.hybrid.rolling_polygon`).

    A ``walker.actuation`` section adds its actuators (:func:`walkerlab.models.hybrid.
    actuated.actuate`).

    Parameters
    ----------
    plant : walkerlab.walker.plant.Plant
        The scene's walker described once: by a stage or the API
        (:meth:`~walkerlab.walker.plant.Plant.from_scene`), or for a neighbouring scene (a
        sweep's point) from the plant handed down (:meth:`~walkerlab.walker.plant.Plant.
        with_`).  Its ``scene`` decides the slope, the ground, the variant and the actuators.

    Returns
    -------
    HybridWalker

    Raises
    ------
    ValueError
        The scene names a walker model or variant that has no rigid hybrid implementation,
        or actuators the walker cannot carry (one line).
    """
    scene = plant.scene
    act = scene.walker.actuation
    walker = _on_ground(scene, plant, _passive(scene, plant))
    if act is None or walker.cycle is not None:  # footholds: each step's walker actuated
        return walker

    if scene.ideal.variant != "derived":
        raise ValueError("walker.actuation: only with ideal.variant: derived (the printed "
                         "Appendix A equations are passive)")
    return actuate(walker, plant.data, act)


def _on_ground(scene, plant: Plant, walker: HybridWalker) -> HybridWalker:
    """The walker on the scene's ``terrain`` (stairs: the heel strike at the next tread,
    :func:`walkerlab.models.hybrid.ground.on_landing`); a slope: ``walker`` itself."""
    steps = foothold_steps(scene.terrain, scene.slope.phi_rad)
    if steps is not None:  # footholds that differ from step to step
        return _on_footholds(scene, plant, walker, steps, on_footholds)
    drop = landing_drop(scene.terrain)
    if drop != 0.0:
        if walker.variant != "derived":
            raise ValueError("terrain.kind: stairs and footholds need ideal.variant: derived "
                             "(the printed Appendix A equations know only the slope)")
        walker = on_landing(walker, plant.data, drop)
    t = scene.terrain
    if t is not None and t.kind == "footholds" and t.periodic is False:
        # footholds of one height that do not repeat: the gait is the one-step map's, the
        # walk ends after the list (as for footholds that differ, on_footholds)
        walker = replace(walker, ground_steps=len(t.foothold_heights_m))
    return walker


def passive_walker_at(plant: Plant):
    """``(walker_at, data_at)``: ``slope [rad] -> HybridWalker`` (the plant's scene's passive
    rigid walker on that slope, the scene's own at its slope) and ``slope -> WalkerData``
    (:meth:`walkerlab.walker.plant.Plant.data_at` of ``plant``)."""
    scene = plant.scene
    own = {}

    def at(g: float) -> HybridWalker:
        if g == scene.slope.phi_rad:
            if "w" not in own:
                own["w"] = _passive(scene, plant)
            return own["w"]
        return _passive_on(scene, plant, g)

    return at, plant.data_at


def _passive_on(scene, plant: Plant, g: float) -> HybridWalker:
    """The scene's passive walker on a slope of ``g`` [rad]."""
    return _passive(scene.model_copy(update={"slope": scene.slope.model_copy(
        update={"angle_rad": float(g), "angle_deg": None})}), plant, float(g))


def build_walker_on_steps(plant: Plant, steps) -> HybridWalker:
    """The plant's scene's rigid walker on a finite list of per-step grounds (a drawn rough
    ground, ``simulate --terrain-seed``): step ``k`` lands ``steps[k][0]`` [m] below the
    stance foot's level on ground of slope ``steps[k][1]`` [rad]; the walk ends after the
    list (:func:`walkerlab.models.hybrid.ground.on_footholds`).  ``plant``: the scene's
    :class:`~walkerlab.walker.plant.Plant`.

    Raises
    ------
    ValueError
        A ground other than the slope under it, or a walker that cannot walk it (one line).
    """
    scene = plant.scene
    if scene.terrain is not None and not scene.terrain.is_slope:
        raise ValueError(f"terrain.kind: {scene.terrain.kind}: per-step draws are of a slope "
                         "(terrain.per_step on kind: slope)")
    return _on_footholds(scene, plant, _passive(scene, plant), steps, on_footholds,
                         periodic=False)


def _on_footholds(scene, plant: Plant, walker: HybridWalker, steps, on_footholds,
                  periodic: bool | None = None) -> HybridWalker:
    """The walker on footholds of several heights or slopes (``on_footholds``:
    :func:`walkerlab.models.hybrid.ground.on_footholds`), each slope's walker built as the
    scene's on that slope."""
    if walker.variant != "derived":
        raise ValueError("terrain.kind: footholds need ideal.variant: derived (the printed "
                         "Appendix A equations know only the slope)")
    plant.kind.require(
        "footholds", "rigid", "terrain.kind")
    finish = None
    act = scene.walker.actuation
    if act is not None:  # every step's walker carries the actuators
        if scene.ideal.variant != "derived":
            raise ValueError("walker.actuation: only with ideal.variant: derived (the "
                             "printed Appendix A equations are passive)")

        def finish(w, d):
            return actuate(w, d, act)

    def at(g: float) -> HybridWalker:
        if g == scene.slope.phi_rad:
            return walker
        return _passive_on(scene, plant, g)

    if periodic is None:
        periodic = scene.terrain.periodic is not False
    return on_footholds(at, plant.data_at, steps, periodic, finish)


def _passive(scene, plant: Plant, slope_rad: float | None = None) -> HybridWalker:
    """The passive walker of the scene (its actuators left out), on its slope or, given
    ``slope_rad`` (``scene``'s own, a copy of the plant's scene on another slope), on
    ``slope_rad`` [rad] (described by ``plant``)."""
    w = scene.walker
    if w.model == "compass_gait" and w.space == "2d":
        return make_compass_gait(
            w.leg_length_m, w.leg_mass_kg, w.hip_mass_kg, w.gravity_m_per_s2,
            w.leg_mass_from_foot_m, scene.slope.phi_rad, scene.ideal.variant,
        )
    # any other walker is described as data: its kind builds it
    # (walkerlab.models.hybrid.rigid.BUILDERS; a rimless wheel: the rolling polygon)
    if scene.ideal.variant != "derived":
        raise ValueError(f"ideal.variant: {scene.ideal.variant!r} exists only for "
                         "model: compass_gait (the paper's printed equations)")
    data = plant.data if slope_rad is None else plant.data_at(slope_rad)
    return make_rigid_walker(data, w.model, "derived")
