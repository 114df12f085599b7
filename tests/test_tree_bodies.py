"""The walker's export bodies read from its body tree (walkerlab/export/tree_bodies.py) in
MuJoCo: a 3D straight-legged walker with an upper body held by a bisecting hip mechanism
(Wisse, Hobbelen & Schwab 2007, "Adding an upper body to passive dynamic walking robots by
means of a bisecting hip mechanism", IEEE T-RO 23(1)), its MJCF loaded and posed at a state
of the walker's coordinates, against the tree's own kinematics
(:func:`walkerlab.codegen.tree_derive.kinematics`): every body's mass, centre of mass and
world inertia, and the torso's pitch held at the legs' mean by the fixed tendon.

Tolerances: the MJCF's numbers are the tree's evaluated (shortest round-trip floats), the
MuJoCo pose the tree's rotations turned into a quaternion, so positions agree to round-off
(measured: 2.2e-16 m); 1e-12 leaves room and still sees a mass misplaced by a micrometre.
The tendon's equality is a soft constraint (MuJoCo's default ``solref`` 0.02 s, timestep
2 ms): while the walker falls freely for 0.2 s with its legs swinging apart, the torso strays
from the legs' mean by < 1e-3 rad (measured 4.6e-5 rad); with the legs' coefficients' signs
wrong it strays by 1.3e-2 rad, with the torso's hinge turned the other way by 0.27 rad (and
0.09 rad at the pose itself).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import sympy as sp

from tests.compass_3d_tree import compass_3d_tree
from walkerlab.codegen.frames import slope_to_world
from walkerlab.codegen.tree_derive import kinematics
from walkerlab.export.axes_3d import TO_MUJOCO
from walkerlab.export.mjcf_document import tree_mjcf_text
from walkerlab.export.tree_bodies import PelvisRoles, export_bodies
from walkerlab.walker.tree import ZERO_INERTIA, Body, BodyTree, CoordinateMap, Joint, diagonal

mujoco = pytest.importorskip("mujoco")

Z = (0, 0, 1)
#: the walker's numbers: configs/hip_width.yaml's legs and pelvis, a rigid trunk and a head
VALUES = dict(g=9.81, L=1.0, gamma=0.0174, M_hip=10.0, m_leg=5.0, a_leg=0.5, w_hip=0.1,
              m_torso_trunk=8.0, d_torso_trunk=0.3, I_torso_trunk=0.4,
              m_torso_head=2.0, d_torso_head=0.6)
#: a state of the walker's coordinates away from every symmetry [rad]
STATE = dict(lean=0.07, swing=-0.31, stance=0.22)
#: MuJoCo's body -> the tree's body it is (the stance leg is the swing leg's copy)
#: and the parts welded to it, folded into its inertial
TREE_BODY = {"pelvis": ("pelvis",), "leg1": ("swing_leg", "swing_leg_mass"),
             "leg2": ("stance_leg", "stance_leg_mass"),
             "torso": ("torso", "torso_trunk", "torso_head")}


def torso_tree(parts=(("trunk", True), ("head", False))) -> tuple[BodyTree, CoordinateMap]:
    """compass_3d_tree's walker with an upper body on the bisecting hip: a massless frame
    ``torso`` on ``torso_pitch`` at the hips' midpoint, its angle the legs' mean pitch, and
    each part welded to it (a rigid part with ``I_torso_<part>`` about every axis normal to
    the torso, a point mass)."""
    base, coords = compass_3d_tree()
    params = base.params + tuple(
        n for p, rigid in parts
        for n in (f"m_torso_{p}", f"d_torso_{p}") + ((f"I_torso_{p}",) if rigid else ()))
    bodies = [*base.bodies, Body("torso", 0, ZERO_INERTIA, (0, 0, 0),
                                 Joint("torso_pitch", "revolute", "pelvis", (0, 0, "w_hip / 2"),
                                       (Z,), ("torso_pitch",)))]
    for p, rigid in parts:
        inertia = diagonal(f"I_torso_{p}", 0, f"I_torso_{p}") if rigid else ZERO_INERTIA
        bodies.append(Body(f"torso_{p}", f"m_torso_{p}", inertia, (0, f"d_torso_{p}", 0),
                           Joint(f"torso_{p}_weld", "fixed", "torso", (0, 0, 0))))
    tree = BodyTree(params, base.root, tuple(bodies), base.contacts)
    return tree, CoordinateMap(coords.names, coords.joint_angles
                               + (("torso_pitch", "(swing + stance) / 2 + gamma"),))


def _tree_at(tree, coords, state):
    """The tree's rotations, origins and centres of mass at ``state`` in MuJoCo's world axes
    (from the stance foot), and the reference pose's rotations."""
    kin = kinematics(tree, coords)
    sub = {**dict(zip(kin.params, (VALUES[p] for p in tree.params))),
           **{q: state[n] for q, n in zip(kin.q, coords.names)}}
    ref = {**sub, **{q: 0.0 for q in kin.q}}
    C = np.array(TO_MUJOCO)
    W = np.array(slope_to_world(kin.gamma).subs(sub), float)

    def ev(m, at):
        return np.array(sp.Matrix(m).subs(at).evalf(30), float)
    R = {b: C @ W @ ev(kin.rotations[b], sub) for b in kin.rotations}
    R0 = {b: C @ W @ ev(kin.rotations[b], ref) for b in kin.rotations}
    origin = {b: C @ W @ ev(kin.origins[b], sub).ravel() for b in kin.origins}
    com = {b: C @ W @ ev(kin.coms[b], sub).ravel() for b in kin.coms}
    inertia = {b: R[b] @ ev(kin.inertias[b], sub) @ R[b].T for b in kin.inertias}
    return R, R0, origin, com, inertia


