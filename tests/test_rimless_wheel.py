"""The rimless wheel (``model: rimless_wheel``; McGeer 1990; Coleman, Chatterjee & Ruina 1997)
at the defaults of Drake's ``RimlessWheel`` example (mass 1 kg, spoke length 1 m, gravity
9.81 m/s^2, 8 spokes, slope 0.08 rad: ``configs/rimless_wheel.yaml``), against closed forms
and a Monte Carlo written here from the wheel's closed-form step map (no walkerlab code).

Closed forms (point mass at the hub, ``alpha = pi / n``, slope ``phi``):

- over a step the hub drops ``L (cos(alpha - phi) - cos(alpha + phi)) = 2 L sin(alpha)
  sin(phi)``, so the rate before heel strike is ``w-^2 = w+^2 + 4 g/L sin(alpha) sin(phi)``;
- the plastic impact keeps the angular momentum about the new foot: ``w+ = cos(2 alpha) w-``;
- the fixed point ``w+ = cos(2 alpha) sqrt(w+^2 + 4 g/L sin(alpha) sin(phi))`` is
  ``w+ = cot(2 alpha) sqrt(4 g/L sin(alpha) sin(phi))``; with a hub inertia ``I`` the
  impact ratio is ``(M L^2 cos(2 alpha) + I) / (M L^2 + I)`` and ``g/L`` becomes
  ``M g L / (M L^2 + I)``;
- the step period is the time of the inverted pendulum from ``alpha - phi`` to ``-alpha -
  phi``, ``int dpsi / sqrt(w+^2 + 2 g/L (cos(alpha - phi) - cos psi))`` (quadrature);
- the Poincaré map in the rate has the one multiplier ``cos(2 alpha)^2`` at the fixed point
  (``dw+'/dw+ = cos(2 alpha) w+ / w- = cos(2 alpha)^2``).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad

from walkerlab.config import SceneError, load_scene, scene_from_dict
from walkerlab.walker.plant import Plant

SCENE = "configs/rimless_wheel.yaml"
G, L, M, N, PHI = 9.81, 1.0, 1.0, 8, 0.08   # Drake RimlessWheelParams defaults


def _closed_form(inertia: float = 0.0):
    """(post-impact rate magnitude [rad/s], step period [s], multiplier) of the passive gait."""
    a = math.pi / N
    J = M * L ** 2 + inertia
    c = (M * L ** 2 * math.cos(2 * a) + inertia) / J
    k = M * G * L / J                                  # g/L for a point mass
    w = c / math.sqrt(1 - c * c) * math.sqrt(4 * k * math.sin(a) * math.sin(PHI))
    top = math.cos(a - PHI)
    period, err = quad(lambda p: 1.0 / math.sqrt(w * w + 2 * k * (top - math.cos(p))),
                       -a - PHI, a - PHI, epsabs=1e-13, epsrel=1e-13, limit=200)
    assert err < 1e-12
    w_minus = math.sqrt(w * w + 4 * k * math.sin(a) * math.sin(PHI))
    return w, period, c * w / w_minus


def _walker(inertia: float | None = None):
    from walkerlab.api import Walker

    scene = load_scene(SCENE)
    if inertia is not None:
        d = scene.model_dump(mode="json")
        d["walker"]["hub_inertia_kg_m2"] = inertia
        scene = scene_from_dict(d)
    return Walker.from_scene(scene)


@pytest.mark.parametrize("inertia", [None, 0.25])
def test_rimless_wheel_gait_matches_closed_form(inertia):
    """Post-impact rate and step period to 1e-8 of the closed form (energy, impact,
    quadrature), the post-impact angle ``alpha - phi``, and the one nontrivial Floquet
    multiplier ``cos(2 alpha)^2`` (the other is 0: the map lands on the section)."""
    gait = _walker(inertia).fixed_point()
    w, period, mult = _closed_form(inertia or 0.0)
    assert gait.names == ("stance_angle", "stance_rate")
    assert gait.x[0] == pytest.approx(math.pi / N - PHI, abs=1e-12)
    assert abs(-gait.x[1] - w) < 1e-8          # rolls downhill: the angle decreases
    assert abs(gait.step_period - period) < 1e-8
    mods = np.sort(np.abs(gait.multipliers))[::-1]
    assert abs(mods[0] - mult) < 1e-6 and mods[1] < 1e-6
    assert gait.step_length == pytest.approx(2 * L * math.sin(math.pi / N), rel=1e-9)
    if inertia is None:
        assert mult == pytest.approx(math.cos(2 * math.pi / N) ** 2, rel=1e-12)


@pytest.mark.parametrize("change, field", [
    ({"spokes": 2}, "walker.spokes"),
    ({"spoke_length_m": -1.0}, "walker.spoke_length_m"),
    ({"hub_inertia_kg_m2": -0.1}, "walker.hub_inertia_kg_m2"),
    ({"leg_length_m": 1.0}, "walker.leg_length_m"),
])
def test_rimless_wheel_bad_input_is_one_line(change, field):
    d = load_scene(SCENE).model_dump(mode="json")
    d["walker"].update(change)
    with pytest.raises(SceneError) as exc:
        scene_from_dict(d)
    msg = str(exc.value)
    assert field in msg and "Traceback" not in msg and len(msg.splitlines()) == 1


def _independent_mfpt(sd: float, walks: int, cap: int, seed: int):
    """Monte Carlo of the closed-form step map on per-step slopes ``phi + sd N(0, 1)``: the
    ground of step k is the line through its stance foot at slope gamma_k; a step starts at
    ``alpha - gamma_{k-1}`` (the previous ground) and fails if the hub cannot vault over the
    foot (``w^2 <= 2 g/L (1 - cos(alpha - gamma_{k-1}))``); else the heel strike at
    ``-alpha - gamma_k`` and the impact give the next rate.  Censored geometric estimate
    ``S / F``, standard error ``sqrt(m (m + 1) / F)`` (Byl & Tedrake 2009)."""
    rng = np.random.default_rng(seed)
    a, k = math.pi / N, G / L
    c = math.cos(2 * a)
    w = np.full(walks, _closed_form()[0])
    prev = np.full(walks, PHI)
    alive = np.ones(walks, bool)
    S = F = 0
    for _ in range(cap):
        idx = np.flatnonzero(alive)
        if idx.size == 0:
            break
        gam = PHI + sd * rng.standard_normal(idx.size)
        p0, p1 = a - prev[idx], -a - gam
        ok = ~((p0 > 0) & (w[idx] ** 2 <= 2 * k * (1 - np.cos(p0))))
        S += int(ok.sum())
        F += int((~ok).sum())
        alive[idx[~ok]] = False
        j = idx[ok]
        w[j] = c * np.sqrt(w[j] ** 2 + 2 * k * (np.cos(p0[ok]) - np.cos(p1[ok])))
        prev[j] = gam[ok]
    m = S / F
    return m, math.sqrt(m * (m + 1) / F)


@pytest.mark.slow
def test_rimless_wheel_mfpt_matches_independent_monte_carlo():
    """walkerlab's Monte Carlo MFPT (batched compiled step map) within 3 combined standard
    errors of the closed-form Monte Carlo, at two roughness levels (MFPT ~200 and ~30
    steps)."""
    from walkerlab.analysis.robustness.mfpt import monte_carlo
    from walkerlab.integrate.python_step import make_step_map
    from walkerlab.models.registry import build_walker
    from walkerlab.studies.mfpt import scene_walker_at

    scene = load_scene(SCENE)
    x0 = _walker().fixed_point().x
    sm = make_step_map(build_walker(Plant.from_scene(scene)), scene_walker_at(scene,
            plant=Plant.from_scene(scene)), 1e-9, 1e-9, 5.0)
    for sd in (0.008, 0.012):
        ours = monte_carlo(sm, x0, sd, range(1500), 4000, seed=3).mfpt
        ref = _independent_mfpt(sd, 6000, 20000, seed=11)
        assert 10 < ref[0] < 1000
        assert abs(ours[0] - ref[0]) < 3 * math.hypot(ours[1], ref[1]), (sd, ours, ref)


def test_rimless_wheel_basin_on_the_phase_plane():
    """``basin.start: phase_plane``: a cell is the stance state itself (the wheel's section
    has one coordinate).  A state with the energy to vault over its stance foot converges to
    the gait; one without it (``w^2 < 2 g/L (1 - cos psi)``) falls backward (the energy
    argument of Coleman, Chatterjee & Ruina 1997)."""
    from walkerlab.studies.basin import CODE, BasinTask, run_basin_chunk

    scene = load_scene(SCENE)
    assert scene.basin.start == "phase_plane"
    x_star = _walker().fixed_point().x
    psi = 0.3
    slow = math.sqrt(2 * G / L * (1 - math.cos(psi)))    # just enough to reach the top
    # (2): rolling back (+0.25 rad/s) past the top, it turns before the top and rolls on
    # (w-^2 = 0.25^2 + 2 g/L (cos 0.1 - cos 0.4727) gives w+^2 = 1.06 > the 0.95 needed)
    cells = ((0, psi, -1.05 * slow), (1, psi, -0.95 * slow), (2, -0.1, 0.25))
    out = {i: code for i, code, _, _ in run_basin_chunk(BasinTask(
        scene.model_dump(mode="json"), tuple(x_star), cells, plant=Plant.from_scene(scene)))}
    assert out == {0: CODE["converged"], 1: CODE["fell_backward"], 2: CODE["converged"]}


def test_rimless_wheel_multibody_tree_is_refused_in_one_line():
    """The wheel is one rigid body, not a tree of leg links: the links' multibody model
    refuses it in one line naming walker.model (its URDF/MJCF have their own writers)."""
    from walkerlab.walker.description import walker_data
    from walkerlab.walker.multibody import multibody

    scene = load_scene(SCENE)
    with pytest.raises(ValueError) as exc:
        multibody(walker_data(scene.walker, scene.slope.phi_rad))
    assert str(exc.value).startswith("walker.model: rimless_wheel") and "\n" not in str(exc.value)


def _scene(**changes):
    d = load_scene(SCENE).model_dump(mode="json")
    for path, value in changes.items():
        section, field = path.split(".")
        if section == "terrain":  # the section as written (its dump names lanes twice)
            d[section] = {field: value}
        elif value is None:
            d[section].pop(field, None)
        else:
            d[section][field] = value
    return scene_from_dict(d)


def test_rimless_wheel_floating_view():
    """The floating view: q = [hip_x, hip_y, wheel_angle], M = diag(M, M, I) (I the contact
    section's regularising inertia for the point-mass hub), bias (0, M g, 0), one contact
    point per spoke at hub + L e(theta + 2 pi k / n), spoke 1 the next ahead of spoke 0."""
    from walkerlab.models.contact.scene import contact_setup

    sc = load_scene(SCENE)
    setup = contact_setup(sc, plant=Plant.from_scene(sc))
    walker, step = setup.build(np.array([math.pi / N - PHI, -1.0]), 4)
    assert walker.coordinate_names() == ("hip_x", "hip_y", "wheel_angle")
    assert walker.contact_names() == tuple(f"spoke{k}" for k in range(N))
    assert step == pytest.approx(2 * L * math.sin(math.pi / N), rel=1e-12)
    q = np.array([0.3, 0.9, 0.2])
    assert np.allclose(walker.mass_matrix(q), np.diag([M, M, 1e-3]), atol=1e-15)
    pts = walker.points(np.r_[q, 0.0, 0.0, 0.0])
    for k in range(N):
        psi = 0.2 + 2 * math.pi * k / N
        tip = np.asarray(pts[f"spoke{k}_foot"], float).ravel()
        assert np.allclose(tip, [0.3 + L * math.sin(psi), 0.9 - L * math.cos(psi)], atol=1e-14)


@pytest.mark.parametrize("changes, field", [
    ({"contact.hub_inertia_kg_m2": None}, "contact.hub_inertia_kg_m2"),
    ({"terrain.lanes": "checkerboard"}, "terrain.lanes"),
    ({"contact_sim.start": "periodic_gait"}, "contact_sim.start"),
    ({"contact_sim.periodic_gait": True}, "periodic_gait"),
])
def test_rimless_wheel_contact_refusals_are_one_line(changes, field):
    """A point-mass hub without the contact model's regularising inertia, checkerboard
    lanes (the spokes have none of their own) and the contact periodic gait (its step map's
    mid-stance section is a biped's: an IndexError before): one line naming the field."""
    from walkerlab.models.contact.scene import ContactSceneError, contact_setup

    with pytest.raises(ContactSceneError) as exc:
        sc = _scene(**changes)
        contact_setup(sc, plant=Plant.from_scene(sc))
    assert field in str(exc.value) and "\n" not in str(exc.value)


def _rigid(scene):
    from walkerlab.api import Walker

    return Walker.from_scene(scene).fixed_point()


@pytest.mark.slow
@pytest.mark.parametrize("inertia, rigid_period", [(None, 1.03455), (0.25, 0.81387)])
def test_rimless_wheel_contact_step_period_matches_rigid(inertia, rigid_period):
    """The contact view rolls: every heel strike is the next spoke touching down (spoke1,
    spoke2, ...), and its step period is the rigid wheel's within 3 % (measured: -0.05 %
    with the point-mass hub regularised by 1e-3 kg m^2, +0.04 % at 0.25 kg m^2)."""
    from walkerlab.analysis.contact.sim import simulate_from
    from walkerlab.models.contact.scene import contact_setup

    scene = _scene(**({"walker.hub_inertia_kg_m2": inertia} if inertia else {}))
    gait = _rigid(scene)
    assert gait.step_period == pytest.approx(rigid_period, abs=1e-5)
    _, res, _, _ = simulate_from(contact_setup(scene,
            plant=Plant.from_scene(scene)), gait.x, gait.step_period, strides=5)
    assert res.outcome.kind in ("heel_strike", "t_final"), res.outcome.message
    assert len(res.heel_strike_times) >= 10
    assert list(res.heel_strike_legs[:9]) == [f"spoke{k % N}" for k in range(1, 10)]
    periods = np.diff(res.heel_strike_times)[2:]
    assert np.all(np.abs(periods / gait.step_period - 1) < 0.03), periods
    assert all(st.bounce_count == 0 and st.scuff_count == 0 for st in res.steps)


@pytest.mark.slow
def test_rimless_wheel_mjcf_rolls_in_mujoco():
    """The exported MJCF (hub on slide joints and a hinge, a sphere at each spoke tip)
    started at the contact view's initial state rolls down the slope in MuJoCo: at least 10
    spoke strikes, each the next spoke ahead, with step periods within 3 % of the rigid
    wheel's (measured: -0.4 % to -0.6 %).  The URDF parses and names the same joints."""
    import xml.etree.ElementTree as ET

    mujoco = pytest.importorskip("mujoco")
    from walkerlab.analysis.contact.sim import initial_state_from_ideal
    from walkerlab.export.multibody import wheel_mjcf_text, wheel_urdf_text
    from walkerlab.models.contact.scene import contact_setup
    from walkerlab.walker.description import walker_data

    scene = load_scene(SCENE)
    gait = _rigid(scene)
    walker, _ = contact_setup(scene, plant=Plant.from_scene(scene)).build(gait.x, 4)
    x0 = initial_state_from_ideal(walker, *gait.x)
    data = walker_data(scene.walker, scene.slope.phi_rad)
    urdf = ET.fromstring(wheel_urdf_text(data, "rimless_wheel"))
    assert [j.get("name") for j in urdf.iter("joint")] == ["hip_x", "hip_z", "wheel"]
    model = mujoco.MjModel.from_xml_string(wheel_mjcf_text(
        data, "rimless_wheel", hub_inertia_kg_m2=scene.contact.hub_inertia_kg_m2,
        qpos=x0[:3], qvel=x0[3:], timestep_s=2e-4))
    d = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, d, 0)
    tips = {mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, f"spoke{k}_tip"): k
            for k in range(N)}
    stance, strikes = 0, []
    while d.time < 11.6 * gait.step_period:
        mujoco.mj_step(model, d)
        touching = {tips[g] for c in d.contact[:d.ncon] for g in (c.geom1, c.geom2) if g in tips}
        if (stance + 1) % N in touching:  # the next spoke ahead touches down
            stance = (stance + 1) % N
            strikes.append(d.time)
    assert len(strikes) >= 10
    periods = np.diff(strikes)
    assert np.all(np.abs(periods / gait.step_period - 1) < 0.03), periods


