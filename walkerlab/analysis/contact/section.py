"""The coordinates of the contact walker's mid-stance Poincaré section
(:mod:`walkerlab.analysis.contact.step_map`'s docstring): their names, units and scales,
read from the walker's leg angle states, and the rise of the ground from one footfall to the
next the section sees (:func:`step_rise`)."""

from __future__ import annotations

import numpy as np

__all__ = ["SCALES", "SECTION_NAMES", "SECTION_UNITS", "other_coordinates",
           "section_coordinates", "step_rise"]

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


def other_coordinates(walker) -> list[str]:
    """The coordinate states after the base's slides that are no leg's link angle (a walker
    in 3D: its heading and rolls), in the state's order."""
    legs = set(walker.leg_angle_states("leg1")) | set(walker.leg_angle_states("leg2"))
    return [c for c in walker.state_names()[walker.dim:walker.nq] if c not in legs]


def section_coordinates(walker) -> tuple[tuple, tuple, np.ndarray]:
    """Names, units and scales of the mid-stance section coordinates of ``walker``.

    All states minus the section constraint (the swing leg's proximal link aligned with the
    stance leg's) minus the translations along the ground (along the slope; in 3D also
    across it), the base's position replaced by the stance foot's contact: the stance
    leg's link angles, the swing leg's other link angles, the walker's other angles (in 3D
    the heading and the rolls), the swing leg's link rates, the stance leg's link rates,
    the other angles' rates, then ``delta_stance`` [m], the stance foot's velocity along
    the ground's tangents (``v_t_stance``, in 3D ``v_lat_stance``) [m/s] and
    ``ddelta_stance`` [m/s].  Straight legs: :data:`SECTION_NAMES` (6); kneed legs: 10;
    straight legs in 3D: 15.

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
    other = other_coordinates(walker)
    angles = ([_role_name(a, "stance") for a in st] + [_role_name(a, "swing") for a in sw[1:]]
              + other)
    rates = ([_role_name("d" + a, "swing") for a in sw]
             + [_role_name("d" + a, "stance") for a in st] + ["d" + a for a in other])
    slips = ("v_t_stance", "v_lat_stance")[:walker.dim - 1]
    names = tuple(angles + rates) + ("delta_stance",) + slips + ("ddelta_stance",)
    units = ("rad",) * len(angles) + ("rad/s",) * len(rates) + ("m",) + ("m/s",) * walker.dim
    scale = np.array([1.0] * (len(angles) + len(rates))
                     + [walker.static_penetration()] + [1e-3] * walker.dim)
    return names, units, scale


def step_rise(walker) -> float:
    """Height [m] (along the slope's normal) of each footfall's patch above the last one's on
    a ground whose every step is alike (stairs, footholds of one height, on checkerboard
    lanes: :func:`walkerlab.models.contact.terrain.terrain_ground`); 0.0 without patch
    heights.

    Raises
    ------
    ValueError
        A polyline ground (continuous stairs, a profile), or footfall heights whose steps
        differ (rough ground): the step map's ground is the same at every step (one line,
        naming ``contact_sim.start``).
    """
    if walker.ground_line is not None:
        raise ValueError("contact_sim.start / periodic_gait: the contact periodic gait's "
                         "step map lays a patch at each foot (checkerboard lanes); a polyline "
                         "ground (stairs on continuous lanes, a profile) has none: use "
                         "terrain.lanes: checkerboard, or start: ideal")
    if walker.heights1 is None and walker.heights2 is None:
        return 0.0
    h2 = np.zeros(walker.lane2.size) if walker.heights2 is None else walker.heights2
    h1 = np.zeros(walker.lane1.size) if walker.heights1 is None else walker.heights1
    n = min(h1.size, h2.size)  # footfall order: leg2's 0, leg1's 1, leg2's 2, ...
    h = np.ravel(np.column_stack([h2[:n], h1[:n]]))
    rises = np.diff(h) if h.size > 1 else np.zeros(1)
    # equal to rounding (the heights are -k * drop * cos(phi), k up to a few hundred)
    if np.ptp(rises) > 1e-9 * max(1.0, float(np.max(np.abs(h)))):
        raise ValueError("contact_sim.start / periodic_gait: the contact periodic gait needs "
                         "a ground whose every step is alike (slope, stairs, footholds of one "
                         "height); these footfall heights differ from step to step")
    return float(rises[0])
