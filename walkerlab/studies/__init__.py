"""Parameter sweeps over any dotted scene field, bifurcation diagrams, contact stability maps.

- :mod:`walkerlab.studies.params`     ``--param`` parsing, grid, per-point scene validation
- :mod:`walkerlab.studies.scene_paths` dotted fields of a scene mapping: read, set, removed
- :mod:`walkerlab.studies.outcomes`   typed outcomes and result columns per stage
- :mod:`walkerlab.studies.points`     point functions (fixedpoint, simulate, contact-sim)
- :mod:`walkerlab.studies.runner`     chunk planning (continuation), local / Dask executors
- :mod:`walkerlab.studies.bifurcation` period-doubling diagram of the ideal walker over the slope
- :mod:`walkerlab.studies.stability`  stability maps of the contact model

The stage entry point is :func:`walkerlab.stages.sweep.run`; the Python front door's is
:func:`walkerlab.api.sweep`.
"""

from walkerlab.studies.outcomes import OUTCOMES
from walkerlab.studies.params import ParamAxis, SweepError, parse_param

__all__ = ["OUTCOMES", "ParamAxis", "SweepError", "parse_param"]
