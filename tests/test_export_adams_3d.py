"""``walkerlab export --format adm`` of a straight-legged walker in 3D
(:mod:`walkerlab.export.adams_3d`), read back by walkerlab's own reader
(:mod:`walkerlab.export.adams_reader`) and set against the rigid model at its fixed point.

References the writer does not compute: the parts' masses are the scene's numbers; their
centres of mass are the rigid model's generated ``points`` (in the exports' axes, z up:
``X = x, Y = -z, Z = y``, written out here); their velocities are central differences of
those positions along the gait's rates (step ``h = 1e-6 s``: truncation ~ h^2 |d^3p/dt^3|
~ 1e-12 m/s, roundoff ~ 1e-16 m / h = 1e-10 m/s); the kinetic energy is the rigid model's
``0.5 dq^T M(q) dq``.  Tolerances: the file writes every number with 17 significant digits,
converted m -> mm and rad -> deg, so positions come back within ~1e-12 m; 1e-9 (m, m/s,
relative) leaves the differences' error and the inertia floor (1e-12 kg m^2 on a point mass,
:data:`walkerlab.export.mjcf_scene.MJCF_MIN_INERTIA_KG_M2`, ~1e-13 of the kinetic energy)
room.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yaml

from walkerlab.config import load_scene
from walkerlab.export.adams_reader import parse_acf, read_adm
from walkerlab.models.contact.rigid_limit import contact_si
from walkerlab.stages import export as export_stage
from walkerlab.walker.description import state_names
from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]
TOL = 1e-9
#: walkerlab's world (x downhill, y up, z right) in the dataset's axes (x downhill, z up)
C = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])
FLOOR = 1e-12  # kg m^2: the export's inertia of a point mass about every axis


_EXPORTED: dict = {}


def _export(name, tmp_path_factory):
    """The scene's export read back, with its rigid gait (once a module)."""
    if name not in _EXPORTED:
        _EXPORTED[name] = _exported(name, tmp_path_factory)
    return _EXPORTED[name]


def _exported(name, tmp_path_factory):
    from walkerlab.analysis.contact.periodic import ideal_gait
    from walkerlab.codegen.cache import functions

    scene = load_scene(ROOT / "configs" / f"{name}.yaml")
    runs = tmp_path_factory.mktemp(f"adm3d_{name}")
    path = export_stage.run(scene, runs, "adm")
    plant = Plant.from_scene(scene)
    ideal = ideal_gait(scene, plant)
    return (scene, plant.data, functions(plant.data), ideal, read_adm(path.read_text()),
            path.read_text(), (path.parent / "walker.acf").read_text())


@pytest.fixture(scope="module", params=[
    "hip_width", "paper_3d", "torso_bhm_3d",
    pytest.param("hip_width_stabilised", marks=pytest.mark.slow)])  # its gait: ~20 s
def case(request, tmp_path_factory):
    return _export(request.param, tmp_path_factory)


#: the scenes' masses [kg] by PART: the hip (PART/2), leg1, leg2, an upper body (PART/5)
MASSES = {"hip_width": {2: 10.0, 3: 5.0, 4: 5.0}, "paper_3d": {2: 10.0, 3: 5.0, 4: 5.0},
          "torso_bhm_3d": {2: 10.0, 3: 5.0, 4: 5.0, 5: 5.0},
          "hip_width_stabilised": {2: 10.0, 3: 5.0, 4: 5.0}}
#: the pelvis' inertia [kg m^2] where it is not a point mass: hip_width_stabilised's
#: walker.hip_roll.pelvis_roll_inertia_kg_m2 about its roll axis (the one axis it turns
#: about: the export writes it about every axis, tree_bodies' rule for such a root)
PELVIS_INERTIA = {"hip_width_stabilised": 0.3}
#: the rigid model's point of each PART's centre of mass (leg1 swings at the start)
POINTS = {2: "hip", 3: "swing_mass", 4: "stance_mass", 5: "torso_mass"}


def _parts(scene):
    """PART id -> (the rigid point of its centre of mass, its mass from the scene [kg])."""
    return {pid: (POINTS[pid], m) for pid, m in MASSES[scene.name].items()}


def _finite_velocity(points, x, key, h=1e-6):
    n = x.size // 2
    xp, xm = x.copy(), x.copy()
    xp[:n] += h * x[n:]
    xm[:n] -= h * x[n:]
    return (np.ravel(points(xp)[key]) - np.ravel(points(xm)[key])) / (2 * h)