@pytest.fixture(scope="module")
def wheel_runs(tmp_path_factory):
    """The shipped scene's ``fixedpoint``, ``simulate``, ``contact-sim`` and ``compare``
    artifacts (about 2 s): (runs folder, scene)."""
    from walkerlab.stages import pipeline

    runs = tmp_path_factory.mktemp("rimless_runs")
    scene = load_scene(SCENE)
    pipeline.run("compare", scene, runs)
    return runs, scene


def test_rimless_wheel_compare_names_the_same_coordinates(wheel_runs):
    """``walkerlab compare``: the contact view names the rigid view's leg coordinates (the
    stance spoke's and the next spoke's angle and rate, ``leg<i>_angle``/``_rate``, from its
    stance and next spoke tips about the hub), so the errors are computed, not NaN: at the
    same fraction of each step the angles agree within 1e-3 rad (measured 1.5e-4: the
    contact steps are 0.05 % shorter) and the limit cycles lie within 5e-3 rad of each other
    (measured 9.2e-4; the impact is spread over the contact's compression).  On the clock,
    99 % of the samples agree within 0.02 rad (measured 7e-3 rad); the largest error
    (4 alpha) is a leg's spoke changing at the heel strike, whose times drift apart by the
    step periods' 0.05 %, as the paper's biped's legs swap at theirs."""
    from walkerlab.io.schemas.compare import load_compare

    runs, scene = wheel_runs
    c = load_compare(runs / scene.name / "compare.h5")
    assert set(c.errors) == {"leg1_angle", "leg2_angle", "leg1_rate", "leg2_rate"}
    assert np.isfinite(c.max_abs_angle_rad) and np.isfinite(c.max_abs_rate_rad_per_s)
    assert c.max_abs_angle_rad <= 4 * math.pi / N + 1e-9
    for name in ("leg1_angle", "leg2_angle"):
        assert np.max(np.abs(c.phase_errors[name])) < 1e-3
        assert np.percentile(np.abs(c.errors[name]), 99) < 0.02
    assert set(c.limit_cycle_distance) == {"leg1", "leg2"}
    assert all(0 < d < 5e-3 for d in c.limit_cycle_distance.values())


