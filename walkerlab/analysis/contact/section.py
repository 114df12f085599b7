"""The coordinates of the contact walker's mid-stance Poincaré section
(:mod:`walkerlab.analysis.contact.step_map`'s docstring): their names, units and scales,
read from the walker's leg angle states."""

from __future__ import annotations

import numpy as np

__all__ = ["SCALES", "SECTION_NAMES", "SECTION_UNITS", "section_coordinates"]

#: Section coordinates of a straight-legged walker.
SECTION_NAMES = ("theta_stance", "dtheta_swing", "dtheta_stance", "delta_stance",
                 "v_t_stance", "ddelta_stance")
SECTION_UNITS = ("rad", "rad/s", "rad/s", "m", "m/s", "m/s")


#: coordinate scales (SI) of the straight-legged section (:data:`SECTION_NAMES`) used for
#: the root finder, the residual and the FD steps; the penetration scale is replaced by the
#: walker's static penetration at run time (:func:`section_coordinates` for any walker).
SCALES = np.array([1.0, 1.0, 1.0, 6e-5, 1e-3, 1e-3])


def _role_name(state: str, role: str) -> str:
    """``theta1_thigh`` -> ``theta_<role>_thigh``, ``dtheta2`` -> ``dtheta_<role>``."""
    head, _, tail = state.partition("_")
    return head.rstrip("12") + f"_{role}" + (f"_{tail}" if tail else "")


def section_coordinates(walker) -> tuple[tuple, tuple, np.ndarray]:
    """Names, units and scales of the mid-stance section coordinates of ``walker``.

    All states minus the section constraint (the swing leg's proximal link aligned with the
    stance leg's) minus the along-slope translation, the hip position replaced by the stance
    foot's contact: the stance leg's link angles, the swing leg's other link angles, the
    swing leg's link rates, the stance leg's link rates, then ``delta_stance`` [m],
    ``v_t_stance`` [m/s], ``ddelta_stance`` [m/s].  Straight legs: :data:`SECTION_NAMES`
    (6); kneed legs: 10.

    Parameters
    ----------
    walker : walkerlab.models.contact.model.ContactWalker

    Returns
    -------
    names : tuple of str
    units : tuple of str
    scale : ndarray (n,)
        1 rad, 1 rad/s, the static penetration, 1 mm/s, 1 mm/s (:data:`SCALES`).
    """
    st, sw = walker.leg_angle_states("leg2"), walker.leg_angle_states("leg1")
    angles = [_role_name(a, "stance") for a in st] + [_role_name(a, "swing") for a in sw[1:]]
    rates = ([_role_name("d" + a, "swing") for a in sw]
             + [_role_name("d" + a, "stance") for a in st])
    names = tuple(angles + rates) + SECTION_NAMES[-3:]
    units = ("rad",) * len(angles) + ("rad/s",) * len(rates) + SECTION_UNITS[-3:]
    scale = np.array([1.0] * (len(angles) + len(rates))
                     + [walker.static_penetration(), 1e-3, 1e-3])
    return names, units, scale
