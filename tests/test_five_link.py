"""The five-link biped (free knees, hinged torso) in the rigid view against an independent
derivation (tests/independent/five_link.py: relative joint coordinates, sympy Lagrangian,
extended-coordinate impact): flow, heel strike, energies, guards, section."""

from __future__ import annotations

import copy
from pathlib import Path

import numpy as np
import pytest

from tests.independent import five_link as ref
from walkerlab.config import load_scene, scene_from_dict
from walkerlab.config.loader import SceneError
from walkerlab.models.registry import build_walker
from walkerlab.walker.description import walker_data
from walkerlab.walker.plant import Plant

#: every test here shares the independent sympy model (tests/independent/five_link.py, ~8 s
#: of CPU to build): one worker builds it once
pytestmark = pytest.mark.xdist_group("five_link_reference")

# RABBIT-like numbers (Westervelt et al. 2003, Table I) with a hip mass and a slope added so
# that every term of the generator is exercised
LT, LS, CT, CS = 0.4, 0.4, 0.11, 0.24
SCENE = {
    "walker": {
        "model": "biped", "gravity_m_per_s2": 9.81, "hip_mass_kg": 1.5,
        "leg": {"length_m": LT + LS, "knee": {"thigh_length_m": LT, "lock": "free"},
                "bodies": [
                    {"kind": "rod", "name": "thigh", "link": "thigh", "mass_kg": 6.8,
                     "com_from_hip_m": CT, "inertia_about_com_kg_m2": 0.47},
                    {"kind": "rod", "name": "shank", "link": "shank", "mass_kg": 3.2,
                     "com_from_hip_m": LT + CS, "inertia_about_com_kg_m2": 0.20}]},
        "torso": {"coupling": "hinged", "bodies": [
            {"kind": "rigid_body", "name": "trunk", "mass_kg": 12.0, "com_from_hip_m": 0.24,
             "inertia_about_com_kg_m2": 1.33}]}},
    "slope": {"angle_rad": 0.05},
}
P = {"g": 9.81, "lt": LT, "ls": LS, "mt": 6.8, "ms": 3.2, "mT": 12.0, "ct": CT, "cs": CS,
     "cT": 0.24, "It": 0.47, "Is": 0.20, "IT": 1.33, "mH": 1.5}


def to_ref(x):
    """walkerlab's absolute link angles (ss, st, wt, ws, t) and rates -> the reference's
    relative ones (th, h1, h2, k1, k2)."""
    def rel(a):
        ss, st, wt, ws, t = a
        return np.array([t, st - t, wt - t, ss - st, ws - wt])
    return rel(x[:5]), rel(x[5:])


def from_ref(r):
    th, h1, h2, k1, k2 = r
    return np.array([th + h1 + k1, th + h1, th + h2, th + h2 + k2, th])


@pytest.fixture(scope="module")
def walker():
    sc = scene_from_dict(SCENE)
    return build_walker(Plant.from_scene(sc))


def states(k=4, seed=3):
    rng = np.random.default_rng(seed)
    base = np.array([0.25, 0.35, -0.3, -0.5, -0.1])
    return [np.concatenate([base + rng.normal(0, 0.2, 5), rng.normal(0, 1.5, 5)])
            for _ in range(k)]


def test_flow_matches_independent_lagrangian(walker):
    for x in states():
        r, dr = to_ref(x)
        qdd = from_ref(ref.acceleration(r, dr, P))  # linear map: accelerations alike
        got = walker.phases[0].flow(0.0, x)
        np.testing.assert_allclose(got[5:], qdd, rtol=0, atol=1e-9 * max(1, abs(qdd).max()))
        np.testing.assert_array_equal(got[:5], x[5:])


def test_energies_match_and_flow_conserves_energy(walker):
    for x in states():
        kin, pot = walker.energies(x)
        assert float(kin + pot) == pytest.approx(ref.energy(*to_ref(x), P), abs=1e-10 * 300)
        # dE/dt = grad E . f: complex step along the flow (round-off level)
        f = walker.phases[0].flow(0.0, x)
        h = 1e-30
        dE = np.imag(sum(walker.energies(x + 1j * h * f))) / h
        assert abs(dE) < 1e-10 * float(kin + abs(pot))


def test_heel_strike_matches_extended_coordinate_impact(walker):
    for x in states():
        r, dr = to_ref(x)
        r_new, dr_new = ref.heel_strike(r, dr, P)
        got = walker.reset(x)
        np.testing.assert_allclose(got[:5], from_ref(r_new), atol=1e-12)
        want = from_ref(dr_new)
        np.testing.assert_allclose(got[5:], want, atol=1e-9 * max(1, abs(want).max()))


def test_generated_extended_matrices_give_the_same_impact(walker):
    """The generated ``impact_matrices`` (De, E) in the KKT system give the reset's rates."""
    from walkerlab.codegen.cache import functions

    data = walker_data(scene_from_dict(SCENE).walker, 0.05)
    fns = functions(data)
    x = states(1)[0]
    De, E = (np.asarray(a, float) for a in fns["impact_matrices"](x[:5]))
    K = np.zeros((9, 9))
    K[:7, :7], K[:7, 7:], K[7:, :7] = De, -E.T, E
    dq = np.linalg.solve(K, np.concatenate([De @ np.concatenate([x[5:], [0, 0]]), [0, 0]]))[:5]
    np.testing.assert_allclose(walker.reset(x)[5:], dq[[3, 2, 1, 0, 4]], atol=1e-10)