def test_rimless_wheel_contact_gait_metrics(wheel_runs):
    """The contact view's Table 3 metrics of the wheel: its step length is the chord between
    neighbouring spoke tips, ``2 L sin(pi / n)`` (0.7654 m; the feet at heel strike are two
    tips of one rigid body, so exactly; today it was NaN: no leg's foot named), and its
    stance-frame energy (PE from the stance spoke's foot) agrees with the rigid view's within
    0.1 % (the contact's compression and its 1e-3 kg m^2 hub inertia; measured 9.935 against
    9.934 J; on today's code it was taken from an unset stance foot: garbage, e.g.
    8.725 or -76.89 J).  The rigid stance-frame energy is constant over a step: ``(M L^2)
    w+^2 / 2 + M g L cos(alpha - phi)``."""
    from walkerlab.io.schemas.compare import load_compare

    runs, scene = wheel_runs
    m = load_compare(runs / scene.name / "compare.h5").metrics
    chord = 2 * L * math.sin(math.pi / N)
    assert m["ideal"]["step_length_m"] == pytest.approx(chord, abs=1e-9)
    assert m["contact"]["step_length_m"] == pytest.approx(chord, abs=1e-9)
    w, _, _ = _closed_form()
    e_stance = 0.5 * M * L ** 2 * w ** 2 + M * G * L * math.cos(math.pi / N - PHI)
    assert m["ideal"]["E_avg_stance_frame_J"] == pytest.approx(e_stance, rel=1e-9)
    assert m["contact"]["E_avg_stance_frame_J"] == pytest.approx(e_stance, rel=1e-3)
    # both count the steps their runs began: the rigid run's 2 x simulate.strides ending
    # at a heel strike; the contact run's 2 x contact_sim.n_strides and the one it ended in
    assert m["ideal"]["n_steps"] == 2 * scene.simulate.strides
    assert m["contact"]["n_steps"] == 2 * scene.contact_sim.n_strides + 1


