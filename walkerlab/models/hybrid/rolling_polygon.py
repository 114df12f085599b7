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
    )
