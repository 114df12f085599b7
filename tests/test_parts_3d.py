"""Walkers written from parts (``model: biped``) in three dimensions (``space: 3d``,
``hip_width_m``; the body tree of :func:`walkerlab.walker.trees.biped_tree`)
against references that share no code with their generated equations: the planar walker of
the same parts (the planar embedding), the ``compass_gait`` shorthand's walker (configs/
hip_width.yaml), and a model written here from Newton's law for the point masses, the upper
body's on the bisector of the legs (tests/independent/parts_3d_newton.py).

Tolerances: the fixed points are solved to 1e-12 (``fixedpoint.tolerance``) with DOP853 at
1e-12, so the same gait found by two derivations agrees to ~1e-11; 1e-9 leaves room for the
conditioning of an unstable gait (a lateral multiplier of ~10-100).  The flow and the impact
of one walker evaluated by two models agree to round-off (1e-11 absolute on rates of order
1 rad/s and accelerations of order 10 rad/s^2).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml

from tests.independent.mirror_stride import stride_against
from tests.independent.parts_3d_newton import PartsReference
from walkerlab.analysis.gait.poincare import find_fixed_point
from walkerlab.config.schema import Scene
from walkerlab.integrate.solver import Solver
from walkerlab.models.registry import build_walker
from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]
SOLVER = Solver(method="DOP853", rtol=1e-12, atol=1e-12)
#: the paper's walker (Table 1) from parts, as configs/hip_width.yaml's shorthand writes it
PAPER_PARTS = {"model": "biped", "coordinates": "absolute", "gravity_m_per_s2": 9.81,
               "hip_mass_kg": 10.0, "leg": {"length_m": 1.0, "bodies": [
                   {"kind": "point_mass", "name": "mass", "mass_kg": 5.0,
                    "from_hip_m": 0.5}]}}


def _raw(name: str) -> dict:
    return yaml.safe_load((ROOT / "configs" / name).read_text())


def _in_3d(raw: dict, width: float) -> Scene:
    raw = dict(raw, walker={**raw["walker"], "space": "3d", "hip_width_m": width})
    for key in ("contact", "terrain", "contact_sim", "contact_solver"):
        raw.pop(key, None)
    return Scene.model_validate(raw)


def _walker(scene: Scene):
    return build_walker(Plant.from_scene(scene))


def _guess(scene: Scene, names) -> np.ndarray:
    g = scene.fixedpoint.initial_guess.model_extra
    return np.array([g.get(n + ("_rad" if n.endswith("_angle") else "_rad_per_s"), 0.0)
                     for n in names])


@pytest.fixture(scope="module")
def planar_torso_gait():
    scene = Scene.model_validate(_raw("torso_bhm.yaml"))
    walker = _walker(scene)
    return walker, find_fixed_point(walker, _guess(scene, walker.state_names()), SOLVER,
                                    fd_check=False)


def test_a_torso_walker_in_3d_with_zero_hip_width_walks_the_planar_torso_gait(
        planar_torso_gait):
    """configs/torso_bhm.yaml (an upper body on a bisecting hip) with ``space: 3d`` and
    ``hip_width_m: 0``, started upright from the planar gait: the same fixed point and step
    period to 1e-9 relative, the lean 0, and the planar multipliers among the 3D ones (the
    rest: the roll's, Kuo 1999's unstable lateral mode)."""
    flat, f = planar_torso_gait
    s = _planar_embedding(flat, f, _walker(_in_3d(_raw("torso_bhm.yaml"), 0.0)))
    assert np.max(np.abs(s.multipliers_variational)) > 1.0   # the roll: unstable


def _planar_embedding(flat, f, w3, tiny: float = 0.0):
    """The 3D walker ``w3`` of zero hip width, started upright from the planar walker
    ``flat``'s fixed point ``f``: the same fixed point and step period to 1e-9 relative, the
    lean and its rate 0, every planar multiplier above ``tiny`` among the 3D ones (to
    1e-7).  Returns the 3D fixed point."""
    names = w3.state_names()
    planar = dict(zip(flat.state_names(), f.x))
    s = find_fixed_point(w3, np.array([planar.get(n, 0.0) for n in names]), SOLVER,
                         fd_check=False)
    x3 = dict(zip(names, s.x))
    for name, value in planar.items():
        assert abs(x3[name] - value) <= 1e-9 * abs(value), name
    assert abs(x3["lean_angle"]) < 1e-12 and abs(x3["lean_rate"]) < 1e-12
    assert abs(s.period_s - f.period_s) <= 1e-9 * f.period_s
    for m in f.multipliers_variational:
        if abs(m) > tiny:
            assert np.min(np.abs(s.multipliers_variational - m)) < 1e-7, m
    return s


def _off_axis_torso() -> dict:
    """configs/torso_bhm.yaml with its leg mass 5 mm behind the leg's axis and a rigid
    upper body (0.05 kg m^2 about its centre, 1 cm behind its axis; the gait moves by a few
    per cent per mm of these offsets: larger ones lose it)."""
    raw = _raw("torso_bhm.yaml")
    walker = raw["walker"]
    walker["leg"]["bodies"][0]["off_axis_m"] = -0.005
    walker["torso"]["bodies"] = [{"kind": "rigid_body", "name": "trunk", "mass_kg": 5.0,
                                  "com_from_hip_m": 0.2, "com_off_axis_m": -0.01,
                                  "inertia_about_com_kg_m2": 0.05}]
    return raw


@pytest.mark.slow   # ~1 min: the planar and the 3D walkers' derivations
def test_off_axis_bodies_and_a_rigid_upper_body_in_3d_walk_the_planar_gait(planar_torso_gait):
    """Bodies off their link's axis (a leg mass 2 cm ahead of the leg, an upper body's
    centre 3 cm ahead of its axis) and a rigid upper body's inertia (about the hip axis; in
    3D about every axis normal to the upper body) at zero hip width, upright: the planar
    walker's fixed point and step period to 1e-9 relative, the lean 0."""
    raw = _off_axis_torso()
    flat = _walker(Scene.model_validate(raw))
    start = planar_torso_gait[1].x                 # the gait with the bodies on their axes
    f = find_fixed_point(flat, np.asarray(start), SOLVER, fd_check=False)
    w3 = _walker(_in_3d(raw, 0.0))
    planar = dict(zip(flat.state_names(), f.x))
    s = find_fixed_point(w3, np.array([planar.get(n, 0.0) for n in w3.state_names()]),
                         SOLVER, fd_check=False)
    x3 = dict(zip(w3.state_names(), s.x))
    for name, value in planar.items():
        assert abs(x3[name] - value) <= 1e-9 * abs(value), name
    assert abs(x3["lean_angle"]) < 1e-12 and abs(s.period_s - f.period_s) <= 1e-9 * f.period_s