def test_the_in_memory_contact_wheel_walks_the_stage_s_run(wheel_runs):
    """``wl.ContactWalker`` builds the shipped wheel as ``walkerlab contact-sim`` does (the
    regularising ``contact.hub_inertia_kg_m2`` the scene sets; it was refused for want of a
    hub inertia) and walks the stage's run bit for bit; its periodic gait, which the
    contact view does not find for a wheel, is refused in one line (an IndexError before),
    as the stage refuses ``--periodic``."""
    from walkerlab.api import ContactWalker
    from walkerlab.io.schemas.contact_sim import load_contact_sim
    from walkerlab.models.contact.scene import ContactSceneError

    runs, scene = wheel_runs
    cw = ContactWalker.from_scene(SCENE)
    assert cw.model.mass_matrix(np.zeros(3))[2, 2] == scene.contact.hub_inertia_kg_m2
    walk = cw.simulate()
    art = load_contact_sim(runs / scene.name / "contact_sim.h5")
    assert walk.walks and walk.heel_strikes.size >= 2 * scene.contact_sim.n_strides
    assert np.array_equal(walk.heel_strikes, art.heel_strike_times)  # bit for bit
    assert np.array_equal(walk.step_periods, art.steps["period"], equal_nan=True)
    assert np.array_equal(walk.t, art.samples.time)
    assert walk.termination == art.termination and walk.outcome == art.outcome
    with pytest.raises(ContactSceneError, match="periodic_gait") as exc:
        cw.periodic_gait()
    assert "\n" not in str(exc.value)


