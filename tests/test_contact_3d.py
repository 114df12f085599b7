"""The compliant-contact model of walkers in 3D against an independent Newton model and
against the planar contact model it contains.

* ``tests/independent/floating_3d_contact.py`` writes the 3D compass walker with hip width
  (configs/hip_width.yaml) set free on the ground from its point masses, with the contact
  law (IMPACT normal force, Adams Coulomb friction against the slip velocity in the
  tangent plane, torsional friction about the normal) implemented again from the Adams
  formulas: the contact flow ``cw.rhs`` must be its, at states where both feet are loaded
  and slip and spin in each regime of the friction law.
* A 3D walker of zero hip width (configs/paper_3d.yaml) moving in its sagittal plane is
  the planar walker (configs/paper.yaml) under the same contact law: equal sagittal
  accelerations, no lateral ones.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import brentq

from tests.independent.floating_3d_contact import Floating3DContact
from walkerlab.analysis.contact.start import initial_state_from_ideal
from walkerlab.analysis.gait.scene import initial_guess
from walkerlab.config import ContactSettings, load_scene
from walkerlab.models.contact import assembly as A
from walkerlab.models.contact.scene import contact_setup
from walkerlab.models.registry import build_walker
from walkerlab.walker.plant import Plant

#: walkerlab's floating coordinates of a 3D compass walker -> the reference's index
#: (tests/independent/floating_3d_contact.COORDINATES)
TO_REF = {"leg2_foot_x": 0, "leg2_foot_y": 1, "leg2_foot_z": 2, "heading": 3,
          "leg2_roll": 4, "leg1_angle": 5, "leg2_angle": 6}


def _continuous(scene):
    """The scene on continuous ground (every foot below the slope plane in contact)."""
    return scene.model_copy(update={"terrain": scene.terrain_or_default().model_copy(
        update={"lanes": "continuous"})})


def _contact_walker(scene):
    """The scene's contact walker and its contact start state (the rigid initial guess's
    stance foot at its static penetration, at rest)."""
    plant = Plant.from_scene(scene)
    xi = np.asarray(initial_guess(scene, build_walker(plant)), float)
    cw, _ = contact_setup(scene, plant=plant).build(xi, 10)
    return cw, initial_state_from_ideal(cw, *xi)


@pytest.fixture(scope="module")
def hip_width():
    """(contact walker, its start state, the reference, permutation walkerlab -> ref)."""
    # the ADAMS View defaults (stiction 0.1 m/s, friction 1 m/s), the regimes STATES are
    # laid out for, not the scene's law
    scene = load_scene("configs/hip_width.yaml").model_copy(
        update={"contact": ContactSettings()})
    cw, x0 = _contact_walker(_continuous(scene))
    names = cw.coordinate_names()
    assert set(names) == set(TO_REF)
    P = dict(zip(cw.structure.param_names, cw.walker_params))
    PC = cw.contact_params
    law = {"k": PC[A.I_K], "e": PC[A.I_E], "cmax": PC[A.I_CMAX], "dmax": PC[A.I_DMAX],
           "mus": PC[A.I_MUS], "mud": PC[A.I_MUD], "vs": PC[A.I_VS], "vd": PC[A.I_VD],
           "tau": PC[A.I_TOR]}
    assert law["tau"] > 0  # the default torsional coefficient: 0.05 leg lengths
    ref = Floating3DContact(P["g"], P["L"], P["gamma"], P["M_hip"], P["m_leg"],
                            P["a_leg"], P["w_hip"], law)
    perm = np.array([TO_REF[n] for n in names])  # walkerlab's coordinate i is ref's perm[i]
    return cw, x0, ref, perm


def _to_ref(x, perm):
    nq = len(perm)
    out = np.empty(2 * nq)
    out[perm], out[nq + perm] = x[:nq], x[nq:]
    return out


def _from_ref(xr, perm):
    nq = len(perm)
    return np.concatenate([xr[:nq][perm], xr[nq:][perm]])


def _double_support(ref, heading, lean, pitch2, depth, rate, slip, lean_rate):
    """A reference state (14,) with both feet in the ground: leg1's foot at penetration
    ``depth[0]``, leg2's at ``depth[1]`` [m] (leg1's pitch found by Brent's method), their
    penetration rates ``rate`` [m/s] and slip velocities ``slip`` ((2, 2): along the fall
    line and across it, [m/s]), the lean's rate ``lean_rate`` [rad/s]; the heading's and the
    legs' rates follow (a linear solve on the feet's Jacobians: the feet's lateral slips
    differ by the heading's rate times the feet's distance along the fall line, so the
    heading turns and the feet spin at about ``(slip1_z - slip2_z) / 0.36 m``)."""
    n, s, z = ref.n, ref.s, ref.z

    def rise(th1):  # leg1's foot above leg2's along n, less the depths' difference
        r = ref.positions(np.array([0, 0, 0, heading, lean, th1, pitch2]))
        return n @ (r["leg1_foot"] - r["leg2_foot"]) - (depth[1] - depth[0])
    th1 = brentq(rise, -pitch2 - 0.3, -pitch2 + 0.05)  # the trailing leg
    q = np.array([0, 0, 0, heading, lean, th1, pitch2], float)
    q[:3] = -depth[1] * n
    v = [-rate[k] * n + slip[k][0] * s + slip[k][1] * z for k in range(2)]
    A_ = np.vstack([ref.jacobian("leg1_foot", q), ref.jacobian("leg2_foot", q),
                    np.eye(7)[4]])
    dq = np.linalg.solve(A_, np.concatenate([v[0], v[1], [lean_rate]]))
    return np.concatenate([q, dq])


def _regime(speed, law):
    return ("rest" if speed == 0 else "stiction" if speed < law["vs"] else
            "transition" if speed < law["vd"] else "sliding")


#: name -> (heading, lean, pitch2, depths, penetration rates, slips (leg1, leg2) along and
#: across the fall line, lean rate), and the regimes expected of (leg1's slip, leg2's
#: slip, leg1's patch slip speed rho |spin|, leg2's); ADAMS default velocities: vs 0.1 m/s,
#: vd 1 m/s, rho = 0.05 / 0.9 m
STATES = {
    "creep": ((0.1, 0.03, 0.15, (8e-5, 1.2e-4), (0.002, -0.003),
               ((-0.02, 0.01), (0.03, 0.04)), 0.2),
              ("stiction", "stiction", "stiction", "stiction")),
    "lateral_skid": ((-0.2, -0.05, 0.18, (1.1e-4, 9e-5), (-0.004, 0.001),
                      ((0.4, -0.3), (0.2, 1.5)), -0.3),
                     ("transition", "sliding", "transition", "transition")),
    "spin": ((0.3, 0.02, 0.12, (6e-5, 1.3e-4), (0.0, 0.0),
              ((0.0, -3.5), (0.1, 3.5)), 0.1),
             ("sliding", "sliding", "sliding", "sliding")),
    "loaded_swing_foot": ((0.0, -0.01, 0.16, (1.5e-4, 3e-5), (0.01, 0.0),
                           ((0.1, -1.2), (0.05, -0.02)), -0.5),
                          ("sliding", "stiction", "transition", "transition")),
}


def _states(ref, x0, perm):
    """The contact start state and the double-support :data:`STATES`, each with its
    expected regimes (None: the start state, leg2 loaded at rest)."""
    out = {"start": (_to_ref(x0, perm), None)}
    for name, (args, regimes) in STATES.items():
        out[name] = (_double_support(ref, *args), regimes)
    return out


def test_the_3d_contact_flow_matches_an_independent_newton_model(hip_width):
    """``cw.rhs`` of configs/hip_width.yaml's contact walker (continuous ground) equals the
    independent Newton model's flow at the contact start state and at four double-support
    states whose feet slip (along and across the fall line) and spin in every regime of the
    Adams Coulomb law (at rest, below the stiction velocity, in the transition, above the
    friction velocity).  The reference's only approximation is its velocity-product term,
    a central difference of step 1e-6 s (its Jacobians are complex-step, exact to
    rounding): truncation ~ 2e-13 m |dq|^3 and rounding ~ 1e-10 |dr/dt| m/s^2, at the
    rates here (<= 23 rad/s) ~ 1e-11 of the largest acceleration (measured <= 2.5e-11; the
    error falls as the step squared down to 1e-6: 2.5e-9 at 1e-5); 1e-8 keeps a margin of
    400.  Checked by hand against a sabotaged assembly (numba off, a private cache):
    without the torsional moment the flow differs by 7e-3 (start) to 0.27 relative, with
    the lateral friction's sign flipped by 1.1 to 1.7 at the four slipping states."""
    cw, x0, ref, perm = hip_width
    law = ref.law
    nq = len(perm)
    worst = 0.0
    for name, (xr, regimes) in _states(ref, x0, perm).items():
        c = [ref.foot_contact(xr[:7], xr[7:], leg) for leg in (1, 2)]
        if regimes is None:
            assert c[1]["fn"] > 0 and c[1]["slip"] == 0, name
        else:  # both feet loaded, their slip and spin in the regimes the state is for
            assert c[0]["fn"] > 0 and c[1]["fn"] > 0, name
            rho = law["tau"] / law["mus"]
            got = (_regime(c[0]["slip"], law), _regime(c[1]["slip"], law),
                   _regime(rho * abs(c[0]["spin"]), law), _regime(rho * abs(c[1]["spin"]), law))
            assert got == regimes, name
            assert np.all(np.abs(xr[7:]) < 30), name
        x = _from_ref(xr, perm)
        want = _from_ref(ref.rhs(0.0, xr), perm)[nq:]
        got_ = np.asarray(cw.rhs(0.0, x))[nq:]
        err = np.max(np.abs(got_ - want)) / np.max(np.abs(want))
        worst = max(worst, err)
        assert err < 1e-8, (name, err, got_, want)
    assert worst > 0  # two codes, not one


