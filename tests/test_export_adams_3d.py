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


def _export(name, tmp_path_factory):
    from walkerlab.analysis.contact.periodic import ideal_gait
    from walkerlab.codegen.cache import functions

    scene = load_scene(ROOT / "configs" / f"{name}.yaml")
    runs = tmp_path_factory.mktemp(f"adm3d_{name}")
    path = export_stage.run(scene, runs, "adm")
    plant = Plant.from_scene(scene)
    ideal = ideal_gait(scene, plant)
    return (scene, plant.data, functions(plant.data), ideal, read_adm(path.read_text()),
            path.read_text(), (path.parent / "walker.acf").read_text())


@pytest.fixture(scope="module", params=["hip_width", "paper_3d", "torso_bhm_3d"])
def case(request, tmp_path_factory):
    return _export(request.param, tmp_path_factory)


#: the scenes' masses [kg] by PART: the hip (PART/2), leg1, leg2, an upper body (PART/5)
MASSES = {"hip_width": {2: 10.0, 3: 5.0, 4: 5.0}, "paper_3d": {2: 10.0, 3: 5.0, 4: 5.0},
          "torso_bhm_3d": {2: 10.0, 3: 5.0, 4: 5.0, 5: 5.0}}
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
    the walker's; every body is a point mass, so its inertia about its CM is the export's
    floor about every axis (in ground axes: a multiple of the identity)."""
    scene, data, _f, _ideal, model, _adm, _acf = case
    parts = _parts(scene)
    assert sorted(p for p in model.by_kind["PART"] if p != 1) == sorted(parts)
    for pid, (_point, mass) in parts.items():
        assert model.part_mass(pid) == pytest.approx(mass, rel=1e-15)
        np.testing.assert_allclose(model.part_inertia(pid), FLOOR * np.eye(3), rtol=0,
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


def test_a_3d_datasets_hips_feet_and_joint_axes_are_the_rigid_walkers(case):
    """Each REVOLUTE's I and J markers coincide, their z axes along the rigid hip axis
    (``Rot(s, lean) z``: lateral, pitch); the pelvis' FIXED markers coincide in pose; the
    stance foot (the pin's marker) at the origin, the trailing foot at the rigid one; both
    foot spheres touch their lanes' patches (their centres r = L / 1000 above the top face
    along the slope's normal)."""
    scene, data, f, ideal, model, _adm, _acf = case
    x = np.asarray(ideal.x, float)
    s = dict(zip(state_names(data.structure.roles), x))
    phi = data.slope_rad
    fall = np.array([math.cos(phi), -math.sin(phi), 0.0])
    lean = s["lean_angle"]
    K = np.array([[0, -fall[2], fall[1]], [fall[2], 0, -fall[0]], [-fall[1], fall[0], 0]])
    Rs = np.eye(3) + math.sin(lean) * K + (1 - math.cos(lean)) * K @ K
    hip_axis = C @ (Rs @ np.array([0.0, 0.0, 1.0]))
    pts = {k: C @ np.ravel(v) for k, v in f["points"](x).items()}
    joints = model.joints()
    revolutes = [j for j in joints.values() if j[0] == "REVOLUTE"]
    assert len(revolutes) == (2 if data.structure.torso else 1)
    for _t, i, j in revolutes:
        (pi, Ri), (pj, Rj) = model.marker_pose(i), model.marker_pose(j)
        np.testing.assert_allclose(pi, pj, atol=TOL)
        assert abs(abs(Ri[:, 2] @ hip_axis) - 1) < TOL and abs(Rj[:, 2] @ Ri[:, 2] - 1) < TOL
    leg1 = next(j for j in revolutes if j[1] == 302)
    np.testing.assert_allclose(model.marker_pose(leg1[1])[0], pts["swing_hip"], atol=TOL)
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


def test_the_cli_writes_a_3d_dataset_and_refuses_hip_roll_and_the_3d_wheel(tmp_path):
    """``walkerlab export configs/hip_width.yaml --format adm`` writes both files; the
    hip-roll walker and the 3D wheel are refused in one line, nothing written."""
    from typer.testing import CliRunner

    from walkerlab.cli import app

    run = CliRunner().invoke
    r = run(app, ["export", str(ROOT / "configs" / "hip_width.yaml"), "--format", "adm",
                  "--runs-dir", str(tmp_path)])
    assert r.exit_code == 0, r.output
    assert (tmp_path / "hip_width" / "walker.acf").is_file()
    for cfg, field in (("hip_width_stabilised", "walker.hip_roll"),
                       ("rimless_wheel_3d", "walker.space: 3d")):
        r = run(app, ["export", str(ROOT / "configs" / f"{cfg}.yaml"), "--format", "adm",
                      "--runs-dir", str(tmp_path)])
        assert r.exit_code != 0 and r.output.strip().count("\n") == 0, r.output
        assert field in r.output and "Traceback" not in r.output
        assert not (tmp_path / cfg / "walker.adm").exists()
