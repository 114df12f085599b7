"""The kneed walker and the round-foot walker built from their YAML descriptions.

Checked against physics (energy in swing, momenta through knee strike and heel strike), the
point-foot walker (round feet with R = 0), the independent prototypes of
``tests/independent/`` (no shared code) and the published numbers
(:mod:`walkerlab.published.hsu_chen2007`, :mod:`walkerlab.published.bhounsule2009`).
"""

from pathlib import Path

import numpy as np
import pytest
import yaml
from independent.kneed_reference import KneedReference
from independent.round_feet_reference import RoundFeetReference

from walkerlab.analysis.gait.poincare import find_fixed_point
from walkerlab.codegen.cache import functions
from walkerlab.config import BipedParams
from walkerlab.integrate.rigid import integrate_step, simulate_steps
from walkerlab.integrate.solver import Solver
from walkerlab.models.hybrid.rigid import make_rigid_walker
from walkerlab.published import bhounsule2009, hsu_chen2007
from walkerlab.walker.description import walker_data

ROOT = Path(__file__).resolve().parents[1]
TIGHT = Solver("DOP853", 1e-12, 1e-12)


def _scene(name):
    return yaml.safe_load((ROOT / "configs" / f"{name}.yaml").read_text())


def _walker(cfg, **walker_overrides):
    w = {**cfg["walker"], **walker_overrides}
    return make_rigid_walker(walker_data(BipedParams.model_validate(w),
                                         cfg["slope"]["angle_rad"]))


def _guess(cfg, walker):
    g = cfg["fixedpoint"]["initial_guess"]
    return np.array([g[n + ("_rad" if n.endswith("_angle") else "_rad_per_s")]
                     for n in walker.state_names()])


def _height(walker, xy):
    """Height [m] of a point above the slope through the stance reference point."""
    gm = walker.slope_rad
    return xy[0] * np.sin(gm) + xy[1] * np.cos(gm)


def _momentum(walker, masses, x, about, keys, h=1e-7):
    """Angular momentum [kg m^2/s] of point masses about ``about``; velocities by central
    differences of the generated ``points`` along ``dq`` (error ~1e-14 relative)."""
    n = walker.n_coordinates
    xp, xm = x.copy(), x.copy()
    xp[:n] += h * x[n:]
    xm[:n] -= h * x[n:]
    P, Pp, Pm = walker.points(x), walker.points(xp), walker.points(xm)
    total = 0.0
    for k in keys:
        r, v = P[k] - about, (Pp[k] - Pm[k]) / (2 * h)
        total += masses[k] * (r[0] * v[1] - r[1] * v[0])
    return total


# ------------------------------------------------------------------------------ kneed
@pytest.fixture(scope="module")
def kneed():
    cfg = _scene("kneed")
    walker = _walker(cfg)
    return cfg, walker, find_fixed_point(walker, _guess(cfg, walker), TIGHT)


def _kneed_masses(walker):
    p = walker.params
    return {"hip": p["M_hip"], "stance_thigh_mass": p["m_thigh_mass"],
            "swing_thigh_mass": p["m_thigh_mass"], "stance_shank_mass": p["m_shank_mass"],
            "swing_shank_mass": p["m_shank_mass"]}


