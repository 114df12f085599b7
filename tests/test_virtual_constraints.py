"""Virtual constraints on RABBIT (configs/rabbit_hzd.yaml): impact invariance of the Bezier
outputs, the restricted Poincare map against the full-order closed loop, the decoupling
matrix against a finite difference of the flow the walker integrates, and one-line
refusals of bad input.

References that share no code with the controller: the outputs recomputed here from the
generated link angles and a de Casteljau evaluation of the Bezier polynomials (the
controller sums the Bernstein basis), their time derivatives by the complex step and a
central difference along the walker's own flow; the full-order Poincare map integrated
by the scene's solver (LSODA) and its variational equations.
"""

from __future__ import annotations

import copy
from pathlib import Path

import numpy as np
import pytest
import yaml

from walkerlab.analysis.gait.poincare import poincare_map
from walkerlab.analysis.gait.zero_dynamics import zero_dynamics
from walkerlab.config import SceneError, scene_from_dict
from walkerlab.integrate.solver import Solver
from walkerlab.models.hybrid.virtual_constraints import bezier
from walkerlab.models.registry import build_walker
from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]
SCENE = yaml.safe_load((ROOT / "configs" / "rabbit_hzd.yaml").read_text())


def scene_with(**vc):
    """configs/rabbit_hzd.yaml with ``virtual_constraints`` fields replaced."""
    cfg = copy.deepcopy(SCENE)
    cfg["walker"]["actuation"]["virtual_constraints"].update(vc)
    return scene_from_dict(cfg)


@pytest.fixture(scope="module")
def walker():
    sc = scene_from_dict(copy.deepcopy(SCENE))
    return build_walker(Plant.from_scene(sc))


@pytest.fixture(scope="module")
def hzd(walker):
    return zero_dynamics(walker.actuators.controller)


def de_casteljau(c, s):
    """Bezier polynomial of the coefficients ``c`` (M + 1,) at ``s`` (complex-safe)."""
    b = list(c)
    while len(b) > 1:
        b = [(1 - s) * b[i] + s * b[i + 1] for i in range(len(b) - 1)]
    return b[0]


def outputs_ref(walker, x):
    """``y`` (4,) recomputed from the generated link angles: joint angles (hips thigh -
    torso, knees shank - thigh) minus the Bezier polynomials of ``s(theta)``, ``theta`` the
    virtual stance leg's angle (or the hip's horizontal position, from the generated
    points)."""
    ctrl = walker.actuators.controller
    d = ctrl.design
    la = walker.leg_angles(x)
    h0 = [la["stance_thigh_angle"] - la["torso_angle"],
          la["swing_thigh_angle"] - la["torso_angle"],
          la["stance_shank_angle"] - la["stance_thigh_angle"],
          la["swing_shank_angle"] - la["swing_thigh_angle"]]
    if ctrl.spec.phase.point == "hip":  # level ground: the hip's x from the stance foot
        theta = walker.points(x)["hip"][0]
    else:
        theta = la["stance_angle"]
    s = (theta - d.theta_plus) / (d.theta_minus - d.theta_plus)
    return np.array([h - de_casteljau(c, s) for h, c in zip(h0, d.alpha)])


def rate_ref(walker, x):
    """``y'`` (4,): the complex step of :func:`outputs_ref` along ``dq``."""
    n = len(x) // 2
    xc = np.asarray(x, complex).copy()
    xc[:n] += 1e-30j * np.asarray(x[n:])
    return np.imag(outputs_ref(walker, xc)) / 1e-30


def accel_ref(walker, x, f, h=1e-5):
    """``y''`` (4,) along the state derivative ``f`` (2n,): central difference of
    :func:`rate_ref`."""
    return (rate_ref(walker, x + h * f) - rate_ref(walker, x - h * f)) / (2 * h)


