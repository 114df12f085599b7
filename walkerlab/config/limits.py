"""Caps and bounds of a scene and the command line, and unit-mistake warnings.

Each size a user can type has one cap, defined here; the scene's fields
(:mod:`~walkerlab.config.schema`, :mod:`~walkerlab.config.studies`) and the CLI's options
(:func:`walkerlab.config.validate_option`) validate through them.
"""

from __future__ import annotations

import os

# Caps that keep a run bounded: a bigger request is a
# one-line error.  Each size a user can type has one cap, defined here; the CLI validates its
# options through the same pydantic fields (:func:`validate_option`).
MAX_SIMULATE_STRIDES = 1000
#: dense samples of one ``simulate`` run (strides x 2 x step period x sample_rate_hz)
MAX_SIMULATE_SAMPLES = 5_000_000
#: integrator steps a ``solver.max_step_s`` may imply for the longest allowed walking step
#: (``max_step_time_s / max_step_s``)
MAX_STEPS_PER_WALKING_STEP = 100_000
#: cells along one axis of a basin map
MAX_BASIN_CELLS_PER_AXIS = 4000
#: cells along one axis of a stability map (each cell is a contact-model search)
MAX_STABILITY_MAP_N = 64
#: local worker processes: 4 per core
MAX_WORKERS = 4 * (os.cpu_count() or 1)
#: bifurcation: steps discarded / heel strikes kept per slope
MAX_BIFURCATION_TRANSIENT = 100_000
MAX_BIFURCATION_KEEP = 10_000
#: characters of a scene's ``source:`` citation (copied into every artifact)
MAX_SOURCE_CHARS = 4000
#: points of a sweep grid (product of the axes' lengths, and each axis)
MAX_SWEEP_POINTS = 1_000_000
#: bytes of a scene YAML file
MAX_SCENE_BYTES = 1_000_000
#: nesting depth of a scene YAML file (mappings and lists)
MAX_YAML_DEPTH = 32
#: seconds a single walking step may take before it counts as a failure
MAX_STEP_TIME_S = 600.0


#: a slope in degrees below this looks like radians (``angle_deg: 0.0174``): a warning
SMALL_SLOPE_DEG = 0.1