def test_kneed_config_is_the_published_walker(kneed):
    cfg, walker, _ = kneed
    p = walker.params
    assert p["gravity_m_per_s2"] == hsu_chen2007.GRAVITY_M_PER_S2
    assert p["L_thigh"] == hsu_chen2007.THIGH_LENGTH_M
    assert p["L"] == hsu_chen2007.THIGH_LENGTH_M + hsu_chen2007.SHANK_LENGTH_M
    assert p["M_hip"] == hsu_chen2007.HIP_MASS_KG
    assert p["m_thigh_mass"] == hsu_chen2007.THIGH_MASS_KG
    assert p["m_shank_mass"] == pytest.approx(hsu_chen2007.SHANK_MASS_KG, rel=1e-15)
    assert p["d_thigh_mass"] == pytest.approx(
        hsu_chen2007.THIGH_LENGTH_M - hsu_chen2007.THIGH_MASS_ABOVE_KNEE_M, rel=1e-15)
    assert p["d_shank_mass"] == pytest.approx(
        walker.params["L"] - hsu_chen2007.SHANK_MASS_ABOVE_FOOT_M, rel=1e-15)
    assert walker.slope_rad == hsu_chen2007.SLOPE_RAD
    g = cfg["fixedpoint"]["initial_guess"]
    assert all(g[k] == v for k, v in hsu_chen2007.INITIAL_CONDITION.items())


def test_kneed_fixed_point_matches_independent_prototype(kneed):
    _, walker, fp = kneed
    ref = KneedReference()
    # prototype order: stance, swing thigh, swing shank (angles, then rates)
    order = [walker.state_names().index(f"{r}_{k}") for k in ("angle", "rate")
             for r in ("stance", "swing_thigh", "swing_shank")]
    x_ref = fp.x[order]
    assert fp.residual < 1e-10
    assert np.max(np.abs(ref.step(x_ref)["x_next"] - x_ref)) < 1e-9   # a fixed point there too
    mu_ref = ref.multipliers(x_ref)
    mu = fp.multipliers_variational[:3]
    assert np.allclose(np.sort_complex(mu), np.sort_complex(mu_ref), atol=1e-7)


def test_kneed_gait_is_stable_and_knee_locks_every_step(kneed):
    _, walker, fp = kneed
    assert fp.stable and np.max(np.abs(fp.multipliers_variational)) < 0.75  # 0.741
    traj = simulate_steps(walker, fp.x, 4, TIGHT)
    assert [s.termination for s in traj.segments] == ["heel_strike"] * 4
    for seg in traj.segments:
        t_knee = seg.phase_times["knee_strike"]
        assert seg.t_start < t_knee < seg.t_end
        xl = seg.sample(np.linspace(t_knee, seg.t_end, 30))
        names = walker.state_names()
        th, sh = names.index("swing_thigh_angle"), names.index("swing_shank_angle")
        assert np.max(np.abs(xl[sh] - xl[th])) < 1e-9  # locked until heel strike


def test_kneed_energy_conserved_and_no_scuffing(kneed):
    _, walker, fp = kneed
    seg = integrate_step(walker, fp.x, TIGHT)
    t_knee = seg.phase_times["knee_strike"]
    for a, b in ((seg.t_start, t_knee), (t_knee, seg.t_end)):
        X = seg.sample(np.linspace(a, b, 80)[1:-1])
        E = np.sum(walker.energies(X), axis=0)
        assert np.ptp(E) < 1e-9 * abs(E[0])     # 12.7 J, tolerances 1e-12
        # the swing foot stays above the slope between lift-off and heel strike (min 1.3 mm)
        assert np.min(_height(walker, walker.points(X)["swing_foot"])) > 0


def test_kneed_swing_foot_through_the_ground_is_reported(kneed):
    # swing leg thrown forward at 2 rad/s from the gait's start: the trailing foot is driven
    # into the slope instead of lifting off - the step ends as a reported fall, not ignored
    _, walker, fp = kneed
    x = fp.x.copy()
    for name in ("swing_thigh_rate", "swing_shank_rate"):
        x[walker.state_names().index(name)] = 2.0
    seg = integrate_step(walker, x, TIGHT)
    assert (seg.termination, seg.event) == ("fall", "swing_foot_scuffs")


