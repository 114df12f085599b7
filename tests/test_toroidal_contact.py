"""Feet curved in both directions and arms coupled to the opposite legs in the contact model
(configs/collins2001_stable.yaml; Collins, Wisse & Ruina 2001, IJRR 20(7)): the floating
view's torus contact against the rigid model's rolling (a Chaplygin reduction, a different
derivation: :mod:`walkerlab.codegen.rolling_feet`), the contact walk's first step against
the rigid step, and the stance foot's drilling that the two models treat differently.

The rigid model's stance foot sits on a universal ankle (roll about the fall line, then
pitch about the rolled hip axis; Kuo 1999): its heading is held, so the foot spins about
the ground's normal at ``omega_n = -beta' sin(phi)`` (``beta`` the stance pitch, ``phi``
the lean).  With the heading free, the contact's torsional friction holds that spin near
zero instead, and the whole walker turns by ``heading' = beta' sin(phi)``; the scene's
contact holds the heading (``contact.hold_heading``) and lets the foot spin (no torsional
friction), the rigid model's assumptions, and walks the rigid gait.

The slow tests need the cold derivations of this structure's rigid and floating views
(about 3 minutes on a 2-core machine).
"""

from __future__ import annotations

import math
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
import yaml

from walkerlab.analysis.gait.poincare import find_fixed_point
from walkerlab.config import TerrainSettings
from walkerlab.config.schema import Scene
from walkerlab.integrate.rigid import simulate_steps
from walkerlab.integrate.solver import Solver
from walkerlab.models.contact.scene import ContactSceneError, ContactSetup, contact_setup
from walkerlab.models.registry import build_walker
from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]
SOLVER = Solver(method="DOP853", rtol=1e-12, atol=1e-12)


def test_default_patches_lengthen_to_hold_a_rolling_foots_touchdown():
    """A round foot that touches down farther behind its patch's centre than the patch's
    half length: the default ground (no terrain section) lengthens its patches by the roll,
    keeping the default's 0.05 m at either end; a scene's own patches are refused in one
    line naming terrain.patch_width_m; a roll the patch holds keeps it (the shipped disc
    walkers' 0.038 m)."""
    default = TerrainSettings()
    setup = SimpleNamespace(terrain=default, name="s", scene=SimpleNamespace(terrain=None))
    grown = ContactSetup._holding_the_roll(setup, 0.0724)
    assert grown.patch_width_m == pytest.approx(2 * (0.0724 + 0.05))
    assert ContactSetup._holding_the_roll(setup, 0.038) is default
    own = SimpleNamespace(terrain=default, name="s", scene=SimpleNamespace(terrain=default))
    with pytest.raises(ContactSceneError, match="terrain.patch_width_m") as err:
        ContactSetup._holding_the_roll(own, 0.0724)
    assert "\n" not in str(err.value)


@pytest.fixture(scope="module")
def collins():
    """The stable Collins walker's scene, plant, rigid walker, its fixed point and its first
    rigid step from there."""
    scene = Scene.model_validate(yaml.safe_load(
        (ROOT / "configs" / "collins2001_stable.yaml").read_text()))
    plant = Plant.from_scene(scene)
    walker = build_walker(plant)
    g = scene.fixedpoint.initial_guess.model_extra
    guess = np.array([g[n + ("_rad" if n.endswith("_angle") else "_rad_per_s")]
                      for n in walker.state_names()])
    x = np.array(find_fixed_point(walker, guess, SOLVER, fd_check=False).x, float)
    step = simulate_steps(walker, x, 1, SOLVER).segments[0]
    return scene, plant, walker, x, step


def _free_heading(scene: Scene) -> Scene:
    """The scene with the heading free and a torsional friction that holds the foot's spin
    (0.08 m: under 0.7 mrad a stance)."""
    raw = scene.model_dump(exclude_none=True)
    raw["contact"].update(hold_heading=False, torsional_friction_m=0.08)
    return Scene.model_validate(raw)


