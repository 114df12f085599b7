"""The rimless wheel in three dimensions (``walker.space: 3d``; Coleman, Chatterjee & Ruina
1997) against references that share no code with its generated equations: the planar
wheel's closed form (McGeer 1990), and a rigid body turning about a fixed point written here
with scipy's rotations (Euler's equations in the body frame, the impact by the angular
momentum about the new foot)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.spatial.transform import Rotation

from walkerlab.analysis.gait.poincare import find_fixed_point
from walkerlab.integrate.solver import Solver
from walkerlab.models.registry import build_walker
from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "configs" / "rimless_wheel_3d.yaml"
G, L, M, SLOPE, N_SPOKES, I_DIAM, I_AXLE = 9.81, 1.0, 1.0, 0.08, 8, 0.1, 0.0
ALPHA = math.pi / N_SPOKES
#: the planar wheel's post-impact rate (McGeer 1990): w+ = cot(2a) sqrt(4 g/L sin a sin g)
W_PLUS = math.sqrt(4 * G / L * math.sin(ALPHA) * math.sin(SLOPE)) / math.tan(2 * ALPHA)


def _scene(**walker):
    import yaml

    from walkerlab.config.schema import Scene

    raw = yaml.safe_load(SCENE.read_text())
    raw["walker"].update(walker)
    if raw["walker"].get("space") == "2d":  # a planar scene takes no torsional friction
        raw["contact"].pop("torsional_friction_m", None)
    return Scene.model_validate(raw)


@pytest.fixture(scope="module")
def wheel():
    sc = _scene()
    return build_walker(Plant.from_scene(sc))


@pytest.fixture(scope="module")
def gait(wheel):
    solver = Solver(method="DOP853", rtol=1e-12, atol=1e-12)
    guess = np.array([0, 0, ALPHA - SLOPE, 0, 0, -1.0])
    return find_fixed_point(wheel, guess, solver, fd_check=False)


# ---- an independent model: a rigid body about a fixed point (scipy rotations) ----------

class Wheel:
    """The spoked wheel as a rigid body turning about its stance foot: Euler's equations in
    the body frame (axle along body z, the stance spoke along -y), the impact by the angular
    momentum about the new foot, the next spoke's frame turned by a spoke."""

    def __init__(self, slope=SLOPE, I_axle=I_AXLE, I_diam=I_DIAM):
        self.slope = slope
        self.n = np.array([math.sin(slope), math.cos(slope), 0.0])
        self.hub = np.array([0.0, L, 0.0])
        self.I_cm = np.diag([I_diam, I_diam, I_axle])
        h = self.hub
        self.J = self.I_cm + M * (h @ h * np.eye(3) - np.outer(h, h))
        self.start_R = Rotation.from_rotvec([0, 0, ALPHA - slope]).as_matrix()

    def foot(self, k):  # foot of the spoke k ahead of the stance spoke, from the stance foot
        a = 2 * k * ALPHA
        return self.hub + L * np.array([math.sin(a), -math.cos(a), 0.0])

    def rhs(self, t, y):
        R, Om = y[:9].reshape(3, 3), y[9:]
        torque = np.cross(self.hub, R.T @ np.array([0.0, -M * G, 0.0]))
        dOm = np.linalg.solve(self.J, torque - np.cross(Om, self.J @ Om))
        dR = R @ np.array([[0, -Om[2], Om[1]], [Om[2], 0, -Om[0]], [-Om[1], Om[0], 0]])
        return np.concatenate([dR.ravel(), dOm])

    def step(self, R, Om):
        """(R, body rates) just after a heel strike -> the next one's, relabelled."""
        def strike(t, y):
            return self.n @ (y[:9].reshape(3, 3) @ self.foot(1))
        strike.terminal, strike.direction = True, -1
        sol = solve_ivp(self.rhs, (0, 5), np.concatenate([R.ravel(), Om]), method="DOP853",
                        rtol=1e-13, atol=1e-13, events=strike)
        y = sol.y_events[0][0]
        R, Om = y[:9].reshape(3, 3), y[9:]
        w = R @ Om
        hub, new = R @ self.hub, R @ self.foot(1)
        d = hub - new
        I_cm = R @ self.I_cm @ R.T
        H = I_cm @ w + M * np.cross(d, np.cross(w, hub))
        w_plus = np.linalg.solve(I_cm + M * (d @ d * np.eye(3) - np.outer(d, d)), H)
        R_new = R @ Rotation.from_rotvec([0, 0, 2 * ALPHA]).as_matrix()
        return R_new, R_new.T @ w_plus, float(sol.t_events[0][0])

    def upright_gait(self):
        """The straight-downhill gait: its spin rate after heel strike (Brent on the one
        step map in the plane) and the state."""
        from scipy.optimize import brentq

        def gap(rate):
            return self.step(self.start_R, np.array([0, 0, -rate]))[1][2] + rate
        rate = brentq(gap, 1.0, 5.0, xtol=1e-15)  # (slower: it rolls back)
        return self.start_R, np.array([0.0, 0.0, -rate])

    def multipliers(self, h=1e-6):
        R0, Om0 = self.upright_gait()

        def chart(dx):
            return R0 @ Rotation.from_rotvec(dx[:3]).as_matrix(), Om0 + dx[3:]

        def back(R, Om):
            return np.concatenate([Rotation.from_matrix(R0.T @ R).as_rotvec(), Om - Om0])

        J = np.zeros((6, 6))
        for j in range(6):
            e = np.zeros(6)
            e[j] = h
            J[:, j] = (back(*self.step(*chart(e))[:2])
                       - back(*self.step(*chart(-e))[:2])) / (2 * h)
        return np.linalg.eigvals(J), self.step(R0, Om0), Om0