def _posed(tree, coords, state):
    """The torso walker's MJCF in MuJoCo at ``state`` (the pelvis placed as the tree has it,
    the legs' hinges at ``swing``, ``stance``, the torso's at their mean), after
    ``mj_forward``."""
    model = mujoco.MjModel.from_xml_string(tree_mjcf_text(tree, coords, VALUES))
    data = mujoco.MjData(model)
    R, R0, origin, _com, _i = _tree_at(tree, coords, state)
    turn = R["pelvis"] @ R0["pelvis"].T              # the pelvis from its reference pose
    hips = R["pelvis"] @ np.array([0.0, 0.0, VALUES["w_hip"] / 2])   # the hips' midpoint
    quat = np.zeros(4)
    mujoco.mju_mat2Quat(quat, turn.ravel())
    q = data.qpos
    q[:3], q[3:7] = origin["pelvis"] + hips, quat
    q[model.jnt_qposadr[model.joint("leg1_hip").id]] = state["swing"]
    q[model.jnt_qposadr[model.joint("leg2_hip").id]] = state["stance"]
    q[model.jnt_qposadr[model.joint("torso_pitch").id]] = (state["swing"] + state["stance"]) / 2
    mujoco.mj_forward(model, data)
    return model, data


def _pitch(model, data, body: str) -> float:
    """``body``'s turn about the pelvis' hip axis (MuJoCo's ``0 -1 0``) from the pelvis
    [rad]: positive moves a leg's foot ahead, leans the torso back."""
    P = data.xmat[model.body("pelvis").id].reshape(3, 3)
    B = data.xmat[model.body(body).id].reshape(3, 3)
    rel = P.T @ B
    return math.atan2(rel[2, 0], rel[0, 0])


def test_the_torso_walkers_mjcf_has_the_trees_masses_centres_of_mass_and_inertias():
    """Posed at a state with lean, every MuJoCo body's centre of mass is the tree's body's
    (leg2 the stance leg), the total mass the tree's, the walker's centre of mass the
    tree's, and the rigid trunk's inertia in world axes the tree's turned with it."""
    tree, coords = torso_tree()
    model, data = _posed(tree, coords, STATE)
    _R, _R0, _origin, com, inertia = _tree_at(tree, coords, STATE)
    masses = {b.name: float(sp.sympify(b.mass_kg).subs(VALUES)) for b in tree.bodies}
    assert float(model.body_mass.sum()) == pytest.approx(sum(masses.values()), abs=1e-12)
    assert model.nbody - 1 == len(TREE_BODY)      # every welded part folded into its body
    for name, parts in TREE_BODY.items():
        i = model.body(name).id
        mass = sum(masses[b] for b in parts)
        assert float(model.body_mass[i]) == pytest.approx(mass, abs=1e-12), name
        centre = sum(masses[b] * com[b] for b in parts) / mass
        np.testing.assert_allclose(data.xipos[i], centre, rtol=0, atol=1e-12, err_msg=name)
    total = sum(masses[b] * com[b] for b in masses) / sum(masses.values())
    np.testing.assert_allclose(data.subtree_com[0], total, rtol=0, atol=1e-12)
    # the upper body's inertia about its centre of mass, world axes: the trunk's turned
    # with it and both parts' moved there (the parallel-axis theorem, written here)
    parts = TREE_BODY["torso"]
    centre = sum(masses[b] * com[b] for b in parts) / sum(masses[b] for b in parts)
    expected = sum(inertia[b] + masses[b] * (np.dot(com[b] - centre, com[b] - centre)
                                             * np.eye(3) - np.outer(com[b] - centre,
                                                                    com[b] - centre))
                   for b in parts)
    i = model.body("torso").id
    X = data.ximat[i].reshape(3, 3)
    world = X @ np.diag(model.body_inertia[i]) @ X.T
    # the frame's and the trunk's floors (1e-12 kg m^2) about the torso's own axis
    np.testing.assert_allclose(world, expected, rtol=0, atol=3e-12)
    assert np.linalg.eigvalsh(world)[-1] > VALUES["I_torso_trunk"]   # the head's on top


