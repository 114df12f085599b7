"""The contact walker's compiled view: what integrators that call no Python per RHS use.

The one public seam between the model's numba kernels (:mod:`walkerlab.contact._kernels`)
and the compiled integration routes (:mod:`walkerlab.integrate._cyrk`,
:mod:`walkerlab.integrate._lsoda`) and the periodic-gait section
(:mod:`walkerlab.analysis.contact_periodic`): code outside this package imports these
names, never the private kernel module.

- :func:`rhs_packed` ``(y (N,), data, dy (N,))``: the right-hand side over one packed data
  vector (numba; callable from a numba ``cfunc``);
- :func:`packed_size` ``(data) -> int``: the length of that vector (numba);
- :func:`packed_data` ``(walker) -> ndarray``: the vector for a walker (its parameters,
  lanes and an RHS call counter as the last entry);
- :func:`foot_state` ``(x, foot, walker) -> (px, py, vx, vy)``: a foot's position [m] and
  velocity [m/s].
"""

from __future__ import annotations

import numpy as np

from . import _kernels

__all__ = ["foot_state", "packed_data", "packed_size", "rhs_packed"]

rhs_packed = _kernels.rhs_packed
packed_size = _kernels.packed_size


def packed_data(walker) -> np.ndarray:
    """Packed data vector of ``walker`` for :func:`rhs_packed` (last entry: call counter)."""
    return _kernels.pack(walker._P, walker.lane1, walker.lane2)


def foot_state(x, foot: int, walker) -> tuple[float, float, float, float]:
    """Position [m] and velocity [m/s] ``(px, py, vx, vy)`` of foot ``foot`` (0: leg1,
    1: leg2) in state ``x``."""
    return _kernels.foot_state(np.asarray(x, float), foot, walker._P)