@pytest.mark.slow
@pytest.mark.parametrize("held", [True, False])
def test_the_torus_contact_moves_as_the_rigid_rolling_foot(collins, held):
    """Over the rigid model's first step, each rigid state placed in the floating view with
    the stance foot's material contact point at rest (its rates then carry the torus'
    rolling, fore-aft ``(R - R_l + R_l cos phi) beta'`` and across ``R_l phi'``) has the
    rigid model's kinetic energy to 1e-12 relative (the arms' coupling and the rolling
    both), and at the rigid heel strike the swing torus' lowest point is on the ground to
    1e-9 m (the torus' lateral section, ``R_l phi`` across, in both derivations); with the
    heading held (the scene's) and free alike, the held view without the heading."""
    scene, plant, walker, _, step = collins
    scene = scene if held else _free_heading(scene)
    cw, _ = contact_setup(scene, plant=plant).build(step.x_start, 2)
    assert ("heading" in cw.coordinate_names()) is not held
    names = walker.state_names()
    assert len(names) == step.x_start.size
    for x in step.sample(np.linspace(step.t_start, step.t_end, 9)).T:
        z = cw.link_state_from_ideal(x)
        xf = cw.pinned_to_full(z, np.zeros(cw.dim))
        ke_rigid = float(np.real(walker.energies(x)[0]))
        ke_floating = float(cw.energies(np.atleast_2d(xf))["kinetic"][0])
        assert abs(ke_floating - ke_rigid) < 1e-12 * ke_rigid
    xf = cw.pinned_to_full(cw.link_state_from_ideal(step.x_end), np.zeros(cw.dim))
    pen = cw.contact_quantities(xf)
    assert abs(pen["leg1"]["penetration"][0] - pen["leg2"]["penetration"][0]) < 1e-9


@pytest.mark.slow
def test_the_stable_collins_walker_steps_in_contact_and_turns_by_the_rigid_foots_drilling(
        collins):
    """The contact walk from the rigid gait, its heading free (:func:`_free_heading`): its
    first step's period within 0.5 % of the rigid step's (measured -0.2 %), and over that
    stance the
    walker turns about the ground's normal by the rigid stance foot's drilling, the
    integral of ``beta' sin(phi)`` over the rigid step (38.7 mrad), within 15 % (measured
    35.1 mrad: the contact's lean departs from the rigid one's by 12 mrad by the heel
    strike) while the stance foot itself turns under 1 mrad."""
    from walkerlab.analysis.contact.sim import simulate_from

    scene, plant, walker, x, step = collins
    names = walker.state_names()
    ts = np.linspace(step.t_start, step.t_end, 2001)
    X = step.sample(ts)
    drill = float(np.trapezoid(X[names.index("stance_rate")]
                               * np.sin(X[names.index("lean_angle")]), ts))
    assert 0.03 < drill < 0.05
    setup = contact_setup(_free_heading(scene), plant=plant)
    cw, run = simulate_from(setup, x, step.period, strides=1)[:2]
    assert abs(run.steps[0].period / step.period - 1) < 0.005
    at = np.searchsorted(run.t, run.heel_strike_times[0])
    heading = run.x[at, list(run.state_names).index("heading")]
    assert abs(heading / drill - 1) < 0.15
    assert abs(run.steps[0].stance_turn_mrad) < 1.0


@pytest.mark.slow
def test_the_stable_collins_walker_with_its_heading_held_walks_the_rigid_gait(collins):
    """The scene's contact (``contact.hold_heading``, no torsional friction: the rigid
    model's stance foot): 10 alternating heel strikes, every step's period within 1 % of
    the rigid step's (measured -0.31 % to +0.40 %: issue 98's 3 %), and the stance foot
    spins about the ground's normal by the rigid universal ankle's drilling, the integral of
    ``beta' sin(phi)`` over the rigid step (38.7 mrad), within 3 % (measured 38.95 mrad)."""
    from walkerlab.analysis.contact.sim import simulate_from

    scene, plant, walker, x, step = collins
    names = walker.state_names()
    ts = np.linspace(step.t_start, step.t_end, 2001)
    X = step.sample(ts)
    drill = float(np.trapezoid(X[names.index("stance_rate")]
                               * np.sin(X[names.index("lean_angle")]), ts))
    setup = contact_setup(scene, plant=plant)
    cw, run = simulate_from(setup, x, step.period, strides=5)[:2]
    assert "heading" not in run.state_names
    periods = np.array([s.period for s in run.steps if np.isfinite(s.period)])
    assert periods.size >= 10
    assert np.max(np.abs(periods[:10] / step.period - 1)) < 0.01
    assert abs(abs(run.steps[0].stance_turn_mrad) / (1e3 * abs(drill)) - 1) < 0.03