def test_knee_stop_pushes_while_locked(kneed):
    # the locked knee's constraint torque lam (M qdd + C dq + G = J_k^T lam, J_k = d(shank -
    # thigh)) stays negative: the stop pushes the shank back, so a plain knee stop would hold
    # the knee straight without a latch (prototype: -0.033 to -0.029 N m)
    cfg, walker, fp = kneed
    f = functions(walker_data(BipedParams.model_validate(cfg["walker"]),
                              cfg["slope"]["angle_rad"]))
    seg = integrate_step(walker, fp.x, TIGHT)
    names = walker.state_names()
    sh = names.index("swing_shank_angle")
    lam = []
    for t in np.linspace(seg.phase_times["knee_strike"], seg.t_end, 25):
        x = seg.sample(np.array([t]))[:, 0]
        M, C, G = f["matrices"](x)
        n = walker.n_coordinates
        tau = M @ f["flow_locked"](t, x)[n:] + C @ x[n:] + G
        lam.append(tau[sh])
        assert abs(tau[names.index("stance_angle")]) < 1e-9   # only the knee is constrained
    ref = KneedReference()
    order = [names.index(f"{r}_{k}") for k in ("angle", "rate")
             for r in ("stance", "swing_thigh", "swing_shank")]
    assert lam[0] == pytest.approx(ref.locked_accel(seg.sample(np.array(
        [seg.phase_times["knee_strike"]]))[:, 0][order])[1], rel=1e-6)
    assert max(lam) < 0


def test_knee_strike_conserves_momenta_and_dissipates(kneed):
    _, walker, fp = kneed
    seg = integrate_step(walker, fp.x, TIGHT)
    # the state just before the knee strike: end of the first phase
    tb = seg.phase_times["knee_strike"]
    xm = seg.sample(np.array([tb]))[:, 0]   # the first phase's dense output at its end
    guard = walker.phases[0].guards[0]
    assert guard.name == "knee_strike" and abs(guard.function(0.0, xm)) < 1e-12
    xp = guard.reset(xm)
    m = _kneed_masses(walker)
    all_keys = list(m)
    L0 = _momentum(walker, m, xm, np.zeros(2), all_keys)
    assert _momentum(walker, m, xp, np.zeros(2), all_keys) == pytest.approx(L0, rel=1e-9)
    hip = walker.points(xm)["hip"]
    swing = ["swing_thigh_mass", "swing_shank_mass"]
    Ls = _momentum(walker, m, xm, hip, swing)
    assert _momentum(walker, m, xp, hip, swing) == pytest.approx(Ls, rel=1e-9)
    assert walker.energies(xp)[0] < walker.energies(xm)[0] - 1e-3   # loses 0.025 J


def test_kneed_heel_strike_conserves_momenta(kneed):
    _, walker, fp = kneed
    seg = integrate_step(walker, fp.x, TIGHT)
    xm, xn = seg.x_end, seg.x_next
    m = _kneed_masses(walker)
    foot = walker.points(xm)["swing_foot"]
    L0 = _momentum(walker, m, xm, foot, list(m))
    assert _momentum(walker, m, xn, np.zeros(2), list(m)) == pytest.approx(L0, rel=1e-9)
    # the old stance leg about the hip (its foot leaves the ground without impulse)
    old = _momentum(walker, m, xm, walker.points(xm)["hip"], ["stance_thigh_mass",
                                                             "stance_shank_mass"])
    new = _momentum(walker, m, xn, walker.points(xn)["hip"], ["swing_thigh_mass",
                                                             "swing_shank_mass"])
    assert new == pytest.approx(old, rel=1e-9)
    assert walker.energies(xn)[0] < walker.energies(xm)[0]


def test_kneed_leg_coordinates_same_keys_every_step(kneed):
    _, walker, fp = kneed
    keys = [set(walker.leg_coordinates(fp.x, leg)) for leg in walker.legs]
    assert keys[0] == keys[1] == set(walker.coordinate_units)
    c = walker.leg_coordinates(fp.x, "leg2")   # leg1 swings: thigh and shank straight
    assert c["leg1_thigh_angle"] == c["leg1_shank_angle"] == fp.x[0]