def test_the_paper_walker_from_parts_in_3d_is_the_compass_shorthands_walker():
    """The paper's walker written from parts with ``space: 3d`` and a 0.1 m hip width
    finds configs/hip_width.yaml's gait (the ``compass_gait`` shorthand, the mass ``a =
    0.5 m`` from the foot = ``d = 0.5 m`` from the hip): fixed point and stride period to
    1e-10, the multipliers (Kuo's lateral one ~100 a stride) to 1e-8 relative."""
    short = Scene.model_validate(_raw("hip_width.yaml"))
    ws = _walker(short)
    a = find_fixed_point(ws, _guess(short, ws.state_names()), SOLVER, fd_check=False)
    parts = Scene.model_validate({**_raw("hip_width.yaml"),
                                  "walker": {**PAPER_PARTS, "space": "3d",
                                             "hip_width_m": 0.1}})
    wp = _walker(parts)
    assert wp.state_names() == ws.state_names()
    b = find_fixed_point(wp, _guess(parts, wp.state_names()), SOLVER, fd_check=False)
    assert np.max(np.abs(np.asarray(b.x) - np.asarray(a.x))) < 1e-10
    assert abs(b.period_s - a.period_s) < 1e-10
    mu_a = np.sort_complex(np.asarray(a.multipliers_variational))
    mu_b = np.sort_complex(np.asarray(b.multipliers_variational))
    assert np.max(np.abs(mu_a - mu_b) / np.maximum(1.0, np.abs(mu_a))) < 1e-8
    assert 50 < np.max(np.abs(mu_a)) < 200


#: configs/hip_width_stabilised.yaml's hip-roll law
LAW = _raw("hip_width_stabilised.yaml")["walker"]["hip_roll"]


def _stabilised_parts() -> dict:
    return {**PAPER_PARTS, "hip_roll": LAW}


