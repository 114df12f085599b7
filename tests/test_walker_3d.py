"""The straight-legged walker in three dimensions (``model: compass_gait``, ``space: 3d``;
Kuo 1999) against references that share no code with its generated equations: the planar
walker of the same scene (the planar embedding), and a model written here from Newton's law
for its three point masses (the rotation matrices' derivatives by hand, d'Alembert's
principle projected on the coordinates) with its impact solved with the impulse at the new
foot as an unknown (a Lagrange multiplier)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yaml
from scipy.integrate import solve_ivp
from scipy.spatial.transform import Rotation

from tests.independent.mirror_stride import stride_against
from tests.independent.parts_3d_newton import PartsReference
from walkerlab.analysis.gait.poincare import find_fixed_point
from walkerlab.config.schema import Scene
from walkerlab.integrate.solver import Solver
from walkerlab.models.registry import build_walker
from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]
SOLVER = Solver(method="DOP853", rtol=1e-12, atol=1e-12)


def _scene(name: str, **walker) -> Scene:
    raw = yaml.safe_load((ROOT / "configs" / name).read_text())
    raw["walker"].update(walker)
    return Scene.model_validate(raw)


def _guess(scene: Scene, names) -> np.ndarray:
    g = scene.fixedpoint.initial_guess.model_extra
    return np.array([g[n + ("_rad" if n.endswith("_angle") else "_rad_per_s")] for n in names])


# ---- the planar embedding ---------------------------------------------------------------

def test_the_paper_walker_in_3d_with_zero_hip_width_walks_as_the_planar_one():
    """Started upright, the 3D walker of zero hip width is the planar walker (configs/
    paper.yaml): the same fixed point and period, to 1e-9."""
    flat_scene = _scene("paper.yaml")
    flat = build_walker(Plant.from_scene(flat_scene))
    f = find_fixed_point(flat, _guess(flat_scene, flat.state_names()), SOLVER, fd_check=False)
    sp_scene = _scene("paper_3d.yaml")
    w3 = build_walker(Plant.from_scene(sp_scene))
    s = find_fixed_point(w3, _guess(sp_scene, w3.state_names()), SOLVER, fd_check=False)
    x3 = dict(zip(w3.state_names(), s.x))
    for name, value in zip(flat.state_names(), f.x):
        assert abs(x3[name] - value) < 1e-9, name
    assert abs(x3["lean_angle"]) < 1e-12 and abs(x3["lean_rate"]) < 1e-12
    assert abs(s.period_s - f.period_s) < 1e-9
    # the planar multipliers are among the 3D ones (the rest: the roll's)
    for m in f.multipliers_variational:
        assert np.min(np.abs(s.multipliers_variational - m)) < 1e-7


# ---- an independent model: Newton's law for three point masses -------------------------

def Reference(g, L, gamma, M, m, a) -> PartsReference:
    """The walker of ``configs/hip_width.yaml`` from Newton's law (module docstring;
    tests/independent/parts_3d_newton.py): the hip mass ``M`` midway between the hips, on
    each leg a mass ``m`` at ``a`` from its foot (``L - a`` from its hip).  State ``[lean,
    swing, stance, rates]`` as walkerlab's; ``w`` (a method's argument) the swing hip's offset
    along the hip axis (sign: the side)."""
    return PartsReference(g, L, gamma, M, legs=[(m, L - a)])


HIP = dict(g=9.81, L=1.0, gamma=0.0174, M=10.0, m=5.0, a=0.5)


@pytest.fixture(scope="module")
def hip_width_gait():
    scene = _scene("hip_width.yaml")
    walker = build_walker(Plant.from_scene(scene))
    res = find_fixed_point(walker, _guess(scene, walker.state_names()), SOLVER, fd_check=False)
    return walker, res, scene.walker.hip_width_m


def test_hip_width_walker_conserves_energy_in_a_passive_swing(hip_width_gait):
    walker = hip_width_gait[0]
    x0 = np.array([0.03, -0.2, 0.17, 0.2, -0.6, -0.85])
    sol = solve_ivp(walker.phases[0].flow, (0, 0.3), x0, method="DOP853", rtol=1e-13,
                    atol=1e-13, dense_output=True)
    ke, pe = walker.energies(sol.sol(np.linspace(0, 0.3, 40)))
    total = np.asarray(ke) + np.asarray(pe)
    assert np.max(np.abs(total - total[0])) < 1e-9


def test_hip_width_walker_flow_and_impact_match_newtons_law(hip_width_gait):
    """The generated flow and heel-strike map against the reference's (states with roll)."""
    walker, _res, w = hip_width_gait
    ref = Reference(**HIP)
    rng = np.random.default_rng(3)
    for _ in range(5):
        x = np.array([0.05, -0.2, 0.17, 0.3, -0.6, -0.85]) + 0.05 * rng.standard_normal(6)
        assert np.max(np.abs(walker.phases[0].flow(0.0, x) - ref.rhs(w)(0.0, x))) < 1e-11
        assert np.max(np.abs(walker.reset(x) - ref.impact(w, x))) < 1e-11