def test_the_held_heading_contact_flow_is_the_newton_models_with_its_heading_held(hip_width):
    """``contact.hold_heading``: configs/hip_width.yaml's contact walker on three slides (no
    heading coordinate) has the independent Newton model's flow with the heading's row and
    column removed, at the double-support states of :data:`STATES` turned to heading 0 and
    its rate 0 (the feet then slip and spin otherwise, both loaded), relative 1e-8 as the
    free-heading test; the torsional friction acts through the feet's spin with the lean
    and pitch rates alone."""
    cw, _x0, ref, perm = hip_width
    scene = load_scene("configs/hip_width.yaml").model_copy(
        update={"contact": ContactSettings(hold_heading=True)})
    held, _ = _contact_walker(_continuous(scene))
    names = held.coordinate_names()
    assert names == tuple(n for n in cw.coordinate_names() if n != "heading")
    perm_held = np.array([TO_REF[n] for n in names])
    for name, (args, _regimes) in STATES.items():
        xr = _double_support(ref, 0.0, *args[1:])
        xr[7 + 3] = 0.0   # the heading's rate
        c = [ref.foot_contact(xr[:7], xr[7:], leg) for leg in (1, 2)]
        assert c[0]["fn"] > 0 and c[1]["fn"] > 0 and abs(c[1]["spin"]) > 0, name
        x = np.concatenate([xr[:7][perm_held], xr[7:][perm_held]])
        want = ref.accelerations(xr, held=(3,))[[k - (k > 3) for k in perm_held]]
        got = np.asarray(held.rhs(0.0, x))[len(names):]
        assert np.max(np.abs(got - want)) / np.max(np.abs(want)) < 1e-8, (name, got, want)