def test_upright_3d_wheel_rolls_downhill_as_the_planar_wheel(gait):
    names = ["heading", "lean", "stance"]
    x = dict(zip([f"{n}_angle" for n in names] + [f"{n}_rate" for n in names], gait.x))
    assert abs(x["stance_rate"] + W_PLUS) < 1e-10
    assert abs(x["stance_angle"] - (ALPHA - SLOPE)) < 1e-12
    assert max(abs(x[k]) for k in ("heading_angle", "lean_angle", "heading_rate",
                                   "lean_rate")) < 1e-12
    # the planar wheel's step period: the pendulum from alpha - gamma to -alpha - gamma
    sc = _scene(space="2d", diametral_inertia_kg_m2=None)
    planar = build_walker(Plant.from_scene(sc))
    solver = Solver(method="DOP853", rtol=1e-12, atol=1e-12)
    flat = find_fixed_point(planar, np.array([ALPHA - SLOPE, -1.0]), solver, fd_check=False)
    assert abs(gait.period_s - flat.period_s) < 1e-10
    assert abs(flat.x[1] + W_PLUS) < 1e-10


def test_3d_wheel_multipliers_match_an_independent_rigid_body_model(gait):
    ref, (R1, Om1, period), Om0 = Wheel().multipliers()
    R0 = Rotation.from_rotvec([0, 0, ALPHA - SLOPE]).as_matrix()
    assert np.max(np.abs(R1 - R0)) < 1e-10 and abs(Om1[2] - Om0[2]) < 1e-10  # a fixed point
    assert abs(Om0[2] + W_PLUS) < 1e-10
    assert abs(period - gait.period_s) < 1e-10
    ours = np.sort_complex(np.asarray(gait.multipliers_variational))
    theirs = np.sort_complex(ref)
    # central differences of h = 1e-6 on maps integrated to 1e-13: error ~ 1e-7 relative
    assert np.max(np.abs(ours - theirs) / np.maximum(1.0, np.abs(theirs))) < 1e-5
    # the neutral heading multiplier, the planar one cos(2 alpha)^2, the trivial 0
    assert np.min(np.abs(ours - 1.0)) < 1e-8
    assert np.min(np.abs(ours - math.cos(2 * ALPHA) ** 2)) < 1e-8
    assert gait.neutral == ("heading_angle",)
    assert abs(gait.neutral_multipliers[0] - 1.0) < 1e-8