@pytest.mark.slow  # ~20 s: the reference's own fixed point and central differences
def test_hip_width_gait_and_multipliers_match_an_independent_model(hip_width_gait):
    walker, res, w = hip_width_gait
    ref = Reference(**HIP)

    dx, dt, dmu = stride_against(ref, w, res, [0, 2, 3, 4, 5])
    assert dx < 1e-8
    assert dt < 1e-8
    assert dmu < 1e-6


def test_hip_width_walkers_urdf_in_pinocchio_has_its_kinetic_energy_and_feet(tmp_path):
    """The exported URDF (a free pelvis, two legs on hip joints) put in the walker's state:
    Pinocchio's kinetic energy and swing foot equal the generated model's (an independent
    computation of the 3D mass matrix: Pinocchio's articulated bodies), and the mass."""
    pin = pytest.importorskip("pinocchio")
    from walkerlab.cli.options import load
    from walkerlab.codegen.cache import functions
    from walkerlab.export.spoked import TO_MUJOCO
    from walkerlab.stages import export
    from walkerlab.walker.description import walker_data

    scene = load(str(ROOT / "configs" / "hip_width.yaml"))
    path = export.write(scene, tmp_path, "urdf").path
    model = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())
    pdata = model.createData()
    assert abs(sum(i.mass for i in model.inertias) - 20.0) < 1e-12
    f = functions(walker_data(scene.walker, scene.slope.phi_rad))
    C = np.array(TO_MUJOCO)
    gamma = scene.slope.phi_rad
    fall = np.array([math.cos(gamma), -math.sin(gamma), 0.0])
    x = np.array([0.04, -0.2, 0.17, 0.3, -0.6, -0.85])   # lean, swing, stance, rates
    pts, vel = f["points"](x), f["point_velocities"](x)
    R_pelvis = C @ Rotation.from_rotvec(x[0] * fall).as_matrix() @ C.T
    quat = Rotation.from_matrix(R_pelvis).as_quat()      # x, y, z, w as Pinocchio's
    q = np.concatenate([C @ pts["hip"], quat,
                        [math.cos(x[1]), math.sin(x[1]), math.cos(x[2]), math.sin(x[2])]])
    v = np.concatenate([R_pelvis.T @ (C @ vel["hip"]), R_pelvis.T @ (C @ (fall * x[3])),
                        [x[4], x[5]]])                   # base rates in the pelvis frame
    ke_pin = pin.computeKineticEnergy(model, pdata, q, v)
    ke, _ = f["energies"](x)
    # the URDF's point masses carry the export's smallest inertia (1e-12 kg m^2)
    assert abs(ke_pin - float(ke)) < 1e-9 * float(ke)
    pin.forwardKinematics(model, pdata, q)
    leg1 = model.getJointId("leg1_hip")
    foot = pdata.oMi[leg1].act(np.array([0.0, 0.0, -1.0]))  # the swing leg's foot (L = 1 m)
    assert np.max(np.abs(foot - C @ pts["swing_foot"])) < 1e-12


