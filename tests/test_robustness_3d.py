"""The robustness study of a walker in 3D (:mod:`walkerlab.studies.robustness_study`): the
disturbances and indicators read from the walker's own coordinates and points (a sideways
push where the points have a lateral axis, the lean and rolls kept absolute in the relative
coordinates), the reflected step map's Jacobian against the gait search's stride
multipliers, the gait sensitivity norm of each disturbance against the nonlinear response
to a small impulse, and the largest sideways push of the passive and the stabilised
hip-width walkers (configs/hip_width.yaml, configs/hip_width_stabilised.yaml) and of the
stabilised kneed walker (configs/kneed_3d_stabilised.yaml), walked by the rigid model's own
simulation on both sides of each bracket; the rigid model's fall of a walker in 3D (its hip
at half its leg length, where a sideways capsize would otherwise stall the integrator).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from walkerlab.analysis.gait.poincare import find_fixed_point, poincare_map
from walkerlab.analysis.robustness import measures as R
from walkerlab.analysis.robustness import push
from walkerlab.config import load_scene
from walkerlab.integrate.batch_step import FALL
from walkerlab.integrate.python_step import ReflectedStepMap, make_step_map
from walkerlab.integrate.solver import Solver
from walkerlab.published import paper
from walkerlab.studies.mfpt import scene_walker_at
from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]
TIGHT = Solver("DOP853", 1e-12, 1e-12, None, "scipy")


def _walk(name: str):
    """The scene's rigid walker (through the study's own builder), its step map at 1e-12 and
    its gait (the stride's fixed point from the scene's initial guess)."""
    scene = load_scene(ROOT / "configs" / f"{name}.yaml")
    at = scene_walker_at(scene, Plant.from_scene(scene))
    walker = at(float(scene.slope.angle_rad))
    g = scene.fixedpoint.initial_guess.model_extra
    x0 = np.array([g[n + ("_rad" if n.endswith("_angle") else "_rad_per_s")]
                   for n in walker.state_names()])
    x = find_fixed_point(walker, x0, TIGHT).x
    return walker, make_step_map(walker, at, 1e-12, 1e-12), x


@pytest.fixture(scope="module")
def stabilised():
    return _walk("hip_width_stabilised")


def _fall(phase):
    """The phase's fall guard of the hip's height (the rigid model's ``fall``)."""
    return next(g for g in phase.guards if g.name == "fall")


def test_a_3d_walker_falls_with_its_hip_at_half_its_leg_length_a_planar_one_at_the_ground(
        paper_walker):
    """The rigid model's fall of the hip: a walker in 3D falls once its hip is half its leg
    length (:data:`walkerlab.models.ground.FALL_HIP_FRACTION`, the compliant-contact
    model's fall) above the slope - a sideways capsize stalls the integrator's steps at 1e-9
    s before the hip reaches the ground (configs/kneed_3d_stabilised.yaml after a 0.25 m
    step-down, the robustness study's first bisection) - in every phase of both steps, on
    the Python guard (against the hip point's height along the slope's normal
    ``(sin gamma, cos gamma, 0)``, world ``y`` up) and on the compiled flow's (the generated
    guard and its offset); a planar walker's fall stays its hip at the ground."""
    from walkerlab.models.ground import FALL_HIP_FRACTION
    from walkerlab.models.registry import build_walker

    scene = load_scene(ROOT / "configs" / "kneed_3d_stabilised.yaml")
    walker = build_walker(Plant.from_scene(scene))
    g = scene.fixedpoint.initial_guess.model_extra
    x = np.array([g[n + ("_rad" if n.endswith("_angle") else "_rad_per_s")]
                  for n in walker.state_names()])
    L, gamma = walker.params["leg_length_m"], walker.slope_rad
    assert FALL_HIP_FRACTION == 0.5 and L == 1.0
    for w in (walker, walker.mirror):
        height = float(np.asarray(w.points(x)["hip"]) @ [np.sin(gamma), np.cos(gamma), 0.0])
        assert 0.9 < height < 1.0
        for phase in w.phases:
            assert _fall(phase).function(0.0, x) == pytest.approx(height - 0.5, abs=1e-12)
            assert ("hip_height", -0.5) in phase.compiled.guards, phase.name
    xp = np.array(paper.EQ11_STATE)
    height = float(np.asarray(paper_walker.points(xp)["hip"])
                   @ [np.sin(paper_walker.slope_rad), np.cos(paper_walker.slope_rad)])
    for phase in paper_walker.phases:
        assert _fall(phase).function(0.0, xp) == pytest.approx(height, abs=1e-12)
        assert ("hip_height", 0.0) in phase.compiled.guards, phase.name


def test_relative_coordinates_keep_a_3d_walkers_lean_and_rolls_absolute():
    """Angles relative to the stance leg are pitches less the stance pitch; a lean or a
    roll (out of the sagittal plane) is no pitch and stays absolute; a planar walker's
    ``T`` is unchanged."""
    names = ["lean_angle", "swing_angle", "stance_angle", "pelvis_roll_angle",
             "lean_rate", "swing_rate", "stance_rate", "pelvis_roll_rate"]
    T = R.relative_coordinates(names)
    assert np.array_equal(T[0], np.eye(8)[0]) and np.array_equal(T[3], np.eye(8)[3])
    assert np.array_equal(T[4], np.eye(8)[4]) and np.array_equal(T[7], np.eye(8)[7])
    assert T[1, 2] == -1.0 and T[5, 6] == -1.0
    planar = R.relative_coordinates(["swing_angle", "stance_angle", "swing_rate",
                                     "stance_rate"])
    assert np.array_equal(planar, [[1, -1, 0, 0], [0, 1, 0, 0], [0, 0, 1, -1], [0, 0, 0, 1]])


def test_a_planar_walker_takes_no_sideways_push(paper_walker):
    """A planar walker's points have no lateral axis: its disturbances and indicators are
    the sagittal ones, and a sideways push is refused in one line."""
    assert push.lateral_axis(paper_walker) is None
    assert R.disturbances_of(paper_walker) == R.DISTURBANCES
    assert R.indicators_of(paper_walker) == R.INDICATORS


@pytest.mark.slow  # the hip-roll walker's gait search and batched map (minutes)
def test_a_sideways_push_changes_the_hips_lateral_velocity_by_its_size(stabilised):
    """The push along the hip axis at the section: the hip's lateral velocity (central
    differences of its position along the rates, independent of the push's Jacobian)
    changes by the push's size, and the impulse is that change times the walker's
    effective mass (positive, below the walker's whole mass of 20 kg)."""
    walker, _sm, x = stabilised
    w = R.step_walker(_sm)
    lay = w.layout()

    def hip_velocity(s):
        h = 1e-6
        q, qd = lay.q(s), lay.qd(s)
        return (np.asarray(w.points(lay.join(q + h * qd, qd))["hip"])
                - np.asarray(w.points(lay.join(q - h * qd, qd))["hip"])) / (2 * h)

    xp, P = push.apply_push(w, x, 0.1, axis=push.LATERAL_AXIS)
    dv = hip_velocity(xp) - hip_velocity(x)
    assert dv[push.LATERAL_AXIS] == pytest.approx(0.1, abs=1e-8)
    assert 0.0 < P / 0.1 < walker.total_mass_kg
    assert np.array_equal(lay.q(xp), lay.q(x))  # an impulse moves no coordinate


@pytest.mark.slow  # the hip-roll walker's gait search and batched map (minutes)
def test_3d_gait_sensitivity_norms_equal_the_nonlinear_response_and_stride_multipliers(
        stabilised):
    """The reflected step map ``Q = S P`` of the stabilised walker: its Jacobian ``S A_step``
    squared is the stride map's (the gait search's multipliers, per stride, are the squares
    of its own, to 1e-8: both from the variational equations at 1e-12), and for each
    disturbance, sagittal and sideways, the linearised gait sensitivity norm equals the
    nonlinear response to a 1e-5 impulse within 1e-5 relative (B, C, D are central
    differences of step 1e-6 of a map integrated at 1e-12: round-off ~1e-12 / 1e-6 = 1e-6;
    the nonlinear response's error O(e^2) ~ 1e-10 and 1e-12 / 1e-5 = 1e-7)."""
    walker, sm, x = stabilised
    assert isinstance(sm, ReflectedStepMap)
    A = walker.reflect(np.eye(x.size)) @ poincare_map(R.step_walker(sm), x, TIGHT,
                                                      jacobian=True)[2]
    stride = poincare_map(walker, x, TIGHT, jacobian=True)[2]
    assert np.abs(A @ A - stride).max() < 1e-8
    lam = np.sort(np.abs(np.linalg.eigvals(A)))
    assert np.allclose(lam ** 2, np.sort(np.abs(np.linalg.eigvals(stride))), atol=1e-8)
    assert R.disturbances_of(R.step_walker(sm)) == (*R.DISTURBANCES, "lateral_push")
    for d in ("slope", "lateral_push"):
        lin = R.linearise(sm, x, A, d)
        assert lin.C.shape == (4, x.size)  # step time, length, stance angle, step width
        g = lin.gsn()
        assert np.isfinite(g) and g > 0
        assert abs(g - R.gsn_nonlinear(sm, x, d, 1e-5, steps=60)) / g < 1e-5, d


@pytest.mark.slow  # two gait searches and bisections of 20-step walks (minutes)
def test_the_passive_hip_width_walker_survives_no_sideways_push_the_stabilised_one_does(
        stabilised):
    """Kuo 1999: the passive walker with hip width has an unstable lateral mode (a stride
    multiplier of ~100): its gait sensitivity norm is infinite and it survives no sideways
    push over 20 steps (the bracket's lower end 0); the walker with the lateral
    foot-placement law survives a finite one both ways (lower end > 0, bracket closed
    below the 1 m/s cap)."""
    walker, sm, x = stabilised
    for sign in (1.0, -1.0):
        lo, hi = R.largest_by_bisection(sm, x, "lateral_push", 1.0, 0.02, 20, sign)
        assert 0.0 < lo < hi < 1.0, (sign, lo, hi)
    p_walker, p_sm, p_x = _walk("hip_width")
    A = p_walker.reflect(np.eye(p_x.size)) @ poincare_map(R.step_walker(p_sm), p_x, TIGHT,
                                                          jacobian=True)[2]
    assert not R.stable(A) and R.linearise(p_sm, p_x, A, "lateral_push").gsn() == np.inf
    lo, hi = R.largest_by_bisection(p_sm, p_x, "lateral_push", 1.0, 0.02, 20)
    assert lo == 0.0 and hi <= 0.02


#: the stabilised kneed walker's largest sideways pushes at heel strike [m/s], toward the
#: swing leg's side and the stance leg's: walkerlab robustness's brackets (lower end
#: survives 40 steps, upper end falls; configs/kneed_3d_stabilised.yaml, the capability
#: evidence's locking_knees_3d/robustness)
KNEED_SIDEWAYS = {1.0: (0.113037109375, 0.11328125), -1.0: (0.294921875, 0.295166015625)}


@pytest.fixture(scope="module")
def kneed_stabilised():
    return _walk("kneed_3d_stabilised")


@pytest.mark.slow  # the kneed 3D walker's gait search and compiled maps (15 s, fixture)
def test_the_kneed_3d_walker_falls_with_its_hip_at_half_its_leg_length_after_a_big_step_down(
        kneed_stabilised):
    """The robustness study's first step-downs of the stabilised kneed walker (a quarter
    and seven eighths of it of its leg length, the bisection's cap and its first round's
    largest), which once stalled the integrator in a sideways capsize: each walk of 41
    steps ends, dead (a fall, not a timeout), and the 0.25 m step's own step ends in the
    fall guard with the hip half a leg length above the slope (its height along the
    slope's normal)."""
    walker, sm, x = kneed_stabilised
    assert not R.survives(sm, x, "floor_height", np.array([0.25, 0.21875]), 40).any()
    r = sm.step(x[None], None, drop_m=np.array([0.25]))
    assert r.outcome[0] == FALL
    gamma = walker.slope_rad
    hip = np.asarray(R.step_walker(sm).points(r.x_pre[0])["hip"])
    assert hip @ [np.sin(gamma), np.cos(gamma), 0.0] == pytest.approx(0.5, abs=1e-9)


@pytest.mark.slow  # the kneed 3D gait (fixture: 15 s), then four walks of 41 steps (1 s)
def test_the_kneed_3d_walkers_largest_sideways_push_separates_a_walk_from_a_fall(
        kneed_stabilised):
    """The study's largest sideways pushes of the stabilised kneed walker
    (:data:`KNEED_SIDEWAYS`, from its batched step map) walked by the rigid model's own
    simulation (:func:`walkerlab.integrate.rigid.simulate_steps`: both legs' walkers, no
    reflection, another integrator): pushed by each bracket's lower end at the gait's
    section it makes the 41 heel strikes of the study's survival (the pushed step and 40
    more), pushed by its upper end it falls before them (a fall guard, not a timeout or a
    solver failure).  The gait itself is the scene's fixed point."""
    from walkerlab.integrate.rigid import simulate_steps

    walker, sm, x = kneed_stabilised
    w = R.step_walker(sm)
    solver = Solver("DOP853", 1e-12, 1e-12)
    for sign, (lo, hi) in KNEED_SIDEWAYS.items():
        for v, lives in ((lo, True), (hi, False)):
            xp = push.apply_push(w, x, sign * v, axis=push.LATERAL_AXIS)[0]
            run = simulate_steps(walker, xp, 41, solver)
            strikes = sum(s.termination == "heel_strike" for s in run.segments)
            assert (strikes == 41) is lives, (sign, v, strikes, run.termination)
            assert lives or run.termination == "fall", (sign, v, run.termination)


def test_each_3d_kind_either_refuses_robustness_or_has_its_verified_measurement():
    """The capability table's robustness study on the 3D kinds: refused in one line
    (:data:`walkerlab.walker.capability_cells.STAGE_CELLS`) or measured and verified
    (:func:`walkerlab.walker.capability_evidence.stage_evidence`: the 3D straight legs and
    locking knees, the latter's detail with the largest sideways pushes walked in
    :func:`test_the_kneed_3d_walkers_largest_sideways_push_separates_a_walk_from_a_fall`),
    never both; ``walkerlab capabilities`` prints the measurement with its ✓."""
    from walkerlab.walker.capability_cells import STAGE_CELLS
    from walkerlab.walker.capability_evidence import stage_evidence, stage_verified
    from walkerlab.walker.capability_tables import text
    from walkerlab.walker.kinds import KINDS

    in_3d = [k for k, kind in KINDS.items() if kind.in_3d]
    assert in_3d
    for kind in in_3d:
        refused = "robustness" in STAGE_CELLS.get(kind, {})
        assert refused != (stage_evidence(kind, "robustness") is not None), kind
        assert refused or stage_verified(kind, "robustness"), kind
    e = stage_evidence("straight_legs_3d", "robustness")
    assert e["case"] == "configs/hip_width_stabilised.yaml" and e["check"] == "self"
    assert "walkerlab robustness: ✓ 1.2e-06 self: configs/hip_width_stabilised.yaml" in text()
    e = stage_evidence("locking_knees_3d", "robustness")
    assert e["case"] == "configs/kneed_3d_stabilised.yaml" and e["check"] == "self"
    assert "walkerlab robustness: ✓ 4.4e-07 self: configs/kneed_3d_stabilised.yaml" in text()
    assert all(f"{lo:.3f} m/s" in e["detail"] for lo, _hi in KNEED_SIDEWAYS.values())


def test_the_report_shows_the_sideways_push_with_its_units_and_a_planar_walker_none():
    """The report's robustness section of a walker in 3D: the sideways push's norm row in
    s/m, its largest pushes in m/s and N·s (the bracket times the impulse per m/s) and step
    width among the indicators; a planar artifact (no ``push_lateral_*``) shows none of it,
    and an unstable gait's infinite norms are said so."""
    from walkerlab.io.schemas.robustness import LATERAL_SCALARS, SCALARS, RobustnessData
    from walkerlab.report.robustness_section import robustness_section

    dists = ["slope", "push", "lateral_push"]
    units = {"slope": "rad", "push": "m/s", "lateral_push": "m/s"}
    sc = {**dict.fromkeys(SCALARS, 0.1), **dict.fromkeys(LATERAL_SCALARS, 0.1),
          "push_lateral_kg": 11.0, "push_lateral_out_m_per_s/lo": 0.06}
    norms = {d: 2.0 for d in dists}
    d3 = RobustnessData(dists, units, {"absolute": 0.7, "relative": 0.7}, norms, norms,
                        {"absolute": norms, "relative": norms}, sc, [])
    text = "\n".join(robustness_section({"robustness": d3}))
    assert "| sideways push at heel strike [s/m] |" in text
    assert "toward the swing leg's side 0.06" in text and "(0.660 N·s)" in text
    assert "step width" in text and "unstable" not in text
    planar = RobustnessData(dists[:2], units, d3.max_abs_multiplier,
                            {"slope": np.inf, "push": np.inf}, {"slope": np.nan,
                                                                 "push": np.nan},
                            d3.state_norm, dict.fromkeys(SCALARS, 0.0), [])
    text = "\n".join(robustness_section({"robustness": planar}))
    assert "sideways" not in text and "step width" not in text
    assert "the gait is unstable" in text and "unstable gait: no finite norm" in text