def test_the_disc_wheel_rolls_stably_above_its_critical_slope_as_the_reference_says():
    """configs/rimless_wheel_3d_disc.yaml (a disc's inertias, 0.2 rad): stable, its
    multipliers (a complex pair: the wobble) those of the independent model."""
    from walkerlab.cli.options import load

    scene = load(str(ROOT / "configs" / "rimless_wheel_3d_disc.yaml"))
    walker = build_walker(Plant.from_scene(scene))
    solver = Solver(method="DOP853", rtol=1e-12, atol=1e-12)
    res = find_fixed_point(walker, np.array([0, 0, ALPHA - 0.2, 0, 0, -1.9]), solver,
                           fd_check=False)
    assert res.stable and abs(res.neutral_multipliers[0] - 1.0) < 1e-8
    ref = Wheel(slope=0.2, I_axle=0.5, I_diam=0.25).multipliers()[0]
    ours = np.sort_complex(np.asarray(res.multipliers_variational))
    assert np.max(np.abs(ours - np.sort_complex(ref))) < 1e-5
    assert np.sum(np.abs(ours.imag) > 0.1) == 2  # the wobble


def test_a_3d_wheel_at_another_heading_is_a_member_of_the_family(wheel):
    """Steady rolling at a heading off the fall line (Coleman et al. 1997): a fixed point
    with the heading held where it started, leaning, and its multiplier 1 again."""
    solver = Solver(method="DOP853", rtol=1e-12, atol=1e-12)
    res = find_fixed_point(wheel, np.array([0.1, 0, ALPHA - SLOPE, 0, 0, -1.0]), solver,
                           fd_check=False)
    assert abs(res.x[0] - 0.1) < 1e-14 and res.residual < 1e-10
    assert abs(res.x[1]) > 1e-3  # it leans: not the upright wheel turned
    assert abs(res.neutral_multipliers[0] - 1.0) < 1e-6


def test_3d_wheel_conserves_energy_in_a_passive_stance(wheel):
    x0 = np.array([0.05, 0.02, ALPHA - SLOPE, 0.1, -0.05, -1.1])
    sol = solve_ivp(wheel.phases[0].flow, (0, 0.6), x0, method="DOP853", rtol=1e-13,
                    atol=1e-13, dense_output=True)
    X = sol.sol(np.linspace(0, 0.6, 50))
    ke, pe = wheel.energies(X)
    total = np.asarray(ke) + np.asarray(pe)
    assert np.max(np.abs(total - total[0])) < 1e-9


def test_3d_wheel_impact_conserves_angular_momentum_about_the_new_foot(wheel):
    x = np.array([0.1, -0.03, -ALPHA - SLOPE + 0.01, 0.2, 0.15, -1.2])
    xp = wheel.reset(x)

    def rot(q):
        nrm = np.array([math.sin(SLOPE), math.cos(SLOPE), 0.0])
        fall = np.array([math.cos(SLOPE), -math.sin(SLOPE), 0.0])
        return (Rotation.from_rotvec(q[0] * nrm) * Rotation.from_rotvec(q[1] * fall)
                * Rotation.from_rotvec([0, 0, q[2]])).as_matrix()

    def omega(q, dq):
        fall = np.array([math.cos(SLOPE), -math.sin(SLOPE), 0.0])
        nrm = np.array([math.sin(SLOPE), math.cos(SLOPE), 0.0])
        A = Rotation.from_rotvec(q[0] * nrm)
        B = A * Rotation.from_rotvec(q[1] * fall)
        return nrm * dq[0] + A.apply(fall) * dq[1] + B.apply([0, 0, 1]) * dq[2]

    ref = Wheel()
    R = rot(x[:3])
    hub, new = R @ ref.hub, R @ ref.foot(1)
    w_minus, w_plus = omega(x[:3], x[3:]), omega(xp[:3], xp[3:])
    I_cm = R @ ref.I_cm @ R.T
    d = hub - new
    H_minus = I_cm @ w_minus + M * np.cross(d, np.cross(w_minus, hub))
    H_plus = I_cm @ w_plus + M * np.cross(d, np.cross(w_plus, d))
    assert np.max(np.abs(H_plus - H_minus)) < 1e-12
    # the relabelling turns the stance spoke by one spoke: the same body orientation
    assert np.max(np.abs(rot(xp[:3]) - R @ Rotation.from_rotvec(
        [0, 0, 2 * ALPHA]).as_matrix())) < 1e-14


