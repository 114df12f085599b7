"""A :class:`~walkerlab.models.hybrid.base.HybridWalker` of a biped whose joints are all free
(``knee.lock: free``; with a hinged torso the five-link biped of Westervelt, Grizzle &
Koditschek 2003, IEEE TAC 48(1):42-56; a hinged torso on straight legs, the three-link
walker of Grizzle, Abba & Plestan 2001, IEEE TAC 46(1):51-64), from the code
:mod:`walkerlab.codegen.legged` generates.

One flow for the whole step (every link free, no knee lock), in two phases so that the
heel strike is looked for only once the swing foot is ahead:

- ``early_swing`` until ``swing_foot_ahead`` (the swing foot's distance ahead of the
  stance foot along the slope) crosses zero upward; a fall if the swing foot goes more than
  ``SCUFF_DEPTH * L`` below the ground (``swing_foot_scuffs``: it starts on the ground, so a
  foot driven into it fires at once; not on straight legs, whose foot passes through the
  ground at mid-stance, ignored as the compass gait's:
  :attr:`~walkerlab.walker.description.Structure.swing_foot_clears`) or the hip reaches the
  slope;
- ``late_swing`` until ``heel_strike`` (the swing foot's height above the slope decreasing
  through zero; straight legs: the legs symmetric about the slope's normal), or a fall:
  the swing foot falling back behind the stance foot, the hip reaching the slope.

The heel strike is plastic, the old stance foot leaves the ground without impulse, the legs
swap roles (:mod:`walkerlab.codegen.legged`).  The passive walker has no compiled flow
(``cyrk_compiled`` runs it on CyRK with the Python flow); one driven by joint torques does
(:mod:`walkerlab.codegen.actuated`, its guards' outputs from :func:`guard_outputs`).
"""

from __future__ import annotations

from functools import partial

from walkerlab.codegen.cache import functions
from walkerlab.models.hybrid.base import LEGS, Guard, HybridWalker, Phase, role_to_leg
from walkerlab.walker.description import WalkerData

__all__ = ["guard_outputs", "make_five_link_walker"]

#: Penetration of the swing foot (fraction of the leg length) reported as scuffing.
SCUFF_DEPTH = 1e-9


def _below(clearance, depth, t, x):
    """``clearance + depth``: crosses zero downward when the foot is ``depth`` deep."""
    return clearance(t, x) + depth


def guard_outputs(phase, data: WalkerData) -> tuple:
    """Each guard of ``phase`` as ``(generated guard, offset)``: the outputs of a compiled
    flow (:class:`walkerlab.models.compiled_flows.CompiledFlow` ``guards``) that are the same
    functions of the state as the phase's Python guards."""
    depth = SCUFF_DEPTH * data.leg_length_m
    table = {"midstance": ("swing_foot_ahead", 0.0),
             "swing_foot_scuffs": ("swing_clearance", depth), "fall": ("hip_height", 0.0),
             "heel_strike": ("heel_strike", 0.0),
             "swing_leg_falls_back": ("swing_foot_ahead", 0.0)}
    return tuple(table[g.name] for g in phase.guards)


def make_five_link_walker(data: WalkerData, name: str = "biped",
                          variant: str = "derived") -> HybridWalker:
    """The hybrid walker of a free-jointed biped (see the module docstring).

    Parameters
    ----------
    data : WalkerData
        Of a free-jointed kind, ``free_joints`` or ``hinged_torso``
        (:attr:`walkerlab.walker.description.Structure.kind`).
    name, variant : str
        Stored in artifacts.

    Returns
    -------
    HybridWalker
        Roles ``stance_shank, stance_thigh, swing_thigh, swing_shank[, torso]``; straight
        legs ``stance, swing, torso``.
    """
    f = functions(data)
    jac, var = f["flow_jacobian"], f.get("flow_variational")
    fall = Guard("fall", f["guard_hip_height"], -1, "fall", gradient=f["grad_hip_height"])
    ahead, dahead = f["guard_swing_foot_ahead"], f["grad_swing_foot_ahead"]
    scuffs = Guard("swing_foot_scuffs", partial(_below, f["guard_swing_clearance"],
                                                SCUFF_DEPTH * data.leg_length_m), -1, "fall",
                   f["grad_swing_clearance"])
    early = Phase("early_swing", f["flow"], (Guard("midstance", ahead, +1, "next_phase",
                                                   dahead),
                                             *((scuffs,) if data.structure.swing_foot_clears
                                               else ()), fall),
                  jacobian=jac, variational=var)
    late = Phase("late_swing", f["flow"], (
        Guard("heel_strike", f["guard_heel_strike"], -1, "heel_strike",
              f["grad_heel_strike"]),
        Guard("swing_leg_falls_back", ahead, -1, "fall", dahead), fall),
        jacobian=jac, variational=var)
    structure = data.structure
    params = {"leg_length_m": data.leg_length_m, "gravity_m_per_s2": data.gravity_m_per_s2,
              "total_mass_kg": data.total_mass_kg, "slope_rad": data.slope_rad, **data.extra,
              **dict(zip(structure.param_names, data.params))}
    return HybridWalker(
        name=name, variant=variant, roles=structure.roles, legs=LEGS, phases=(early, late),
        reset=f["reset"], energies=f["energies"], points=f["points"], hip_x=f.get("hip_x"),
        section=f["section"], from_section=f["from_section"], role_to_leg=role_to_leg,
        total_mass_kg=data.total_mass_kg, slope_rad=data.slope_rad, params=params,
        variational=jac, reset_jacobian=f["reset_jacobian"],
        heel_strike_guard=f["guard_heel_strike"], leg_angles=f["leg_angles"],
        matrices=f["matrices"])