# ------------------------------------------------------------------------- round feet
@pytest.fixture(scope="module")
def round_feet():
    cfg = _scene("round_feet")
    walker = _walker(cfg)
    fp = find_fixed_point(walker, _guess(cfg, walker), TIGHT, max_step_time=20.0)
    return cfg, walker, fp


def test_round_feet_fixed_point_matches_prototype_and_published(round_feet):
    _, walker, fp = round_feet
    ref = RoundFeetReference()
    assert np.max(np.abs(ref.step(fp.x)["x_next"] - fp.x)) < 1e-9
    assert fp.stable and np.max(np.abs(fp.multipliers_variational)) == pytest.approx(
        np.max(np.abs(ref.multipliers(fp.x))), abs=1e-7)
    # Bhounsule's printed root: angles agree to 4e-5 rad; his heel-strike law writes the old
    # stance leg's spin as I (v1 - v2) instead of I v1, which moves the swing rate by 2.2e-3
    pub = bhounsule2009.root_as_absolute_angles()
    x_pub = np.array([pub[n + ("_rad" if n.endswith("_angle") else "_rad_per_s")]
                      for n in walker.state_names()])
    angles = [walker.state_names().index(n) for n in ("swing_angle", "stance_angle")]
    assert np.max(np.abs(fp.x[angles] - x_pub[angles])) < 1e-4
    assert np.max(np.abs(fp.x - x_pub)) < 3e-3


def test_round_feet_prototype_agrees_with_published_law_without_inertia(round_feet):
    # with I = 0 the two heel-strike laws coincide: same gait within the root tolerance
    cfg, _, _ = round_feet
    body = {**cfg["walker"]["leg"]["bodies"][0], "inertia_about_com_kg_m2": 0.0}
    walker = _walker(cfg, leg={**cfg["walker"]["leg"], "bodies": [body]})
    ref = RoundFeetReference(p={**RoundFeetReference().p, "I": 0.0})
    x = find_fixed_point(walker, _guess(cfg, walker), TIGHT, max_step_time=20.0).x
    assert np.max(np.abs(ref.step(x)["x_next"] - x)) < 1e-9


def test_round_feet_energy_conserved_while_rolling(round_feet):
    _, walker, fp = round_feet
    seg = integrate_step(walker, fp.x, TIGHT, max_step_time=20.0)
    X = seg.sample(np.linspace(seg.t_start, seg.t_end, 100))
    E = np.sum(walker.energies(X), axis=0)
    assert np.ptp(E) < 1e-9 * abs(E[0])
    # the stance arc touches the slope at its contact point, which rolls R * angle
    c = walker.points(X)["stance_contact"]
    assert np.max(np.abs(_height(walker, c))) < 1e-12


def test_round_feet_world_chaining(round_feet):
    # the next step's reference point is where the new stance arc touches after rolling
    # back: stance contact at the start of step k+1 = swing contact at the end of step k
    _, walker, fp = round_feet
    traj = simulate_steps(walker, fp.x, 2, TIGHT, max_step_time=20.0)
    s0, s1 = traj.segments
    end = s0.stance_foot_world + walker.points(s0.x_end)["swing_contact"]
    start = s1.stance_foot_world + walker.points(s1.x_start)["stance_contact"]
    assert np.max(np.abs(end - start)) < 1e-14