def test_a_3d_wheel_without_its_diametral_inertia_is_refused_in_one_line():
    with pytest.raises(Exception, match="walker.diametral_inertia_kg_m2"):
        _scene(diametral_inertia_kg_m2=None)


@pytest.mark.slow  # ~5 s: 5 s of MuJoCo at 0.1 ms
def test_the_3d_wheels_mjcf_walks_in_mujoco_as_the_rigid_model_predicts(tmp_path):
    """The disc wheel's MJCF (a free body on its spoke tips, no plane constraint) in MuJoCo,
    started from the rigid gait with a lateral push (lean rate +0.1 rad/s): it keeps rolling
    (>= 10 spoke strikes, mean step period within 3 % of the rigid gait's), and its lean at
    the strikes follows the rigid model's from the same start."""
    mujoco = pytest.importorskip("mujoco")
    from walkerlab.cli.options import load
    from walkerlab.codegen.cache import functions
    from walkerlab.export.spoked import WHEEL_TIP_FRACTION, wheel3d_keyframe, wheel3d_mjcf_text
    from walkerlab.integrate.rigid import simulate_steps
    from walkerlab.walker.description import walker_data

    scene = load(str(ROOT / "configs" / "rimless_wheel_3d_disc.yaml"))
    walker = build_walker(Plant.from_scene(scene))
    solver = Solver(method="DOP853", rtol=1e-12, atol=1e-12)
    gait = find_fixed_point(walker, np.array([0, 0, ALPHA - 0.2, 0, 0, -1.9]), solver,
                            fd_check=False)
    x0 = gait.x.copy()
    x0[walker.state_names().index("lean_rate")] += 0.1
    data = walker_data(scene.walker, scene.slope.phi_rad)
    f = functions(data)
    qpos, qvel = wheel3d_keyframe(f["points"], f["point_velocities"], x0, 0.2,
                                  WHEEL_TIP_FRACTION * L)
    model = mujoco.MjModel.from_xml_string(wheel3d_mjcf_text(data, "disc", "", qpos, qvel))
    d = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, d, 0)
    tips = {mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, f"spoke{k}_tip"): k
            for k in range(N_SPOKES)}
    nrm = np.array([math.sin(0.2), 0.0, math.cos(0.2)])
    stance, times, lean = 0, [], []
    while d.time < 5.0:
        mujoco.mj_step(model, d)
        touching = {tips[g] for c in d.contact[:d.ncon] for g in (c.geom1, c.geom2)
                    if g in tips}
        if (stance + 1) % N_SPOKES in touching:
            stance = (stance + 1) % N_SPOKES
            times.append(d.time)
            lean.append(float(d.xmat[1].reshape(3, 3)[:, 1] @ nrm))  # sin(lean)
    assert len(times) >= 11
    assert abs(np.mean(np.diff(times)) / gait.period_s - 1.0) < 0.03
    rigid = simulate_steps(walker, x0, 8, Solver(method="DOP853", rtol=1e-10, atol=1e-10))
    i_lean = walker.state_names().index("lean_angle")
    ours = np.sin([s.x_next[i_lean] for s in rigid.segments[:6]])
    # soft contact (2 ms) and 1 mm tip spheres against the rigid impact: a few mrad
    assert np.max(np.abs(np.array(lean[:6]) - ours)) < 3e-3
    assert np.max(np.abs(ours)) > 0.04  # the push was felt: the comparison is not of zeros


def test_the_3d_wheels_urdf_loads_as_a_free_body_in_pinocchio_and_drake(tmp_path):
    """The URDF: one link, a free body in both loaders, its mass and inertia the scene's
    (the axle's along the link's y)."""
    pin = pytest.importorskip("pinocchio")
    from walkerlab.cli.options import load
    from walkerlab.stages import export

    scene = load(str(ROOT / "configs" / "rimless_wheel_3d_disc.yaml"))
    path = export.write(scene, tmp_path, "urdf").path
    model = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())
    assert (model.nq, model.nv) == (7, 6)
    assert abs(pin.computeTotalMass(model) - 1.0) < 1e-12
    assert np.allclose(model.inertias[1].inertia, np.diag([0.25, 0.5, 0.25]), atol=1e-12)
    try:
        from pydrake.multibody.parsing import Parser
        from pydrake.multibody.plant import MultibodyPlant
    except ImportError:
        return
    plant = MultibodyPlant(0.0)
    Parser(plant).AddModels(str(path))
    plant.Finalize()
    assert (plant.num_positions(), plant.num_velocities()) == (7, 6)