def test_a_3d_dataset_reads_back_the_walkers_masses_and_inertias(case):
    """Each part's mass is the scene's (legs 5 kg, hip 10 kg, an upper body 5 kg), the total
    the walker's; every body but a rolling pelvis is a point mass, so its inertia about its
    CM is the export's floor about every axis (in ground axes: a multiple of the identity);
    the hip-roll walker's pelvis carries its roll inertia."""
    scene, data, _f, _ideal, model, _adm, _acf = case
    parts = _parts(scene)
    assert sorted(p for p in model.by_kind["PART"] if p != 1) == sorted(parts)
    for pid, (_point, mass) in parts.items():
        assert model.part_mass(pid) == pytest.approx(mass, rel=1e-15)
        moment = PELVIS_INERTIA.get(scene.name, FLOOR) if pid == 2 else FLOOR
        np.testing.assert_allclose(model.part_inertia(pid), moment * np.eye(3), rtol=1e-12,
                                   atol=1e-6 * FLOOR)
    total = sum(model.part_mass(p) for p in parts)
    assert total == pytest.approx(data.total_mass_kg, rel=1e-15)


def test_a_3d_dataset_starts_at_the_rigid_gaits_positions_and_velocities(case):
    """Each part's centre of mass and CM velocity (VX, VY, VZ) are the rigid model's at the
    fixed point (positions: its points; velocities: central differences of them)."""
    scene, _data, f, ideal, model, _adm, _acf = case
    x = np.asarray(ideal.x, float)
    for pid, (point, _m) in _parts(scene).items():
        cm, _R = model.marker_pose(model.get("PART", pid).integer("CM"))
        np.testing.assert_allclose(cm, C @ np.ravel(f["points"](x)[point]), atol=TOL)
        v, _w = model.part_velocity(pid)
        np.testing.assert_allclose(v, C @ _finite_velocity(f["points"], x, point), atol=TOL)


def test_a_3d_datasets_kinetic_energy_is_the_rigid_models(case):
    """0.5 sum(m v^2 + w^T I w) over the dataset's parts equals 0.5 dq^T M(q) dq of the
    rigid model at the fixed point (relative 1e-9)."""
    scene, _data, f, ideal, model, _adm, _acf = case
    x = np.asarray(ideal.x, float)
    n = x.size // 2
    M = np.asarray(f["matrices"](x)[0], float).reshape(n, n)
    want = 0.5 * x[n:] @ M @ x[n:]
    got = 0.0
    for pid in _parts(scene):
        v, w = model.part_velocity(pid)
        got += 0.5 * model.part_mass(pid) * v @ v + 0.5 * w @ model.part_inertia(pid) @ w
    assert got == pytest.approx(want, rel=TOL)


def _roll(fall, angle):
    """Rotation (3, 3) by ``angle`` [rad] about the unit vector ``fall`` (Rodrigues)."""
    K = np.array([[0, -fall[2], fall[1]], [fall[2], 0, -fall[0]], [-fall[1], fall[0], 0]])
    return np.eye(3) + math.sin(angle) * K + (1 - math.cos(angle)) * K @ K


