"""Parameter sweeps over any dotted scene field, bifurcation diagrams, contact stability maps.

- :mod:`walkerlab.sweep.params`     ``--param`` parsing, grid, per-point scene validation
- :mod:`walkerlab.sweep.outcomes`   typed outcomes and result columns per stage
- :mod:`walkerlab.sweep.points`     point functions (fixedpoint, simulate, contact-sim)
- :mod:`walkerlab.sweep.runner`     chunk planning (continuation), local / Dask executors
- :mod:`walkerlab.sweep.store`      incremental HDF5 artifact (append, resume, finalize)
- :mod:`walkerlab.sweep.bifurcation` period-doubling diagram of the ideal walker over the slope
- :mod:`walkerlab.sweep.stability`  stability maps of the contact model

The stage entry point is :func:`walkerlab.stages.sweep.run`.
"""

import sys
import types

from walkerlab.sweep.outcomes import OUTCOMES
from walkerlab.sweep.params import ParamAxis, SweepError, parse_param

__all__ = ["OUTCOMES", "ParamAxis", "SweepError", "parse_param"]


class _CallablePackage(types.ModuleType):
    """``walkerlab.sweep`` is this package *and* the top-level API name
    ``walkerlab.sweep(scene, param, values)``: once the package is imported, Python binds the
    attribute ``walkerlab.sweep`` to it, so calling it calls :func:`walkerlab.api.sweep`."""

    def __call__(self, *args, **kwargs):
        from walkerlab.api import sweep

        return sweep(*args, **kwargs)


sys.modules[__name__].__class__ = _CallablePackage