def test_rimless_wheel_contact_trajectory_alternates_its_legs(wheel_runs):
    """The contact view's named trajectory: the stance leg alternates at every heel strike
    (a spoke's lane would repeat a leg on a wheel with an odd number of spokes), each leg's
    foot is a spoke tip (the stance leg's on the ground: height above the slope < 0.1 mm)."""
    from walkerlab.io.schemas.contact_sim import load_contact_sim

    runs, scene = wheel_runs
    tr = load_contact_sim(runs / scene.name / "contact_sim.h5").samples
    change = np.flatnonzero(np.diff(tr.stance_leg)) + 1
    assert change.size == 2 * scene.contact_sim.n_strides
    assert np.all(np.diff(tr.stance_leg[change]) != 0)
    n = np.array([math.sin(PHI), math.cos(PHI)])
    for i, leg in enumerate(tr.legs):
        foot = tr.points[f"{leg}_foot"]
        assert np.allclose(np.hypot(*(foot - tr.points["hip"])), L, atol=1e-12)
        on = tr.stance_leg == i
        assert np.max(np.abs(n @ foot[:, on])) < 1e-4


def _keyframe_closed_form():
    """The gait keyframe from the closed form: spoke 0's tip at the origin, the hub at
    ``L (-sin q, cos q)``, ``q = alpha - phi``, turning at ``-w+`` (hub velocity
    ``w L (-cos q, -sin q)``)."""
    w, _, _ = _closed_form()
    q, dq = math.pi / N - PHI, -w
    return ([-L * math.sin(q), L * math.cos(q), q],
            [-L * math.cos(q) * dq, -L * math.sin(q) * dq, dq])