def test_a_3d_datasets_hips_feet_and_joint_axes_are_the_rigid_walkers(case):
    """Each hip joint's I and J markers coincide at the rigid hip, their z axes the rigid
    model's: a REVOLUTE's both along the hip axis ``Rot(s, lean) z`` (lateral, pitch); a
    hip-roll walker's UNIVERSAL the leg's pitch axis ``Rot(s, roll) z`` on the leg and the
    fall line ``s`` on the pelvis (its roll axis, the JPRIM's); the pelvis' FIXED markers
    coincide in pose and a JPRIM keeps leg2's hip axis perpendicular to the fall line (no
    yaw, as the rigid walker); the stance foot (the pin's marker) at the origin, the trailing
    foot at the rigid one; both foot spheres touch their lanes' patches (their centres
    r = L / 1000 above the top face)."""
    scene, data, f, ideal, model, _adm, _acf = case
    x = np.asarray(ideal.x, float)
    s = dict(zip(state_names(data.structure.roles), x))
    phi = data.slope_rad
    fall = np.array([math.cos(phi), -math.sin(phi), 0.0])
    z = np.array([0.0, 0.0, 1.0])
    rolled = data.structure.hip_roll
    pitch = {302: C @ _roll(fall, s["swing_roll_angle" if rolled else "lean_angle"]) @ z,
             402: C @ _roll(fall, s["lean_angle"]) @ z}
    hips = {302: "swing_hip", 402: "stance_hip"}
    pts = {k: C @ np.ravel(v) for k, v in f["points"](x).items()}
    joints = model.joints()
    hinged = {i: (t, j) for t, i, j in joints.values() if t in ("REVOLUTE", "UNIVERSAL")}
    assert set(hinged) == ({302, 402} if rolled else {302} | (
        {502} if data.structure.torso else set()))
    for i, (t, j) in hinged.items():
        (pi, Ri), (pj, Rj) = model.marker_pose(i), model.marker_pose(j)
        np.testing.assert_allclose(pi, pj, atol=TOL)
        axis = pitch.get(i, pitch[402])  # an upper body turns about the stance hip's axis
        assert abs(abs(Ri[:, 2] @ axis) - 1) < TOL, (i, Ri[:, 2], axis)
        if t == "REVOLUTE":
            assert abs(Rj[:, 2] @ Ri[:, 2] - 1) < TOL
        else:
            assert abs(abs(Rj[:, 2] @ (C @ fall)) - 1) < TOL
        if i in hips:
            np.testing.assert_allclose(pi, pts[hips[i]], atol=TOL)
    if rolled:
        jp = model.get("JPRIM", 1)
        for m in (jp.integer("I"), jp.integer("J")):
            assert abs(abs(model.marker_pose(m)[1][:, 2] @ (C @ fall)) - 1) < TOL
    else:   # no yaw: leg2's hip axis perpendicular to the fall line
        jp = model.get("JPRIM", 2)
        assert "PERPENDICULAR" in jp.flags
        zi, zj = (model.marker_pose(jp.integer(k))[1][:, 2] for k in "IJ")
        assert abs(abs(zi @ pitch[402]) - 1) < TOL and abs(zj @ (C @ fall) - 1) < TOL
        assert abs(zi @ zj) < TOL
        (_t, i, j), = [j for j in joints.values() if j[0] == "FIXED"]
        (pi, Ri), (pj, Rj) = model.marker_pose(i), model.marker_pose(j)
        np.testing.assert_allclose(pi, pj, atol=TOL)
        np.testing.assert_allclose(Ri, Rj, atol=TOL)
    pin = joints[99]
    assert pin[0] == "SPHERICAL"
    np.testing.assert_allclose(model.marker_pose(pin[1])[0], np.zeros(3), atol=TOL)
    np.testing.assert_allclose(model.marker_pose(303)[0], pts["swing_foot"], atol=TOL)
    r = data.leg_length_m / 1000
    for foot in (403, 303):
        centre = model.marker_pose(foot)[0]
        contacts = [c for c in model.by_kind["CONTACT"].values() if c.integer("IGEOM") == foot]
        gaps = []
        for c in contacts:
            g = model.get("GRAPHICS", c.integer("JGEOM"))
            o, R = model.marker_pose(g.integer("CORNER"))
            size = np.array([g.number(k) for k in "XYZ"]) * model.length
            local = R.T @ (centre - o)
            if 0 <= local[0] <= size[0] and 0 <= local[1] <= size[1]:
                gaps.append(local[2] - size[2])
        assert len(gaps) == 1 and abs(gaps[0] - r) < TOL, (foot, gaps)


def test_a_3d_datasets_contact_law_is_the_scenes(case):
    """Every CONTACT carries the scene's IMPACT law and Coulomb friction (SI, relative
    1e-12), one per foot and patch of its own lane."""
    scene, _data, _f, _ideal, model, _adm, _acf = case
    from walkerlab.config.contact import ContactSettings

    c, _ = contact_si(scene.contact or ContactSettings())
    want = {"k": c.k, "e": c.e, "cmax": c.cmax, "dmax": c.dmax, "mu_s": c.mu_s,
            "mu_d": c.mu_d, "v_s": c.v_s, "v_d": c.v_d}
    contacts = model.by_kind["CONTACT"]
    assert contacts
    for cid, st in contacts.items():
        got = model.contact_si(cid)
        for k, v in want.items():
            assert got[k] == pytest.approx(v, rel=1e-12), (cid, k)
        assert st.integer("IGEOM") in (303, 403)  # the feet's spheres


