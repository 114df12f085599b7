"""Walkers from parts (issue 22): legs that differ, a hip spring, an upper body on a bisecting
hip mechanism - the generated rigid model against an independent reference
(``tests/independent/parts_reference.py``: the coupling enforced by a multiplier, the impact by
the extended-coordinate method) and the physics invariants.

Tolerances: flows and resets are closed-form algebra on both sides, compared at 1e-11
relative (round-off of two different formulations, a few hundred operations); fixed points
are compared through the reference's own integration (DOP853, rtol = atol = 1e-12 over a
0.5-1.4 s map) at 1e-8.
"""

import numpy as np
import pytest
from independent.parts_reference import Parts, PartsReference

from walkerlab.analysis.gait.poincare import find_fixed_point
from walkerlab.config import load_scene, scene_from_dict
from walkerlab.integrate.rigid import integrate_step, simulate_steps
from walkerlab.integrate.solver import Solver
from walkerlab.models.registry import build_walker
from walkerlab.walker.description import walker_data
from walkerlab.walker.plant import Plant

SOLVER = Solver("DOP853", 1e-12, 1e-12)
GUESS = np.array([-0.2022, 0.1674, -0.60, -0.84])
REFS = {
    "asymmetric_legs": Parts(legs={"A": (5.0, 0.5), "B": (5.5, 0.5)}),
    "hip_spring": Parts(spring=(20.0, 0.0, 0.0)),
    "torso_bhm": Parts(torso=(5.0, 0.2, 0.0, 0.0)),
}

SHIPPED = {"asymmetric_legs": (1.3928103873, 0.3531098),  # a stride: 0.67839 + 0.71442 s
           "hip_spring": (0.5221933351, 0.6320066),
           "torso_bhm": (0.8509063711, 0.4412226)}


def _walker(name):
    sc = load_scene(f"configs/{name}.yaml")
    return build_walker(Plant.from_scene(sc))


def _with(walker_extra: dict, base="torso_bhm"):
    """A scene dict from ``configs/<base>.yaml`` with ``walker`` keys replaced."""
    import yaml

    with open(f"configs/{base}.yaml") as fh:
        d = yaml.safe_load(fh)
    d["walker"].update(walker_extra)
    return scene_from_dict(d, origin=f"{base}.yaml")


@pytest.fixture(scope="module")
def fixed_points():
    out = {}
    for name in REFS:
        w = _walker(name)
        out[name] = (w, find_fixed_point(w, GUESS, SOLVER, fd_check=False))
    return out


@pytest.mark.parametrize("name", list(REFS))
def test_flow_and_reset_match_the_independent_reference(name):
    w, ref = _walker(name), PartsReference(REFS[name])
    rng = np.random.default_rng(7)
    for stance, step_walker in (("B", w), ("A", w.for_stance("leg1"))):
        for _ in range(4):
            x = rng.uniform([-0.4, -0.4, -1.5, -1.5], [0.4, 0.4, 1.5, 1.5])
            ours, theirs = step_walker.phases[0].flow(0.0, x), ref.flow(x, stance)
            assert ours == pytest.approx(theirs, rel=1e-11, abs=1e-11)
            x[0] = -2 * 0.0174 - x[1]  # on the heel-strike surface
            assert step_walker.reset(x) == pytest.approx(ref.reset(x, stance), rel=1e-11,
                                                         abs=1e-12)


@pytest.mark.slow  # in `pytest -m slow`: the quick suite keeps to its CPU budget
def test_off_axis_rigid_upper_body_matches_the_reference():
    # a rigid body with inertia, its centre of mass off the torso's axis, on legs that differ
    # (leg B's point mass 3 cm ahead of its axis)
    body = {"kind": "rigid_body", "name": "trunk", "mass_kg": 4.0, "com_from_hip_m": 0.3,
            "com_off_axis_m": 0.05, "inertia_about_com_kg_m2": 0.2}
    leg = {"length_m": 1.0, "bodies": [{"kind": "point_mass", "name": "mass", "mass_kg": 5.0,
                                        "from_hip_m": 0.5}]}
    heavy = {**leg, "bodies": [{**leg["bodies"][0], "mass_kg": 6.0, "from_hip_m": 0.4,
                                "off_axis_m": 0.03}]}
    sc = _with({"leg": None, "legs": [leg, heavy],
                            "torso": {"bodies": [body]}})
    w = build_walker(Plant.from_scene(sc))
    ref = PartsReference(Parts(legs={"A": (5.0, 0.5), "B": (6.0, 0.4, 0.03)},
                               torso=(4.0, 0.3, 0.05, 0.2)))
    rng = np.random.default_rng(3)
    for stance, step_walker in (("B", w), ("A", w.mirror)):
        x = rng.uniform([-0.4, -0.4, -1.5, -1.5], [0.4, 0.4, 1.5, 1.5])
        assert step_walker.phases[0].flow(0.0, x) == pytest.approx(ref.flow(x, stance),
                                                                   rel=1e-11, abs=1e-11)
        x[0] = -2 * 0.0174 - x[1]
        assert step_walker.reset(x) == pytest.approx(ref.reset(x, stance), rel=1e-11,
                                                     abs=1e-12)
        assert sum(step_walker.energies(x)) == pytest.approx(sum(ref.energy(x, stance)),
                                                             rel=1e-12)


