"""A sweep point's row: the columns of a fixed point (its state, Floquet multipliers, step
period, cost), of its ground verdict and of a state, and the inter-leg angle that tells a
degenerate gait (no step) from a walking one.  Nothing here knows a state's row: the
columns are named from ``walker.state_names()``.
"""

from __future__ import annotations

import math

import numpy as np

from walkerlab.analysis.gait.zero_dynamics import zero_dynamics
from walkerlab.studies.outcomes import state_column

__all__ = ["interleg_angle"]


def interleg_angle(walker, x: np.ndarray) -> float:
    """Angle [rad] between the legs, from the foot-to-foot distance ``d`` of state ``x``.

    ``2 asin(d / 2L)`` with ``L = walker.params["leg_length_m"]``: for straight legs this is
    ``|theta_swing - theta_stance|`` exactly; for any walker it is the angle of the isosceles
    triangle hip-feet with the same step, so it needs no state row.

    Parameters
    ----------
    walker : HybridWalker
    x : ndarray, shape (2n,)
        State (``walker.state_names()``, [rad, rad/s]); only the feet's positions are read.
    """
    d = float(np.hypot(*walker.points(x)["swing_foot"][:2]))  # sagittal (3D: width apart)
    L = float(walker.params["leg_length_m"])
    return float(2.0 * np.arcsin(min(1.0, d / (2.0 * L))))


def _state_columns(walker, x, prefix: str = "") -> dict:
    return {prefix + state_column(n, u): float(v)
            for n, u, v in zip(walker.state_names(), walker.state_units(), x)}


def _fp_columns(walker, res) -> dict:
    cols = _state_columns(walker, res.x)
    mult = np.asarray(res.multipliers_variational, complex)
    for k in range(len(walker.state_names())):
        z = mult[k] if k < mult.size else complex(math.nan, math.nan)
        cols[f"multiplier_{k}_re"], cols[f"multiplier_{k}_im"] = float(z.real), float(z.imag)
    # per step: a stride map's period (legs that differ) is two steps'
    cols.update(step_period_s=float(res.period_s) / walker.steps_per_map,
                residual=float(res.residual),
                max_abs_multiplier=float(np.max(np.abs(mult))), stable=float(res.stable),
                map_evaluations=float(res.iterations),
                variational_maps=float(res.variational_maps), nfev=float(res.nfev))
    ctrl = getattr(getattr(walker, "actuators", None), "controller", None)
    if ctrl is not None:  # virtual constraints: the restricted map beside the full one

        z = zero_dynamics(ctrl)
        cols.update(delta2=z.delta2, v_minus=z.v_minus, v_max=z.v_max,
                    existence_margin=z.existence_margin, hzd_step_period_s=z.step_period_s)
    return cols


def _ground_columns(ground) -> dict:
    """The chosen gait's ground verdict: the stance foot's smallest normal force, the
    friction it needs against the ground's and, in 3D, the twist it carries (NaN where not
    checked)."""
    fr = getattr(ground, "friction", None)
    inside = None if fr is None else fr.inside
    return {"min_normal_force_n": float(getattr(ground, "min_normal_force_n", math.nan)),
            "max_friction_ratio": math.nan if fr is None else float(fr.max_ratio),
            "friction_coefficient": math.nan if fr is None else float(fr.mu),
            "inside_friction_cone": math.nan if inside is None else float(inside),
            "max_twist_n_m": float(getattr(ground, "max_twist_n_m", math.nan))}


# ----------------------------------------------------------------------------- stages