def test_round_feet_with_zero_radius_is_the_point_foot_walker(paper_walker, paper_fixed_point):
    # the round-foot structure (rod leg, arc feet) with R = 0, I = 0 and the paper's numbers
    cfg = {"walker": {"model": "biped", "coordinates": "absolute", "gravity_m_per_s2": 9.81,
                      "hip_mass_kg": 10.0, "leg": {
                          "length_m": 1.0, "foot": {"kind": "arc", "radius_m": 0.0},
                          "bodies": [{"kind": "rod", "name": "leg_body", "mass_kg": 5.0,
                                      "com_from_hip_m": 0.5, "inertia_about_com_kg_m2": 0.0}]}},
           "slope": {"angle_rad": paper_walker.slope_rad}}
    walker = _walker(cfg)
    rng = np.random.default_rng(1)
    for x in [paper_fixed_point.x, *rng.uniform(-0.4, 0.4, (5, 4))]:
        f0, f1 = paper_walker.phases[0].flow(0.0, x), walker.phases[0].flow(0.0, x)
        assert np.max(np.abs(f1 - f0)) < 1e-12 * (1 + np.max(np.abs(f0)))
        assert np.max(np.abs(walker.reset(x) - paper_walker.reset(x))) < 1e-12
        assert np.allclose(walker.energies(x), paper_walker.energies(x), rtol=1e-13, atol=1e-12)
        p0, p1 = paper_walker.points(x), walker.points(x)
        for k in ("hip", "swing_foot", "stance_foot"):
            assert np.max(np.abs(p1[k] - p0[k])) < 1e-15
    seg0 = integrate_step(paper_walker, paper_fixed_point.x, TIGHT)
    seg1 = integrate_step(walker, paper_fixed_point.x, TIGHT)
    assert np.max(np.abs(seg1.x_next - seg0.x_next)) < 1e-12


# ------------------------------------------------------------------------ config errors
@pytest.mark.parametrize(("scene", "edit", "field"), [
    ("kneed", lambda w: w["leg"]["bodies"][0].update(from_hip_m=0.7), "thigh_mass"),  # below knee
    ("kneed", lambda w: w["leg"]["knee"].update(thigh_length_m=1.2), "thigh_length_m"),
    ("kneed", lambda w: w["leg"]["bodies"][1].update(link="leg"), "shank_mass"),
    ("kneed", lambda w: w.update(coordinates="slope_relative"), "coordinates"),
    ("round_feet", lambda w: w["leg"]["foot"].update(radius_m=1.5), "radius_m"),
    ("round_feet", lambda w: w["leg"]["bodies"][0].update(link="shank"), "needs a knee"),
])
def test_bad_knee_or_foot_field_is_named_in_one_line(scene, edit, field):
    from walkerlab.config import SceneError, scene_from_dict

    d = _scene(scene)
    edit(d["walker"])
    with pytest.raises(SceneError) as exc:
        scene_from_dict(d, f"{scene}.yaml")
    msg = str(exc.value)
    assert field in msg and "\n" not in msg


# ----------------------------------------------------------- generated Jacobians (codegen)
def _central(fun, x, h=1e-6):
    return np.stack([(fun(x + h * e) - fun(x - h * e)) / (2 * h) for e in np.eye(x.size)],
                    axis=1)


@pytest.mark.parametrize("scene", ["kneed", "round_feet"])
def test_generated_jacobians_match_central_differences(scene):
    """Flow, locked-knee flow, heel-strike and knee-strike Jacobians (the variational
    equations and saltation matrices use them) against central differences (h = 1e-6: error
    ~1e-9 here) at random states."""
    cfg = _scene(scene)
    f = functions(walker_data(BipedParams.model_validate(cfg["walker"]),
                              cfg["slope"]["angle_rad"]))
    pairs = [("flow", "flow_jacobian", True), ("reset", "reset_jacobian", False)]
    if scene == "kneed":
        pairs += [("flow_locked", "flow_locked_jacobian", True),
                  ("knee_reset", "knee_reset_jacobian", False)]
    rng = np.random.default_rng(5)
    n = 6 if scene == "kneed" else 4
    for _ in range(3):
        x = rng.normal(size=n) * 0.3
        for fun, jac, timed in pairs:
            F = (lambda z, _f=f[fun]: _f(0.0, z)) if timed else f[fun]
            J = f[jac](0.0, x) if timed else f[jac](x)
            assert np.max(np.abs(J - _central(F, x))) < 1e-7 * (1 + np.max(np.abs(J))), fun
