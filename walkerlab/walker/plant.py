"""The *plant*: a scene's walker described once and handed down.

A stage, the API or the CLI builds one :class:`Plant` from its scene
(:meth:`Plant.from_scene`), as Pinocchio builds its ``Model`` once and hands it to every
algorithm; the models, the analyses, the studies, the optimisers, the exports and the gym
take it (or its :attr:`Plant.data`, its :attr:`Plant.kind`) from their caller instead of
describing the walker again from the scene (:func:`walkerlab.walker.description.walker_data`).

A scene that differs (a sweep's point, a continuation's step, a design point, a planar
twin) is reached from the plant the caller handed down (:meth:`Plant.with_`): the same
walker section keeps its descriptions (only the slope's is looked up), another walker is
described anew.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

from walkerlab.config import CompassGaitParams
from walkerlab.walker.description import Structure, WalkerData, walker_data
from walkerlab.walker.kinds import Kind


@dataclass(frozen=True, eq=False)
class Plant:
    """A scene's walker, described once: its structure, kind and numbers.

    Parameters
    ----------
    scene : walkerlab.config.Scene
        The validated scene the plant was built from (its ``walker`` and ``slope`` sections
        decide :attr:`data`).
    data : WalkerData
        The walker's description on the scene's slope
        (:func:`walkerlab.walker.description.walker_data` of ``scene.walker`` at
        ``scene.slope.phi_rad``).

    Notes
    -----
    Build it with :meth:`from_scene`.  The descriptions on other slopes (a ground of several
    slopes: footholds, a height profile, a drawn rough ground) are built on first asking
    (:meth:`data_at`) and kept in this plant, so that one plant describes each slope once.
    The kind's parts are reached from :attr:`kind` (the capability table's cells, the
    collocation's and contact model's parts); the integrator
    (:class:`walkerlab.integrate.solver.Solver`, a floor above this one) stays with the
    caller (the API's walker holds both: :class:`walkerlab.rigid_walker.SceneWalker`).
    """

    scene: Any
    data: WalkerData
    _slopes: dict = field(default_factory=dict, repr=False, compare=False)

    @classmethod
    def from_scene(cls, scene) -> Plant:
        """The plant of ``scene``: its walker described on its slope.

        Parameters
        ----------
        scene : walkerlab.config.Scene
            A validated scene.

        Returns
        -------
        Plant
        """
        return cls(scene, walker_data(scene.walker, scene.slope.phi_rad))

    @property
    def slope_rad(self) -> float:
        """The scene's slope angle [rad] (that of :attr:`data`)."""
        return self.data.slope_rad

    @property
    def structure(self) -> Structure:
        """The walker's structure (everything that decides the form of its equations)."""
        return self.data.structure

    @property
    def kind(self) -> Kind:
        """The walker's structural kind (:func:`walkerlab.walker.kinds.kind_of`)."""
        return self.data.structure.kind

    def data_at(self, slope_rad: float) -> WalkerData:
        """The walker's description on a slope of ``slope_rad`` [rad].

        The scene's own slope gives :attr:`data`; another slope's description is built once
        and kept in this plant.

        Parameters
        ----------
        slope_rad : float
            Slope angle [rad].

        Returns
        -------
        WalkerData
        """
        key = _slope_key(slope_rad)
        if key == _slope_key(self.data.slope_rad):
            return self.data
        if key not in self._slopes:
            self._slopes[key] = walker_data(self.scene.walker, slope_rad)
        return self._slopes[key]

    def with_(self, scene) -> Plant:
        """The plant of a neighbouring scene (a study's point, a continuation's step, a
        design point, a planar twin, a replay's scene).

        A scene whose ``walker`` section equals this plant's scene's (pydantic equality:
        a sweep over the slope, the solver, the contact or the noise settings) is the same
        walker: its description is this plant's on the new scene's slope (:meth:`data_at`),
        and the new plant shares this one's descriptions of other slopes, so the walker is
        never described again.  A scene with another walker section is described anew
        (:meth:`from_scene`).

        Parameters
        ----------
        scene : walkerlab.config.Scene
            A validated scene.

        Returns
        -------
        Plant
            ``self`` when ``scene`` is this plant's scene (the same object).
        """
        if scene is self.scene:
            return self
        if scene.walker != self.scene.walker:
            return Plant.from_scene(scene)
        self._slopes.setdefault(_slope_key(self.data.slope_rad), self.data)
        return Plant(scene, self.data_at(scene.slope.phi_rad), self._slopes)

    def on_slope(self, slope_rad: float) -> Plant:
        """The plant of the scene on a slope of ``slope_rad`` [rad] (its ``slope`` section
        set to that angle): described by :meth:`data_at`, its other slopes kept with this
        plant's.

        Parameters
        ----------
        slope_rad : float
            Slope angle [rad].

        Returns
        -------
        Plant
        """
        g = float(slope_rad)
        scene = self.scene.model_copy(update={"slope": self.scene.slope.model_copy(
            update={"angle_rad": g, "angle_deg": None})})
        return Plant(scene, self.data_at(g), self._slopes)


def _slope_key(slope_rad: float) -> tuple[float, float]:
    """A slope's key among a plant's descriptions: the angle and its sign (-0.0 and 0.0
    apart)."""
    return slope_rad, math.copysign(1.0, slope_rad)


def compass_gait_data(leg_length_m: float, leg_mass_kg: float, hip_mass_kg: float,
                      gravity_m_per_s2: float, leg_mass_from_foot_m: float,
                      slope_rad: float) -> WalkerData:
    """The paper's compass gait (Table 1) described from its five numbers (all SI), on a
    slope of ``slope_rad`` [rad]: :func:`~walkerlab.walker.description.walker_data` of a
    ``compass_gait`` section holding them (the printed-equation model,
    :mod:`walkerlab.models.hybrid.printed_equations`, which has numbers, not a scene).

    Returns
    -------
    WalkerData
    """

    w = CompassGaitParams(leg_length_m=leg_length_m, leg_mass_kg=leg_mass_kg,
                          hip_mass_kg=hip_mass_kg, gravity_m_per_s2=gravity_m_per_s2,
                          leg_mass_from_foot_m=leg_mass_from_foot_m)
    return walker_data(w, slope_rad)