def test_hip_width_steps_release_the_slopes_energy_along_the_fall_line(hip_width_gait):
    """A step's length is its advance in the direction of walking (the sagittal plane's
    ``x, y``), its width apart: over a step of the passive gait the ledger's slope energy
    ``M g d sin(gamma)`` is gravity's work, the potential energy the walker loses, and the
    heel strike takes it (the 3D foot-to-foot distance, 0.1 m hip width included, had
    overstated it by 3.8 %).  Bound: the fixed point's tolerance (1e-12) through a step."""
    from walkerlab.analysis.gait.energy import trajectory_ledger
    from walkerlab.analysis.gait.metrics import step_length
    from walkerlab.integrate.rigid import simulate_steps

    walker, res, w = hip_width_gait
    traj = simulate_steps(walker, res.x, 2, SOLVER)
    led = trajectory_ledger(traj)
    for k, seg in enumerate(traj.segments):
        foot = np.asarray(walker.for_stance(seg.stance_leg).points(seg.x_end)["swing_foot"],
                          float).ravel()
        assert abs(abs(foot[2]) - w) < 0.02  # the step's width: about the hip width
        assert step_length(walker, seg) == pytest.approx(math.hypot(foot[0], foot[1]),
                                                         rel=1e-15)
        assert led["slope_energy"][k] == pytest.approx(led["potential_work"][k], rel=1e-9)
        assert led["heel_strike_loss"][k] == pytest.approx(led["slope_energy"][k], rel=1e-9)
        assert led["cost_of_transport"][k] == pytest.approx(math.sin(HIP["gamma"]), rel=1e-12)


def test_a_3d_derivation_draws_from_a_seeded_generator_and_restores_its_state():
    """The walkers' derivations from their trees (``derive_legged``, ``derive_spoked``) run
    with sympy's random number generator seeded (``trigsimp``'s factorisation draws from
    it: its time, not its factors, depends on the draws), so every derivation draws the
    same numbers, and the caller's generator state is as it was."""
    import sympy.core.random as srand

    from walkerlab.codegen.derive_3d import _seeded, derive_spoked
    from walkerlab.codegen.legged import derive_legged

    assert derive_legged.__wrapped__ is not None and derive_spoked.__wrapped__ is not None
    draws = []
    derive = _seeded(lambda s: draws.append((s, srand.rng.random(), srand.randint(0, 10**9))))
    srand.rng.seed(123)
    before = srand.rng.getstate()
    derive("a")
    srand.rng.random()  # the caller draws between two derivations
    after = srand.rng.getstate()
    derive("b")
    assert draws[0][1:] == draws[1][1:]
    assert srand.rng.getstate() == after != before


def test_a_stride_map_of_the_zero_width_walker_squares_its_step_multipliers():
    """Issue 82 item 1: a study puts the zero-width 3D walker (a step map of its own) on the
    stride map of its other points (``HybridWalker.with_steps_per_map``).  Its legs are
    mirror images, so the stride is two identical steps: the same fixed point, twice the
    period, every Floquet multiplier squared - each found by its own root finder and
    variational equations, not one computed from the other."""
    scene = _scene("paper_3d.yaml")
    step = build_walker(Plant.from_scene(scene))
    assert step.steps_per_map == 1
    stride = step.with_steps_per_map(2)
    assert stride.steps_per_map == 2 and step.with_steps_per_map(1) is step
    a = find_fixed_point(step, _guess(scene, step.state_names()), SOLVER, fd_check=False)
    b = find_fixed_point(stride, a.x, SOLVER, fd_check=False)
    assert np.max(np.abs(b.x - a.x)) < 1e-10
    assert b.period_s == pytest.approx(2 * a.period_s, rel=1e-12)
    # relative 1e-7: the two Jacobians each to the integrator's tolerance (1e-12)
    assert np.sort(np.abs(b.multipliers_variational)) == pytest.approx(
        np.sort(np.abs(a.multipliers_variational) ** 2), rel=1e-7, abs=1e-9)
    with pytest.raises(ValueError, match="not made of this walker's maps"):
        sc = _scene("hip_width.yaml")
        build_walker(Plant.from_scene(sc)).with_steps_per_map(3)