# ---- studies on the 3D wheel against its planar embedding (the upright wheel) ----------

def _target_slope(scene_path, speed=0.5, **changes):
    """``slope.angle_rad`` (and the gait) that ``walkerlab target --vary slope.angle_rad
    --speed-m-per-s SPEED`` answers for ``scene_path`` with ``changes``."""
    import walkerlab as wl
    from walkerlab.config import load_scene

    w = wl.Walker.from_scene(load_scene(scene_path)).with_changes(changes)
    found, gait = w.find_gait_for("slope.angle_rad", speed_m_per_s=speed)
    return found.scene.slope.angle_rad, gait


@pytest.mark.parametrize("scene, planar_changes", [
    ("rimless_wheel_3d.yaml", {}),
    ("rimless_wheel_3d_disc.yaml", {"walker.hub_inertia_kg_m2": 0.5}),
], ids=["point_mass", "disc"])
def test_a_3d_wheels_target_slope_is_the_planar_wheels_rolling_upright_down_the_fall_line(
        scene, planar_changes):
    """``target`` holds the neutral heading where the scene's gait has it (0: the fall
    line), so the answer is the upright wheel's: the planar wheel's slope for 0.5 m/s
    (configs/rimless_wheel.yaml, with the disc's axle inertia for the disc), 0.07057 rad
    and 0.04667 rad, both downhill.  The two models are different code (a planar hinge, a
    free rigid body) and each answer is solved to MINPACK's xtol 1e-11 on maps integrated
    at rtol = atol = 1e-12: they agree to ~2e-12 relative; 1e-9 leaves margin.  With the
    heading freed the point-mass wheel answered 0.07082 rad at 4.5 deg heading (3.6e-3
    off), the disc wheel -0.74 rad (uphill) at 106 deg heading and 41 deg lean."""
    slope_3d, gait = _target_slope(ROOT / "configs" / scene)
    slope_planar, _ = _target_slope(ROOT / "configs" / "rimless_wheel.yaml", **planar_changes)
    assert slope_3d > 0 and slope_planar > 0  # downhill
    assert abs(slope_3d - slope_planar) <= 1e-9 * slope_planar
    assert gait.state["heading_angle"] == 0.0  # held where the scene's gait has it
    for n in ("lean_angle", "heading_rate", "lean_rate"):
        assert abs(gait.state[n]) < 1e-12, n  # upright, rolling straight
    assert abs(gait.speed - 0.5) < 1e-9


def test_a_3d_wheels_target_gait_is_judged_with_its_neutral_multiplier_set_aside():
    """The disc wheel's gait at 1.9 m/s lies at 0.1944 rad, above its critical slope
    (0.1857 rad, where the lateral multiplier crosses +1): stable, its largest |multiplier|
    besides the neutral 1 (the heading) 0.93, as the fixed-point search's verdict; with the
    neutral 1 counted it was called unstable at max |multiplier| 1.  The slope is the planar
    wheel's with the disc's axle inertia (to 1e-9 relative, as above)."""
    slope, gait = _target_slope(ROOT / "configs" / "rimless_wheel_3d_disc.yaml", speed=1.9)
    planar, _ = _target_slope(ROOT / "configs" / "rimless_wheel.yaml", speed=1.9,
                              **{"walker.hub_inertia_kg_m2": 0.5, "slope.angle_rad": 0.2,
                                 "fixedpoint.initial_guess.stance_rate_rad_per_s": -1.9})
    assert abs(slope - planar) <= 1e-9 * planar
    assert 0.1857 < slope < 0.2 and gait.neutral == ("heading_angle",)
    assert 0.9 < gait.max_abs_multiplier < 0.95 and gait.stable
    assert abs(np.max(np.abs(gait.multipliers)) - 1.0) < 1e-8  # the neutral 1 is there