def test_torus_contact_point_is_the_tube_circles_lowest_point_lowered_by_the_tube():
    """The floating view's torus contact (``_disc_contact`` with a lateral radius) against
    the rigid model's formula ``c - (R - R_l) Rot(s, phi) n - R_l n`` for a leg rolled by
    ``phi`` and pitched by ``beta`` (no heading), and its material point's velocity against
    the rolling of :mod:`walkerlab.codegen.rolling_feet`: ``v_m = c' + (R - R_l + R_l
    cos phi) beta' s - R_l phi' z``, symbolically."""
    import sympy as sp

    from walkerlab.codegen.floating_equations import _disc_contact
    from walkerlab.codegen.frames import rotation
    from walkerlab.codegen.rolling_feet import contact_point, material_jacobian

    phi, beta, x, y, z = sp.symbols("phi beta x y z")
    R, R_l = sp.Rational(21, 100), sp.Rational(37, 100)
    E_S, E_Z = sp.Matrix([1, 0, 0]), sp.Matrix([0, 0, 1])
    rot = rotation(E_S, phi) * rotation(E_Z, beta)
    q = (x, y, z, phi, beta)
    c = sp.Matrix([x, y, z])
    dq = sp.symbols("dx dy dz dphi dbeta")
    omega_world = dq[3] * E_S + dq[4] * (rotation(E_S, phi) * E_Z)
    omega = rot.T * omega_world
    kin = SimpleNamespace(rotations={"leg": rot}, omegas={"leg": omega}, q=q, dq=dq)
    low, J = _disc_contact(kin, "leg", c, R, R_l)
    ref_low = contact_point(c, phi, R, R_l)
    ref = material_jacobian(ref_low, q, phi, beta, R, R_l)
    for lean in (-0.1, 0.0, 0.03):
        vals = {phi: lean, beta: -0.3, x: 0.2, y: 0.1, z: -0.05}
        assert np.allclose(np.array(low.subs(vals), float),
                           np.array(ref_low.subs(vals), float), atol=1e-15)
        assert np.allclose(np.array(J.subs(vals), float), np.array(ref.subs(vals), float),
                           atol=1e-14)
        assert math.isclose(float((low[1] - y).subs(vals)),
                            -(0.21 - 0.37) * math.cos(lean) - 0.37, abs_tol=1e-15)


def test_the_mjcf_spheroid_has_the_torus_rim_and_lateral_curvature():
    """The MJCF's toroidal foot (MuJoCo has no torus): the spheroid of semi-axes ``(R,
    sqrt(R R_l), R)`` about the hip axis.  Its lowest point, leaned by ``phi`` (the support
    function of its meridian ellipse, ``sqrt(R^2 cos^2 phi + b^2 sin^2 phi)`` below the
    centre), against the torus' ``(R - R_l) cos phi + R_l``: equal upright and through the
    second order in the lean (the lateral radius ``b^2 / R = R_l``; both even in the lean,
    they part at its fourth power), 3.5 um apart at 0.1 rad on
    configs/collins2001_stable.yaml's 0.21 / 0.37 m feet (5.6 nm at 0.02 rad)."""
    from walkerlab.export.legs_3d_mjcf import foot_spheroid

    R, R_l = 0.21, 0.37
    a, b, c = foot_spheroid(R, R_l)
    assert (a, c) == (R, R) and b * b / R == pytest.approx(R_l, rel=1e-15)
    for phi, most in ((0.0, 1e-15), (0.02, 1e-8), (0.05, 3e-7), (0.1, 4e-6)):
        spheroid = math.sqrt((R * math.cos(phi)) ** 2 + (b * math.sin(phi)) ** 2)
        torus = (R - R_l) * math.cos(phi) + R_l
        assert abs(spheroid - torus) < most
    phi = 0.1
    gap = math.sqrt((R * math.cos(phi)) ** 2 + (b * math.sin(phi)) ** 2) - (
        (R - R_l) * math.cos(phi) + R_l)
    assert gap == pytest.approx(-3.5e-6, rel=0.05)


