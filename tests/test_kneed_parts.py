"""Parts on a kneed walker (issue 22): a hip spring between the legs, a knee spring, legs that
differ and an upper body on a bisecting hip mechanism on the Hsu Chen (2007) kneed walker, in
both views.

Rigid view: the generated flows (knee free, knee locked), the plastic knee strike and the heel
strike against the independent kneed prototype (``tests/independent/kneed_reference.py``:
Lagrange in its own coordinates, the locked knee, the torso's coupling and the impacts as
multiplier systems, no code shared with the generator), for both steps of a stride; energy
including the spring potential conserved in the unlocked and in the locked swing; the fixed
point mapping to itself under the prototype's own integration.  Contact view: the floating
equations against the independent floating reference
(``tests/independent/floating_reference.py``).

Tolerances: flows and resets are closed-form algebra on both sides, compared at 1e-11 relative
(round-off of two formulations); energy drift of DOP853 at rtol = atol = 1e-12 over a 0.5 s
phase of a ~13 J walker stays below 1e-11 relative (measured <= 1.4e-13); the fixed point
through the prototype's integration (DOP853 at 1e-12 over a 0.5 s step) at 1e-9.
"""

from pathlib import Path

import numpy as np
import pytest
import yaml
from independent import floating_reference as fref
from independent.kneed_reference import HSU_CHEN, KneedReference, KneedTorsoReference

from walkerlab.analysis.gait.poincare import find_fixed_point
from walkerlab.config import scene_from_dict
from walkerlab.integrate.rigid import integrate_step
from walkerlab.integrate.solver import Solver
from walkerlab.models.registry import build_walker
from walkerlab.walker.description import walker_data
from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]
SOLVER = Solver("DOP853", 1e-12, 1e-12)
#: A hip spring light enough for the 1.6 kg walker to keep its gait (0.2 N m/rad loses it).
HIP_SPRING = {"between": ["leg1", "leg2"], "stiffness_n_m_per_rad": 0.1}
#: A knee spring pulling the knee straight (0.05 N m/rad keeps the gait: 0.5609 s).
KNEE_SPRING = {"stiffness_n_m_per_rad": 0.05}
#: Every part variant of configs/kneed.yaml: springs, a knee spring, legs that differ.
VARIANTS = {
    "hip_spring": {"springs": [HIP_SPRING]},
    # rest angle and damping: not a mirror-symmetric walker (a stride map), dissipative
    "spring_rest_damping": {"springs": [{**HIP_SPRING, "rest_angle_rad": 0.2,
                                         "damping_n_m_s_per_rad": 0.05}]},
    "legs_differ": {"legs_differ": True},
    "knee_spring": {"knee_spring": KNEE_SPRING},
    # an upper body on the bisecting hip (the thighs' bisector): 0.2 kg, 0.2 m up
    "torso": {"torso": {"bodies": [{"kind": "point_mass", "name": "mass", "mass_kg": 0.2,
                                    "from_hip_m": 0.2}]}},
    # all at once, the knee spring with a flexed rest angle and damping
    "all_parts": {"legs_differ": True, "springs": [{**HIP_SPRING, "rest_angle_rad": -0.1}],
                  "knee_spring": {"stiffness_n_m_per_rad": 0.2, "rest_angle_rad": -0.3,
                                  "damping_n_m_s_per_rad": 0.02}},
}


def _cfg(variant):
    d = yaml.safe_load((ROOT / "configs" / "kneed.yaml").read_text())
    v = VARIANTS[variant]
    if "knee_spring" in v:
        d["walker"]["leg"]["knee"]["spring"] = v["knee_spring"]
    if "springs" in v:
        d["walker"]["springs"] = v["springs"]
    if "torso" in v:
        d["walker"]["torso"] = v["torso"]
    if v.get("legs_differ"):  # leg B's thigh 10 % heavier, its shank mass 2 cm lower
        leg = d["walker"].pop("leg")
        other = yaml.safe_load(yaml.safe_dump(leg))
        other["bodies"][0]["mass_kg"] = 0.55
        other["bodies"][1]["from_hip_m"] = 0.67
        d["walker"]["legs"] = [leg, other]
    return d


def _scene(variant):
    return scene_from_dict(_cfg(variant), origin=f"kneed_{variant}.yaml")