@pytest.mark.parametrize("name", ["rimless_wheel_3d.yaml", "rimless_wheel_3d_disc.yaml"])
def test_a_3d_wheel_without_initial_guess_finds_the_shipped_gait(tmp_path, name):
    """Without a guess, the 3D wheel starts from the planar wheel's closed-form gait
    (McGeer 1990: w+ = eta sqrt(4 M g L sin(alpha) sin(gamma) / ((M L^2 + I)(1 - eta^2))),
    upright, heading 0) and reaches the gait the shipped scene finds from its guess, to the
    root finder's tolerance (xtol 1e-12 relative; 1e-9 rad/s leaves room for the lateral
    multiplier 22)."""
    import yaml

    from walkerlab.analysis.gait.scene import solve_scene
    from walkerlab.config import load_scene

    data = yaml.safe_load((ROOT / "configs" / name).read_text())
    data["fixedpoint"].pop("initial_guess")
    data["fixedpoint"].pop("gait", None)
    (tmp_path / name).write_text(yaml.safe_dump(data))
    sc = load_scene(ROOT / "configs" / name)
    _w, shipped = solve_scene(sc, fd_check=False, plant=Plant.from_scene(sc))
    sc1 = load_scene(tmp_path / name)
    _w, found = solve_scene(sc1, fd_check=False, plant=Plant.from_scene(sc1))
    assert any("closed form" in n for n in found.notes)
    np.testing.assert_allclose(found.result.x, shipped.result.x, rtol=0, atol=1e-9)


def test_the_planar_wheel_closed_form_gait_is_a_fixed_point():
    """The planar wheel's closed form (with a hub inertia: eta = (M L^2 cos 2a + I) /
    (M L^2 + I)) is its map's fixed point to the integrator's tolerance, and for a point
    mass it is McGeer's cot(2 alpha) sqrt(4 g/L sin(alpha) sin(gamma))."""
    from walkerlab.analysis.gait.poincare import poincare_map
    from walkerlab.config import load_scene

    scene = load_scene(ROOT / "configs" / "rimless_wheel.yaml")
    w = build_walker(Plant.from_scene(scene))
    x = w.closed_form_gait()
    assert x[1] == pytest.approx(-W_PLUS, rel=1e-14)
    for inertia in (0.0, 0.5):
        sc = scene.model_copy(update={"walker": scene.walker.model_copy(
            update={"hub_inertia_kg_m2": inertia})})
        wi = build_walker(Plant.from_scene(sc))
        xi = wi.closed_form_gait()
        xn, _, _ = poincare_map(wi, xi, Solver(method="DOP853", rtol=1e-12, atol=1e-12))
        np.testing.assert_allclose(xn, xi, atol=1e-10)


# ---- the 3D wheel down stairs and on footholds (the rigid model's landing) -------------

DISC_STAIRS = ROOT / "configs" / "rimless_wheel_3d_disc_stairs.yaml"
#: the disc wheel's slope (configs/rimless_wheel_3d_disc.yaml) and its spokes' chord: its
#: drop and run, the riser and tread on which the spoke tips land as on that slope
DISC_SLOPE = 0.2
CHORD_DROP, CHORD_RUN = (2 * L * math.sin(ALPHA) * math.sin(DISC_SLOPE),
                         2 * L * math.sin(ALPHA) * math.cos(DISC_SLOPE))
SOLVER = Solver(method="DOP853", rtol=1e-12, atol=1e-12)


def _raw(path, **changes):
    """The scene mapping of ``path`` with the dotted ``changes`` set."""
    import yaml

    raw = yaml.safe_load(Path(path).read_text())
    for key, value in changes.items():
        *head, last = key.split(".")
        d = raw
        for k in head:
            d = d.setdefault(k, {})
        d[last] = value
    return raw


def _built(raw):
    from walkerlab.config.schema import Scene

    plant = Plant.from_scene(Scene.model_validate(raw))
    return plant, build_walker(plant)