def test_hold_heading_is_refused_in_one_line_where_there_is_no_heading(tmp_path):
    """A planar walker and a 3D spoked wheel (whose heading is a rigid coordinate) refuse
    ``contact.hold_heading`` in one line naming it, as the scene loader reports it."""
    import yaml

    for name in ("paper", "rimless_wheel_3d"):
        raw = yaml.safe_load(Path(f"configs/{name}.yaml").read_text())
        raw.setdefault("contact", {})["hold_heading"] = True
        path = tmp_path / f"{name}.yaml"
        path.write_text(yaml.safe_dump(raw))
        with pytest.raises(ValueError, match="contact.hold_heading") as err:
            load_scene(path)
        assert "\n" not in str(err.value)


def _planar_and_3d():
    """configs/paper.yaml's and configs/paper_3d.yaml's contact walkers under paper.yaml's
    contact law on continuous ground, and the planar contact start state."""
    planar = _continuous(load_scene("configs/paper.yaml"))
    spatial = load_scene("configs/paper_3d.yaml").model_copy(
        update={"contact": planar.contact, "terrain": planar.terrain})
    cp, xp = _contact_walker(planar)
    c3, _ = _contact_walker(spatial)
    return cp, xp, c3


def _lift(xp, names_p, names_3d, L):
    """The 3D state of a planar contact state (hip position, leg angles and rates), no
    lateral motion: leg2's foot at ``hip + L (sin th2, -cos th2)``."""
    q = dict(zip(names_p, xp[:4]))
    dq = dict(zip(names_p, xp[4:]))
    th2, w2 = q["leg2_angle"], dq["leg2_angle"]
    foot = np.array([q["hip_x"] + L * np.sin(th2), q["hip_y"] - L * np.cos(th2)])
    vfoot = np.array([dq["hip_x"] + L * w2 * np.cos(th2), dq["hip_y"] + L * w2 * np.sin(th2)])
    q3 = {"leg2_foot_x": foot[0], "leg2_foot_y": foot[1], "leg1_angle": q["leg1_angle"],
          "leg2_angle": th2}
    dq3 = {"leg2_foot_x": vfoot[0], "leg2_foot_y": vfoot[1], "leg1_angle": dq["leg1_angle"],
           "leg2_angle": w2}
    return np.array([q3.get(n, 0.0) for n in names_3d] + [dq3.get(n, 0.0) for n in names_3d])