@pytest.mark.parametrize("name", list(REFS))
def test_floating_view_matches_the_reference(name):
    # the compliant-contact model's mass matrix and bias (floating base, no foot pinned)
    from walkerlab.models.hybrid.floating_view import FloatingView

    sc = load_scene(f"configs/{name}.yaml")
    view = FloatingView(walker_data(sc.walker, sc.slope.phi_rad))
    ref = PartsReference(REFS[name])
    rng = np.random.default_rng(11)
    for _ in range(4):
        q = rng.uniform([-0.3, 0.8, -0.4, -0.4], [0.3, 1.0, 0.4, 0.4])
        dq = rng.uniform(-1.5, 1.5, 4)
        M, h = ref.floating(q, dq)
        Mw, hw = view.dynamics(q, dq)
        assert Mw == pytest.approx(M, rel=1e-12, abs=1e-12)
        assert hw == pytest.approx(h, rel=1e-11, abs=1e-11)


def test_legs_that_differ_make_a_stride_map_and_others_one_step():
    assert _walker("asymmetric_legs").steps_per_map == 2
    assert _walker("hip_spring").steps_per_map == 1
    assert _walker("torso_bhm").steps_per_map == 1
    # a rest angle breaks the mirror symmetry of equal legs; a torso-to-leg spring too
    spring = {"between": ["leg1", "leg2"], "stiffness_n_m_per_rad": 5.0, "rest_angle_rad": 0.1}
    sc = _with({"springs": [spring]})
    assert build_walker(Plant.from_scene(sc)).steps_per_map == 2
    spring = {"between": ["torso", "leg1"], "stiffness_n_m_per_rad": 5.0}
    sc1 = _with({"springs": [spring]})
    assert build_walker(Plant.from_scene(sc1)).steps_per_map == 2


def test_leg_shorthand_expands_to_the_same_walker_as_an_equal_pair():
    sc = load_scene("configs/torso_bhm.yaml")
    leg = sc.walker.leg.model_dump()
    pair = _with({"leg": None, "legs": [leg, leg]})
    a = walker_data(sc.walker, sc.slope.phi_rad)
    b = walker_data(pair.walker, pair.slope.phi_rad)
    assert (a.structure, a.params, a.mirror_params) == (b.structure, b.params, None)


@pytest.mark.parametrize("name", list(REFS))
def test_fixed_point_maps_to_itself_under_the_reference(name, fixed_points):
    w, fp = fixed_points[name]
    ref = PartsReference(REFS[name])
    x = fp.x.copy()
    T = 0.0
    for stance in ("B", "A")[:w.steps_per_map]:
        t, _, x, _ = ref.step(x, stance)
        T += t
    assert np.max(np.abs(x - fp.x)) < 1e-8
    assert T == pytest.approx(fp.period_s, abs=1e-9)
    assert fp.stable and fp.residual < 1e-10
    # the shipped scenes' numbers (closing note of issue 22): map period [s], max |multiplier|
    period, mult = SHIPPED[name]
    assert fp.period_s == pytest.approx(period, abs=1e-9)
    assert np.max(np.abs(fp.multipliers_variational)) == pytest.approx(mult, abs=1e-6)


def test_stride_steps_differ_and_compose(fixed_points):
    w, fp = fixed_points["asymmetric_legs"]
    assert len(fp.step_periods_s) == 2 and sum(fp.step_periods_s) == pytest.approx(fp.period_s)
    # the heavier leg B swings slower: its step lasts longer (measured 0.678 vs 0.714 s)
    assert fp.step_periods_s[1] - fp.step_periods_s[0] > 0.02
    # the stride's DP is the product of the steps' (variational with saltation) DPs
    s1 = integrate_step(w, fp.x, SOLVER, variational=True, stance_leg="leg2")
    s2 = integrate_step(w.mirror, s1.x_next, SOLVER, variational=True, stance_leg="leg1")
    assert s2.monodromy @ s1.monodromy == pytest.approx(fp.jacobian_variational, abs=1e-12)