def test_other_gait_false_stops_the_second_gait_search_of_a_3d_walker(tmp_path):
    """Issue 82 item 14: the hip-width walker's passive gait is unstable (its lateral mode),
    so ``fixedpoint.gait: stable`` went on to look for the other gait of the pair (and
    found a short-period one) although the scene says ``other_gait: false``.  Now the
    scene's word is kept: one gait, the one from its guess, and a note that says why; the
    fixedpoint text gives its multipliers per stride (the walker's map)."""
    from walkerlab.analysis.gait.scene import solve_scene
    from walkerlab.io.schemas.fixedpoint import load_fixedpoint
    from walkerlab.report.text import fixedpoint_text
    from walkerlab.stages import fixedpoint as fixedpoint_stage

    scene = _scene("hip_width.yaml")
    assert scene.fixedpoint.other_gait is False and scene.fixedpoint.gait == "stable"
    walker, search = solve_scene(scene, fd_check=False, plant=Plant.from_scene(scene))
    assert len(search.gaits) == 1 and not search.result.stable
    assert any("other_gait: false" in n for n in search.notes)
    assert "deflated" not in " ".join(search.tried) and "seed" not in " ".join(search.tried)
    # the scene's own word is what stops it: with other_gait true the pair is looked for
    both = scene.model_copy(update={"fixedpoint": scene.fixedpoint.model_copy(
        update={"other_gait": True})})
    assert len(solve_scene(both, fd_check=False, plant=Plant.from_scene(both))[1].gaits) == 2
    fp = load_fixedpoint(fixedpoint_stage.run(scene, runs_root=tmp_path).path)
    assert fp.steps_per_map == 2
    text = fixedpoint_text(fp)
    assert "Floquet multipliers (variational, per stride)" in text
    assert "largest variational |multiplier| per stride = 99.92" in text
    assert "was not looked for" in text
def _without_guess(tmp_path: Path, name: str, **walker) -> Path:
    """configs/<name> copied to ``tmp_path`` without its ``fixedpoint.initial_guess`` (and
    its ``gait: nearest_guess``, which needs one), ``walker`` fields replaced."""
    data = yaml.safe_load((ROOT / "configs" / name).read_text())
    data["fixedpoint"].pop("initial_guess")
    data["fixedpoint"].pop("gait", None)
    data["walker"].update(walker)
    path = tmp_path / name
    path.write_text(yaml.safe_dump(data))
    return path


#: two roots of the same map at xtol 1e-12 (MINPACK's relative step) and residual < 1e-11
#: differ by at most |(I - DP)^-1| times that: the lateral multiplier (up to ~20) and the
#: 1e-12 integration give ~1e-10; 1e-8 leaves room and is still far below any gait's scale
SAME_GAIT_TOL = 1e-8