def test_a_3d_walker_without_hip_width_has_the_planar_contact_flow():
    """configs/paper_3d.yaml (hip width 0) in its sagittal plane is configs/paper.yaml's
    walker: at the planar contact start state and at a double-support state whose feet slip
    (leg2 in the friction law's transition, leg1 above the friction velocity), lifted to 3D
    with no lateral motion, the 3D contact model's hip and leg accelerations are the planar
    contact model's to 1e-9 relative (two generated codes of one law: rounding, measured
    <= 7e-13) and its lateral, roll and heading accelerations vanish (< 1e-12 of the
    largest; the torsional friction sees no spin)."""
    cp, xp, c3 = _planar_and_3d()
    names_p, names_3 = cp.coordinate_names(), c3.coordinate_names()
    assert set(names_p) == {"hip_x", "hip_y", "leg1_angle", "leg2_angle"}
    L = dict(zip(c3.structure.param_names, c3.walker_params))["L"]
    # double support: the hip lowered so both feet are in; leg2's foot slipping at 0.05 m/s
    # (vs 0.01, vd 0.1 m/s) and leg1's foot at the rate that keeps it pressed in
    slipping = xp.copy()
    i = {n: k for k, n in enumerate(names_p)}
    slipping[i["hip_y"]] -= 6e-5
    n = np.array([np.sin(0.0174), np.cos(0.0174)])
    t = np.array([n[1], -n[0]])
    th1, th2 = slipping[i["leg1_angle"]], slipping[i["leg2_angle"]]
    w2 = slipping[4 + i["leg2_angle"]]
    v_foot2 = 0.05 * t + 0.001 * (-n)
    v_hip = v_foot2 - L * w2 * np.array([np.cos(th2), np.sin(th2)])
    # leg1's foot: penetration rate 0.002 m/s
    w1 = (-0.002 - n @ v_hip) / (L * n @ np.array([np.cos(th1), np.sin(th1)]))
    slipping[4 + i["hip_x"]], slipping[4 + i["hip_y"]] = v_hip
    slipping[4 + i["leg1_angle"]] = w1
    for name, x in (("start", xp), ("slipping", slipping)):
        table = cp.contact_quantities(x[None, :])
        loaded = [float(table[leg]["normal_force"][0]) > 0 for leg in ("leg1", "leg2")]
        assert loaded == ([False, True] if name == "start" else [True, True]), name
        ap = np.asarray(cp.rhs(0.0, x))[4:]
        x3 = _lift(x, names_p, names_3, L)
        a3 = dict(zip(names_3, np.asarray(c3.rhs(0.0, x3))[len(names_3):]))
        q3 = dict(zip(names_3, x3[:len(names_3)]))
        dq3 = dict(zip(names_3, x3[len(names_3):]))
        th2, w2, al2 = q3["leg2_angle"], dq3["leg2_angle"], a3["leg2_angle"]
        # the hip's acceleration from leg2's foot's: hip = foot2 + L (-sin th2, cos th2)
        hip = (np.array([a3["leg2_foot_x"], a3["leg2_foot_y"]])
               + L * al2 * np.array([-np.cos(th2), -np.sin(th2)])
               + L * w2 ** 2 * np.array([np.sin(th2), -np.cos(th2)]))
        lifted = dict(zip(("hip_x", "hip_y"), hip), leg1_angle=a3["leg1_angle"],
                      leg2_angle=al2)
        want = dict(zip(names_p, ap))
        scale = max(abs(v) for v in want.values())
        err = max(abs(lifted[k] - want[k]) for k in want) / scale
        assert err < 1e-9, (name, err, lifted, want)
        for k in ("leg2_foot_z", "heading", "leg2_roll"):
            assert abs(a3[k]) < 1e-12 * scale, (name, k, a3[k])


# ---------------------------------------------------------------------------- shipped walks
def _contact_run(name: str, tmp_path, strides: int = 5):
    """``walkerlab contact-sim configs/<name>.yaml --strides <strides>``: (its outcome's
    failure or None, the step periods [s], the heel strikes, the rigid step period [s])."""
    import h5py

    from walkerlab.stages import pipeline

    out = pipeline.run("contact-sim", load_scene(f"configs/{name}.yaml"), tmp_path,
                       strides=strides)
    with h5py.File(out.path) as f:
        periods = np.asarray(f["steps/period"][()], float)
        strikes = int(f["summary/heel_strikes"][()])
    with h5py.File(tmp_path / name / "fixedpoint.h5") as f:
        rigid = float(f["step_period"][()])
    return out.failure, periods[np.isfinite(periods)], strikes, rigid