def test_energy_with_spring_potential_is_conserved_in_swing(fixed_points):
    w, fp = fixed_points["hip_spring"]
    seg = integrate_step(w, fp.x, SOLVER)
    X = seg.sample(np.linspace(seg.t_start, seg.t_end, 80))
    E = np.sum(w.energies(X), axis=0)
    ref = PartsReference(REFS["hip_spring"])
    assert sum(ref.energy(fp.x, "B")) == pytest.approx(E[0], rel=1e-13)  # spring included
    # ~150 J; DOP853 at 1e-12 over a 0.52 s step: drift a few 1e-12 relative
    assert np.ptp(E) < 1e-10 * abs(E[0])
    # without the spring's potential the total is not conserved (the test can fail)
    nospring = PartsReference(Parts())
    E0 = np.array([sum(nospring.energy(x, "B")) for x in X.T])
    assert np.ptp(E0) > 1e-3


def test_damper_dissipates_exactly_c_times_relative_rate_squared():
    spring = {"between": ["leg1", "leg2"], "stiffness_n_m_per_rad": 20.0,
              "damping_n_m_s_per_rad": 0.5}
    sc = _with({"springs": [spring]}, base="hip_spring")
    w = build_walker(Plant.from_scene(sc))
    x0 = np.array([-0.18, 0.15, -0.7, -0.9])
    seg = integrate_step(w, x0, SOLVER)
    t = np.linspace(seg.t_start, seg.t_end, 4001)
    X = seg.sample(t)
    E = np.sum(w.energies(X), axis=0)
    rate = X[3] - X[2]  # d(delta)/dt between the legs
    from scipy.integrate import simpson

    lost = 0.5 * simpson(rate ** 2, x=t)
    assert lost > 1e-3
    assert E[0] - E[-1] == pytest.approx(lost, rel=1e-7)  # Simpson's rule, 4000 intervals


def test_bisecting_coupling_holds_along_a_run(fixed_points):
    w, fp = fixed_points["torso_bhm"]
    traj = simulate_steps(w, fp.x, 4, SOLVER)
    worst = 0.0
    for seg in traj.segments:
        X = seg.sample(np.linspace(seg.t_start, seg.t_end, 50))
        P = w.points(X)
        hip, torso = P["hip"], P["torso_mass"]
        t_angle = np.arctan2(-(torso[0] - hip[0]), torso[1] - hip[1])  # from upward vertical
        legs = [np.arctan2(P[f][0] - hip[0], -(P[f][1] - hip[1]))
                for f in ("stance_foot", "swing_foot")]
        worst = max(worst, float(np.max(np.abs(t_angle - 0.5 * (legs[0] + legs[1])))))
    assert len(traj.segments) == 4 and traj.termination == "heel_strike"
    assert worst < 1e-10  # geometry of the generated points (round-off ~1e-16)
    # leaning back (behind the hip, -x) when both feet are ahead (+x) of the hip
    P = w.points(np.array([0.2, 0.2, 0.0, 0.0]))
    assert P["swing_foot"][0] > P["hip"][0] and P["torso_mass"][0] < P["hip"][0]


@pytest.mark.parametrize("name", list(REFS))
def test_heel_strike_conserves_angular_momentum_about_the_impact_point(name, fixed_points):
    w, fp = fixed_points[name]
    ref = PartsReference(REFS[name])
    seg = integrate_step(w, fp.x, SOLVER)
    xm = seg.x_end
    xp = w.reset(xm)
    foot = ref.swing_foot(xm, "B")
    before = ref.angular_momentum(xm, "B", foot)
    # after: the new stance leg (A) at the origin; the same point, the walker shifted by foot
    after = ref.angular_momentum(xp, "A", np.zeros(2))
    assert after == pytest.approx(before, rel=1e-12)


def test_one_line_errors_for_the_new_parts():
    from walkerlab.config import SceneError

    bad = [({"legs": [{"length_m": 1.0, "bodies": [{"kind": "point_mass", "name": "m",
                                                    "mass_kg": 5, "from_hip_m": 0.5}]}]},
            "walker.legs"),
           ({"springs": [{"between": ["leg1", "leg1"], "stiffness_n_m_per_rad": 1.0}]},
            "springs"),
           ({"torso": {"bodies": []}}, "walker.torso.bodies"),
           ({"springs": [{"between": ["torso", "leg1"], "stiffness_n_m_per_rad": 1.0}],
             "torso": None}, "needs a 'torso'")]
    for extra, field in bad:
        with pytest.raises(SceneError) as e:
            _with(extra)
        assert field in str(e.value) and "Traceback" not in str(e.value)