def test_guards_and_section(walker):
    x = states(1)[0]
    foot = ref.swing_foot(to_ref(x)[0], P)
    n = np.array([np.sin(0.05), np.cos(0.05)])
    heel = next(g for g in walker.phases[1].guards if g.name == "heel_strike")
    assert heel.function(0.0, x) == pytest.approx(foot @ n, abs=1e-14)
    assert heel.direction == -1
    ahead = walker.phases[0].guards[0]
    assert ahead.function(0.0, x) == pytest.approx(foot @ np.array([n[1], -n[0]]), abs=1e-14)
    # a post-impact state: the new swing foot (behind) on the slope; the section round trip
    xs = x.copy()
    xs[3] = 0.0
    xs = walker.from_section(walker.section(xs))  # the swing shank solved from the surface
    assert heel.function(0.0, xs) == pytest.approx(0.0, abs=1e-14)
    assert walker.points(xs)["swing_foot"][0] < 0  # behind the stance foot
    np.testing.assert_allclose(walker.from_section(walker.section(xs)), xs, atol=1e-14)


def test_leg_coordinates_by_physical_leg(walker):
    x = states(1)[0]
    c = walker.leg_coordinates(x, "leg2")
    assert c["leg2_shank_angle"] == x[0] and c["leg1_thigh_angle"] == x[2]
    assert c["torso_angle"] == x[4]
    hip = walker.points(x)["hip"]  # the virtual stance leg: hip -> stance foot
    assert np.sin(c["leg2_angle"]) == pytest.approx(-hip[0] / np.hypot(*hip), abs=1e-14)


@pytest.mark.parametrize("edit, field", [
    (lambda w: w["torso"].update(coupling="bisecting_hip"), "torso.coupling"),
    (lambda w: w["leg"]["knee"].update(lock="plastic"), "torso.coupling"),
    (lambda w: w["leg"].update(foot={"kind": "arc", "radius_m": 0.1}), "leg.knee.lock"),
])
def test_refusals_are_one_line(edit, field):
    cfg = copy.deepcopy(SCENE)
    edit(cfg["walker"])
    with pytest.raises(SceneError) as e:
        scene_from_dict(cfg)
    assert field in str(e.value) and "\n" not in str(e.value).strip()


def test_passive_structures_keep_their_keys():
    """A locking-knee walker's structure key (the generated-code cache key) has no new
    entries: shipped scenes regenerate nothing new and their numbers stay."""
    from pathlib import Path

    from walkerlab.config import load_scene

    root = Path(__file__).resolve().parents[1] / "configs"
    for name in ("kneed.yaml", "torso_bhm.yaml", "paper.yaml"):
        sc = load_scene(root / name)
        key = walker_data(sc.walker, sc.slope.phi_rad).structure.key()
        assert "free_knees" not in key and "hinged_torso" not in key
        dumped = sc.model_dump(mode="json")
        assert "angle_rad" not in str(dumped.get("walker", {}).get("actuation", ""))


# -------------------- the five-link step map's compiled flow on LSODA
ROOT = Path(__file__).resolve().parents[1]


# ------------------------------------- 8: RABBIT's step map runs its compiled flow on LSODA
@pytest.mark.slow  # builds RABBIT and maps twice (the Python map alone ~1 s)
def test_the_five_link_step_map_on_lsoda_calls_no_python_flow_and_agrees_with_it(
        monkeypatch):
    """RABBIT (LSODA: scipy) runs the phase's compiled actuated flow, as its replays do (one
    map 0.72 -> 0.07 s CPU; with the variational equations 7.9 -> 0.14 s): no call of the
    Python flow, and the same map to the integrator's tolerance (rtol = atol = 1e-11:
    measured 2e-11 rad on the state, 1.4e-12 s on the period)."""
    from dataclasses import replace

    import walkerlab.integrate.rigid as rigid
    from walkerlab.analysis.gait.poincare import poincare_map
    from walkerlab.analysis.gait.scene import initial_guess
    from walkerlab.integrate.solver import Solver
    from walkerlab.models.registry import build_walker

    scene = load_scene(ROOT / "configs" / "rabbit.yaml")
    w = build_walker(Plant.from_scene(scene))
    calls = []

    def counted(f):
        return lambda t, x: calls.append(1) or f(t, x)

    w = replace(w, phases=tuple(replace(p, flow=counted(p.flow)) for p in w.phases))
    solver = Solver.from_settings(scene.solver)
    assert solver.resolved_backend() == "scipy"
    x0 = np.asarray(initial_guess(scene, w), float)
    x1, T1, _ = poincare_map(w, x0, solver)
    assert calls == []
    monkeypatch.setattr(rigid, "_runs_compiled_on_scipy", lambda phase: False)
    x2, T2, _ = poincare_map(w, x0, solver)
    assert calls  # the Python flow, as before
    assert np.max(np.abs(x1 - x2)) < 1e-9 and abs(T1 - T2) < 1e-10