@pytest.mark.slow
def test_the_hip_roll_walker_walks_in_contact_at_its_rigid_step_period(tmp_path):
    """configs/hip_width_stabilised.yaml (Kuo 1999's lateral foot placement at the hips,
    the paper's contact law, torsional friction 0.05 m at the feet): five strides on the
    checkerboard, every heel strike of them, and the last four steps' mean period within
    1 % of the rigid gait's (measured: 0.9976 of it, the spread over the run 0.6 %: the
    contact start's transient; the law blends the legs by their load share only through
    the double support)."""
    failure, periods, strikes, rigid = _contact_run("hip_width_stabilised", tmp_path)
    assert not failure
    assert strikes >= 10
    assert abs(periods[-4:].mean() / rigid - 1.0) < 0.01


@pytest.mark.slow
def test_the_passive_3d_walker_capsizes_in_contact_as_its_lateral_multiplier_says(tmp_path):
    """configs/hip_width.yaml: its rigid gait's lateral multiplier is ~100 a stride, so the
    contact walker, started a little off it (the foot's static penetration), leaves it
    within a few steps and goes down sideways; the run says so (measured: 3 heel strikes,
    capsized to the right, 60 deg from the normal)."""
    failure, _, strikes, _ = _contact_run("hip_width", tmp_path)
    assert failure and strikes <= 6
    assert "capsized sideways" in failure and "Floquet multiplier" in failure


# ---------------------------------------------------------------- the spoked wheel in 3D
def _wheel(scene):
    """(contact walker of the 3D wheel ``scene`` with the ADAMS defaults and a torsional
    coefficient 0.05 m, its start state, the Newton-Euler reference)."""
    from tests.independent.wheel_3d_contact import Wheel3DContact

    scene = scene.model_copy(update={"contact": ContactSettings(
        torsional_friction_m=0.05)})
    cw, x0 = _contact_walker(scene)
    P = dict(zip(cw.structure.param_names, cw.walker_params))
    PC = cw.contact_params
    law = {"k": PC[A.I_K], "e": PC[A.I_E], "cmax": PC[A.I_CMAX], "dmax": PC[A.I_DMAX],
           "mus": PC[A.I_MUS], "mud": PC[A.I_MUD], "vs": PC[A.I_VS], "vd": PC[A.I_VD],
           "tau": PC[A.I_TOR]}
    return cw, x0, Wheel3DContact(P["g"], P["L"], P["gamma"], P["M_hub"], P["I_hub"],
                                  P["I_diam"], cw.structure.spokes, law)


def _two_tips(ref, heading, lean, depth, slip, slip_dir, rates):
    """A state with spokes 0 and n-1 level (the wheel's angle ``alpha - gamma``: their
    tips are level at every heading and lean) ``depth`` [m] into the slope, every tip
    sliding at ``slip`` [m/s] along ``slip_dir`` [rad] from the fall line (plus the
    rotation's share) and spoke 0's tip penetrating at 1e-4 m/s; ``rates`` the heading's,
    lean's and wheel's [rad/s]."""
    alpha = np.pi / ref.spokes
    q = np.r_[-depth * ref.n, heading, lean, alpha - ref.gamma]
    dq = np.r_[np.zeros(3), rates]
    J0 = ref.jacobian(lambda qq: ref.tip(qq, 0), q)
    v0 = J0 @ dq
    want = slip * (np.cos(slip_dir) * ref.s + np.sin(slip_dir) * ref.z) - 1e-4 * ref.n
    dq[:3] = want - (v0 - (v0 @ ref.n) * ref.n) - (v0 @ ref.n) * ref.n
    return np.r_[q, dq]


def test_the_3d_wheel_contact_flow_matches_an_independent_newton_euler_model():
    """``cw.rhs`` of the 3D disc wheel (configs/rimless_wheel_3d_disc.yaml; ADAMS View
    friction 0.1 / 1 m/s, torsional coefficient 0.05 m) against the Newton-Euler model of
    one rigid body (tests/independent/wheel_3d_contact.py) at the contact start and at
    states with two spokes loaded, leaning and heading off the fall line, their tips
    slipping in each regime of the friction law (0.01, 0.5, 2 m/s) and spinning about the
    normal in each regime of the torsional law (rho |w| = 0.03, 0.28, 0.9 m/s).  The
    reference's error (complex step exact; the central difference of its velocity-product
    terms ~1e-12) bounds the agreement: measured <= 3e-11 relative."""
    cw, x0, ref = _wheel(load_scene("configs/rimless_wheel_3d_disc.yaml"))
    assert cw.coordinate_names() == ("spoke0_foot_x", "spoke0_foot_y", "spoke0_foot_z",
                                     "heading", "lean", "wheel_angle")
    states = [x0,
              _two_tips(ref, 0.0, 0.0, 5e-5, 0.01, 0.0, (0.5, 1e-4, -2e-4)),
              _two_tips(ref, 0.3, 0.1, 6e-5, 0.5, 0.8, (5.0, -2e-4, 1e-4)),
              _two_tips(ref, -0.5, -0.2, 4e-5, 2.0, -1.9, (-16.0, 3e-4, 2e-4))]
    for x in states:
        loaded = [ref.tip_contact(x[:6], x[6:], k)["fn"] > 0 for k in range(ref.spokes)]
        if x is not x0:
            assert loaded[0] and loaded[-1]
        a, b = cw.rhs(0.0, x), ref.rhs(0.0, x)
        assert np.abs(a - b).max() <= 1e-8 * np.abs(b).max(), (a - b, b)


