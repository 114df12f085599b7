"""Map a scene's ``walker.model`` to a model builder (the only place that knows the list)."""

from __future__ import annotations

from walkerlab.models.base import HybridWalker


def build_walker(scene) -> HybridWalker:
    """Build the rigid hybrid walker of a :class:`~walkerlab.config.Scene`.

    Raises
    ------
    ValueError
        The scene names a walker model that has no rigid hybrid implementation.
    """
    w = scene.walker
    if w.model == "compass_gait":
        from walkerlab.models.compass_gait import make_compass_gait

        return make_compass_gait(
            w.leg_length_m, w.leg_mass_kg, w.hip_mass_kg, w.gravity_m_per_s2,
            w.leg_mass_from_foot_m, scene.slope.phi_rad, scene.ideal.variant,
        )
    raise ValueError(f"walker.model: no rigid model for {w.model!r}")