@pytest.mark.slow  # 1-2 min each: the hip-roll walker's and the round feet's derivations
@pytest.mark.parametrize("shorthand, parts, width", [
    ("hip_width_stabilised.yaml", _stabilised_parts, 0.1),
    ("round_feet_3d.yaml", lambda: _raw("round_feet.yaml")["walker"], 0.0)],
    ids=["hip_roll_law", "round_feet_rod_legs"])
def test_a_3d_walker_from_parts_finds_the_shorthands_gait(shorthand, parts, width):
    """The same walker written from parts finds the ``compass_gait`` shorthand's gait with
    every 3D part the tree has: hip-roll joints and their foot-placement law (configs/
    hip_width_stabilised.yaml: the paper's legs with the scene's law), and round feet on rod
    legs (configs/round_feet.yaml's parts in 3D: configs/round_feet_3d.yaml): fixed point
    and period to 1e-10, the multipliers to 1e-8 relative."""
    short = Scene.model_validate(_raw(shorthand))
    ws = _walker(short)
    a = find_fixed_point(ws, _guess(short, ws.state_names()), SOLVER, fd_check=False)
    raw = _raw(shorthand)
    raw["walker"] = {**parts(), "space": "3d", "hip_width_m": width}
    wp = _walker(Scene.model_validate(raw))
    assert wp.state_names() == ws.state_names()
    b = find_fixed_point(wp, np.asarray(a.x), SOLVER, fd_check=False)
    assert np.max(np.abs(np.asarray(b.x) - np.asarray(a.x))) < 1e-10
    assert abs(b.period_s - a.period_s) < 1e-10
    mu_a = np.sort_complex(np.asarray(a.multipliers_variational))
    mu_b = np.sort_complex(np.asarray(b.multipliers_variational))
    assert np.max(np.abs(mu_a - mu_b) / np.maximum(1.0, np.abs(mu_a))) < 1e-8


#: configs/torso_bhm_3d.yaml's walker in the reference's terms
TORSO = dict(g=9.81, L=1.0, gamma=0.0174, M_hip=10.0, legs=[(5.0, 0.5)], torso=[(5.0, 0.2)])


@pytest.fixture(scope="module")
def torso_3d():
    scene = Scene.model_validate(_raw("torso_bhm_3d.yaml"))
    return _walker(scene), scene


def test_a_3d_torso_walkers_flow_and_impact_match_newtons_law(torso_3d):
    """configs/torso_bhm_3d.yaml's generated flow and heel-strike map against Newton's law
    for its point masses (the upper body's on the legs' bisector) at rolled states, on both
    sides (the mirror step's swing hip on the other side)."""
    walker, scene = torso_3d
    w = scene.walker.hip_width_m
    ref = PartsReference(**TORSO)
    rng = np.random.default_rng(5)
    for side, model in ((1.0, walker), (-1.0, walker.mirror)):
        for _ in range(4):
            x = np.array([0.05, -0.2, 0.17, 0.3, -0.6, -0.85]) + 0.05 * rng.standard_normal(6)
            assert np.max(np.abs(model.phases[0].flow(0.0, x)
                                 - ref.rhs(side * w)(0.0, x))) < 1e-11
            assert np.max(np.abs(model.reset(x) - ref.impact(side * w, x))) < 1e-11


@pytest.mark.slow  # ~40 s: the reference's own fixed point and central differences
def test_the_shipped_3d_torso_gait_and_multipliers_match_an_independent_model(torso_3d):
    """configs/torso_bhm_3d.yaml's period-1 gait (a stride: its steps mirrored) against
    the Newton's-law model's, found by scipy alone: the fixed point and the stride period
    to 1e-8, the multipliers to 1e-6 relative (central differences, h = 1e-6); the lateral
    mode unstable as Kuo's."""
    walker, scene = torso_3d
    res = find_fixed_point(walker, _guess(scene, walker.state_names()), SOLVER,
                           fd_check=False)
    assert res.residual < 1e-10
    dx, dt, dmu = stride_against(PartsReference(**TORSO), scene.walker.hip_width_m, res,
                                 [0, 2, 3, 4, 5])
    assert dx < 1e-8
    assert dt < 1e-8
    assert dmu < 1e-6
    assert np.max(np.abs(res.multipliers_variational)) > 1.0