def _contact_sim(scene_path, runs, *args):
    """Run ``walkerlab contact-sim`` on ``scene_path`` into ``runs``; the artifacts' folder."""
    import shutil
    import subprocess
    from pathlib import Path

    subprocess.run([shutil.which("walkerlab"), "contact-sim", str(scene_path),
                    "--runs-dir", str(runs), *args], check=True, capture_output=True)
    return Path(runs) / Path(scene_path).stem


@pytest.mark.slow
@pytest.mark.parametrize("angle_rad", [0.2, 0.25])
def test_the_3d_disc_wheel_rolls_in_contact_at_the_rigid_step_period(tmp_path, angle_rad):
    """configs/rimless_wheel_3d_disc.yaml (stable above its critical slope, 0.18-0.2 rad)
    and a variant on 0.25 rad: 5 strides of the contact run are >= 10 spoke touchdowns,
    and the last four steps' mean period is the rigid gait's ``step_period`` within 1 %
    (measured -0.028 % at 0.2 rad, -0.097 % at 0.25 rad)."""
    from pathlib import Path

    import h5py

    text = Path("configs/rimless_wheel_3d_disc.yaml").read_text()
    if angle_rad != 0.2:  # the rigid gait's guess follows the slope: alpha - slope
        text = text.replace("  angle_rad: 0.2\n", f"  angle_rad: {angle_rad}\n").replace(
            "stance_angle_rad: 0.1927", f"stance_angle_rad: {np.pi / 8 - angle_rad:.4f}")
    scene = tmp_path / f"disc_{int(angle_rad * 100)}.yaml"
    scene.write_text(text)
    out = _contact_sim(scene, tmp_path / "runs", "--strides", "5")
    with h5py.File(out / "fixedpoint.h5") as f:
        period = float(f["step_period"][()])
    with h5py.File(out / "contact_sim.h5") as f:
        strikes = f["events/heel_strike_times"][()]
    assert strikes.size >= 10
    steps = np.diff(strikes)
    assert abs(steps[-4:].mean() / period - 1.0) < 0.01, (steps, period)


@pytest.mark.slow
def test_the_unstable_3d_wheel_capsizes_sideways_in_contact():
    """configs/rimless_wheel_3d.yaml (lateral Floquet multiplier 22.4): from its rigid gait
    with a lean rate of 0.05 rad/s the contact run falls within its first steps (measured:
    after 1 heel strike, t = 1.65 s) and names how: capsized sideways, the hub 60 deg from
    the slope's normal beside its stance spoke's tip.  (Unperturbed the lean grows x23 a
    step from 1e-26 rad, as the rigid gait's multiplier says.)"""

    from walkerlab.analysis.contact.record import contact_walk
    from walkerlab.models.contact.scene import contact_setup as setup_of

    scene = load_scene("configs/rimless_wheel_3d.yaml")
    plant = Plant.from_scene(scene)
    x = np.asarray(initial_guess(scene, build_walker(plant)), float)
    names = build_walker(plant).state_names()
    x[list(names).index("lean_rate")] += 0.05
    walker, res, *_ = contact_walk(setup_of(scene, plant=plant), x, 1.04)
    assert res.termination == "fall"
    assert len(res.heel_strike_times) <= 4
    how = walker.fall_how(res.x[-1])
    assert how.startswith("capsized sideways: the hub") and "stance spoke's tip" in how


@pytest.mark.slow
def test_the_shipped_unstable_3d_wheel_falls_in_contact_from_its_start_offset(tmp_path):
    """``walkerlab contact-sim configs/rimless_wheel_3d.yaml``: its scene starts the contact
    run with a lean rate of 0.05 rad/s (``contact_sim.start_offset``; exactly upright the
    lean grows from round-off only), and the run ends in a fall within its first steps,
    named (measured: capsized sideways after 1 heel strike, t = 1.65 s)."""
    failure, _, strikes, _ = _contact_run("rimless_wheel_3d", tmp_path)
    assert failure and strikes <= 4
    assert "capsized sideways" in failure and "Floquet multiplier" in failure