@pytest.mark.slow
@pytest.mark.parametrize("name", ["hip_width.yaml", "hip_width_stabilised.yaml"])
def test_a_3d_walker_without_initial_guess_finds_the_shipped_gait(tmp_path, name):
    """Without a guess, a 3D walker with hip width starts from its planar twin's gait
    (lateral states zero) carried in hip width: it reaches the gait the shipped scene finds
    from its own guess (before: 0 of 45 scale-free seeds, no gait)."""
    from walkerlab.analysis.gait.scene import solve_scene
    from walkerlab.config import load_scene

    sc = load_scene(ROOT / "configs" / name)
    _w, shipped = solve_scene(sc, fd_check=False, plant=Plant.from_scene(sc))
    sc1 = load_scene(_without_guess(tmp_path, name))
    _w, found = solve_scene(sc1, fd_check=False, plant=Plant.from_scene(sc1))
    assert any("planar twin" in n for n in found.notes)
    np.testing.assert_allclose(found.result.x, shipped.result.x, rtol=0, atol=SAME_GAIT_TOL)


def test_a_3d_walker_not_shipped_finds_a_gait_without_initial_guess(tmp_path):
    """A hip width of 7 cm and other masses (no scene ships it, no guess): a gait, on the
    heel-strike section to the scene's tolerance, near the planar twin's sagittally and
    leaning (the hip width's lateral motion), found in seconds."""
    import time

    from walkerlab.analysis.gait.scene import solve_scene
    from walkerlab.config import load_scene

    scene = load_scene(_without_guess(tmp_path, "hip_width.yaml", hip_width_m=0.07,
                                      leg_mass_kg=3.0, hip_mass_kg=12.0))
    t0 = time.process_time()
    walker, search = solve_scene(scene, fd_check=False, plant=Plant.from_scene(scene))
    assert time.process_time() - t0 < 30.0
    res = search.result
    assert res.residual < 1e-10
    x = dict(zip(walker.state_names(), res.x))
    assert abs(x["lean_rate"]) > 1e-3  # out of the plane: not the upright embedding
    assert -0.3 < x["swing_angle"] < -0.1 and 0.1 < x["stance_angle"] < 0.3


@pytest.mark.slow
def test_a_changed_gain_falls_back_to_the_stored_gait_and_finds_the_gait(tmp_path):
    """lean_rate_gain_s -0.18 -> -0.25 with the shipped scene's guess (the gait at -0.18):
    Newton from the guess does not converge (before: then 0 of 45 seeds, no gait); the gait
    stored for -0.18, carried over the gain, is the start of a gait at -0.25 on the
    heel-strike section to the scene's tolerance, far from the guess (issue 82 item 9)."""
    from walkerlab.analysis.gait.scene import initial_guess, solve_scene
    from walkerlab.config import load_scene
    from walkerlab.models.registry import build_walker
    from walkerlab.studies.warm_start import StoredGait, stored_gait_start

    data = yaml.safe_load((ROOT / "configs" / "hip_width_stabilised.yaml").read_text())
    data["walker"]["hip_roll"]["lean_rate_gain_s"] = -0.25
    path = tmp_path / "lrg025.yaml"
    path.write_text(yaml.safe_dump(data))
    scene = load_scene(path)
    known = load_scene(ROOT / "configs" / "hip_width_stabilised.yaml")
    guess = initial_guess(known, build_walker(Plant.from_scene(known)))
    nearby = stored_gait_start(scene, [StoredGait(known, lambda: guess, "known")],
                               plant=Plant.from_scene(scene))
    walker, search = solve_scene(scene, fd_check=False, nearby=nearby,
                                 plant=Plant.from_scene(scene))
    assert any("initial guess did not converge" in n for n in search.notes)
    assert search.gait.source == "stored_gait"
    res = search.result
    assert res.residual < 1e-10
    assert np.max(np.abs(res.x - guess)) > 0.1  # a gait of its own, not the guess's


def _copy_with(tmp_path, name: str, edit) -> Path:
    data = yaml.safe_load((ROOT / "configs" / name).read_text())
    edit(data)
    path = tmp_path / f"copy_of_{name}"
    path.write_text(yaml.safe_dump(data))
    return path