@pytest.mark.parametrize("change, field", [
    # free knees (locking ones walk in 3D: tests/test_kneed_3d.py)
    ({"leg": {"length_m": 1.0, "knee": {"thigh_length_m": 0.5, "lock": "free"}, "bodies": [
        {"kind": "point_mass", "name": "thigh", "link": "thigh", "mass_kg": 5.0,
         "from_hip_m": 0.25},
        {"kind": "point_mass", "name": "shank", "link": "shank", "mass_kg": 1.0,
         "from_hip_m": 0.75}]}},
     "walker.leg.knee"),
    ({"coordinates": "slope_relative"}, "walker.coordinates"),
    ({"springs": [{"between": ["leg1", "leg2"], "stiffness_n_m_per_rad": 1.0}]},
     "walker.springs"),
    ({"torso": {"coupling": "hinged", "bodies": [
        {"kind": "point_mass", "name": "mass", "mass_kg": 5.0, "from_hip_m": 0.2}]}},
     "walker.torso.coupling"),
    ({"hip_width_m": 2.5}, "walker.hip_width_m"),
    ({"space": "2d", "hip_width_m": 0.1}, "walker.hip_width_m"),
    ({"hip_width_m": 0.0, "hip_roll": LAW}, "walker.hip_roll"),
    # arc feet take hip-roll joints (tests/test_round_feet_hip_roll_3d.py); rods do not
    ({"leg": {"length_m": 1.0, "bodies": [
        {"kind": "rod", "name": "rod", "mass_kg": 5.0, "com_from_hip_m": 0.5,
         "inertia_about_com_kg_m2": 0.4}]},
      "hip_roll": LAW}, "walker.hip_roll"),
])
def test_a_3d_biped_refuses_what_it_cannot_walk_yet_naming_the_field(change, field):
    raw = {**_raw("hip_width.yaml"), "walker": {**PAPER_PARTS, "space": "3d",
                                               "hip_width_m": 0.1, **change}}
    with pytest.raises(ValueError, match=field.replace(".", r"\.")):
        Scene.model_validate(raw)


def test_a_3d_torso_walkers_urdf_names_the_bisecting_hip_it_cannot_hold(torso_3d):
    """URDF has no joint held at the mean of two others: the torso walker's URDF carries the
    upper body on its hinge and names the coupling it leaves out (``2 torso_pitch - leg1_hip
    - leg2_hip = 0``); its masses add up to the walker's."""
    import xml.etree.ElementTree as ET

    from walkerlab.export.urdf import legs_urdf_text

    _walker_, scene = torso_3d
    data = Plant.from_scene(scene).data
    text = legs_urdf_text(data, "torso_bhm_3d")
    assert "2 * torso_pitch + -1 * leg1_hip + -1 * leg2_hip = 0" in text
    masses = [float(m.get("value")) for m in ET.fromstring(text.split("\n", 1)[1]).iter("mass")]
    assert sum(masses) == pytest.approx(data.total_mass_kg, abs=1e-9)


@pytest.mark.slow   # ~2 min: both gaits of the pair searched in 3D
def test_a_3d_torso_scene_of_zero_hip_width_selects_the_planar_gait():
    """configs/torso_bhm.yaml with ``space: 3d`` and ``hip_width_m: 0`` run as a user runs
    it (its own initial guess, which does not converge in 3D, and ``fixedpoint.gait:
    stable``): the search falls back to the planar twin's gait and, both 3D gaits being
    unstable in roll, selects the one nearest that start - the planar gait (step period
    0.850906 s), not the short-period one (0.706 s) nearer the scene's failed guess."""
    from walkerlab.analysis.gait.scene import solve_scene

    raw = _raw("torso_bhm.yaml")
    raw["fixedpoint"]["initial_guess"].update(lean_angle_rad=0.0, lean_rate_rad_per_s=0.0)
    scene = _in_3d(raw, 0.0)
    _w, search = solve_scene(scene, fd_check=False, plant=Plant.from_scene(scene))
    chosen = search.gaits[search.selected].result
    flat = Scene.model_validate(_raw("torso_bhm.yaml"))
    wf = _walker(flat)
    f = find_fixed_point(wf, _guess(flat, wf.state_names()), SOLVER, fd_check=False)
    assert abs(chosen.period_s - f.period_s) <= 1e-9 * f.period_s