@pytest.mark.slow
def test_the_stable_collins_mjcf_starts_at_the_rigid_gait(collins, tmp_path):
    """configs/collins2001_stable.yaml's MJCF (arms on shoulder hinges held to the opposite
    legs' by tendon equalities, the pelvis on three slides and a roll as the rigid model's,
    spheroid feet), loaded by MuJoCo: its keyframe's kinetic energy from MuJoCo's own mass
    matrix is the rigid gait's to 1e-12 (the arms' inertia and coupling, the torus'
    rolling rates), the couplings hold there, and both spheroids (the heel strike's) touch
    their patches within 1e-6 m (measured 2.4e-8 m: the spheroid is not quite the torus at
    the lean); the walk is tests/test_export_walks.py's (11 heel strikes, +0.11 %)."""
    mujoco = pytest.importorskip("mujoco")
    from walkerlab.stages import export as export_stage

    scene, _, walker, x, _ = collins
    m = mujoco.MjModel.from_xml_path(str(export_stage.run(scene, tmp_path, "mjcf")))
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, 0)
    mujoco.mj_forward(m, d)
    M = np.zeros((m.nv, m.nv))
    mujoco.mj_fullM(m, d, M)
    ke = 0.5 * d.qvel @ M @ d.qvel
    ke_rigid = float(np.real(walker.energies(x)[0]))
    assert abs(ke - ke_rigid) < 1e-12 * ke_rigid
    assert [m.joint(i).name for i in range(4)] == ["pelvis_x", "pelvis_y", "pelvis_z",
                                                    "pelvis_roll"]
    assert m.neq == 2 and np.max(np.abs(d.ten_length)) < 1e-12
    for leg in ("leg1", "leg2"):
        assert m.geom(f"{leg}_foot").type == mujoco.mjtGeom.mjGEOM_ELLIPSOID
    for leg in ("leg1", "leg2"):   # each spheroid's lowest point on its patch's top
        foot, patch = m.geom(f"{leg}_foot").id, m.geom(f"{leg}_patch0").id
        n = d.geom_xmat[patch].reshape(3, 3)[:, 2]
        top = d.geom_xpos[patch] + m.geom_size[patch][2] * n
        A = d.geom_xmat[foot].reshape(3, 3) @ np.diag(m.geom_size[foot])
        w = A.T @ n
        low = d.geom_xpos[foot] - A @ (w / np.linalg.norm(w))
        assert abs((low - top) @ n) < 1e-6


@pytest.mark.parametrize(("scene_name", "fmt", "field"), [
    ("toroidal_feet_3d", "urdf", "walker.leg.foot.kind"),
    ("toroidal_feet_3d", "adm", "walker.leg.foot.kind"),
    ("toroidal_feet_3d", "osim", "walker.leg.foot.kind"),
    ("collins2001_stable", "adm", "walker.arms"),
    ("collins2001_stable", "osim", "walker.arms"),
])
def test_formats_without_a_spheroid_or_the_arms_coupling_refuse_them(scene_name, fmt, field,
                                                                     tmp_path):
    """The URDF (no spheroid geometry), the Adams dataset and the OpenSim model refuse
    toroidal feet, and the latter two arms, in one line naming the field and pointing at
    the MJCF, before any gait search, writing nothing (a torus written as their disc would
    be a different foot)."""
    from walkerlab.stages import export as export_stage

    scene = Scene.model_validate(yaml.safe_load(
        (ROOT / "configs" / f"{scene_name}.yaml").read_text()))
    with pytest.raises(ValueError, match=field) as err:
        export_stage.run(scene, tmp_path, fmt)
    assert "--format mjcf" in str(err.value) and "\n" not in str(err.value)
    assert not list(tmp_path.rglob("walker.*"))
