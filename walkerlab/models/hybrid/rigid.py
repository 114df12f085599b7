"""Build a :class:`~walkerlab.models.hybrid.base.HybridWalker` from generated model code.

Any biped described as data (:mod:`walkerlab.walker.description`) becomes a walker here: the
flow, its Jacobian, guards and their gradients, the heel-strike reset and its Jacobian,
energies, points and leg angles all come from the generated module
(:mod:`walkerlab.codegen.source`, cached by :mod:`walkerlab.codegen.cache`).

Phases of a step (point feet, straight legs):

- ``early_swing`` until ``swing_foot_ahead`` (``psi_sw - psi_st``) crosses zero upward (the
  legs pass each other; the point foot scuffs through the ground there, which the ideal
  model ignores, paper Sec. 3.2);
- ``late_swing`` until ``heel_strike`` (``psi_sw + psi_st + 2 gamma`` decreasing through
  zero: the swing foot reaches the slope), or a fall: the swing leg falls back behind the
  stance leg, or the hip reaches the slope.

Flat feet on ankle springs have their own phase graph
(:mod:`walkerlab.models.hybrid.rigid_foot_modes`), free joints theirs
(:mod:`walkerlab.models.hybrid.rigid_free_joints`), a rimless wheel its one phase
(:mod:`walkerlab.models.hybrid.rolling_polygon`): :func:`make_rigid_walker` reaches each
through the walker's kind, whose rigid part each gives its behaviour (:class:`RigidMaker`).

Phases of a step with a knee (McGeer 1990 "Passive walking with knees"; Hsu Chen 2007):

- ``unlocked_swing`` (three links) until ``knee_extension`` (shank minus thigh angle) crosses
  zero upward: the knee straightens against its stop, the plastic knee strike
  (``knee_reset``) locks it and the step goes on; a fall if the swing foot reaches the ground
  first - scuffing, or landing on a bent knee (``swing_foot_scuffs``: its clearance above the
  slope falls below
  ``-SCUFF_DEPTH * L`` - reported, not ignored; the small depth makes a foot that starts on
  the ground, clearance 0 to round-off, and is driven into it fire the guard) or the hip
  reaches the slope;
- ``locked_swing`` (two links, same coordinates, knee constraint) until ``heel_strike``; a
  fall if the swing leg falls back behind the stance leg, if the straight swing leg passes
  the stance leg (``swing_foot_scuffs``: its foot would go through the ground), or the hip
  reaches the slope.  The heel strike takes place with the knee locked; the new swing knee
  starts straight and free.

A walker in 3D (straight legs or locking knees) falls when its hip is half its leg length
above the ground (:data:`~walkerlab.models.ground.FALL_HIP_FRACTION`, the
compliant-contact model's fall), not at the ground: a sideways capsize (a lean of 1 rad at
15 rad/s) stalls the integrator's steps at 1e-9 s before the hip gets there.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from functools import partial

import numpy as np

from walkerlab.codegen.cache import functions
from walkerlab.models.compiled_flows import CompiledFlow
from walkerlab.models.ground import FALL_HIP_FRACTION
from walkerlab.models.hybrid.base import LEGS, Guard, HybridWalker, Phase, role_to_leg
from walkerlab.models.hybrid.rigid_foot_modes import make_flat_walker
from walkerlab.models.hybrid.rigid_free_joints import make_five_link_walker
from walkerlab.models.hybrid.rolling_polygon import make_spoked_walker
from walkerlab.walker import parts as P
from walkerlab.walker.description import WalkerData
from walkerlab.walker.foot_trees import creep_rate

#: Penetration of the swing foot (fraction of the leg length) reported as scuffing.
SCUFF_DEPTH = 1e-9


def _below(clearance, depth, t, x):
    """``clearance + depth``: crosses zero downward when the foot is ``depth`` deep."""
    return clearance(t, x) + depth


def _fall_offset(data: WalkerData) -> float:
    """The offset [m] of the generated ``hip_height`` guard at which a step is a fall: a
    walker in 3D falls with its hip :data:`~walkerlab.models.ground.FALL_HIP_FRACTION`
    of its leg length above the ground (the compliant-contact model's fall: a sideways
    capsize stalls the integrator before the hip reaches the ground), a planar one with its
    hip at the ground (0)."""
    return -FALL_HIP_FRACTION * data.leg_length_m if data.structure.in_3d else 0.0


def _kneed_phases(data: WalkerData, f: dict, flow, flow_jacobian, var, compiled, heel: Guard,
                  falls_back: Guard, fall: Guard) -> tuple[Phase, Phase]:
    """The two phases of a kneed walker for :func:`make_rigid_walker`: ``unlocked_swing``
    (the free knee, ended by the knee strike, its reset leading to the next phase, or by a
    swing foot scuffing more than :data:`SCUFF_DEPTH` times the leg length below the ground)
    and ``locked_swing`` (the locked knee, ended by the heel strike), each also by a fall;
    ``f`` are the generated functions, ``flow`` the unlocked flow, ``var`` its variational
    right-hand side and ``compiled(name, *guards)`` the compiled flow (or None);
    ``flow_jacobian`` is unused (the printed equations' replacements are straight-legged)."""
    ahead, dahead = f["guard_swing_foot_ahead"], f["grad_swing_foot_ahead"]
    return (
        Phase("unlocked_swing", flow, (
            Guard("knee_strike", f["guard_knee_extension"], +1, "next_phase",
                  f["grad_knee_extension"], f["knee_reset"], f["knee_reset_jacobian"]),
            Guard("swing_foot_scuffs", partial(_below, f["guard_swing_clearance"],
                                               SCUFF_DEPTH * data.leg_length_m), -1, "fall",
                  f["grad_swing_clearance"]), fall),
            jacobian=f["flow_jacobian"], variational=var,
            compiled=compiled("flow", ("knee_extension", 0.0),
                              ("swing_clearance", SCUFF_DEPTH * data.leg_length_m),
                              ("hip_height", _fall_offset(data)))),
        Phase("locked_swing", f["flow_locked"], (
            heel, falls_back, Guard("swing_foot_scuffs", ahead, +1, "fall", dahead), fall),
            jacobian=f["flow_locked_jacobian"],
            variational=f.get("flow_locked_variational"),
            compiled=compiled("flow_locked", ("heel_strike", 0.0), ("swing_foot_ahead", 0.0),
                              ("swing_foot_ahead", 0.0), ("hip_height", _fall_offset(data))),
            constraint=partial(_lock_gradient, f["grad_knee_extension"])),
    )


def _lock_gradient(grad, x):
    """The locked knee's constraint gradient in ``q`` (n,): the first half of the generated
    ``knee_extension`` guard's state gradient (it depends on the angles only)."""
    x = np.asarray(x)
    return np.asarray(grad(x))[:x.size // 2]


def _straight_leg_phases(data: WalkerData, f: dict, flow, flow_jacobian, var, compiled,
                         heel: Guard, falls_back: Guard, fall: Guard) -> tuple[Phase, Phase]:
    """The two phases of a straight-leg walker for :func:`make_rigid_walker`:
    ``early_swing`` until mid-stance (the swing foot passing the stance foot) and
    ``late_swing`` until the heel strike or the swing leg falling back, each also ended by a
    fall; ``data`` the walker's description (its fall's hip height, :func:`_fall_offset`),
    ``f`` the generated functions, ``flow``/``flow_jacobian`` the flow and its
    Jacobian (``flow_jacobian`` None: the generated one), ``var`` the variational
    right-hand side and ``compiled(name, *guards)`` the compiled flow (or None)."""
    ahead, dahead = f["guard_swing_foot_ahead"], f["grad_swing_foot_ahead"]
    early = Phase("early_swing", flow, (Guard("midstance", ahead, +1, "next_phase", dahead),
                                        fall), jacobian=flow_jacobian or f["flow_jacobian"],
                  variational=var,
                  compiled=compiled("flow", ("swing_foot_ahead", 0.0),
                                    ("hip_height", _fall_offset(data))))
    late = Phase("late_swing", flow, (heel, falls_back, fall),
                 jacobian=flow_jacobian or f["flow_jacobian"], variational=var,
                 compiled=compiled("flow", ("heel_strike", 0.0), ("swing_foot_ahead", 0.0),
                                   ("hip_height", _fall_offset(data))))
    return early, late


def make_rigid_walker(data: WalkerData, name: str = "biped", variant: str = "derived",
                      flow=None, flow_jacobian=None, reset=None, reset_jacobian=None,
                      double_support: bool = True) -> HybridWalker:
    """A hybrid walker from generated code; ``flow``/``reset`` may override the generated ones
    (the paper's printed Appendix A variants).

    The walker's kind (:attr:`walkerlab.walker.description.Structure.kind`) holds its
    rigid model's maker (:attr:`walkerlab.walker.kinds.Kind.rigid`), given its behaviour
    here.

    Parameters
    ----------
    data : WalkerData
    name, variant : str
        Stored in artifacts.
    flow, flow_jacobian, reset, reset_jacobian : callable, optional
        Replacements for the generated functions (same signatures): straight legs and
        locking knees only.
    double_support : bool
        Flat feet: the double support after heel strike
        (:func:`walkerlab.models.hybrid.rigid_foot_modes.make_flat_walker`); False: the trailing
        foot leaves the ground at heel strike.

    Returns
    -------
    HybridWalker

    Raises
    ------
    ValueError
        Replacements for a kind whose equations have none (one line).
    """
    printed = {"flow": flow, "flow_jacobian": flow_jacobian, "reset": reset,
               "reset_jacobian": reset_jacobian}
    return data.structure.kind.rigid.build(data, name, variant, printed, double_support)


@dataclass(frozen=True)
class _Legs:
    """What the legged kinds built on one generated flow differ in: ``phases`` (the phases
    of a step, :func:`_straight_leg_phases` or :func:`_kneed_phases`) and
    ``angles_are_coordinates(structure)`` (the state's coordinates are the legs' absolute
    angles, so the walker needs no ``leg_angles`` map)."""

    phases: Callable
    angles_are_coordinates: Callable


def _absolute_legs_only(structure) -> bool:
    """Straight legs: absolute coordinates and no upper body."""
    return structure.coordinates == "absolute" and not structure.torso


def _never(structure) -> bool:
    """A knee's shank angle is a coordinate of its own: the map is always needed."""
    return False


#: the legged kinds' parts (:func:`_make_legged`): straight legs, knees that lock, straight
#: legs in 3D (the state has the lean besides the legs' angles: the map names them)
_STRAIGHT = _Legs(_straight_leg_phases, _absolute_legs_only)
_LOCKING = _Legs(_kneed_phases, _never)
_STRAIGHT_3D = _Legs(_straight_leg_phases, _never)


def _make_legged(legs: _Legs, data: WalkerData, name: str, variant: str, printed: dict,
                 double_support: bool) -> HybridWalker:
    """Straight legs or locking knees (``legs``: their phases): one generated flow, its
    phases, the heel-strike reset (``printed``: the printed equations' replacements)."""
    flow, flow_jacobian = printed["flow"], printed["flow_jacobian"]
    reset, reset_jacobian = printed["reset"], printed["reset_jacobian"]
    f = functions(data)
    # the compiled flow is the generated one: none when the flow is replaced
    generated_flow = flow is None and flow_jacobian is None
    # the generated variational right-hand side belongs to the generated flow only
    var = f.get("flow_variational") if generated_flow else None

    def compiled(name, *guards):  # guards: (generated guard, offset) of each Phase guard
        if generated_flow:   # a 3D walker's Python flow is slow: compiled under "auto"
            return CompiledFlow(data.structure, tuple(data.params), name, guards,
                                by_default=data.structure.in_3d)
        return None
    flow = flow or f["flow"]
    # the hip at the ground, or a walker in 3D's at half its leg length (_fall_offset)
    hip, drop = f["guard_hip_height"], _fall_offset(data)
    if drop:
        hip = partial(_below, hip, drop)
    fall = Guard("fall", hip, -1, "fall", gradient=f["grad_hip_height"])
    ahead, dahead = f["guard_swing_foot_ahead"], f["grad_swing_foot_ahead"]
    heel = Guard("heel_strike", f["guard_heel_strike"], -1, "heel_strike", f["grad_heel_strike"])
    falls_back = Guard("swing_leg_falls_back", ahead, -1, "fall", dahead)
    phases = legs.phases(data, f, flow, flow_jacobian, var, compiled, heel, falls_back, fall)
    structure = data.structure
    params = {"leg_length_m": data.leg_length_m, "gravity_m_per_s2": data.gravity_m_per_s2,
              "total_mass_kg": data.total_mass_kg, "slope_rad": data.slope_rad, **data.extra,
              **dict(zip(structure.param_names, data.params))}
    coords = None if legs.angles_are_coordinates(structure) else f["leg_angles"]
    mirror = data.mirror
    odd = None
    if mirror is not None:  # legs that differ: the next step's walker (leg2 swinging)
        mirror = make_rigid_walker(replace(mirror, mirror_params=None), name, variant)
        roles = structure.mirror_odd_roles  # a 3D walker's steps on alternate sides
        odd = None if roles is None else tuple(f"{r}_{k}" for k in ("angle", "rate")
                                                for r in roles)
    return HybridWalker(
        name=name, variant=variant, roles=structure.roles, legs=LEGS, phases=phases,
        reset=reset or f["reset"], energies=f["energies"], points=f["points"],
        hip_x=f.get("hip_x"),
        section=f["section"], from_section=f["from_section"], role_to_leg=role_to_leg,
        total_mass_kg=data.total_mass_kg, slope_rad=data.slope_rad, params=params,
        variational=flow_jacobian or f["flow_jacobian"],
        reset_jacobian=reset_jacobian or f["reset_jacobian"],
        heel_strike_guard=f["guard_heel_strike"], leg_angles=coords, mirror=mirror,
        mirror_reflection=odd, matrices=f["matrices"],
        creep_rate=creep_rate(structure.roles, params),
    )


def _only_generated(data: WalkerData, printed: dict) -> None:
    """Refuse the printed equations' replacements for a kind that has none (one line)."""
    given = [k for k, v in printed.items() if v is not None]
    if given:
        raise ValueError(f"{', '.join(given)}: printed equations replace a straight-legged "
                         f"walker's only, not the {data.structure.kind.title}")


def _make_flat(data: WalkerData, name: str, variant: str, printed: dict,
               double_support: bool) -> HybridWalker:
    """Flat feet: the stance foot's modes, a phase graph of their own
    (:func:`walkerlab.models.hybrid.rigid_foot_modes.make_flat_walker`)."""
    _only_generated(data, printed)
    return make_flat_walker(data, name, variant, double_support=double_support)


def _make_free(data: WalkerData, name: str, variant: str, printed: dict,
               double_support: bool) -> HybridWalker:
    """Every joint free (five-link bipeds): one flow
    (:func:`walkerlab.models.hybrid.rigid_free_joints.make_five_link_walker`)."""
    _only_generated(data, printed)
    return make_five_link_walker(data, name, variant)


def _make_polygon(data: WalkerData, name: str, variant: str, printed: dict,
                  double_support: bool) -> HybridWalker:
    """A rimless (spoked) wheel rolling on its spokes
    (:func:`walkerlab.models.hybrid.rolling_polygon.make_spoked_walker`)."""
    _only_generated(data, printed)
    return make_spoked_walker(data, name, variant)


@dataclass(frozen=True)
class RigidMaker:
    """A rigid model's maker, the behaviour of a kind's rigid part
    (:attr:`walkerlab.walker.kinds.Kind.rigid`): ``make(data, name, variant, printed,
    double_support) -> HybridWalker``."""

    make: Callable

    def build(self, data: WalkerData, name: str, variant: str, printed: dict,
              double_support: bool) -> HybridWalker:
        """The kind's rigid hybrid walker (see :func:`make_rigid_walker`)."""
        return self.make(data, name, variant, printed, double_support)


P.RIGID_STRAIGHT_LEGS.provide(RigidMaker(partial(_make_legged, _STRAIGHT)))
P.RIGID_LOCKING_KNEES.provide(RigidMaker(partial(_make_legged, _LOCKING)))
P.RIGID_STRAIGHT_LEGS_3D.provide(RigidMaker(partial(_make_legged, _STRAIGHT_3D)))
P.RIGID_FLAT_FEET.provide(RigidMaker(_make_flat))
P.RIGID_FREE_JOINTS.provide(RigidMaker(_make_free))
P.RIGID_SPOKES.provide(RigidMaker(_make_polygon))