def test_a_3d_acf_runs_the_requested_strides(case):
    """The command file names the dataset ``walker``, deactivates the pin and runs
    ``2 n_strides`` rigid step periods (5 strides: no contact_sim section)."""
    scene, _data, _f, ideal, _model, adm, acf = case
    lines = acf.splitlines()
    assert lines[:2] == ["walker", "walker"]
    cmds = parse_acf(acf)
    sim = [c for c in cmds if c.name == "SIMULATE" and "DYNAMICS" in c.flags]
    step = float(ideal.period_s) / max(1, len(ideal.step_lengths_m))
    assert sim[0].number("END") == pytest.approx(2 * 5 * step, rel=1e-15)
    assert any(c.name == "DEACTIVATE" and c.integer("ID") == 99 for c in cmds)
    assert max(len(s) for s in adm.splitlines()[1:]) <= 80


def test_the_cli_writes_the_hip_roll_walkers_dataset_and_a_wheel_on_footholds(tmp_path):
    """``walkerlab export configs/hip_width_stabilised.yaml --format adm`` writes both files.
    A spoked wheel on footholds 5 mm below and above its slope in turn (its contact model's
    continuous ground: a tread through each landing, risers half-way) writes its dataset
    too: a box per segment of that ground, and each landing of the rigid wheel - two tips a
    chord ``c = 2 L sin(pi / n)`` apart, footfall ``k + 1`` at ``h_k cos(phi)`` along the
    slope's normal and ``sqrt(c^2 - (h_k cos phi)^2)`` along it from footfall ``k``, written
    out here from the scene's numbers - lies on a box's top face raised by the tip sphere's
    radius, to 1e-9 m (footfalls -1 to 6)."""
    from typer.testing import CliRunner

    from walkerlab.cli import app
    from walkerlab.export.spoked import WHEEL_TIP_FRACTION
    from walkerlab.walker.reference_cases import reference_scene

    run = CliRunner().invoke
    r = run(app, ["export", str(ROOT / "configs" / "hip_width_stabilised.yaml"), "--format",
                  "adm", "--runs-dir", str(tmp_path)])
    assert r.exit_code == 0, r.output
    folder = tmp_path / "hip_width_stabilised"
    assert set(read_adm((folder / "walker.adm").read_text()).by_kind["GFORCE"]) == {31, 32}
    assert parse_acf((folder / "walker.acf").read_text())
    _case, d = reference_scene("rolling_polygon", "footholds", "adams")
    d["name"] = "wheel_footholds"
    cfg = tmp_path / "wheel_footholds.yaml"
    cfg.write_text(yaml.safe_dump(d))
    r = run(app, ["export", str(cfg), "--format", "adm", "--runs-dir", str(tmp_path)])
    assert r.exit_code == 0, r.output
    model = read_adm((tmp_path / "wheel_footholds" / "walker.adm").read_text())
    L, n_spokes = d["walker"]["spoke_length_m"], d["walker"]["spokes"]
    phi, h = d["slope"]["angle_rad"], d["terrain"]["foothold_heights_m"]
    c, radius = 2 * L * math.sin(math.pi / n_spokes), WHEEL_TIP_FRACTION * L
    t, nrm = np.array([math.cos(phi), -math.sin(phi)]), np.array([math.sin(phi), math.cos(phi)])

    def step(k):
        up = h[k % len(h)] * math.cos(phi)
        return math.sqrt(c * c - up * up) * t + up * nrm

    falls = [-step(-1), np.zeros(2)]
    for k in range(6):
        falls.append(falls[-1] + step(k))
    tops = []  # each box's top face (x, z) [m], raised by the tip sphere's radius
    for g in model.by_kind["GRAPHICS"].values():
        if "BOX" not in g.flags:
            continue
        origin, rot = model.marker_pose(g.integer("CORNER"))
        up = rot @ np.array([0.0, 0.0, g.number("Z") / 1000.0])
        along = rot @ np.array([g.number("X") / 1000.0, 0.0, 0.0])
        a = (origin + up + radius * up / np.linalg.norm(up))[[0, 2]]
        tops.append((a, along[[0, 2]]))
    for p in falls:
        on = [np.linalg.norm(p - (a + np.clip((p - a) @ e / (e @ e), 0, 1) * e)) < 1e-9
              for a, e in tops]
        assert any(on), p