def test_a_start_offset_names_the_rigid_states_or_is_refused_in_one_line():
    """``contact_sim.start_offset`` adds to the named rigid states only (0 elsewhere); a
    name that is not one of the walker's states is refused naming the field and listing
    the states, an unparseable one by the scene's check."""
    from walkerlab.config.studies import StateOffset

    names = ["heading_angle", "lean_angle", "stance_angle", "heading_rate", "lean_rate",
             "stance_rate"]
    off = StateOffset.model_validate({"lean_rate_rad_per_s": 0.05, "lean_angle_rad": -0.01})
    np.testing.assert_array_equal(off.as_array(names), [0, -0.01, 0, 0, 0.05, 0])
    with pytest.raises(ValueError, match="tilt_rate_rad_per_s: not a state of the walker "
                                         r"\(its states: <role>_angle_rad and "
                                         r"<role>_rate_rad_per_s of the roles heading, "
                                         r"lean, stance\)$"):
        StateOffset.model_validate({"tilt_rate_rad_per_s": 1.0}).as_array(names)
    scene = load_scene("configs/rimless_wheel_3d.yaml")
    d = scene.model_dump(mode="json", exclude_none=True)
    d["contact_sim"]["start_offset"] = {"lean_rate": 0.05}
    from walkerlab.config import Scene

    with pytest.raises(ValueError, match="(?s)start_offset.*lean_rate: not a state name"):
        Scene.model_validate(d)


def test_a_3d_walkers_pinned_start_is_refused_in_one_line():
    """The pinned start phase (planar walkers': it holds the stance foot's slides, not its
    turn, and carries no hip-roll law) is refused by the scene check, before any model is
    built."""
    from walkerlab.config.contact_sim import ContactSimSettings
    from walkerlab.models.contact.scene import ContactSceneError

    scene = load_scene("configs/hip_width_stabilised.yaml")
    plant = Plant.from_scene(scene)
    bad = scene.model_copy(update={"contact_sim": ContactSimSettings(
        pin_stance_until="first_touchdown")})
    with pytest.raises(ContactSceneError, match="pin_stance_until") as exc:
        contact_setup(bad, plant=plant)
    assert "\n" not in str(exc.value)


# ---------------------------------------------------------------- the periodic gait in 3D
def _stride_map():
    """The contact periodic gait's map of configs/hip_width_stabilised.yaml at its search's
    tolerances, and the rigid gait's post-impact state."""
    from walkerlab.analysis.contact.periodic import COARSE_SOLVER
    from walkerlab.analysis.contact.step_map import StepMap

    scene = load_scene("configs/hip_width_stabilised.yaml")
    plant = Plant.from_scene(scene)
    xi = np.asarray(initial_guess(scene, build_walker(plant)), float)
    cw, _ = contact_setup(scene, plant=plant).build(xi, 10)
    return StepMap(cw, solver=COARSE_SOLVER), xi


def test_a_3d_walkers_contact_section_drops_the_ground_translations_and_round_trips():
    """The 3D section (leg2's mid-stance: the base is leg2's foot) has the stance pitch,
    the heading and the three rolls, the six rates and the stance foot's penetration and
    3-velocity (15 = 18 - the swing pitch - the two translations along the ground): a
    section state placed (``to_state``) reads back (``to_section``) to rounding, the
    stance foot at its penetration below s = 0; the same walker moved along the slope
    and across it has the same section state, with its along-slope position the shift;
    the map is a stride (its two steps mirror each other)."""
    P, xi = _stride_map()
    w = P.walker
    assert P.steps == w.steps_per_map == 2
    assert P.names == ("theta_stance", "heading", "phi2", "phi_pelvis", "phi1",
                       "dtheta_swing", "dtheta_stance", "dheading", "dphi2", "dphi_pelvis",
                       "dphi1", "delta_stance", "v_t_stance", "v_lat_stance",
                       "ddelta_stance")
    rng = np.random.default_rng(3)
    z = rng.normal(size=15) * 0.1
    z[11:] = [6e-5, 2e-4, -3e-4, 1e-5]
    x = P.to_state(z)
    p, v = w.foot_state(x, 1)
    assert np.allclose(p, -6e-5 * w.normal, atol=1e-17)
    assert np.allclose(v, 2e-4 * w.tangent - 3e-4 * np.array([0, 0, 1.0]) - 1e-5 * w.normal,
                       atol=1e-17)
    back, s = P.to_section(x, 1, 0)
    assert np.allclose(back, z, rtol=0, atol=1e-15) and abs(s) < 1e-15
    moved = x.copy()
    shift = 0.3 * w.tangent + np.array([0, 0, -0.2])
    moved[:3] += shift  # the base's slides: leg2's foot
    back, s = P.to_section(moved, 1, 0)
    assert np.allclose(back, z, rtol=0, atol=1e-15) and s == pytest.approx(0.3, abs=1e-15)