def test_bezier_derivatives_match_de_casteljau_and_scipy():
    """hd of the controller's Bernstein sums = de Casteljau's; hd', hd'' = scipy's
    Bernstein polynomial (:class:`scipy.interpolate.BPoly`) derivatives."""
    from scipy.interpolate import BPoly

    rng = np.random.default_rng(3)
    c = rng.normal(size=(3, 7))
    for s in (0.0, 0.3, 0.77, 1.0):
        h, h1, h2 = bezier(c, s)
        np.testing.assert_allclose(h, [de_casteljau(ci, s) for ci in c], atol=1e-14)
        for i, ci in enumerate(c):
            bp = BPoly(ci[:, None], [0.0, 1.0])
            assert abs(h1[i] - bp.derivative(1)(s)) < 1e-12
            assert abs(h2[i] - bp.derivative(2)(s)) < 1e-11


def test_invariant_coefficients_zero_outputs_after_impact(walker, hzd):
    """invariant: true -> a pre-impact state on the surface (y = y' = 0 at theta-, any
    phase rate) is mapped by the heel strike onto the surface: |y+|, |y'+| <= 1e-12."""
    ctrl = walker.actuators.controller
    d = ctrl.design
    dth = d.theta_minus - d.theta_plus
    qp = ctrl.tangent(d.q_minus, bezier(d.alpha, 1.0)[1], dth)
    for rate in (-0.7, -1.2726722264, -2.0):
        x_minus = np.concatenate([d.q_minus, qp * rate])
        assert np.max(np.abs(outputs_ref(walker, x_minus))) < 1e-13
        assert np.max(np.abs(rate_ref(walker, x_minus))) < 1e-12
        x_plus = walker.reset(x_minus)
        assert np.max(np.abs(outputs_ref(walker, x_plus))) < 1e-12
        assert np.max(np.abs(rate_ref(walker, x_plus))) < 1e-12
    assert d.residual_position < 1e-14 and d.residual_rate < 1e-13
    # the scene's placeholders are not invariant: the residual says by how much
    assert np.max(np.abs(d.given[:, :2] - d.alpha[:, :2])) > 0.1


def test_non_invariant_coefficients_report_their_residual():
    """invariant: false keeps the given c_0, c_1: the outputs jump at the heel strike by
    the reported residual."""
    sc = scene_with(invariant=False)
    w = build_walker(Plant.from_scene(sc))
    d = w.actuators.controller.design
    np.testing.assert_array_equal(d.alpha, d.given)
    dth = d.theta_minus - d.theta_plus
    qp = w.actuators.controller.tangent(d.q_minus, bezier(d.alpha, 1.0)[1], dth)
    x_plus = w.reset(np.concatenate([d.q_minus, -qp]))
    # the fit's c_0 lie within a milliradian of the invariant ones, its c_1 do not
    assert d.residual_position > 5e-4 and d.residual_rate > 0.5
    np.testing.assert_allclose(np.max(np.abs(outputs_ref(w, x_plus))), d.residual_position,
                               rtol=1e-9)
    # y'+ per unit of the phase rate: the rate residual
    per_phase = rate_ref(w, x_plus) / abs(w.leg_angles(x_plus)["stance_rate"])
    np.testing.assert_allclose(np.max(np.abs(per_phase)), d.residual_rate, rtol=1e-9)


@pytest.fixture(scope="module")
def hip_phase_walker():
    """The outputs on the hip's horizontal position: a phase variable nonlinear in the
    angles (its second derivative enters L_f^2 h)."""
    sc = scene_with(phase={"point": "hip"})
    return build_walker(Plant.from_scene(sc))