def test_rimless_wheel_export_stage_writes_the_wheel_with_its_gait(wheel_runs):
    """``walkerlab export --format urdf|mjcf`` writes the wheel's own files (hub on hip_x,
    hip_z and the hinge wheel, a tip sphere per spoke) with the rigid gait (from the stored
    fixedpoint.h5) as the MJCF's ``gait`` keyframe and the URDF's sidecar: the closed form's
    state to 1e-9."""
    import json
    import xml.etree.ElementTree as ET

    from walkerlab.stages import export as export_stage

    runs, scene = wheel_runs
    qpos, qvel = _keyframe_closed_form()
    mjcf = ET.parse(export_stage.run(scene, runs, "mjcf")).getroot()
    assert [j.get("name") for j in mjcf.iter("joint")] == ["hip_x", "hip_z", "wheel"]
    assert {g.get("name") for g in mjcf.iter("geom")} >= {f"spoke{k}_tip" for k in range(N)}
    key = mjcf.find("keyframe/key")
    assert key.get("name") == "gait"
    assert np.allclose([float(v) for v in key.get("qpos").split()], qpos, atol=1e-9)
    assert np.allclose([float(v) for v in key.get("qvel").split()], qvel, atol=1e-9)
    urdf = ET.parse(export_stage.run(scene, runs, "urdf")).getroot()
    assert [j.get("name") for j in urdf.iter("joint")] == ["hip_x", "hip_z", "wheel"]
    side = json.loads((runs / scene.name / export_stage.SIDECAR).read_text())
    assert side["joints"] == ["hip_x", "hip_z", "wheel"]
    assert np.allclose(side["qpos"], qpos, atol=1e-9) and np.allclose(side["qvel"], qvel,
                                                                       atol=1e-9)