def test_a_copied_scene_names_the_shipped_scene_its_initial_guess_was_written_for(tmp_path):
    """A scene copied from a shipped one and a gain changed keeps the shipped scene's
    initial guess: the guess's own walker is that scene (``guess_owners``, the start of
    the homotopy when Newton from the guess fails); a guess of its own names none, nor does
    a planar walker (its search has the scale-free seeds) (issue 82 item 9)."""
    from walkerlab.config import load_scene
    from walkerlab.stages.fixedpoint import guess_owners

    def gain(d):
        d["walker"]["hip_roll"]["lean_rate_gain_s"] = -0.25

    owners = guess_owners(load_scene(_copy_with(tmp_path, "hip_width_stabilised.yaml", gain)))
    where = {o.where: o for o in owners}   # the stabilised walker and its shipped copies
    assert "hip_width_stabilised.yaml" in where              # (on stairs, footholds, ...)
    assert where["hip_width_stabilised.yaml"].scene.walker.hip_roll.lean_rate_gain_s == -0.18
    assert all(o.scene.walker.model == "compass_gait" or o.scene.walker.space == "3d"
               for o in owners)

    def guess(d):
        gain(d)
        d["fixedpoint"]["initial_guess"]["lean_angle_rad"] = 0.02

    assert guess_owners(load_scene(_copy_with(tmp_path, "hip_width_stabilised.yaml",
                                              guess))) == []
    # a planar walker's search has its seeds: no guess owners (paper_rods shares nothing,
    # but a copy of paper.yaml would have paper.yaml's guess)
    assert guess_owners(load_scene(_copy_with(tmp_path, "paper.yaml", lambda d: None))) == []


@pytest.mark.slow
def test_a_changed_gain_with_an_empty_runs_folder_finds_the_gait_from_the_scenes_own_guess(
        tmp_path):
    """lean_rate_gain_s -0.18 -> -0.25 in a copy of the stabilised walker, nothing stored:
    before, 'no period-1 gait found' (the guess fails, the planar twin's width continuation
    stalls at 0.072 m); now the gait of the scene the guess was written for, carried over
    the gain, starts the search.  The gait equals the one ``--from`` finds (a homotopy of
    10 points from the known scene, another path) to 1e-9 (issue 82 item 9)."""
    from walkerlab.config import load_scene
    from walkerlab.io.schemas.fixedpoint import load_fixedpoint
    from walkerlab.stages import fixedpoint

    def gain(d):
        d["walker"]["hip_roll"]["lean_rate_gain_s"] = -0.25

    scene = load_scene(_copy_with(tmp_path, "hip_width_stabilised.yaml", gain))
    plain = fixedpoint.run(scene, tmp_path / "plain")
    known = load_scene(ROOT / "configs" / "hip_width_stabilised.yaml")
    via = fixedpoint.run(scene, tmp_path / "from", known=known)
    a, b = load_fixedpoint(plain.path), load_fixedpoint(via.path)
    assert np.max(np.abs(a.x - b.x)) < 1e-9
    assert a.residual < 1e-10 and np.max(np.abs(a.multipliers)) > 1.5  # unstable at -0.25
    assert [g.source for g in a.gaits.values()] == ["stored_gait"]
@pytest.mark.parametrize("width", [2.0, 100.0])
def test_a_hip_width_of_twice_the_leg_or_more_is_refused_naming_the_field(width):
    """Leaning its centre of mass over the stance foot (tan(lean) ~ w / 2L) lifts the swing
    foot w^2 / 2L, and legs of length L reach down 2 L at most: hips 2 L apart or more
    cannot walk.  ``hip_width_m: 100`` on a 1 m leg took 57 s to a 'math domain error';
    now the scene refuses it in one line naming the field; 1.9 m is accepted."""
    from walkerlab.config import SceneError

    with pytest.raises((SceneError, ValueError), match=r"walker\.hip_width_m: .* below 2 m"):
        _scene("hip_width.yaml", hip_width_m=width)
    assert _scene("hip_width.yaml", hip_width_m=1.9).walker.hip_width_m == 1.9