@pytest.mark.parametrize("which", ["stance_leg", "hip"])
def test_decoupling_matrix_is_the_flows_torque_derivative(which, walker, hip_phase_walker):
    """L_g L_f h and L_f^2 h of the controller = y'' of the walker's own flow (the
    generated passive flow plus M^-1 B u, B from the generic actuators' unit rates) by a
    central difference of the complex-step y' (test-side outputs), at states off the
    surface; and along the closed-loop flow y'' = -kp y - kd y'."""
    walker = walker if which == "stance_leg" else hip_phase_walker
    ctrl = walker.actuators.controller
    acts = walker.actuators
    fns = ctrl.fns
    rng = np.random.default_rng(5)
    x0 = walker.actuators.controller.design.q_plus
    n = 5
    from walkerlab.walker.joints import joint_columns

    # B from the generated link angles' unit rates (not the controller's symbolic pieces)
    B = joint_columns(acts.link_angles, n, acts.links)
    np.testing.assert_array_equal(B, ctrl.B)
    for _ in range(3):
        x = np.concatenate([x0 + rng.normal(scale=0.05, size=n), rng.normal(size=n)])
        M = fns["matrices"](x)[0]

        def f(u, x=x, M=M):
            out = np.array(fns["flow"](0.0, x), float)
            out[n:] += np.linalg.solve(M, B @ u)
            return out
        y0 = accel_ref(walker, x, f(np.zeros(4)))
        A = np.column_stack([accel_ref(walker, x, f(e)) - y0 for e in np.eye(4)])
        _y, _dy, A_ctrl, Lf2, _mb = ctrl.terms(x)
        np.testing.assert_allclose(A_ctrl, A, rtol=0, atol=1e-7 * np.abs(A).max())
        np.testing.assert_allclose(Lf2, y0, rtol=0, atol=1e-7 * max(1, np.abs(y0).max()))
        # the closed loop the integrator runs: the phase's flow
        fc = walker.phases[0].flow(0.0, x)
        y, dy = outputs_ref(walker, x), rate_ref(walker, x)
        want = -ctrl.kp * y - ctrl.kd * dy
        if ctrl.limit is None or np.all(np.abs(ctrl.torques(x)) < ctrl.limit):
            np.testing.assert_allclose(accel_ref(walker, x, fc), want, rtol=0,
                                       atol=1e-7 * np.abs(want).max())


def test_restricted_map_fixed_point_is_the_full_order_one(walker, hzd):
    """The zero dynamics' periodic orbit (by quadrature) is a fixed point of the full-order
    Poincare map (LSODA, rtol 1e-11): P(x*) = x* and the step period and the phase rate at
    impact agree to 1e-8."""
    assert hzd.exists and hzd.stable
    steps = []
    x1, period, _nfev = poincare_map(walker, hzd.x_plus, Solver.from_settings(
        scene_from_dict(copy.deepcopy(SCENE)).solver), steps=steps)
    np.testing.assert_allclose(x1, hzd.x_plus, rtol=0, atol=1e-8)
    assert abs(period - hzd.step_period_s) < 1e-8
    x_minus = steps[0].x_end
    theta_rate = walker.leg_angles(x_minus)["stance_rate"]
    assert abs(theta_rate - hzd.phase_rate_minus) < 1e-8
    assert np.max(np.abs(walker.actuators.controller.outputs(x_minus)[0])) < 1e-8
    # the existence condition as the issue states it
    d2 = hzd.delta2
    assert d2 / (1 - d2) * hzd.v_minus + hzd.v_max < 0
    assert hzd.kinetic_invariance < 1e-12


def test_delta2_is_a_full_order_floquet_multiplier(walker, hzd):
    """The variational equations of the full-order closed loop at the fixed point: one
    multiplier is delta^2 (to 1e-6), the others the feedback's (kd = 100/s over a 0.56 s
    step: far below 1e-6)."""
    sol = Solver(method="LSODA", rtol=1e-10, atol=1e-10)
    _x, _T, DP, _n = poincare_map(walker, hzd.x_plus, sol, jacobian=True)
    mult = np.linalg.eigvals(DP)
    j = np.argmin(np.abs(mult - hzd.delta2))
    assert abs(mult[j] - hzd.delta2) < 1e-6
    assert np.max(np.abs(np.delete(mult, j))) < 1e-6


# ---------------------------------------------------------------------- refusals
def one_line(exc) -> str:
    msg = str(exc.value)
    assert "\n" not in msg and "Traceback" not in msg
    return msg


def test_too_few_actuators_refused():
    with pytest.raises(ValueError) as e:
        sc = scene_with(joints=["stance_hip", "swing_hip"])
        build_walker(Plant.from_scene(sc))
    msg = one_line(e)
    assert "virtual_constraints.outputs" in msg and "2 actuators" in msg


def test_phase_not_monotone_refused():
    """The torso's angle keeps its value across the heel strike: theta+ = theta-."""
    with pytest.raises(ValueError) as e:
        sc = scene_with(phase={"link": "torso"})
        build_walker(Plant.from_scene(sc))
    msg = one_line(e)
    assert "virtual_constraints.phase" in msg and "not monotone" in msg


