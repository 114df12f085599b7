"""Typed scene configuration (YAML -> pydantic v2).

The package is the bottom of the settings: :mod:`walkerlab.config.walker` holds the walker
sections, :mod:`walkerlab.config.studies` the sections of the analyses,
:mod:`walkerlab.config.contact` the compliant-contact sections (contact law, terrain, run)
and :mod:`walkerlab.config.schema` the scene that holds them; every section is importable
from ``walkerlab.config``.  Nothing here imports a model package (the model
packages import their settings from here).

A *scene* declares only the sections it uses; every section is optional except the walker
and the slope.  Every numeric field carries its unit in its name (``leg_length_m``) and a
description; validation always runs and unknown keys are rejected (``extra="forbid"``).

Modules: :mod:`~walkerlab.config.schema` (:class:`Scene`, the slope, the model variant and
the command-line sizes), :mod:`~walkerlab.config.walker` (compass gait, biped; its legs,
bodies, feet, knee, torso, springs in :mod:`~walkerlab.config.biped_parts`),
:mod:`~walkerlab.config.studies` (fixed point, simulation, work-precision, basin, MFPT,
robustness; a state by name), :mod:`~walkerlab.config.base`
(the strict base of every section), :mod:`~walkerlab.config.errors` (error lines,
:class:`SceneError`),
:mod:`~walkerlab.config.loader` (YAML reading, validation, error lines),
:mod:`~walkerlab.config.limits` (caps and unit-mistake warnings),
:mod:`~walkerlab.config.contact` (compliant-contact sections),
:mod:`~walkerlab.config.solver` (the one solver section, ``solver`` and
``contact_solver``).  This module only re-exports their public names.

Raises
------
SceneError
    One line naming the file and the offending field, for every bad input.
"""

from walkerlab.config.base import AsTuple
from walkerlab.config.biped_parts import (
    AnkleSpec,
    ArcFoot,
    Body,
    FlatFoot,
    Foot,
    KneeSpec,
    KneeSpringSpec,
    LegSpec,
    PointFoot,
    PointMassBody,
    RodBody,
    SpringSpec,
    TorsoBody,
    TorsoPointMass,
    TorsoRigidBody,
    TorsoSpec,
)
from walkerlab.config.contact import ContactSettings
from walkerlab.config.contact_sim import MAX_CONTACT_STRIDES, ContactSimSettings
from walkerlab.config.errors import WALKER_VOCABULARY, SceneError
from walkerlab.config.limits import (
    MAX_BASIN_CELLS_PER_AXIS,
    MAX_BIFURCATION_KEEP,
    MAX_BIFURCATION_TRANSIENT,
    MAX_SCENE_BYTES,
    MAX_SIMULATE_SAMPLES,
    MAX_SIMULATE_STRIDES,
    MAX_SOURCE_CHARS,
    MAX_STABILITY_MAP_N,
    MAX_STEP_TIME_S,
    MAX_STEPS_PER_WALKING_STEP,
    MAX_SWEEP_POINTS,
    MAX_WORKERS,
    MAX_YAML_DEPTH,
    SMALL_SLOPE_DEG,
)
from walkerlab.config.loader import (
    default_scene_path,
    load_scene,
    parse_yaml,
    scene_from_dict,
    unit_warnings,
    validate_option,
)
from walkerlab.config.schema import (
    CommandOptions,
    IdealModelSettings,
    Scene,
    SlopeSettings,
)
from walkerlab.config.solver import SolverSettings
from walkerlab.config.studies import (
    BasinSettings,
    FixedPointSettings,
    GuessFromArtifact,
    MfptSettings,
    RobustnessSettings,
    SimulateSettings,
    StateSpec,
    WorkPrecisionSettings,
)
from walkerlab.config.terrain import PerStepTerrain, TerrainSettings
from walkerlab.config.walker import BipedParams, CompassGaitParams, WalkerParams
from walkerlab.config.wheel import RimlessWheelParams

__all__ = [
    "AnkleSpec",
    "ArcFoot",
    "AsTuple",
    "BasinSettings",
    "BipedParams",
    "Body",
    "CommandOptions",
    "CompassGaitParams",
    "ContactSettings",
    "ContactSimSettings",
    "FixedPointSettings",
    "FlatFoot",
    "Foot",
    "GuessFromArtifact",
    "IdealModelSettings",
    "KneeSpec",
    "KneeSpringSpec",
    "LegSpec",
    "MAX_BASIN_CELLS_PER_AXIS",
    "MAX_BIFURCATION_KEEP",
    "MAX_BIFURCATION_TRANSIENT",
    "MAX_CONTACT_STRIDES",
    "MAX_SCENE_BYTES",
    "MAX_SIMULATE_SAMPLES",
    "MAX_SIMULATE_STRIDES",
    "MAX_SOURCE_CHARS",
    "MAX_STABILITY_MAP_N",
    "MAX_STEPS_PER_WALKING_STEP",
    "MAX_STEP_TIME_S",
    "MAX_SWEEP_POINTS",
    "MAX_WORKERS",
    "MAX_YAML_DEPTH",
    "MfptSettings",
    "PerStepTerrain",
    "PointFoot",
    "PointMassBody",
    "RimlessWheelParams",
    "RobustnessSettings",
    "RodBody",
    "SMALL_SLOPE_DEG",
    "Scene",
    "SceneError",
    "SimulateSettings",
    "SlopeSettings",
    "SolverSettings",
    "SpringSpec",
    "StateSpec",
    "TerrainSettings",
    "TorsoBody",
    "TorsoPointMass",
    "TorsoRigidBody",
    "TorsoSpec",
    "WALKER_VOCABULARY",
    "WalkerParams",
    "WorkPrecisionSettings",
    "default_scene_path",
    "load_scene",
    "parse_yaml",
    "scene_from_dict",
    "unit_warnings",
    "validate_option",
]