@pytest.mark.slow
def test_the_hip_roll_walkers_contact_periodic_gait_is_its_rigid_gait_within_a_percent():
    """The contact periodic gait of configs/hip_width_stabilised.yaml (the stride map from
    leg2's mid-stance), against the rigid gait the contact model does not compute: step
    period and step length within 1 % (measured -0.18 %, -0.85 %: the paper's 0.2 % on
    the slower contact), its slow Floquet multipliers those of the rigid stride within
    0.03 (measured 0.540 vs 0.546, 0.114±0.439j vs 0.099±0.434j, 0.339 vs 0.327, 0.0797
    vs 0.0798), plus one the rigid walker has not: the heading, which the rigid stance
    foot holds and the compliant one lets turn, near-neutral (1.0018 a stride)."""
    from walkerlab.analysis.contact.periodic import find_contact_periodic_gait, ideal_gait
    from walkerlab.analysis.contact.rigid_limit import match_multipliers

    P, xi = _stride_map()
    scene = load_scene("configs/hip_width_stabilised.yaml")
    rigid = ideal_gait(scene, Plant.from_scene(scene))
    g = find_contact_periodic_gait(P.walker, rigid.x)
    assert g.converged and g.steps_per_map == 2
    T_r = np.mean(rigid.step_periods_s)
    assert abs(g.period_s / T_r - 1) < 0.01
    assert abs(g.step_length_m / np.mean(rigid.step_lengths_m) - 1) < 0.01
    lam_r = rigid.multipliers_variational[np.abs(rigid.multipliers_variational) > 1e-3]
    assert len(lam_r) == 5
    matched = match_multipliers(g.multipliers, lam_r, free_modes=1)
    assert np.max(np.abs(matched - lam_r)) < 0.03
    heading = [m for m, name in zip(g.multipliers, g.multiplier_modes) if name == "heading"]
    assert len(heading) >= 1 and abs(heading[0] - 1.0) < 0.01
    assert g.patch_margin_m > 0


@pytest.mark.slow
def test_the_hip_roll_walkers_contact_gait_tends_to_the_rigid_gait_as_the_contact_stiffens():
    """The rigid-limit family (stiffness, damping and stiction velocity scaled together,
    :mod:`walkerlab.models.contact.rigid_limit`) on configs/hip_width_stabilised.yaml at
    1, 2 and 4 times the contact's stiffness: the contact periodic gait's step length and
    step period close on the rigid gait's monotonically. The step length's gap falls at
    the order of the family's stiction velocity, kappa^-1/2 (the stance foot's creep along,
    across and about the normal; measured 0.51 on each octave to 8), the period's faster
    than the impact's duration (1/(e+1) = 0.31; measured 0.74, 0.95, 1.56: a gap of two
    parts of opposite sign)."""
    from walkerlab.analysis.contact.periodic import ideal_gait
    from walkerlab.analysis.contact.rigid_limit import convergence, observed_order

    P, _ = _stride_map()
    scene = load_scene("configs/hip_width_stabilised.yaml")
    rigid = ideal_gait(scene, Plant.from_scene(scene))
    tab = convergence(P.walker, rigid, (1.0, 2.0, 4.0))
    assert tab.converged.all()
    assert tab.rigid_period_s == pytest.approx(np.mean(rigid.step_periods_s), rel=1e-12)
    step, period = np.abs(tab.step_gap_m), np.abs(tab.period_gap_s)
    assert np.all(np.diff(step) < 0) and np.all(np.diff(period) < 0)
    assert np.all(np.abs(observed_order(tab.kappa, tab.step_gap_m) - 0.5) < 0.1)
    assert np.all(observed_order(tab.kappa, tab.period_gap_s) > 0.5)


def test_a_planar_walkers_torsional_friction_is_refused_in_one_line():
    """``contact.torsional_friction_m`` acts about the ground's normal, which a planar
    walker's feet never turn about: on configs/paper.yaml it is refused, naming the field;
    on a 3D walker (configs/hip_width.yaml) it is taken."""
    from walkerlab.config import Scene

    for name, ok in (("paper", False), ("hip_width", True)):
        d = load_scene(f"configs/{name}.yaml").model_dump(mode="json", exclude_none=True)
        d["contact"]["torsional_friction_m"] = 0.03
        if ok:
            assert Scene.model_validate(d).contact.torsional_friction_m == 0.03
        else:
            with pytest.raises(ValueError, match="contact.torsional_friction_m: a planar "
                                                 "walker's feet hold no moment"):
                Scene.model_validate(d)