def test_singular_decoupling_matrix_refused_naming_outputs():
    """Actuators at both hips and between the thighs (dependent columns of B) cannot drive
    four outputs: the decoupling matrix is singular."""
    with pytest.raises(ValueError) as e:
        sc = scene_with(joints=["stance_hip", "swing_hip", "stance_knee", "hip"])
        build_walker(Plant.from_scene(sc))
    msg = one_line(e)
    assert "virtual_constraints.outputs" in msg and "decoupling matrix" in msg
    assert "joint:" in msg


@pytest.mark.parametrize("change, key", [
    (lambda o: o[1]["bezier_rad"].append(0.1), "outputs.1.bezier_rad"),
    (lambda o: o[0].update(bezier_rad=o[0]["bezier_rad"][:3]), "outputs.0.bezier_rad"),
])
def test_bezier_length_refused(change, key):
    cfg = copy.deepcopy(SCENE)
    change(cfg["walker"]["actuation"]["virtual_constraints"]["outputs"])
    with pytest.raises(SceneError) as e:
        scene_from_dict(cfg)
    assert key in str(e.value) and len(str(e.value).splitlines()) == 1


def test_unknown_link_refused():
    outs = copy.deepcopy(SCENE["walker"]["actuation"]["virtual_constraints"]["outputs"])
    outs[0] = {"link": "stance_leg", "bezier_rad": outs[0]["bezier_rad"]}
    cfg = copy.deepcopy(SCENE)
    cfg["walker"]["actuation"]["virtual_constraints"]["phase"] = {"coordinates": {"foo": 1.0}}
    with pytest.raises(ValueError) as e:
        sc = scene_from_dict(cfg)
        build_walker(Plant.from_scene(sc))
    assert "phase.coordinates.foo" in one_line(e)


def test_torques_beside_virtual_constraints_refused():
    cfg = copy.deepcopy(SCENE)
    cfg["walker"]["actuation"]["torques"] = [{"joint": "stance_hip",
                                               "law": {"constant_n_m": 1.0}}]
    with pytest.raises(SceneError) as e:
        scene_from_dict(cfg)
    assert "torques" in str(e.value) and len(str(e.value).splitlines()) == 1


def test_views_without_the_controller_refuse_it(tmp_path):
    """The Adams and OpenSim exports do not carry the controller yet: each
    refuses it in one line naming the field (the capability table's cell); the contact
    model and the MJCF take it (tests/test_virtual_constraint_views.py walks them), and
    optimize designs it (tests/test_optimize_virtual_constraints.py), the gym runs it as its
    baseline policy (tests/test_gym.py)."""
    from walkerlab.export.scene import check_exportable
    from walkerlab.models.contact.scene import contact_setup
    from walkerlab.walker.kinds import KINDS, KindRefused
    from walkerlab.walker.walker_trees import walker_tree

    scene = scene_from_dict(copy.deepcopy(SCENE))
    assert contact_setup(scene, plant=Plant.from_scene(scene)).actuators.controller is not None
    tree = walker_tree(Plant.from_scene(scene).structure)[0]
    check_exportable(scene, KINDS["free_joints"], "mjcf", tree=tree)
    for fmt in ("adm", "osim"):
        with pytest.raises(KindRefused) as e:
            check_exportable(scene, KINDS["free_joints"], fmt, tree=tree)
        assert one_line(e).startswith("walker.actuation.virtual_constraints: ")
    from walkerlab.stages import export

    with pytest.raises(KindRefused) as e:  # the Adams writer's own path asks the table too
        export.run(scene, tmp_path, "adm")
    assert one_line(e).startswith("walker.actuation.virtual_constraints: ")
    for view in ("adams", "osim"):
        assert not KINDS["free_joints"].supports("virtual_constraints", view)
        assert not KINDS["hinged_torso"].supports("virtual_constraints", view)
    # optimize: design by collocation; gym: the scene's controller as its baseline policy
    for view in ("rigid", "contact", "mjcf", "optimize", "gym"):
        assert KINDS["free_joints"].supports("virtual_constraints", view)
    assert KINDS["hinged_torso"].supports("virtual_constraints", "optimize")
    assert not KINDS["straight_legs"].supports("virtual_constraints", "optimize")
    assert not KINDS["locking_knees"].supports("virtual_constraints", "rigid")


