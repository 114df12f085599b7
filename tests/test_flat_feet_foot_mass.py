"""Flat feet with mass (issue 58 item 2: one mass model for every view): ``walker.leg.foot.
mass_kg`` and ``inertia_about_ankle_kg_m2`` put the same foot in the rigid view (each foot a
body at its ankle), the contact model and the MJCF export.

The rigid model's equations are checked against a reference that shares no code with the
generator (:func:`_bodies`: the walker's bodies written out here from the geometry, energy
and angular momentum summed over them): with the ankle damper off, each pinned mode's flow
and the double support's closed-chain flow conserve that energy, and the heel strike
conserves the angular momentum about the striking heel.  The three views' step periods
agree within 1 % (``configs/flat_feet_foot_mass.yaml``, slow), the contact run walking the
5 strides asked for."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml
from scipy.integrate import solve_ivp

from walkerlab.codegen.cache import functions
from walkerlab.config import load_scene
from walkerlab.walker.description import walker_data
from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "configs" / "flat_feet_foot_mass.yaml"
G = 9.81
GAMMA = 0.04
L, M_HIP, M_LEG, D_LEG = 1.0, 10.0, 5.0, 0.5
HEEL, TOE, K, REST = 0.05, 0.10, 120.0, 0.0
M_FOOT, I_FOOT = 0.1, 5e-4


def _undamped(tmp_path, **foot):
    """The shipped scene's walker with the ankle damper off (a conservative flow), its feet's
    mass and inertia replaced by ``foot`` if given."""
    d = yaml.safe_load(SCENE.read_text())
    d["walker"]["leg"]["foot"]["ankle"]["damping_n_m_s_per_rad"] = 0.0
    d["walker"]["leg"]["foot"].update(foot)
    p = tmp_path / "undamped.yaml"
    p.write_text(yaml.safe_dump(d))
    scene = load_scene(p)
    return functions(walker_data(scene.walker, scene.slope.angle_rad))


def _e(angle):
    """Unit vector from the hip to the foot of a leg at ``angle`` from the downward vertical
    (positive foot ahead), world axes: x forward (downhill), y up."""
    return np.array([np.sin(angle), -np.cos(angle)])


def _de(angle, rate):
    return np.array([np.cos(angle), np.sin(angle)]) * rate


def _bodies(x, pin="heel"):
    """(mass, position, velocity, inertia, angular velocity) of every body, world axes (x
    forward, y up), written from the geometry (Wisse et al. 2006's walker on flat feet), not
    from the generator: the stance sole at ``th = stance + a`` from the horizontal (toe up
    positive), the heel at the origin (``pin="heel"``) or the toe pinned ``HEEL + TOE`` down
    the slope from it (``pin="toe"``); the ankle on the sole ``HEEL`` ahead of the heel; the
    hip ``L`` up the stance leg; the swing foot at its ankle turning with its leg (held at
    its spring's rest angle)."""
    sw, st, a, dsw, dst, da = x
    th, dth = st + a, dst + da
    s, ds = np.array([np.cos(th), np.sin(th)]), np.array([-np.sin(th), np.cos(th)]) * dth
    if pin == "heel":
        ankle, vankle = HEEL * s, HEEL * ds
    else:
        ankle = (HEEL + TOE) * np.array([np.cos(GAMMA), -np.sin(GAMMA)]) - TOE * s
        vankle = -TOE * ds
    hip, vhip = ankle - L * _e(st), vankle - L * _de(st, dst)
    out = [(M_HIP, hip, vhip, 0.0, 0.0)]
    for ang, dang in ((st, dst), (sw, dsw)):
        out.append((M_LEG, hip + D_LEG * _e(ang), vhip + D_LEG * _de(ang, dang), 0.0, 0.0))
    out.append((M_FOOT, ankle, vankle, I_FOOT, dth))  # the stance foot
    out.append((M_FOOT, hip + L * _e(sw), vhip + L * _de(sw, dsw), I_FOOT, dsw))  # swing
    return out


def _energy(x, pin="heel", trailing=None):
    """Kinetic + gravity + ankle spring [J]; ``trailing = (b, db)``: the swing foot on its
    toe in double support (its sole turning at ``dsw + db``, its spring deflected)."""
    bodies = _bodies(x, pin)
    if trailing is not None:
        m, r, v, i, _w = bodies[-1]
        bodies[-1] = (m, r, v, i, x[3] + trailing[1])
    e = sum(0.5 * m * v @ v + 0.5 * i * w * w + m * G * r[1] for m, r, v, i, w in bodies)
    e += 0.5 * K * (x[2] - REST) ** 2
    if trailing is not None:
        e += 0.5 * K * (trailing[0] - REST) ** 2
    return e


def _momentum_about(bodies, point):
    """Angular momentum about ``point`` [kg m^2/s]."""
    return sum(m * ((r - point)[0] * v[1] - (r - point)[1] * v[0]) + i * w
               for m, r, v, i, w in bodies)


def _flow_energy_drift(rhs, x0, t_end, pin="heel", trailing=None):
    """Peak-to-peak of the reference energy [J] along ``rhs``'s solution, and its start."""
    sol = solve_ivp(rhs, (0.0, t_end), x0, method="DOP853", rtol=1e-12, atol=1e-12,
                    dense_output=True)
    assert sol.success
    ts = np.linspace(0.0, t_end, 21)
    e = [_energy(sol.sol(t), pin, None if trailing is None else trailing(sol.sol(t)))
         for t in ts]
    return float(np.ptp(e)), e[0]


X_HEEL = np.array([-0.30, 0.22, 0.03, -1.3, -1.2, -8.0])


def _heel_strike_state(st, a, dq):
    """A heel-off state (toe pinned) whose swing heel is on the slope: the swing angle by
    bisection on the reference geometry."""
    from scipy.optimize import brentq

    n = np.array([np.sin(GAMMA), np.cos(GAMMA)])

    def heel_height(sw):
        swing_ankle = _bodies(np.array([sw, st, a, 0, 0, 0]), "toe")[4][1]
        return float((swing_ankle - HEEL * np.array([np.cos(sw), np.sin(sw)])) @ n)
    sw = brentq(heel_height, 0.05, 0.8)
    return np.array([sw, st, a, *dq])


X_STRIKE = _heel_strike_state(-0.36, -0.12, (-1.3, -1.3, 1.0))


def test_kinematics_reference_matches_the_generated_points(tmp_path):
    """The reference's geometry (:func:`_bodies`) is the generator's: hip, ankles and leg
    bodies at the same places, heel or toe pinned (the conventions the dynamics checks below
    rest on, not the dynamics)."""
    f = _undamped(tmp_path)
    for pin, x in (("heel", X_HEEL), ("toe", X_STRIKE)):
        pts = {k: np.asarray(v, float).ravel() for k, v in f["points"](x).items()}
        ref = _bodies(x, pin)
        for name, i in (("hip", 0), ("stance_mass", 1), ("swing_mass", 2),
                        ("stance_ankle", 3), ("swing_ankle", 4)):
            np.testing.assert_allclose(pts[name], ref[i][1], atol=1e-12, err_msg=name)
    # the state built for the heel strike has its swing heel on the slope
    assert f["guard_swing_heel_height_toe"](0.0, X_STRIKE) == pytest.approx(0.0, abs=1e-12)


@pytest.mark.parametrize("mode,pin,x0", [
    ("heel_contact", "heel", X_HEEL),
    ("heel_off", "toe", np.array([-0.10, -0.05, -0.15, -1.2, -1.1, -2.0])),
])
def test_undamped_pinned_flows_conserve_the_reference_energy(tmp_path, mode, pin, x0):
    """Heel contact and heel off with the damper off: the generated flow keeps the
    reference's energy (feet of 0.1 kg and 5e-4 kg m^2 included) to 1e-8 J over 0.15 s,
    while the foot's own terms are ~1e-3 J: a flow missing the foot's inertia or mass,
    or the reference with massless feet, drifts by more than 1e-5 J (checked below)."""
    f = _undamped(tmp_path)
    flow = f[f"flow_{mode}"]
    drift, e0 = _flow_energy_drift(flow, x0, 0.15, pin)
    assert drift < 1e-8, (drift, e0)
    # the check can fail: the generated massless-foot flow does not keep this energy
    g = _undamped(tmp_path, mass_kg=None, inertia_about_ankle_kg_m2=None)
    drift0, _ = _flow_energy_drift(g[f"flow_{mode}"], x0, 0.15, pin)
    assert drift0 > 1e-5


def test_undamped_double_support_conserves_the_reference_energy(tmp_path):
    """The closed chain (leading heel and trailing toe pinned) with the dampers off keeps
    the reference energy including the trailing sole's ``I (dsw + db)^2 / 2`` and its
    spring, ``b`` from the toe on the slope (the generator's ``double_support_trailing``,
    geometry only): 1e-8 J over 10 ms of double support, from a heel strike and the
    toe-pinning entry (the trailing toe's impulse pushes: a double support)."""
    f = _undamped(tmp_path)
    x = f["reset_heel_strike_toe"](X_STRIKE)
    x, (lam_n, _lam_t) = f["double_support_heel_contact_entry"](x)
    assert lam_n > 0

    def trailing(xs):
        return f["double_support_trailing"](xs)[:2]
    drift, e0 = _flow_energy_drift(f["flow_double_support_heel_contact"], x, 0.01,
                                   "heel", trailing)
    assert drift < 1e-8, (drift, e0)
    # the trailing toe stays on the slope (the constraint the flow holds)
    sol = solve_ivp(f["flow_double_support_heel_contact"], (0, 0.01), x, method="DOP853",
                    rtol=1e-12, atol=1e-12)
    sw, b = sol.y[0, -1], f["double_support_trailing"](sol.y[:, -1])[0]
    toe = _bodies(sol.y[:, -1])[4][1] + TOE * np.array([np.cos(sw + b), np.sin(sw + b)])
    assert float(toe @ np.array([np.sin(GAMMA), np.cos(GAMMA)])) == pytest.approx(0, abs=1e-9)


def test_heel_strike_conserves_angular_momentum_about_the_striking_heel(tmp_path):
    """The plastic heel strike's impulse acts at the striking heel only (the trailing foot
    released): the angular momentum about that heel, summed here over the bodies (feet
    included: 0.1 kg at each ankle, 5e-4 kg m^2 about it), is the same before and after
    (roles swapped; the new stance heel at the origin of the post-impact kinematics), to
    1e-12 relative.  The heel strike of massless feet misses it (by > 1e-4 kg m^2/s)."""
    f = _undamped(tmp_path)
    assert X_STRIKE[1] + X_STRIKE[2] + GAMMA < 0  # heel off: the toe pinned
    pre = _bodies(X_STRIKE, "toe")
    sw = X_STRIKE[0]
    strike = pre[4][1] - HEEL * np.array([np.cos(sw + REST), np.sin(sw + REST)])
    h_pre = _momentum_about(pre, strike)
    post = f["reset_heel_strike_toe"](X_STRIKE)
    assert post[2] == REST  # the new stance foot lands at its rest angle
    assert _momentum_about(_bodies(post, "heel"), np.zeros(2)) == pytest.approx(h_pre,
                                                                                 rel=1e-12)
    g = _undamped(tmp_path, mass_kg=None, inertia_about_ankle_kg_m2=None)
    h0 = _momentum_about(_bodies(g["reset_heel_strike_toe"](X_STRIKE), "heel"), np.zeros(2))
    assert abs(h0 - h_pre) > 1e-4


def test_feet_of_vanishing_mass_give_the_massless_walker(tmp_path):
    """The limit ``m_foot, I_foot -> 0`` (1e-7 kg, 1e-10 kg m^2) is the massless model: the
    heel strike and the double support's toe-pinning entry (on ``(q, b)`` with mass, in
    ``q`` through the ankle without) agree to 1e-5 rad/s and N s, and the gait's step
    period is configs/flat_feet.yaml's 0.81016 s to 1e-5 s (0.8290 s with 0.1 kg feet)."""
    from walkerlab.analysis.contact.periodic import ideal_gait

    light = _undamped(tmp_path, mass_kg=1e-7, inertia_about_ankle_kg_m2=1e-10)
    none = _undamped(tmp_path, mass_kg=None, inertia_about_ankle_kg_m2=None)
    x_l, x_n = (f["reset_heel_strike_toe"](X_STRIKE) for f in (light, none))
    np.testing.assert_allclose(x_l, x_n, atol=1e-5)
    (e_l, i_l), (e_n, i_n) = (f["double_support_heel_contact_entry"](x_n)
                              for f in (light, none))
    np.testing.assert_allclose(e_l, e_n, atol=1e-5)
    np.testing.assert_allclose(i_l, i_n, atol=1e-5)
    scene = load_scene(_scene_with(tmp_path, lambda d: d["walker"]["leg"]["foot"].update(
        mass_kg=1e-7, inertia_about_ankle_kg_m2=1e-10)))
    assert float(ideal_gait(scene,
            plant=Plant.from_scene(scene)).period_s) == pytest.approx(0.8101592422, abs=1e-5)


def test_energy_ledger_closes_with_the_feet_kinetic_energy(tmp_path):
    """walkerlab simulate's per-step ledger closes (dE equals the dampers' work less the
    impacts' losses to 1e-9 J) with feet of mass: the trailing sole's kinetic energy
    beyond turning with its leg, which the walker's energies leave out in double support,
    is held with its spring's and lost with it at toe off (without it the ledger missed
    5.5 mJ a step)."""
    import h5py

    from tests.cli_run import run_cli

    code, err, _out = run_cli("-q", "simulate", SCENE, "--runs-dir", tmp_path)
    assert code == 0, err
    with h5py.File(tmp_path / "flat_feet_foot_mass" / "simulate.h5") as f:
        closure = f["ledger/closure"][()]
        loss = f["ledger/heel_strike_loss"][()]
    assert np.max(np.abs(closure)) < 1e-9
    assert np.all(loss > 0.5)


def _scene_with(tmp_path, edit):
    d = yaml.safe_load(SCENE.read_text())
    edit(d)
    p = tmp_path / "edited.yaml"
    p.write_text(yaml.safe_dump(d))
    return p


@pytest.mark.parametrize("edit,key", [
    (lambda d: d["contact"].update(flat_foot_mass_kg=0.1, flat_foot_inertia_kg_m2=5e-4),
     "contact.flat_foot_mass_kg"),
    (lambda d: d["walker"]["leg"]["foot"].pop("inertia_about_ankle_kg_m2"),
     "inertia_about_ankle_kg_m2"),
    (lambda d: d["walker"].update(legs=[d["walker"]["leg"], {
        **d["walker"]["leg"], "foot": {**d["walker"]["leg"]["foot"], "mass_kg": 0.2}}])
     or d["walker"].pop("leg"), "mass_kg"),
])
def test_a_second_or_half_given_foot_mass_is_refused_in_one_line(tmp_path, edit, key):
    """The contact section's regularising foot beside the walker's own feet, a mass
    without its inertia, legs whose feet differ in mass: one line naming the key."""
    from tests.cli_run import run_cli

    code, err, _out = run_cli("fixedpoint", _scene_with(tmp_path, edit), "--runs-dir",
                              tmp_path)
    assert code != 0 and key in err and "Traceback" not in err
    assert len(err.splitlines()) == 1, err


def test_massless_feet_keep_their_structure_key_and_parameters():
    """A scene that leaves the foot's mass unset is the massless walker it was: the same
    structure key (the generated code's cache key) and parameter vector as before the
    fields existed (configs/flat_feet.yaml's artifacts stay bit-identical); with the mass,
    the rigid view's parameters end the feet's block with ``m_foot``, ``I_foot`` and the
    walker's mass counts both feet."""
    old = load_scene(ROOT / "configs" / "flat_feet.yaml")
    d = walker_data(old.walker, old.slope.angle_rad)
    assert "foot_mass" not in d.structure.key() and "m_foot" not in d.structure.param_names
    assert "mass_kg" not in old.model_dump()["walker"]["leg"]["foot"]
    new = load_scene(SCENE)
    e = walker_data(new.walker, new.slope.angle_rad)
    assert e.structure.param_names == d.structure.param_names + ("m_foot", "I_foot")
    assert e.params == d.params + (0.1, 5e-4)
    assert e.total_mass_kg == pytest.approx(d.total_mass_kg + 0.2)


@pytest.mark.slow
def test_rigid_contact_and_mujoco_agree_within_one_percent_on_feet_with_mass(tmp_path):
    """configs/flat_feet_foot_mass.yaml (0.1 kg feet in every view): rigid step period
    0.8290 s; the contact run from its own periodic gait (patches at its footfalls) walks
    the 5 strides asked for (11 heel strikes), each full step 0.8224-0.8229 s (-0.77 %),
    its periodic gait 0.8226 s; MuJoCo 0.8256 s (-0.41 %) over 11 heel strikes.  With the
    0.1 kg feet in the contact and MJCF views only (configs/flat_feet.yaml) they are +1.5 %
    and +1.94 % off the massless rigid gait (tests/test_export_flat_feet.py).  ~90 s."""
    import h5py

    from tests.cli_run import run_cli
    from walkerlab.analysis.contact.periodic import ideal_gait

    scene = load_scene(SCENE)
    rigid = float(ideal_gait(scene, plant=Plant.from_scene(scene)).period_s)
    assert rigid == pytest.approx(0.8290, abs=1e-4)
    code, err, _out = run_cli("-q", "contact-sim", SCENE, "--runs-dir", tmp_path)
    assert code == 0, err
    with h5py.File(tmp_path / "flat_feet_foot_mass" / "contact_sim.h5") as f:
        periods = f["steps/period"][()]
        gait = float(f["periodic_gait/step_period"][()])
    full = periods[1:][np.isfinite(periods[1:])]  # the first starts at mid-stance
    assert len(full) >= 2 * 5  # 5 strides after the first half step
    np.testing.assert_allclose(full, rigid, rtol=0.01)
    assert gait == pytest.approx(rigid, rel=0.01)
    mujoco = pytest.importorskip("mujoco")
    assert mujoco is not None
    from walkerlab.export.mujoco_walk import walk
    from walkerlab.stages import export as export_stage

    run = walk(export_stage.run(scene, tmp_path / "mjcf", "mjcf"), 9.2)
    assert not run.fell and run.alternating and len(run.times_s) >= 10
    assert run.step_periods_s.mean() == pytest.approx(rigid, rel=0.01)