def _planar(raw):
    """The planar wheel of the 3D scene mapping ``raw`` (its axle inertia, no diameters')."""
    import copy

    raw = copy.deepcopy(raw)
    raw["walker"]["space"] = "2d"
    raw["walker"].pop("diametral_inertia_kg_m2")
    raw["contact"].pop("torsional_friction_m", None)
    return raw


@pytest.mark.parametrize("riser_m, tread_m", [(CHORD_DROP, CHORD_RUN), (0.152, 0.75),
                                              (0.1, 0.75)], ids=["chord", "shipped", "0.1"])
def test_the_upright_3d_wheel_down_stairs_is_the_planar_wheel_down_them(riser_m, tread_m):
    """Upright and rolling straight down the stairs' fall line, the 3D disc wheel's gait is
    the planar wheel's (its axle inertia) on the same stairs: a different generated model
    (one coordinate, a hinge) landing by the same shared code (walkerlab.models.hybrid.
    ground).  Both searched to 1e-12: fixed point and step period to 1e-9.  On stairs whose
    riser and tread are the spokes' chord's drop and run on the 0.2 rad slope, the gait is
    that slope's (the tips land on its plane: the stairs' mean slope), to 1e-9 too."""
    raw = _raw(DISC_STAIRS, **{"terrain.riser_m": riser_m, "terrain.tread_m": tread_m})
    _p, wheel = _built(raw)
    _p, planar = _built(_planar(raw))
    g3 = find_fixed_point(wheel, np.array([0, 0, ALPHA - DISC_SLOPE, 0, 0, -1.9]), SOLVER,
                          fd_check=False)
    g2 = find_fixed_point(planar, np.array([ALPHA - DISC_SLOPE, -1.9]), SOLVER,
                          fd_check=False)
    assert g3.residual < 1e-11 and g2.residual < 1e-11
    assert np.max(np.abs(g3.x[[0, 1, 3, 4]])) < 1e-12  # upright, straight down
    assert abs(g3.x[2] - g2.x[0]) < 1e-9 and abs(g3.x[5] - g2.x[1]) < 1e-9
    assert abs(g3.period_s - g2.period_s) < 1e-9
    # the section's stance spoke leans back by the slope on which the chord drops the
    # riser, asin(riser / (2 L sin alpha)): the stairs' mean slope atan(riser / tread)
    # when the tread is the chord's run (the rigid landing reads the riser only)
    assert abs(g3.x[2] - (ALPHA - math.asin(riser_m / (2 * L * math.sin(ALPHA))))) < 1e-12
    if riser_m == CHORD_DROP:
        _p, plane = _built(_raw(ROOT / "configs" / "rimless_wheel_3d_disc.yaml"))
        gp = find_fixed_point(plane, np.array([0, 0, ALPHA - DISC_SLOPE, 0, 0, -1.9]),
                              SOLVER, fd_check=False)
        assert np.max(np.abs(g3.x - gp.x)) < 1e-9 and abs(g3.period_s - gp.period_s) < 1e-9


def test_a_zero_landing_gives_the_plane_slopes_gait_exactly():
    """Footholds of height 0 on the disc wheel's 0.2 rad slope: the slope's walker itself
    (landing_drop 0: no guard changed), so its gait is the plane's bit for bit; and the
    landing's own guard at depth 0 (the generated clearance, the section's trailing tip
    solved by Newton on the spin's mirror: walkerlab.models.hybrid.ground.
    with_clearance_guard) gives the plane's section state, map and gait to 1e-12."""
    from walkerlab.analysis.gait.poincare import poincare_map
    from walkerlab.models.hybrid.ground import with_clearance_guard

    disc = ROOT / "configs" / "rimless_wheel_3d_disc.yaml"
    plant, plane = _built(_raw(disc))
    _p, zero = _built(_raw(disc, terrain={"kind": "footholds", "foothold_heights_m": [0.0],
                                          "lanes": "continuous"}))
    guess = np.array([0, 0, ALPHA - DISC_SLOPE, 0, 0, -1.9])
    gp = find_fixed_point(plane, guess, SOLVER, fd_check=False)
    gz = find_fixed_point(zero, guess, SOLVER, fd_check=False)
    assert np.array_equal(gp.x, gz.x) and gp.period_s == gz.period_s
    clear = with_clearance_guard(plane, plant.data)
    # a leaned, turned, wobbling state's section: the trailing tip found on the slope
    for x0 in (gp.x, np.array([0.1, -0.05, 0.2, 0.3, -0.2, -1.8])):
        z = plane.section(x0)
        xa, xb = plane.from_section(z), clear.from_section(z)
        assert np.max(np.abs(xa - xb)) < 1e-12
        pa, ta = poincare_map(plane, xa, SOLVER)[:2]
        pb, tb = poincare_map(clear, xb, SOLVER)[:2]
        assert np.max(np.abs(pa - pb)) < 1e-12 and abs(ta - tb) < 1e-12
    gc = find_fixed_point(clear, guess, SOLVER, fd_check=False)
    assert np.max(np.abs(gc.x - gp.x)) < 1e-12 and abs(gc.period_s - gp.period_s) < 1e-12