def test_exported_legs_that_differ_match_pinocchio_mujoco_and_the_reference(tmp_path):
    # URDF / MJCF of the asymmetric walker: Pinocchio's CRBA/RNEA and MuJoCo's qM/qfrc_bias
    # against the independent reference (MuJoCo's inertia floor 1e-12 kg m^2 bounds M's gap)
    from tests.test_export import MuJoCo, Pinocchio
    from walkerlab.stages import export as export_stage

    sc = load_scene("configs/asymmetric_legs.yaml")
    names = ("hip_x", "hip_y", "leg1_angle", "leg2_angle")
    libs = {"pinocchio": Pinocchio(export_stage.run(sc, tmp_path, "urdf"), names, 9.81),
            "mujoco": MuJoCo(export_stage.run(sc, tmp_path, "mjcf"), names)}
    ref = PartsReference(REFS["asymmetric_legs"])
    rng = np.random.default_rng(5)
    for _ in range(3):
        q = rng.uniform([-0.3, 0.8, -0.4, -0.4], [0.3, 1.0, 0.4, 0.4])
        dq = rng.uniform(-1.5, 1.5, 4)
        Mr, hr = ref.floating(q, dq)
        for lib in libs.values():
            M, h = lib(q, dq)
            assert np.abs(M - Mr).max() <= 1e-10 * np.abs(Mr).max()
            assert np.abs(h - hr).max() <= 1e-10 * np.abs(hr).max()


@pytest.mark.parametrize("name, element", [("hip_spring", '<fixed name="spring0"'),
                                           ("torso_bhm", '<tendon name="bisecting_hip"')])
def test_export_writes_the_parts(name, element, tmp_path):
    # springs as MuJoCo tendons, the bisecting hip as a tendon equality (checked against
    # MuJoCo's energy, passive forces and a run in tests/test_export.py)
    from typer.testing import CliRunner

    from walkerlab.cli import app

    r = CliRunner().invoke(app, ["export", f"configs/{name}.yaml", "--format", "mjcf",
                                 "--runs-dir", str(tmp_path)])
    assert r.exit_code == 0, r.output
    assert element in (tmp_path / name / "walker.xml").read_text()


def test_table3_gives_each_legs_step_where_legs_differ(fixed_points):
    from walkerlab.analysis.gait.metrics import sample_trajectory, step_table
    from walkerlab.comparison.tables import gait_metrics

    w, fp = fixed_points["asymmetric_legs"]
    traj = simulate_steps(w, fp.x, 4, SOLVER)
    m = gait_metrics(sample_trajectory(traj, 200.0))
    # leg1 (left) swings first: its steps are the stride's first (measured 0.3720 / 0.3634 m)
    assert m["step_length_left_m"] == pytest.approx(fp.step_lengths_m[0], abs=1e-9)
    assert m["step_length_right_m"] == pytest.approx(fp.step_lengths_m[1], abs=1e-9)
    assert m["t_left_s"] == pytest.approx(fp.step_periods_s[0], abs=1e-9)
    # impact losses with each step's own walker: every step loses energy
    assert np.all(step_table(traj)["impact_energy_loss"] > 0)


def test_basin_iterates_strides_where_legs_differ(fixed_points):
    from walkerlab.config import BasinSettings
    from walkerlab.studies.basin import CODE, classify_cell

    w, fp = fixed_points["asymmetric_legs"]
    st = BasinSettings()
    near = fp.x + np.array([0.0, 0.0, 0.01, 0.0])
    # iterated with one walker for every step it would go to another gait (leg1's numbers
    # swinging every step), never within 1e-4 of the stride's fixed point
    code, steps, period = classify_cell(w, near, fp.x, SOLVER, st)
    assert code == CODE["converged"] and period == 1 and steps % 2 == 0


def test_gait_search_without_a_guess_finds_the_stride_fixed_point(fixed_points):
    from walkerlab.analysis.gait.search import find_gaits

    w, fp = fixed_points["asymmetric_legs"]
    search = find_gaits(w, SOLVER, None, other_gait=False, fd_check=False)
    found = search.gaits[search.selected].result
    assert np.max(np.abs(found.x - fp.x)) < 1e-9 and found.stable


@pytest.mark.slow
def test_contact_view_walks_the_hip_spring_walker_near_its_rigid_gait(fixed_points):
    # the compliant-contact walker generated from the same description (spring in the
    # floating equations): 2 strides from the rigid fixed point, step periods within 2 %
    # of the rigid 0.5222 s (measured: 0.5245, 0.5281, 0.5290, 0.5284 s)
    from walkerlab.analysis.contact.sim import simulate_from
    from walkerlab.models.contact.scene import contact_setup

    w, fp = fixed_points["hip_spring"]
    sc = load_scene("configs/hip_spring.yaml")
    _cw, res, _x0, _d = simulate_from(contact_setup(sc,
            plant=Plant.from_scene(sc)), fp.x, fp.period_s, strides=2)
    periods = np.diff(np.concatenate([[0.0], res.heel_strike_times]))
    assert len(periods) >= 3
    assert np.all(np.abs(periods / fp.period_s - 1) < 0.02)