def test_sweep_and_continuation_name_a_bezier_coefficient():
    """``...outputs.1.bezier_rad.5`` names one coefficient (its unit rad); a point sets it
    alone; an index past the list or a field below a number is refused in one line."""
    from walkerlab.studies.params import (
        SweepError,
        apply_point,
        axis_unit,
        check_axes,
        parse_param,
    )

    scene = scene_from_dict(copy.deepcopy(SCENE))
    path = "walker.actuation.virtual_constraints.outputs.1.bezier_rad.5"
    axis = parse_param(f"{path}=0.40,0.44")
    check_axes(scene, [axis])
    assert axis_unit(scene, axis) == "rad"
    sc = apply_point(scene.model_dump(mode="json"), [path], (0.44,))
    got = sc.walker.actuation.virtual_constraints.outputs[1].bezier_rad
    want = list(scene.walker.actuation.virtual_constraints.outputs[1].bezier_rad)
    want[5] = 0.44
    assert got == want
    gain = parse_param("walker.actuation.virtual_constraints.feedback.kd_per_s=80,120")
    check_axes(scene, [gain])
    assert axis_unit(scene, gain) == "1/s"
    for bad in (f"{path[:-1]}9=0.1", f"{path}.x=0.1"):
        with pytest.raises(SweepError) as e:
            check_axes(scene, [parse_param(bad)])
        assert "\n" not in str(e.value)


@pytest.mark.slow
def test_fixedpoint_stores_and_prints_the_zero_dynamics(tmp_path):
    """``walkerlab fixedpoint configs/rabbit_hzd.yaml``: fixedpoint.h5's zero_dynamics/ with
    units, the restricted map beside the full-order fixed point (delta^2 a multiplier to
    1e-6; the period and the phase rate at impact to 1e-8), printed side by side."""
    from tests.cli_run import run_cli
    from walkerlab.io.schemas.fixedpoint import load_fixedpoint

    code, err, out = run_cli("fixedpoint", ROOT / "configs" / "rabbit_hzd.yaml",
                             "--runs-dir", tmp_path)
    assert code == 0, err
    fp = load_fixedpoint(tmp_path / "rabbit_hzd" / "fixedpoint.h5")
    z = fp.zero_dynamics
    assert z["exists"] and z["stable"] and not z["saturates"]
    fo = z["full_order"]
    assert abs(fo["delta2_multiplier"] - z["delta2"]) < 1e-6
    assert abs(fo["step_period_s"] - z["step_period_s"]) < 1e-8
    assert abs(fo["phase_rate_minus"] - z["phase_rate_minus"]) < 1e-8
    assert fo["other_multiplier"] < 1e-6
    assert fo["output_plus"] < 1e-8 and fo["output_rate_plus"] < 1e-8
    assert z["phase_unit"] == "rad" and z["timing_delta2_s"] > 0
    assert "delta^2" in out and "full-order multiplier" in out and "existence" in out


def test_compass_gait_under_one_virtual_constraint():
    """The controller on another walker: straight legs with one hip actuator
    (configs/paper_rods.yaml on its slope), the swing leg's absolute angle a cubic Bezier
    polynomial of the stance leg's.  The restricted map's orbit (delta^2 = 0.8577, by
    quadrature with gravity along the slope) is the full-order fixed point: P(x*) = x*,
    the period to 1e-8, and delta^2 its variational Floquet multiplier to 1e-6."""
    cfg = yaml.safe_load((ROOT / "configs" / "paper_rods.yaml").read_text())
    cfg["walker"]["actuation"] = {"virtual_constraints": {
        "phase": {"link": "stance_leg"},
        "outputs": [{"link": "swing_leg", "bezier_rad": [-0.15, -0.15, 0.2, 0.15]}],
        "feedback": {"kind": "input_output_linearization", "kp_per_s2": 2500,
                     "kd_per_s": 100}}}
    scene = scene_from_dict(cfg)
    w = build_walker(Plant.from_scene(scene))
    ctrl = w.actuators.controller
    assert ctrl.joints == ["hip"]
    z = zero_dynamics(ctrl)
    assert z.exists and z.stable and z.kinetic_invariance < 1e-12
    x1, period, DP, _n = poincare_map(w, z.x_plus, Solver(method="LSODA", rtol=1e-11,
                                                           atol=1e-11), jacobian=True)
    np.testing.assert_allclose(x1, z.x_plus, rtol=0, atol=1e-8)
    assert abs(period - z.step_period_s) < 1e-8
    mult = np.linalg.eigvals(DP)
    j = np.argmin(np.abs(mult - z.delta2))
    assert abs(mult[j] - z.delta2) < 1e-6 and np.max(np.abs(np.delete(mult, j))) < 1e-6