def test_a_leaned_turned_wheels_landing_is_measured_along_the_normal_at_the_tips():
    """The landing's section for a leaned, heading-turned wheel: its trailing spoke's tip
    (the generated trailing_foot point, not the mirrored clearance the section solves) lies
    ``drop cos(gamma)`` above the plane through the stance tip, along the slope's normal;
    and the step from it ends with the next tip that far below that plane (on footholds
    2 cm below the 0.2 rad slope)."""
    from walkerlab.integrate.rigid import integrate_step

    disc = ROOT / "configs" / "rimless_wheel_3d_disc.yaml"
    _p, w = _built(_raw(disc, terrain={"kind": "footholds", "foothold_heights_m": [-0.02],
                                       "lanes": "continuous"}))
    nrm = np.array([math.sin(DISC_SLOPE), math.cos(DISC_SLOPE), 0.0])
    level = 0.02 * math.cos(DISC_SLOPE)
    x = w.from_section(np.array([0.3, 0.1, 0.05, -0.1, -1.9]))
    assert abs(x[1] - 0.1) < 1e-15 and abs(x[0] - 0.3) < 1e-15
    trailing = np.asarray(w.points(x)["trailing_foot"], float).reshape(-1)
    assert abs(trailing @ nrm - level) < 1e-13
    seg = integrate_step(w, x, SOLVER)
    assert seg.termination == "heel_strike"
    nxt = np.asarray(w.points(seg.x_end)["swing_foot"], float).reshape(-1)
    assert abs(nxt @ nrm + level) < 1e-10


def test_the_shipped_disc_wheel_down_stairs_rolls_stably(tmp_path):
    """configs/rimless_wheel_3d_disc_stairs.yaml through the CLI: its gait (the numbers in
    the scene's header) stable besides the neutral heading, and simulate's 20 spoke
    strikes at that period."""
    from tests.cli_run import run_cli

    scene = str(DISC_STAIRS)
    code, err, out = run_cli("fixedpoint", scene, "--runs-dir", tmp_path)
    assert code == 0, err
    assert "verdict: STABLE" in out and "step period     0.3962678048 s" in out
    assert "stays ahead of the riser edge" in out and "SCUFF" not in out
    code, err, out = run_cli("simulate", scene, "--runs-dir", tmp_path)
    assert code == 0, err
    assert "20 heel strikes" in out and "mean step period  0.3962678 s" in out


@pytest.mark.slow  # ~25 s: a contact run and a MuJoCo roll of 11 spoke strikes
@pytest.mark.parametrize("view", ["contact", "mjcf"])
def test_the_disc_wheel_rolls_down_stairs_in_contact_and_in_mujoco(view, tmp_path):
    """configs/rimless_wheel_3d_disc_stairs.yaml in the contact model (its treads and risers
    a polyline, level across the fall line) and in MuJoCo (the treads as boxes): >= 10
    spoke strikes at the rigid step period within 3 % (measured -0.03 % and -0.36 %)."""
    from walkerlab.api.capabilities import measure

    m = measure("rolling_polygon_3d", "stairs", view, tmp_path)
    assert m.ok and abs(m.value) < 0.03, m.detail