def _reference(variant, stance_leg):
    """The prototype for the step with ``stance_leg`` in stance (role numbers of that step)."""
    p = dict(HSU_CHEN)
    v = VARIANTS[variant]
    if v.get("legs_differ"):
        thigh = {"leg1": 0.5, "leg2": 0.55}
        b1 = {"leg1": 0.15, "leg2": 0.17}
        swing = "leg1" if stance_leg == "leg2" else "leg2"
        # the prototype's shank mass sits b1 below the knee on the swing leg and a1 above
        # the foot on the stance leg: the two legs' own distances, by role
        p.update(mt=thigh[stance_leg], mt_sw=thigh[swing], a1=0.5 - b1[stance_leg],
                 b1=b1[swing])
    if "knee_spring" in v:
        ks = v["knee_spring"]
        p.update(k_knee=ks["stiffness_n_m_per_rad"], rest_knee=ks.get("rest_angle_rad", 0.0),
                 c_knee=ks.get("damping_n_m_s_per_rad", 0.0))
    if "springs" in v:
        s = v["springs"][0]
        # config delta = leg2 - leg1; the prototype's = stance - swing thigh
        sign = 1.0 if stance_leg == "leg2" else -1.0
        p.update(k_hip=s["stiffness_n_m_per_rad"], rest_hip=sign * s.get("rest_angle_rad", 0),
                 c_hip=s.get("damping_n_m_s_per_rad", 0.0))
    if "torso" in v:
        body = v["torso"]["bodies"][0]
        return KneedTorsoReference({**p, "m_tor": body["mass_kg"], "d_tor": body["from_hip_m"]})
    return KneedReference(p)


def _order(walker):
    """Our state -> the prototype's ``[stance, swing thigh, swing shank]`` order."""
    names = walker.state_names()
    return [names.index(f"{r}_{k}") for k in ("angle", "rate")
            for r in ("stance", "swing_thigh", "swing_shank")]


@pytest.fixture(scope="module")
def gaits():
    guess = {"hip_spring": [-0.2866, -0.2866, 0.1859, -0.188, -0.188, -1.160],
             "legs_differ": [-0.29, -0.29, 0.189, -0.11, -0.11, -1.13],
             "knee_spring": [-0.2912, -0.2912, 0.1905, -0.028, -0.028, -1.111],
             "torso": [-0.3198, -0.3198, 0.2190, -0.235, -0.235, -1.104]}
    out = {}
    for name, x0 in guess.items():
        sc = _scene(name)
        w = build_walker(Plant.from_scene(sc))
        out[name] = (w, find_fixed_point(w, np.array(x0), SOLVER, fd_check=False))
    return out


def test_the_parts_are_accepted_with_a_knee():
    for variant in VARIANTS:
        s = _scene(variant)
        assert s.walker.leg_pair()[0].knee is not None


def test_torso_on_a_kneed_walker_bisects_the_thighs(gaits):
    """The upper body's angle (from the upward vertical) is the mean of the stance leg's and
    the swing thigh's angles along a step, through the knee strike (to round-off)."""
    w, fp = gaits["torso"]
    seg = integrate_step(w, fp.x, SOLVER)
    X = seg.sample(np.linspace(seg.t_start, seg.t_end, 60))
    P = w.points(X)
    hip, torso = P["hip"], P["torso_mass"]
    angle = np.arctan2(-(torso[0] - hip[0]), torso[1] - hip[1])
    names = w.state_names()
    mean = 0.5 * (X[names.index("swing_thigh_angle")] + X[names.index("stance_angle")])
    assert np.max(np.abs(angle - mean)) < 1e-12
    assert np.ptp(mean) > 0.05  # it moves


@pytest.mark.parametrize("variant", list(VARIANTS))
def test_flows_and_impacts_match_the_kneed_prototype(variant):
    """Knee free, knee locked, knee strike, heel strike: ours = the prototype's at random
    states, for both steps of a stride (``walker.for_stance``)."""
    sc = _scene(variant)
    w0 = build_walker(Plant.from_scene(sc))
    rng = np.random.default_rng(7)
    gamma = w0.slope_rad
    for stance in ("leg2", "leg1"):
        w, ref = w0.for_stance(stance), _reference(variant, stance)
        order = _order(w)
        unlocked, locked = w.phases
        knee = next(g for g in unlocked.guards if g.name == "knee_strike")
        for _ in range(3):
            x = rng.uniform([-0.4, -0.6, -0.3, -1.5, -2.0, -1.5], [0.1, 0.1, 0.3, 0.5, 2.0, 0.5])
            xr = x[order]
            assert unlocked.flow(0.0, x)[order] == pytest.approx(
                ref.flow_unlocked(0.0, xr), rel=1e-11, abs=1e-11)
            # the knee straight and locked
            x[1], x[4] = x[0], x[3]
            xr = x[order]
            assert locked.flow(0.0, x)[order] == pytest.approx(
                ref.flow_locked(0.0, xr), rel=1e-11, abs=1e-11)
            assert knee.reset(x)[order] == pytest.approx(ref.knee_strike(xr), rel=1e-11,
                                                         abs=1e-12)
            # on the heel-strike surface (swing thigh = -2 gamma - stance), knee locked
            x[0] = x[1] = -2 * gamma - x[2]
            xr = x[order]
            assert w.reset(x)[order] == pytest.approx(ref.heel_strike(xr), rel=1e-11,
                                                      abs=1e-12)
            assert sum(w.energies(x)) == pytest.approx(sum(ref.energies(xr)), rel=1e-12)