@pytest.mark.parametrize("name, words", [("round_feet", "needs point feet"),
                                         ("kuo2002", "carry mass")])
def test_walkers_the_quadrature_does_not_hold_for_refused(name, words):
    """Arc feet roll (the stance foot is not a pin: sigma' != -b^T G) and massless legs
    have no inertia to drive: one line naming the key."""
    cfg = yaml.safe_load((ROOT / "configs" / f"{name}.yaml").read_text())
    cfg["walker"]["actuation"] = {"virtual_constraints": {
        "phase": {"link": "stance_leg"},
        "outputs": [{"link": "swing_leg", "bezier_rad": [-0.15, -0.15, 0.2, 0.15]}],
        "feedback": {"kind": "input_output_linearization", "kp_per_s2": 400,
                     "kd_per_s": 40}}}
    with pytest.raises(ValueError) as e:
        sc = scene_from_dict(cfg)
        build_walker(Plant.from_scene(sc))
    msg = one_line(e)
    assert msg.startswith("walker.actuation.virtual_constraints: ") and words in msg


@pytest.mark.parametrize("limit", [None, 40.0])
def test_the_compiled_law_equals_the_numpy_law(walker, limit):
    """The law runs compiled by numba (issue 65: the virtual-constraint feedback compiled
    like the flow); at states off the surface its torques and M^-1 B u equal the numpy
    law's (the same expressions printed apart) to 1e-12 of their size, real and complex
    (the complex step along a random direction: its derivative to 1e-9, the complex step
    being exact to round-off), and a torque limit saturates both alike.  The closed loop's
    y'' = -kp y - kd y' against test-side outputs is checked above on the compiled path."""
    ctrl = walker.actuators.controller
    assert ctrl._compiled_law() is not None
    saved = ctrl.limit
    ctrl.limit = limit
    try:
        rng = np.random.default_rng(11)
        d = ctrl.design
        saturated = 0
        for _ in range(40):
            q = d.q_plus + rng.uniform() * (d.q_minus - d.q_plus) + rng.normal(scale=0.05,
                                                                              size=ctrl.n)
            x = np.concatenate([q, rng.normal(scale=2.0, size=ctrl.n)])
            u, a = ctrl.acceleration(x)
            u0, a0 = ctrl.acceleration_numpy(x)
            assert isinstance(u, np.ndarray) and u.dtype == float
            np.testing.assert_allclose(u, u0, rtol=0, atol=1e-12 * (1 + np.abs(u0).max()))
            np.testing.assert_allclose(a, a0, rtol=0, atol=1e-12 * (1 + np.abs(a0).max()))
            xc = x + 1e-30j * rng.normal(size=x.size)
            uc, ac = ctrl.acceleration(xc)
            uc0, ac0 = ctrl.acceleration_numpy(xc)
            assert uc.dtype == complex
            np.testing.assert_allclose(np.real(uc), u0, rtol=0,
                                       atol=1e-12 * (1 + np.abs(u0).max()))
            for c, c0 in ((uc, uc0), (ac, ac0)):
                g, g0 = np.imag(c) / 1e-30, np.imag(c0) / 1e-30
                np.testing.assert_allclose(g, g0, rtol=0, atol=1e-9 * (1 + np.abs(g0).max()))
            saturated += limit is not None and np.any(np.abs(u) == limit)
        assert (saturated > 0) == (limit is not None)
    finally:
        ctrl.limit = saved
