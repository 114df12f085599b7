"""A 3D walker's planar twin: the walker of the same sagittal numbers moving in the sagittal
plane only, and the field that takes it out of the plane.

Upright (no lean, no heading, no roll) and at zero hip width a 3D straight-legged walker is
the planar compass gait embedded in 3D (Kuo 1999, "Stabilization of lateral motion in
passive dynamic walking", IJRR 18(9)), and a 3D rimless wheel rolling straight downhill is
the planar wheel (Coleman, Chatterjee & Ruina 1997, "Motions of a rimless spoked wheel",
Dyn. Stab. Syst. 12(3)): the planar twin's gait, its state names' values kept and the
lateral coordinates zero, is a gait of the 3D walker at zero width and a start for its
root finder (:mod:`walkerlab.analysis.gait.planar_start`).
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["CONTACT_ONLY_IN_3D", "PlanarTwin", "planar_twin"]

#: fields of a 3D walker section that only a 3D walker has, left out of its planar twin
ONLY_IN_3D = ("space", "hip_width_m", "hip_roll", "diametral_inertia_kg_m2")
#: fields of the contact section that only a 3D walker takes (a planar scene refuses them),
#: left out of its planar twin's scene
CONTACT_ONLY_IN_3D = ("torsional_friction_m",)
#: fields a planar twin cannot carry (a 3D walker with one of them set has no planar twin
#: here: a planar walker's round feet are ``model: biped``'s ``leg.foot``)
NO_TWIN = ("foot_radius_m", "leg_inertia_kg_m2")
#: the field along which the twin's gait is carried out of the plane (0: the embedding)
WIDTH_FIELD = "hip_width_m"


@dataclass(frozen=True)
class PlanarTwin:
    """The planar twin of a 3D walker section.

    Attributes
    ----------
    walker : dict
        The twin's ``walker`` section (a mapping: ``space: 2d`` and no 3D-only field).
    width_field : str or None
        The ``walker`` field (:data:`WIDTH_FIELD`) whose value takes the embedded twin to
        the 3D walker, None when nothing does (a wheel: the embedding is the walker itself
        upright).
    width : float
        The 3D walker's value of ``width_field`` [m] (0 without one).
    width_zero_allowed : bool
        Whether the 3D walker is a valid scene at width 0 (hip-roll joints need a width:
        then the carrying starts a little above 0).
    """

    walker: dict
    width_field: str | None
    width: float
    width_zero_allowed: bool


def planar_twin(walker) -> PlanarTwin | None:
    """The planar twin of the scene's ``walker`` section, or None (a planar walker, or a 3D
    one with a field the plane cannot carry: :data:`NO_TWIN`).

    Parameters
    ----------
    walker : pydantic model
        A scene's ``walker`` section (:mod:`walkerlab.config.walker`).

    Returns
    -------
    PlanarTwin or None
    """
    if getattr(walker, "space", "2d") != "3d":
        return None
    data = walker.model_dump(mode="json")
    if any(data.get(k) is not None for k in NO_TWIN):
        return None
    twin = {k: v for k, v in data.items() if k not in ONLY_IN_3D}
    width = data.get(WIDTH_FIELD)
    if not width:
        return PlanarTwin(twin, None, 0.0, True)
    return PlanarTwin(twin, WIDTH_FIELD, float(width), data.get("hip_roll") is None)