@pytest.mark.parametrize("name", ["hip_spring", "legs_differ", "knee_spring", "torso"])
def test_fixed_point_maps_to_itself_under_the_prototype(name, gaits):
    w, fp = gaits[name]
    x = fp.x.copy()
    T = 0.0
    order = _order(w)
    back = np.argsort(order)
    for stance in ("leg2", "leg1")[:w.steps_per_map]:
        r = _reference(name, stance).step(x[order])
        x, T = r["x_next"][back], T + r["t_heel"]
    assert np.max(np.abs(x - fp.x)) < 1e-9
    assert T == pytest.approx(fp.period_s, abs=1e-9)
    assert fp.residual < 1e-10
    # the gaits of the closing note (measured): hip spring 0.1 N m/rad 0.521625 s, stable
    # (max |multiplier| 0.821); legs that differ a stride of two steps
    if name == "hip_spring":
        assert w.steps_per_map == 1 and fp.period_s == pytest.approx(0.5216252366, abs=1e-8)
    elif name == "knee_spring":  # the knee straightens sooner; 0.5609 s, max |mu| 0.653
        assert w.steps_per_map == 1 and fp.period_s == pytest.approx(0.5609225352, abs=1e-8)
    elif name == "torso":  # longer, slower steps; 0.6437 s, max |mu| 0.605
        assert w.steps_per_map == 1 and fp.period_s == pytest.approx(0.6436584121, abs=1e-8)
    else:
        assert w.steps_per_map == 2 and len(fp.step_periods_s) == 2


@pytest.mark.parametrize("name", ["hip_spring", "knee_spring", "torso"])
def test_energy_with_spring_potential_is_conserved_unlocked_and_locked(name, gaits):
    """A spring's potential is part of the energy: conserved in the unlocked and the locked
    swing (to 1e-11 relative), and the total without it is not (the check can fail; the
    knee spring's share moves only while the knee is free)."""
    w, fp = gaits[name]
    seg = integrate_step(w, fp.x, SOLVER)
    t_knee = seg.phase_times["knee_strike"]
    names = w.state_names()
    th, sh, st = (names.index(f"{r}_angle") for r in ("swing_thigh", "swing_shank", "stance"))
    for a, b in ((seg.t_start, t_knee), (t_knee, seg.t_end)):
        X = seg.sample(np.linspace(a, b, 80)[1:-1])
        E = np.sum(w.energies(X), axis=0)
        assert np.ptp(E) < 1e-11 * abs(E[0])
        if name == "torso":
            continue
        spring = (0.1 * (X[st] - X[th]) ** 2 / 2 if name == "hip_spring"
                  else 0.05 * (X[sh] - X[th]) ** 2 / 2)
        if a == seg.t_start or name == "hip_spring":
            assert np.ptp(E - spring) > 1e-5  # the spring's share moves
    # the knee strike loses kinetic energy, the potential is continuous
    xm = seg.sample(np.array([t_knee]))[:, 0]
    knee = next(g for g in w.phases[0].guards if g.name == "knee_strike")
    assert w.energies(knee.reset(xm))[1] == pytest.approx(w.energies(xm)[1], rel=1e-13)


@pytest.mark.parametrize("variant", list(VARIANTS))
@pytest.mark.slow  # in `pytest -m slow`: the quick suite keeps to its CPU budget
def test_floating_view_matches_the_floating_reference(variant):
    """The contact view's equations (floating base, both knees free): mass matrix and bias,
    springs included, against the independent floating reference."""
    from walkerlab.models.hybrid.floating_view import FloatingView

    sc = _scene(variant)
    data = walker_data(sc.walker, sc.slope.phi_rad)
    view = FloatingView(data)
    assert tuple(view.coordinate_names()) == fref.coordinate_names(data)
    rng = np.random.default_rng(13)
    for _ in range(4):
        q = np.concatenate([rng.uniform(-1, 1, 2), rng.uniform(-0.6, 0.6, 4)])
        dq = rng.uniform(-2, 2, 6)
        M, b = fref.mass_matrix_and_bias(data, q, dq)
        h = b - fref.spring_force(data, q, dq)
        assert view.mass_matrix(q) == pytest.approx(M, rel=1e-12, abs=1e-13)
        assert view.bias(q, dq) == pytest.approx(h, rel=1e-11, abs=1e-12)
        V = view.energies(np.concatenate([q, dq]))[1]
        assert float(V) == pytest.approx(fref.potential(data, q), rel=1e-12)


def test_elastic_knee_lock_is_refused_in_one_line(tmp_path):
    """``knee.lock: elastic``: one line naming the field and saying why (a rigid elastic stop
    is Zeno) and where an elastic stop exists (the contact view's compliant knee stop); exit
    code 1, nothing written."""
    from typer.testing import CliRunner

    from walkerlab.cli import app

    d = _cfg("knee_spring")
    d["walker"]["leg"]["knee"]["lock"] = "elastic"
    path = tmp_path / "elastic.yaml"
    path.write_text(yaml.safe_dump(d))
    r = CliRunner().invoke(app, ["simulate", str(path), "--runs-dir", str(tmp_path / "runs")])
    assert r.exit_code == 1
    out = r.output.strip()
    assert out.count("\n") == 0 and "walker.leg.knee.lock" in out
    assert "contact view only" in out and "contact.knee_stop" in out
    assert not (tmp_path / "runs").exists() or not any((tmp_path / "runs").rglob("*.h5"))