def test_rimless_wheel_export_stage_mjcf_rolls_in_mujoco(wheel_runs):
    """The stage's MJCF, reset to its ``gait`` keyframe, rolls down the slope in MuJoCo:
    over 5.6 rigid steps each strike is the next spoke ahead touching down, 5 strikes, with
    step periods within 2 % of the rigid 1.03455 s (measured -0.3 % to -0.6 %: MuJoCo's soft
    contact of time constant 2 ms, the scene's friction 0.9)."""
    mujoco = pytest.importorskip("mujoco")
    from walkerlab.stages import export as export_stage

    runs, scene = wheel_runs
    w, period, _ = _closed_form()
    model = mujoco.MjModel.from_xml_path(str(export_stage.run(scene, runs, "mjcf")))
    d = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, d, model.key("gait").id)
    tips = {model.geom(f"spoke{k}_tip").id: k for k in range(N)}
    stance, strikes = 0, []
    while d.time < 5.6 * period:
        mujoco.mj_step(model, d, nstep=10)  # strikes to 10 timesteps (1 ms)
        touching = {tips.get(g) for c in d.contact[:d.ncon] for g in (c.geom1, c.geom2)}
        if (stance + 1) % N in touching:  # the next spoke ahead touches down
            stance = (stance + 1) % N
            strikes.append(d.time)
    assert len(strikes) == 5, strikes
    assert np.all(np.abs(np.diff(strikes) / period - 1) < 0.02), np.diff(strikes)


@pytest.mark.parametrize("inertia", [0.0, 0.25])
def test_the_steady_roll_in_closed_form_is_the_gaits_rate(inertia):
    """:func:`~walkerlab.models.hybrid.rolling_polygon.steady_roll`'s post-impact rate is
    the closed form of this module (McGeer 1990; the shipped wheel's documented 1.095463
    rad/s at no hub inertia), and the shipped wheel vaults its spokes."""
    from walkerlab.models.hybrid.rolling_polygon import cannot_roll, steady_roll
    from walkerlab.walker.description import walker_data

    scene = _scene(**{"walker.hub_inertia_kg_m2": inertia})
    data = walker_data(scene.walker, scene.slope.phi_rad)
    w_plus, w_vault = steady_roll(dict(zip(data.structure.param_names, data.params)))
    assert w_plus == pytest.approx(_closed_form(inertia)[0], rel=1e-12)
    assert w_plus > w_vault > 0 and cannot_roll(data) is None


def test_a_wheel_that_cannot_vault_a_spoke_is_refused_at_once():
    """6 spokes on a 0.12 rad slope: the steady roll's post-impact rate (0.885 rad/s) is
    below the 1.256 rad/s that brings the hub over the stance spoke (J w^2 / 2 = M g L (1 -
    cos(alpha - slope))), so there is no gait: the search refuses in one line naming
    walker.spokes before building the walker (it took 3 min 46 s to 'rates nan')."""
    import time

    from walkerlab.analysis.gait.scene import solve_scene
    from walkerlab.analysis.gait.search import GaitNotFound

    scene = _scene(**{"walker.spokes": 6, "slope.angle_rad": 0.12})
    t0 = time.perf_counter()
    with pytest.raises(GaitNotFound, match=r"^walker\.spokes: 6 spokes on a 0\.12 rad slope "
                                           r"cannot roll steadily: the post-impact rate "
                                           r"0\.8848 rad/s is below the 1\.256 rad/s"):
        solve_scene(scene, plant=Plant.from_scene(scene))
    assert time.perf_counter() - t0 < 1.0