def _evaluate(model, ids=(331, 332, 333, 334, 341, 343, 351, 352)) -> dict:
    """The dataset's VARIABLEs at its start, its expressions evaluated on the parts' poses
    and velocities as the reader gives them (Adams Solver semantics: ``DY(i, j, k)`` the
    displacement of marker i from j along k's y axis, ``WX(i, j, k)`` i's angular velocity
    relative to ground marker j along k's x, ``IF(e: a, b, c)`` a, b, c for e <, =, > 0;
    ``CONTACT`` 0: the start's feet touch their patches without penetrating)."""
    import re

    fns = model.functions("VARIABLE")
    cache: dict = {}

    def varval(n):
        if n not in cache:
            e = re.sub(r"IF\(([^:]*):", r"_if(\1,", fns[int(n)])
            cache[n] = eval(e, {"__builtins__": {}}, env)  # noqa: S307 (the test's own file)
        return cache[n]

    def disp(i, j, k, axis):
        (pi, _), (pj, _), (_, Rk) = (model.marker_pose(m) for m in (i, j, k))
        return (Rk.T @ (pi - pj))[axis] / model.length

    def wx(i, _j, k):
        part = model.get("MARKER", i).integer("PART")
        return (model.marker_pose(k)[1].T @ model.part_velocity(part)[1])[0]

    env = {"VARVAL": varval, "ATAN2": math.atan2, "CONTACT": lambda *a: 0.0,
           "DY": lambda i, j, k: disp(i, j, k, 1), "DZ": lambda i, j, k: disp(i, j, k, 2),
           "WX": wx, "_if": lambda e, a, b, c: a if e < 0 else (b if e == 0 else c)}
    return {n: varval(n) for n in ids}


@pytest.mark.slow
def test_a_3d_datasets_hip_roll_law_at_the_start_is_the_rigid_models(tmp_path_factory):
    """hip_width_stabilised: the dataset's rolls and rates (from its markers) are the rigid
    state's (stance = leg2: the lean; swing = leg1: swing_roll), and its roll torques the
    rigid law's ``tau_st = k_p phi_p + c_p dphi_p``, ``tau_sw = -k_s (phi_w - g_l phi -
    g_r dphi) - c_s (dphi_w - dphi_p)`` [N m] at the fixed point (1e-9 relative; leg2's GFORCE
    the stance torque, leg1's the swing torque)."""
    scene, data, _f, ideal, model, _adm, _acf = _export("hip_width_stabilised",
                                                         tmp_path_factory)
    s = dict(zip(state_names(data.structure.roles), np.asarray(ideal.x, float)))
    law = scene.walker.hip_roll
    v = _evaluate(model)
    want = {331: s["lean_angle"], 332: s["swing_roll_angle"], 333: s["lean_rate"],
            334: s["swing_roll_rate"]}
    for n, w in want.items():
        assert v[n] == pytest.approx(w, rel=TOL, abs=1e-12), n
    tau_st = (law.pelvis_stiffness_n_m_per_rad * s["pelvis_roll_angle"]
              + law.pelvis_damping_n_m_s_per_rad * s["pelvis_roll_rate"])
    tau_sw = (-law.swing_stiffness_n_m_per_rad * (
        s["swing_roll_angle"] - law.lean_gain * s["lean_angle"]
        - law.lean_rate_gain_s * s["lean_rate"])
        - law.swing_damping_n_m_s_per_rad * (s["swing_roll_rate"] - s["pelvis_roll_rate"]))
    assert v[352] / 1000 == pytest.approx(tau_st, rel=TOL)
    assert v[351] / 1000 == pytest.approx(tau_sw, rel=TOL)
    g = {gid: model.gforce(gid) for gid in (31, 32)}
    assert g[31]["TZ"] == "VARVAL(351)" and g[32]["TZ"] == "VARVAL(352)"
    assert (g[31]["I"], g[32]["I"]) == ("302", "402")


def test_an_upper_body_on_hip_roll_joints_is_refused_in_one_line(tmp_path):
    """configs/torso_bhm_3d_stabilised.yaml (an upper body on the bisecting hip, hip-roll
    joints): each leg's pitch is the second axis of its UNIVERSAL joint, which Adams'
    COUPLER cannot relate, so the dataset is refused in one line naming walker.torso (it was
    an internal KeyError), nothing written."""
    from typer.testing import CliRunner

    from walkerlab.cli import app

    r = CliRunner().invoke(app, ["export", str(ROOT / "configs" / "torso_bhm_3d_stabilised.yaml"),
                                 "--format", "adm", "--runs-dir", str(tmp_path)])
    assert r.exit_code != 0 and r.output.count("error:") == 1, r.output
    assert "walker.torso:" in r.output and "COUPLER" in r.output, r.output
    assert "internal error" not in r.output and "Traceback" not in r.output
    assert not list(tmp_path.rglob("*.adm"))