def test_the_bisecting_hip_tendon_holds_the_torso_at_the_legs_mean_pitch():
    """At a pose with the coupling met the tendon has zero length and the torso's pitch is
    the legs' mean to 1e-9 (its frame's up, MuJoCo's z, leaning back when the feet are
    ahead); let fall freely for 0.2 s from rates that spread the legs, MuJoCo's equality
    keeps it there (< 1e-3 rad: a soft constraint; module docstring)."""
    tree, coords = torso_tree()
    model, data = _posed(tree, coords, STATE)
    assert model.ntendon == 1 and model.neq == 1
    assert abs(float(data.ten_length[0])) < 1e-15
    legs = (_pitch(model, data, "leg1"), _pitch(model, data, "leg2"))
    np.testing.assert_allclose(legs, (STATE["swing"], STATE["stance"]), rtol=0, atol=1e-12)
    torso = _pitch(model, data, "torso")
    assert abs(torso - sum(legs) / 2) < 1e-9
    up = data.xmat[model.body("torso").id].reshape(3, 3)[:, 2]
    pelvis = data.xmat[model.body("pelvis").id].reshape(3, 3)
    ahead = pelvis[:, 0]                                     # downhill, in the pelvis' roll
    assert (up @ ahead) * (sum(legs) / 2) < 0                # feet ahead: the torso leans back
    dof = {j: model.jnt_dofadr[model.joint(j).id] for j in ("leg1_hip", "leg2_hip",
                                                           "torso_pitch")}
    data.qvel[dof["leg1_hip"]], data.qvel[dof["leg2_hip"]] = -2.0, 1.0
    data.qvel[dof["torso_pitch"]] = -0.5
    worst = 0.0
    for _ in range(int(0.2 / model.opt.timestep)):
        mujoco.mj_step(model, data)
        legs = (_pitch(model, data, "leg1"), _pitch(model, data, "leg2"))
        worst = max(worst, abs(_pitch(model, data, "torso") - sum(legs) / 2))
    assert worst < 1e-3
    assert abs(legs[0] - legs[1]) > 0.7                     # the legs did spread


def test_the_hip_roll_pelvis_and_rod_legs_carry_the_trees_inertias():
    """The hip-roll pelvis turns about the fall line only: its roll moment ``I_pelvis``
    about every axis; a rod leg's ``I_leg`` about the axes normal to it (MuJoCo's x and
    y: the leg along z) and the export's floor along it; the roll hinges' axes the fall
    line in MuJoCo's axes (``cos gamma, 0, -sin gamma``)."""
    tree, coords = compass_3d_tree(hip_roll=True, leg_inertia=True)
    values = {**VALUES, "I_leg": 0.05, "I_pelvis": 0.3, "kp_pelvis": 0.0, "kd_pelvis": 0.0,
              "kp_swing": 0.0, "kd_swing": 0.0, "g_lean": 0.0, "g_lean_rate": 0.0}
    root, couplings = export_bodies(tree, coords, values,
                                    PelvisRoles(pelvis_hinges=("stance_hip_roll",)))
    assert couplings == ()
    assert np.array_equal(root.inertia_kg_m2, 0.3 * np.eye(3))
    fall = (math.cos(0.0174), 0.0, -math.sin(0.0174))
    assert [j.name for j in root.joints] == ["pelvis_x", "pelvis_y", "pelvis_z", "pelvis_roll"]
    assert root.joints[-1].axis == fall
    for leg in root.children:
        assert np.array_equal(leg.inertia_kg_m2, np.diag([0.05, 0.05, 1e-12]))
        assert [j.name for j in leg.joints] == [f"{leg.name}_roll", f"{leg.name}_hip"]
        assert leg.joints[0].axis == fall and leg.joints[1].axis == (0.0, -1.0, 0.0)


def test_a_tree_missing_a_number_or_a_role_is_refused_in_one_line():
    tree, coords = torso_tree()
    with pytest.raises(ValueError, match=r"^values: no number for I_torso_trunk$"):
        export_bodies(tree, coords, {k: v for k, v in VALUES.items() if k != "I_torso_trunk"})
    with pytest.raises(ValueError, match=r"^roles.leg: 'thigh' is not a body of the tree$"):
        export_bodies(tree, coords, VALUES, PelvisRoles(leg="thigh"))
