"""The contact model on terrain (stairs, footholds, profiles): risers and profiles as contact
geometry, patches at the rigid footholds, the contact run and the MJCF down stairs and on a
profile (a height field).

Physics checks: a toe pushed into a riser's face meets the IMPACT law on its depth into the
riser, acting horizontally (the riser's normal), so a toe swinging into a riser is caught;
the paper walker's contact run down the shipped stairs (patches at the rigid footholds, each
a riser lower) keeps the rigid stair gait's step period within 3 % (issue 49's check).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from walkerlab.config import load_scene, scene_from_dict
from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[2]


def _stairs(**terrain):
    d = load_scene(ROOT / "configs" / "stairs.yaml").model_dump(mode="json")
    d["terrain"] = {**d["terrain"], **terrain}
    return scene_from_dict(d)


def test_a_toe_in_a_riser_is_pushed_back_along_the_riser_normal():
    """Stairs going up as a polyline ground: the swing foot 1 mm past an up-riser's face,
    3 cm below the upper tread, penetrates the riser (its nearest segment) by 1 mm, gets the
    IMPACT force k delta^e at rest, and that force acts along -x (the riser's outward
    normal): the walker's generalized contact force is J^T (-F, 0) exactly (M (a - a0) with
    a0 the same state with the foot in the air).  The flat-slope model has no riser: the
    same foot would be 3 cm in the air above the lower tread."""
    from walkerlab.models.contact.model import ContactWalker

    w0 = ContactWalker(phi=0.0)
    z = np.array([-0.25, 0.2, 0.0, 0.0])  # leg1 behind, at rest; leg2 stands at the origin
    x = w0.pinned_to_full(z, np.zeros(2))
    (fx, fy), _ = w0.foot_positions(x)
    base = fy - 0.02  # the lower tread 2 cm under the swing foot; the stance foot's ground
    xr = fx - 0.001  # the up-riser 1 mm behind the swing foot: the foot is inside the step
    # ... and the stance foot just touching its own tread (no force)
    step = np.array([[-5.0, base], [xr, base], [xr, base + 0.05], [-0.2, base + 0.05],
                     [-0.2, 0.0], [10.0, 0.0]])
    air = step.copy()
    air[2:4, 1] = base  # the same ground without the step: the swing foot 2 cm above it
    w, wa = ContactWalker(phi=0.0, ground_line=step), ContactWalker(phi=0.0, ground_line=air)
    q = w.contact_quantities(x)["leg1"]
    assert q["penetration"][0] == pytest.approx(0.001, abs=1e-12)
    k, e = w.contact.k, w.contact.e
    assert q["normal_force"][0] == pytest.approx(k * 0.001 ** e, rel=1e-12)
    assert wa.contact_quantities(x)["leg1"]["normal_force"][0] == 0.0
    nq = w.nq
    dq = (w.rhs(0.0, x) - wa.rhs(0.0, x))[nq:]
    gen = w.mass_matrix(x[:nq]) @ dq  # the generalized force of the riser's push
    P, V, J = (np.empty((len(w.contact_names()), 2)), np.empty((len(w.contact_names()), 2)),
               np.empty((len(w.contact_names()), 2, nq)))
    w.kernels.feet(x, w.walker_params, P, V, J)
    expect = J[0].T @ np.array([-q["normal_force"][0], 0.0])
    assert np.allclose(gen, expect, rtol=1e-9, atol=1e-9 * np.abs(expect).max())


def test_stairs_as_patches_at_the_footholds_and_as_treads_and_risers():
    """Checkerboard lanes: footfall j's patch lies j risers below the first (leg2's lane the
    even footfalls); continuous: one polyline of level treads and vertical risers, the
    stance foot mid-tread."""
    from walkerlab.models.contact.model import ContactWalker
    from walkerlab.models.contact.rigid_limit import contact_si

    sc = _stairs()
    si, knee = contact_si(sc.contact)
    w = ContactWalker(contact=si, phi=0.0, knee_stop=knee)
    on = w.on_terrain(sc.terrain, step_length=0.414, n_steps=6)
    assert np.allclose(on.lane_heights("leg2")[:3], [0.0, -0.02, -0.04])
    assert np.allclose(on.lane_heights("leg1")[:3], [-0.01, -0.03, -0.05])
    line = w.on_terrain(_stairs(lanes="continuous").terrain, step_length=0.414,
                        n_steps=6).ground_line
    seg = np.diff(line, axis=0)
    assert np.all((seg[:, 0] == 0) | (seg[:, 1] == 0))  # level treads, vertical risers
    assert np.allclose(seg[1::2, 1], -0.01) and np.allclose(seg[2:-2:2, 0], 0.41)
    i = np.flatnonzero((line[:-1, 0] <= 0) & (line[1:, 0] >= 0) & (line[:-1, 1] == 0))
    assert line[i[0], 0] == pytest.approx(-0.205) and line[i[0] + 1, 0] == pytest.approx(0.205)


def test_footholds_on_continuous_ground_are_treads_through_the_footfalls():
    """Footholds 1 cm below each other on continuous lanes (before: refused, "no ground
    between the footholds"): one polyline of level treads (the stairs scene's level slope)
    through the footfalls ``k l`` at ``-k`` cm, footfall -1 (the trailing foot's) at
    +1 cm, joined by vertical risers half-way between footfalls; the first and last treads
    run on 100 m."""
    from walkerlab.models.contact.model import ContactWalker
    from walkerlab.models.contact.rigid_limit import contact_si

    sc = _stairs(kind="footholds", foothold_heights_m=[-0.01], lanes="continuous",
                 riser_m=None, tread_m=None, direction=None)
    si, knee = contact_si(sc.contact)
    w = ContactWalker(contact=si, phi=0.0, knee_stop=knee)
    ell = 0.414
    line = w.on_terrain(sc.terrain, step_length=ell, n_steps=6).ground_line
    seg = np.diff(line, axis=0)
    assert np.all((seg[:, 0] == 0) | (seg[:, 1] == 0))  # level treads, vertical risers
    assert line[0, 0] == pytest.approx(-ell - 100.0) and line[0, 1] == pytest.approx(0.01)
    risers = line[1:-1:2, 0]
    np.testing.assert_allclose(risers, (np.arange(risers.size) - 0.5) * ell, atol=1e-12)
    np.testing.assert_allclose(line[1:-1:2, 1], 0.01 - 0.01 * np.arange(risers.size),
                               atol=1e-12)
    np.testing.assert_allclose(seg[1::2, 1], -0.01, atol=1e-12)


def test_a_point_beyond_a_convex_corner_is_outside_the_ground():
    """The polyline's signed distance past the top of an up-riser (a convex corner: the
    riser's line has the point inside, the upper tread's outside): the point is outside,
    at its distance from the corner, the normal from the corner to it; in the concave
    corner at the riser's foot a point is inside by its distance to the nearer face.
    (Before: the riser, listed first, decided the side, and a wheel's spoke tip 1.9 m above
    such a corner was taken 1.9 m deep in the ground.)"""
    from walkerlab.models.contact._kernels import ground_line

    line = np.ascontiguousarray(np.array([[-5.0, 0.0], [0.0, 0.0], [0.0, 0.05],
                                          [5.0, 0.05]]).ravel())
    for p in ((0.01, 1.9), (0.3, 1.0), (1e-6, 0.06)):
        delta, nx, ny = ground_line(*p, line)
        assert delta < 0.0
        if p[0] < 0.05:  # nearest the tread: above it
            assert delta == pytest.approx(-(p[1] - 0.05), abs=1e-12)
    delta, nx, ny = ground_line(-0.01, 0.06, line)  # above the corner, behind the riser
    r = np.hypot(0.01, 0.01)
    assert delta == pytest.approx(-r, abs=1e-12) and (nx, ny) == pytest.approx((-0.01 / r,
                                                                                 0.01 / r))
    delta, _, _ = ground_line(0.002, 0.001, line)  # inside the step at its foot
    assert delta == pytest.approx(0.002, abs=1e-12)  # 2 mm behind the riser's face


@pytest.mark.parametrize("terrain, field", [
    ({"kind": "footholds", "foothold_heights_m": [-0.01], "foothold_slopes_rad": [0.02],
      "riser_m": None, "tread_m": None, "direction": None}, "terrain.foothold_slopes_rad"),
])
def test_ground_the_contact_model_does_not_build_is_refused_in_one_line(terrain, field):
    from walkerlab.models.contact.scene import ContactSceneError, contact_setup

    d = _stairs().model_dump(mode="json")
    d["terrain"] = {k: v for k, v in {**d["terrain"], **terrain}.items() if v is not None}
    with pytest.raises(ContactSceneError) as err:
        sc = scene_from_dict(d)
        contact_setup(sc, plant=Plant.from_scene(sc))
    assert field in str(err.value) and "\n" not in str(err.value)



def test_the_contact_periodic_gait_on_stairs_is_laid_per_step():
    """Issue 56 item 10b: ``contact_sim.start: periodic_gait`` on stairs ended in "heights1:
    one finite height [m] per patch of lane1 (1), got shape (9,)" (the step map's one patch
    per lane kept the stairs' nine heights).  The step map now lays its stance patch at 0
    and the swing patch a riser lower, and measures the new stance foot's penetration from
    its own patch: the gait it finds is one of the stairs, so the run started from it on the
    stairs' patches repeats its step period at every step."""
    from walkerlab.analysis.contact.periodic import simulate_from_periodic_gait
    from walkerlab.analysis.gait.scene import solve_scene
    from walkerlab.models.contact.scene import contact_setup

    sc = _stairs()
    d = sc.model_dump(mode="json")
    d["contact_sim"] = {**d["contact_sim"], "start": "periodic_gait", "n_strides": 2}
    sc = scene_from_dict(d)
    _, search = solve_scene(sc, plant=Plant.from_scene(sc))
    _, res, _, _, gait = simulate_from_periodic_gait(contact_setup(sc,
            plant=Plant.from_scene(sc)), search.result.x)
    assert gait.converged and gait.stable
    periods = np.diff(res.heel_strike_times)
    assert periods.size >= 3
    # measured: every step within 3.5e-5 s of the gait's 0.717155 s (the run's solver is
    # the scene's contact_solver, the gait's map CyRK's BDF at its own tolerance)
    assert np.max(np.abs(periods - gait.period_s)) < 1e-4
    # the stairs' gait: 1 mm shorter than the rigid 0.414 m step (measured 0.41305 m; at
    # the ADAMS default 100 mm/s stiction velocity the stance foot's creep made it 9 mm)
    assert gait.step_length_m == pytest.approx(0.4131, abs=1e-3)


def test_the_contact_periodic_gait_on_a_polyline_ground_is_refused_in_one_line(tmp_path):
    """Stairs on continuous lanes are a polyline the step map cannot re-centre (before:
    scipy's "f(a) and f(b) must have different signs"): one line naming the field."""
    import yaml
    from typer.testing import CliRunner

    from walkerlab.cli import app

    d = yaml.safe_load((ROOT / "configs" / "stairs.yaml").read_text())
    d["terrain"]["lanes"] = "continuous"
    d["contact_sim"]["start"] = "periodic_gait"
    f = tmp_path / "st.yaml"
    f.write_text(yaml.safe_dump(d))
    r = CliRunner().invoke(app, ["contact-sim", str(f), "--runs-dir", str(tmp_path / "r")])
    assert r.exit_code != 0
    assert r.stderr.startswith("error: contact_sim.start / periodic_gait: ")
    assert len(r.stderr.splitlines()) == 1 and "lanes: checkerboard" in r.stderr

@pytest.mark.slow
def test_contact_run_down_stairs_keeps_the_rigid_stair_gait():
    """configs/stairs.yaml (the paper walker down 1 cm stairs, 0.3 m patches at the rigid
    footholds): the contact run makes its 10 heel strikes and its step period (mean of the
    steps after the first two, the start's transient) is within 3 % of the rigid stair
    gait's (issue 49).  Measured: 0.7167 s against 0.70998 s, +0.9 % (the contact steps are
    9 mm shorter than the rigid 0.414 m)."""
    from walkerlab.analysis.contact.sim import simulate_from
    from walkerlab.analysis.gait.scene import solve_scene
    from walkerlab.models.contact.scene import contact_setup

    sc = load_scene(ROOT / "configs" / "stairs.yaml")
    _, search = solve_scene(sc, plant=Plant.from_scene(sc))
    rigid = search.result
    _, res, _, _ = simulate_from(contact_setup(sc,
                                               plant=Plant.from_scene(sc)), rigid.x, rigid.period_s)
    assert str(res.outcome.kind) in ("t_final", "heel_strike"), res.message
    assert len(res.heel_strike_times) >= 10
    period = float(np.mean(np.diff(res.heel_strike_times)[2:]))
    assert period == pytest.approx(rigid.period_s, rel=0.03)
    assert period == pytest.approx(rigid.period_s, rel=0.015)  # what it is (+0.9 %)


def _kneed_on(profile):
    """configs/kneed.yaml (whose knees clear continuous ground) on a profile, continuous."""
    d = load_scene(ROOT / "configs" / "kneed.yaml").model_dump(mode="json")
    d["terrain"] = {"kind": "profile", "profile_m": profile, "lanes": "continuous"}
    d["contact_sim"]["n_strides"] = 3
    return scene_from_dict(d)


def _heel_strikes(scene):
    from walkerlab.analysis.contact.sim import simulate_from
    from walkerlab.analysis.gait.scene import solve_scene
    from walkerlab.models.contact.scene import contact_setup

    _, search = solve_scene(scene, plant=Plant.from_scene(scene))
    _, res, _, _ = simulate_from(contact_setup(scene,
                                               plant=Plant.from_scene(scene)), search.result.x,
                                 search.result.period_s)
    return np.asarray(res.heel_strike_times), res


def test_a_profile_is_the_contact_models_polyline_ground():
    """The profile's first point at the first stance foot (as the rigid walk places it), its
    end segments run on along their lines; a profile along the slope line through the stance
    foot is the slope: the kneed walker's contact run on it strikes the ground when it does
    on continuous slope ground (to 1e-5 s, the integrator's tolerance: two kernels, the
    half-plane and the polyline), and on a 1 mm undulation it keeps walking."""
    import math

    from walkerlab.models.contact.terrain import profile_line

    phi = load_scene(ROOT / "configs" / "kneed.yaml").slope.angle_rad
    t = math.tan(phi)
    flat = _kneed_on([[-1.0, t], [6.0, -6.0 * t]])
    line = profile_line(flat.terrain, 0.0, 0.0)
    assert np.allclose(line[1], [0.0, 0.0]) and np.allclose(line[2], [7.0, -7.0 * t])
    assert np.allclose(np.diff(line[:, 1]) / np.diff(line[:, 0]), -t)  # one straight line
    d = flat.model_dump(mode="json")
    d["terrain"] = {"kind": "slope", "lanes": "continuous"}
    slope = scene_from_dict(d)
    a, _ = _heel_strikes(slope)
    b, _ = _heel_strikes(flat)
    assert len(a) >= 5 and len(a) == len(b)
    assert np.max(np.abs(a - b)) < 1e-5
    bumpy = _kneed_on([[round(-1.0 + 0.1 * i, 6), -(-1.0 + 0.1 * i) * t
                        + (0.001 * math.sin(2 * math.pi * (-1.0 + 0.1 * i) / 0.9)
                           if -1.0 + 0.1 * i > 0.3 else 0.0)] for i in range(61)])
    c, res = _heel_strikes(bumpy)
    assert len(c) == len(a) and not np.allclose(c, a, atol=1e-4), res.message


def _rods_on(terrain: dict, n_strides: int = 5):
    """configs/paper_rods.yaml (straight legs: the swing foot passes below the ground at
    mid-stance, the checkerboard's gap takes it) on ``terrain``, its own lanes."""
    d = load_scene(ROOT / "configs" / "paper_rods.yaml").model_dump(mode="json")
    d["terrain"] = {"lanes": "checkerboard", "patch_width_m": 0.3, **terrain}
    d["contact_sim"]["n_strides"] = n_strides
    return scene_from_dict(d)


def test_a_profile_on_checkerboard_lanes_lays_the_slopes_patches_or_says_how_far_off():
    """A profile on checkerboard lanes (before: refused; the straight-legged walkers of the
    capability table's profile cells fell on the continuous polyline, scuffing at
    mid-stance): flat patches at the footfalls at the profile's height, its first point at
    the first stance foot.  The slope written as a profile gives the slope's patches
    (heights 0 to rounding: 1e-15 m); the same line 2 mm lower from 3 m on gives patches
    2 mm cos(phi) lower past it; a 0.5 mm sine of 0.9 m
    wavelength is refused in one line naming terrain.lanes and the depth it departs from a
    patch (between 0.01 and 0.5 mm, more than the 1 um allowed)."""
    import math

    from walkerlab.models.contact.model import ContactWalker

    sc = _rods_on({})
    phi = sc.slope.phi_rad
    t = math.tan(phi)
    xs = [float(x) for x in range(-2, 11)]
    w0 = ContactWalker(phi=phi, data=None)

    def walker(points):
        terrain = _rods_on({"kind": "profile", "profile_m": points}).terrain
        return w0.on_terrain(terrain, step_length=0.4, n_steps=20)

    w = walker([[x, -x * t] for x in xs])
    assert np.max(np.abs(np.concatenate([w.heights1, w.heights2]))) < 1e-15
    assert w.ground_line is None and not w.continuous
    ref = w0.on_terrain(sc.terrain, step_length=0.4, n_steps=20)
    assert np.array_equal(w.lane1, ref.lane1) and np.array_equal(w.lane2, ref.lane2)
    step = [[-2.0, 2 * t], [1.0, -t], [1.0 + 1e-6, -(1.0 + 1e-6) * t - 0.002],
            [10.0, -10 * t - 0.002]]
    w = walker(step)
    s_step = 3.0 / math.cos(phi)  # x = 1 m along the slope from the first point (s = 0)
    for lane, h in ((w.lane1, w.heights1), (w.lane2, w.heights2)):
        assert np.allclose(h[lane > s_step + 0.15], -0.002 * math.cos(phi), atol=1e-12)
        assert np.allclose(h[lane < s_step - 0.15], 0.0, atol=1e-12)
        assert np.sum(lane > s_step + 0.15) >= 3 and np.sum(lane < s_step - 0.15) >= 3
    wavy = [[0.1 * i - 2, -(0.1 * i - 2) * t + 5e-4 * math.sin(2 * math.pi * (0.1 * i - 2)
                                                               / 0.9)] for i in range(121)]
    with pytest.raises(ValueError) as exc:
        walker(wavy)
    msg = str(exc.value)
    assert "\n" not in msg and msg.startswith("terrain.lanes: checkerboard on a profile")
    depth_mm = float(msg.split(" m along the slope by ")[1].split(" mm")[0])
    assert 0.01 < depth_mm < 0.5


@pytest.mark.slow
def test_the_straight_legged_contact_walk_on_its_slope_as_a_profile_is_the_slopes_walk():
    """The capability table's reference case: configs/paper_rods.yaml on its slope written
    as a profile (checkerboard lanes, as on the slope).  Before: 0 heel strikes (the
    profile was continuous ground only).  Now its contact walk is the slope's, heel strike
    for heel strike, to integration tolerance (1e-9 s; measured identical)."""
    import math

    phi = _rods_on({}).slope.phi_rad
    pts = [[float(x), -x * math.tan(phi)] for x in range(-2, 21)]
    a, _ = _heel_strikes(_rods_on({}, 3))
    b, res = _heel_strikes(_rods_on({"kind": "profile", "profile_m": pts}, 3))
    assert len(a) >= 6 and len(b) == len(a), res.message
    assert np.max(np.abs(a - b)) < 1e-9


@pytest.mark.slow  # in `pytest -m slow`: the quick suite keeps to its CPU budget
def test_a_profile_exports_as_a_height_field_and_walks_in_mujoco(tmp_path):
    """``walkerlab export --format mjcf`` of a profile (before: an internal error): a MuJoCo
    height field of the polyline.  The kneed walker on a profile along the slope line walks
    as on the slope's plane (mean step period to 0.5 %: triangles against a plane), and on a
    1 mm undulation its steps follow the rigid walk's on the same profile (step k + 1 of the
    rigid walk against MuJoCo's k-th period between strikes, each within 1.5 %; measured
    -1.2 % to +0.9 %), and the OpenSim export refuses it in one line."""
    import math

    pytest.importorskip("mujoco")
    from walkerlab.analysis.gait.rigid_run import profile_walk
    from walkerlab.analysis.gait.scene import solve_scene
    from walkerlab.export.mujoco_walk import walk
    from walkerlab.stages import export as export_stage

    phi = load_scene(ROOT / "configs" / "kneed.yaml").slope.angle_rad
    t = math.tan(phi)
    flat = _kneed_on([[-1.0, t], [6.0, -6.0 * t]])
    d = flat.model_dump(mode="json")
    d["terrain"] = {"kind": "slope", "lanes": "continuous"}
    xs = [round(-1.0 + 0.1 * i, 6) for i in range(61)]
    bumpy = _kneed_on([[x, -x * t + (0.001 * math.sin(2 * math.pi * x / 0.9) if x > 0.3
                                      else 0.0)] for x in xs])
    periods = {}
    for name, sc in (("plane", scene_from_dict(d)), ("line", flat), ("bumpy", bumpy)):
        path = export_stage.run(sc, tmp_path / name, "mjcf")
        if name != "plane":
            assert 'type="hfield"' in path.read_text()
        w = walk(path, 6.0)
        assert not w.fell and w.alternating and len(w.times_s) >= 10, name
        periods[name] = np.diff(w.times_s)
    assert np.mean(periods["line"]) == pytest.approx(np.mean(periods["plane"]), rel=5e-3)
    _, search = solve_scene(bumpy, plant=Plant.from_scene(bumpy))
    T = np.array([seg.period for seg in profile_walk(bumpy, search.result.x, 12,
                                                     plant=Plant.from_scene(bumpy)).segments])
    k = min(len(T) - 1, len(periods["bumpy"]))
    assert np.allclose(periods["bumpy"][:k], T[1:k + 1], rtol=0.015)
    with pytest.raises(ValueError, match=r"^terrain\.kind: profile: not in the OpenSim"):
        export_stage.run(bumpy, tmp_path / "osim", "osim")
