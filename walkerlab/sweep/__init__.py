"""Parameter sweeps over any dotted scene field, bifurcation diagrams, contact stability maps.

- :mod:`walkerlab.sweep.params`     ``--param`` parsing, grid, per-point scene validation
- :mod:`walkerlab.sweep.outcomes`   typed outcomes and result columns per stage
- :mod:`walkerlab.sweep.points`     point functions (fixedpoint, simulate, contact-sim)
- :mod:`walkerlab.sweep.runner`     chunk planning (continuation), local / Dask executors
- :mod:`walkerlab.sweep.bifurcation` period-doubling diagram of the ideal walker over the slope
- :mod:`walkerlab.sweep.stability`  stability maps of the contact model

The stage entry point is :func:`walkerlab.stages.sweep.run`; the Python front door's is
:func:`walkerlab.api.sweep`.
"""

from walkerlab.sweep.outcomes import OUTCOMES
from walkerlab.sweep.params import ParamAxis, SweepError, parse_param

__all__ = ["OUTCOMES", "ParamAxis", "SweepError", "parse_param"]
