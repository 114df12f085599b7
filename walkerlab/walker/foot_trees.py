"""The stance side of a 3D biped on feet curved in both directions (a torus patch: fore-aft
radius ``R`` in the leg's sagittal plane, lateral radius ``R_l`` across it; Coleman & Ruina
1998, "An uncontrolled walking toy that cannot stand still", PRL 80(16); Collins, Wisse &
Ruina 2001, "A three-dimensional passive-dynamic walking robot with two legs and knees",
IJRR 20(7)), as bodies of :func:`walkerlab.walker.trees.biped_tree`'s tree.

The foot's lowest point, with the leg rolled by ``phi`` about the fall line ``s`` and
pitched by ``beta`` about the rolled hip axis, is ``R_l`` below the lateral section's
centre, which is ``R - R_l`` along the rolled normal below the torus' axis (the leg frame's
origin).  Rolling without slip moves that contact ``R_l phi`` across the fall line
(holonomic) and along it at the rate ``-(R - R_l + R_l cos phi) beta'`` (the rolling radius
about the axis changes with the lean: not holonomic, a Chaplygin constraint that
:mod:`walkerlab.codegen.rolling_feet` imposes), so the tree carries the travel along the
fall line as a coordinate of its own.
"""

from __future__ import annotations

import math

from walkerlab.walker.tree import ZERO_INERTIA, Body, Joint

__all__ = ["creep_rate", "stance_torus"]

S, Z = (1, 0, 0), (0, 0, 1)


def stance_torus(R: str, lateral: str, leg: str = "stance_leg") -> list:
    """The stance leg's frame ``leg`` on a foot curved in both directions (3D; module
    docstring), ``R`` and ``R_l`` the names of the radii: slides along the fall line (the
    coordinate ``travel``) and across it (``R_l lean``), the roll about the fall line at the
    lateral section's centre ``R_l`` above the contact, the pitch about the torus' axis
    ``R - R_l`` further along the rolled normal (the leg frame's origin ``R`` above the
    foot's lowest point, as a disc foot's)."""
    return [Body("stance_travel", 0, ZERO_INERTIA, (0, 0, 0),
                 Joint("stance_roll_travel", "prismatic", "slope", (0, 0, 0), (S,),
                       ("stance_travel",))),
            Body("stance_side", 0, ZERO_INERTIA, (0, 0, 0),
                 Joint("stance_side_travel", "prismatic", "stance_travel", (0, 0, 0), (Z,),
                       ("stance_lateral_travel",))),
            Body("stance_roll", 0, ZERO_INERTIA, (0, 0, 0),
                 Joint("stance_ankle_roll", "revolute", "stance_side", (0, lateral, 0), (S,),
                       ("stance_ankle_roll",))),
            Body(leg, 0, ZERO_INERTIA, (0, 0, 0),
                 Joint("stance_ankle_pitch", "revolute", "stance_roll",
                       (0, f"{R} - {lateral}", 0), (Z,), ("stance_ankle_pitch",)))]


def creep_rate(roles: tuple, params: dict):
    """The rate [m/s] at which a toroidal stance foot's contact runs along the fall line
    ahead of the holonomic reference travel ``-R beta`` the printed points and potential
    are measured at (module docstring): ``-(R - R_l + R_l cos phi) beta' + R beta' =
    R_l (1 - cos phi) beta'``, ``phi`` the lean, ``beta' `` the stance leg's pitch rate.
    Over a step its integral moves every point of the walker that far along the fall line
    (the energy ledger's true potential, :func:`walkerlab.analysis.gait.energy.
    step_ledger`).

    Parameters
    ----------
    roles : tuple of str
        The walker's coordinates (``lean`` and ``stance`` among them).
    params : dict
        The numbers by parameter name; the lateral radius ``R_lat`` [m].

    Returns
    -------
    callable ``x (2n,) -> float`` or None
        None without a lateral radius (holonomic feet: the reference is the travel).
    """
    if "R_lat" not in params:
        return None
    r_l, n = float(params["R_lat"]), len(roles)
    lean, stance = roles.index("lean"), n + roles.index("stance")

    def rate(x) -> float:
        return r_l * (1.0 - math.cos(float(x[lean]))) * float(x[stance])
    return rate
