"""A spoked wheel rolling on its spokes' feet (``model: rimless_wheel``) as a
:class:`~walkerlab.models.hybrid.base.HybridWalker`, from its generated code.

The equations are :func:`walkerlab.codegen.derive_3d.derive_spoked`'s (McGeer 1990; Coleman,
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
from walkerlab.models.compiled_flows import CompiledFlow
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
        neutral=("heading_angle",) if structure.in_3d else (),
        closed_form_gait=None if structure.in_3d else partial(rolling_gait, params),
    )


def steady_roll(p: dict) -> tuple[float, float] | None:
    """The steady roll's post-impact rate and the rate needed to vault the hub over the
    stance spoke, in closed form (McGeer 1990, "Passive dynamic walking", IJRR 9(2), Sec. 2;
    Coleman, Chatterjee & Ruina 1997): with ``J = I_hub + M L^2`` and the impact's ratio
    ``eta = (I_hub + M L^2 cos 2 alpha) / J`` (angular momentum about the new foot),
    ``w+^2 = eta^2 (4 M g L / J) sin(alpha) sin(gamma) / (1 - eta^2)``; the hub, ``alpha -
    gamma`` behind the vertical through the new foot after the impact, goes over it if
    ``J w+^2 / 2 > M g L (1 - cos(alpha - gamma))``.  The 3D wheel's upright roll is the
    same motion (its rates about the axle).

    Parameters
    ----------
    p : dict
        The wheel's generated parameters by name: ``M_hub`` [kg], ``I_hub`` [kg m^2], ``L``
        [m], ``g`` [m/s^2], ``alpha`` (half the angle between spokes) and ``gamma`` (slope)
        [rad].

    Returns
    -------
    (w_plus, w_vault) : float, float
        [rad/s]; ``w_vault`` 0 on a slope at least the spokes' half angle.  None: no slope
        down, or fewer than 5 spokes (``eta <= 0``: the closed form does not hold).
    """
    g, L, gamma, M, i_hub, alpha = (float(p[k]) for k in ("g", "L", "gamma", "M_hub",
                                                          "I_hub", "alpha"))
    J = i_hub + M * L * L
    eta = (i_hub + M * L * L * math.cos(2 * alpha)) / J
    if eta <= 0 or gamma <= 0:
        return None
    w_plus = math.sqrt(eta * eta * 4 * M * g * L / J * math.sin(alpha) * math.sin(gamma)
                       / (1 - eta * eta))
    barrier = M * g * L * (1 - math.cos(alpha - gamma)) if alpha > gamma else 0.0
    return w_plus, math.sqrt(2 * barrier / J)


def rolling_gait(params: dict) -> np.ndarray | None:
    """The planar spoked wheel's steady rolling gait in closed form (:func:`steady_roll`):
    its state just after heel strike ``[stance_angle, stance_rate]`` =
    ``[alpha - gamma, -w+]`` [rad, rad/s] (downhill), or None when the wheel cannot roll
    over its stance foot at this slope (``w+`` not above the vaulting rate).

    Parameters
    ----------
    params : dict
        As :func:`steady_roll`'s.

    Returns
    -------
    ndarray (2,) or None
    """
    r = steady_roll(params)
    if r is None or not r[0] > r[1]:
        return None
    return np.array([float(params["alpha"]) - float(params["gamma"]), -r[0]])


def cannot_roll(data: WalkerData, field: str = "walker.spokes") -> str | None:
    """Why the spoked wheel has no steady roll on its slope (:func:`steady_roll`: its
    post-impact rate cannot vault the hub over the stance spoke), one line naming
    ``field``; None when it can or the closed form does not apply."""
    if not data.structure.kind.spoked:
        return None
    p = dict(zip(data.structure.param_names, data.params))
    r = steady_roll(p)
    if r is None or r[0] > r[1]:
        return None
    return (f"{field}: {round(math.pi / p['alpha'])} spokes on a {p['gamma']:g} rad slope cannot "
            f"roll steadily: the post-impact rate {r[0]:.4g} rad/s is below the {r[1]:.4g} "
            "rad/s that vaults the hub over a spoke (McGeer 1990); give more spokes or a "
            "steeper slope")
