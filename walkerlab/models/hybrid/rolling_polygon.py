"""A spoked wheel rolling on its spokes' feet (``model: rimless_wheel``) as a
:class:`~walkerlab.models.hybrid.base.HybridWalker`, from its generated code.

The equations are :mod:`walkerlab.codegen.rolling_polygon`'s (McGeer 1990; Coleman,
Chatterjee & Ruina 1997), printed and cached as every walker's
(:mod:`walkerlab.codegen.source`, :mod:`walkerlab.codegen.cache`), with a compiled flow for
the C++/numba integrators and the per-step-terrain batch map.  A step is one phase,
``stance`` (rotation about the stance spoke's foot), ended by ``heel_strike`` (the next
spoke's foot reaching the slope; the impact map turns the roles by a spoke) or by the fall
``rolls_back`` (the wheel stops before vaulting over its stance foot) or ``fall`` (the hub
reaching the slope: a wheel on a slope steeper than its spokes' half angle).

The state is ``x = [stance_angle, stance_rate]`` (n = 1); the legs of the vocabulary are the
two spokes of a step (``leg1`` and ``leg2`` alternate, the odd and even spokes of a wheel
with an even number of spokes), and :meth:`HybridWalker.leg_coordinates` gives both
spokes' absolute angles on every step.
"""

from __future__ import annotations

import math
from functools import partial

import numpy as np

from walkerlab.codegen.cache import functions
from walkerlab.codegen.compiled import CompiledFlow
from walkerlab.models.hybrid.base import LEGS, Guard, HybridWalker, Phase, role_to_leg
from walkerlab.walker.description import WalkerData


def make_spoked_walker(data: WalkerData, name: str = "rimless_wheel",
                       variant: str = "derived") -> HybridWalker:
    """The hybrid walker of a spoked wheel (module docstring).

    Parameters
    ----------
    data : WalkerData
        Of the ``rolling_polygon`` kind (:func:`walkerlab.walker.description.walker_data`
        of a ``model: rimless_wheel`` section), reached through it
        (:data:`walkerlab.models.hybrid.rigid.BUILDERS`).
    name, variant : str
        Stored in artifacts.

    Returns
    -------
    HybridWalker
        Roles ``("stance",)``; one phase ``stance``.
    """
    f = functions(data)
    heel = Guard("heel_strike", f["guard_heel_strike"], -1, "heel_strike",
                 f["grad_heel_strike"])
    back = Guard("rolls_back", f["guard_rolls_back"], +1, "fall", f["grad_rolls_back"])
    fall = Guard("fall", f["guard_hip_height"], -1, "fall", f["grad_hip_height"])
    compiled = CompiledFlow(data.structure, tuple(data.params), "flow",
                            (("heel_strike", 0.0), ("rolls_back", 0.0), ("hip_height", 0.0)))
    stance = Phase("stance", f["flow"], (heel, back, fall), jacobian=f["flow_jacobian"],
                   variational=f.get("flow_variational"), compiled=compiled)
    structure = data.structure
    params = {"leg_length_m": data.leg_length_m, "gravity_m_per_s2": data.gravity_m_per_s2,
              "total_mass_kg": data.total_mass_kg, "slope_rad": data.slope_rad, **data.extra,
              **dict(zip(structure.param_names, data.params))}
    return HybridWalker(
        name=name, variant=variant, roles=structure.roles, legs=LEGS, phases=(stance,),
        reset=f["reset"], energies=f["energies"], points=f["points"], hip_x=f.get("hip_x"),
        section=f["section"], from_section=f["from_section"], role_to_leg=role_to_leg,
        total_mass_kg=data.total_mass_kg, slope_rad=data.slope_rad, params=params,
        variational=f["flow_jacobian"], reset_jacobian=f["reset_jacobian"],
        heel_strike_guard=f["guard_heel_strike"], leg_angles=f["leg_angles"],
        matrices=f["matrices"],
        neutral=("heading_angle",) if structure.spatial else (),
        closed_form_gait=None if structure.spatial else partial(rolling_gait, params),
    )


def rolling_gait(params: dict) -> np.ndarray | None:
    """The planar spoked wheel's steady rolling gait in closed form: its state just after
    heel strike ``[stance_angle, stance_rate]`` [rad, rad/s], or None when the wheel
    cannot roll over its stance foot at this slope.

    Between heel strikes the wheel turns about the stance foot from ``q = alpha - gamma``
    to ``q = -alpha - gamma``, gaining ``2 M g L sin(alpha) sin(gamma)`` of kinetic energy;
    the heel strike keeps the angular momentum about the new foot, ``w+ = eta w-`` with
    ``eta = (M L^2 cos(2 alpha) + I) / (M L^2 + I)``.  The fixed point
    (McGeer 1990, "Passive dynamic walking", IJRR 9(2), Sec. 2; Coleman, Chatterjee & Ruina
    1997, Eq. for the steady rolling rate; a point mass, ``I = 0``:
    ``w+ = cot(2 alpha) sqrt(4 g/L sin(alpha) sin(gamma))``):

    ``w+ = eta sqrt(4 M g L sin(alpha) sin(gamma) / ((M L^2 + I) (1 - eta^2)))``,

    downhill (``stance_rate = -w+``).  It rolls on when its energy at ``w+`` lifts the hub
    over the stance foot: ``(M L^2 + I) w+^2 / 2 > M g L (1 - cos(alpha - gamma))``.

    Parameters
    ----------
    params : dict
        The wheel's ``M_hub`` [kg], ``I_hub`` [kg m^2], ``L`` [m], ``g`` [m/s^2],
        ``alpha`` (half the angle between spokes) and ``gamma`` (slope) [rad].

    Returns
    -------
    ndarray (2,) or None
    """
    m, inertia, length = float(params["M_hub"]), float(params["I_hub"]), float(params["L"])
    g, alpha, gamma = float(params["g"]), float(params["alpha"]), float(params["gamma"])
    about = m * length ** 2 + inertia
    eta = (m * length ** 2 * math.cos(2 * alpha) + inertia) / about
    gain = 4 * m * g * length * math.sin(alpha) * math.sin(gamma)
    if not (gain > 0 and 0 < eta < 1):
        return None
    rate = eta * math.sqrt(gain / (about * (1 - eta ** 2)))
    if not about * rate ** 2 / 2 > m * g * length * (1 - math.cos(alpha - gamma)):
        return None
    return np.array([alpha - gamma, -rate])
