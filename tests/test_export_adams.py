"""``walkerlab export --format adm``: the Adams Solver dataset and command file, read back by
walkerlab's own reader of that subset (:mod:`walkerlab.export.adams_reader`).

Round trip scene -> .adm -> walker numbers: masses, inertias, geometry, the contact law in
the declared mm-kg-s units and the start.  Tolerances: the file carries every number with
17 significant digits (shortest repr), converted m -> mm and rad -> deg, so a number comes
back within a few ulp (1e-12 relative); numbers the scene writes in mm-kg-s come back
bit for bit.  The reader's semantics (3-1-3 REULER, D for degrees, QP in the part's frame,
IP about the CM marker, UNITS) are checked on a pendulum with a closed-form period.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from walkerlab.config import load_scene
from walkerlab.export.adams import PIN_JOINT
from walkerlab.export.adams_feet import part_ids
from walkerlab.export.adams_reader import (
    AdmReadError,
    parse_acf,
    parse_adm,
    read_adm,
    reuler_matrix,
)
from walkerlab.export.adams_statements import LINE_WIDTH, marker_id
from walkerlab.models.contact.rigid_limit import contact_si
from walkerlab.stages import export as export_stage
from walkerlab.walker.description import walker_data
from walkerlab.walker.multibody import multibody
from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]
REL = 1e-12


def _export(name, tmp_path_factory):
    scene = load_scene(ROOT / "configs" / f"{name}.yaml")
    runs = tmp_path_factory.mktemp(f"adm_{name}")
    path = export_stage.run(scene, runs, "adm")
    data = walker_data(scene.walker, scene.slope.phi_rad)
    return scene, multibody(data), path.read_text(), (path.parent / "walker.acf").read_text()


@pytest.fixture(scope="module")
def paper(tmp_path_factory):
    return _export("paper", tmp_path_factory)


@pytest.fixture(scope="module")
def kneed(tmp_path_factory):
    return _export("kneed", tmp_path_factory)


def _close(a, b, rel=REL):
    return np.allclose(a, b, rtol=rel, atol=rel * max(1.0, float(np.max(np.abs(b)))))


def test_paper_statements_and_contact_as_written(paper):
    """The paper's walker: UNITS mm-kg-s, one PART per link + hip, the contact law exactly
    as the scene writes it (1e5 N/mm^2.2, 90 N s/mm, 0.1 mm, 0.9/0.7, 10 and 100 mm/s),
    every line within 80 columns, every statement within the reader's subset."""
    scene, mb, adm, acf = paper
    assert all(len(ln) <= LINE_WIDTH for ln in adm.splitlines())
    title, stmts = parse_adm(adm)
    assert title.startswith("walker paper")
    kinds = {s.name for s in stmts}
    assert {"UNITS", "PART", "MARKER", "JOINT", "ACCGRAV", "GRAPHICS", "CONTACT",
            "REQUEST", "OUTPUT"} <= kinds
    model = read_adm(adm)
    assert model.length == 1e-3 and model.mass == 1.0
    contacts = model.by_kind["CONTACT"]
    assert len(contacts) == sum(1 for s in stmts if s.name == "GRAPHICS" and "BOX" in s.flags)
    for c in contacts.values():
        assert {k: c.number(k) for k in ("STIFFNESS", "EXPONENT", "DAMPING", "DMAX",
                                         "MU_STATIC", "MU_DYNAMIC",
                                         "STICTION_TRANSITION_VELOCITY",
                                         "FRICTION_TRANSITION_VELOCITY")} == {
            "STIFFNESS": 1e5, "EXPONENT": 2.2, "DAMPING": 90.0, "DMAX": 0.1,
            "MU_STATIC": 0.9, "MU_DYNAMIC": 0.7, "STICTION_TRANSITION_VELOCITY": 10.0,
            "FRICTION_TRANSITION_VELOCITY": 100.0}
        si = model.contact_si(c.id)
        want = contact_si(scene.contact)[0]
        assert all(math.isclose(si[k], getattr(want, k), rel_tol=REL) for k in si)
    # the .acf: initial conditions with the pin, the pin (a REVOLUTE) deactivated, the run
    cmds = parse_acf(acf)
    assert [c.name for c in cmds] == ["SIMULATE", "DEACTIVATE", "SIMULATE"]
    assert cmds[1].integer("ID") == PIN_JOINT and model.joints()[PIN_JOINT][0] == "REVOLUTE"
    assert "DYNAMICS" in cmds[2].flags and cmds[2].number("END") > 0


def _round_trip(scene, mb, adm):
    """Every link's mass, inertia, CM, foot/knee geometry and start, and the hip, back
    from the file."""
    from walkerlab.export.adams import adams_start

    model = read_adm(adm)
    start = adams_start(scene, mb, Plant.from_scene(scene))
    ids = part_ids(mb)
    total = sum(model.part_mass(p) for p in model.by_kind["PART"] if p != 1)
    assert math.isclose(total, mb.hip_mass_kg + sum(ln.mass_kg for ln in mb.links),
                        rel_tol=REL)
    assert _close(model.gravity(), [0.0, -mb.gravity_m_per_s2, 0.0])
    for ln in mb.links:
        p = ids[ln.name]
        assert math.isclose(model.part_mass(p), ln.mass_kg, rel_tol=REL)
        inertia = model.part_inertia(p)
        assert math.isclose(inertia[2, 2], ln.inertia_kg_m2, rel_tol=REL, abs_tol=1e-15)
        joint, rot = model.marker_pose(marker_id(p, "joint"))
        psi = math.atan2(rot[1, 0], rot[0, 0])
        assert math.isclose(psi, start.angles[ln.name], rel_tol=REL, abs_tol=1e-15)
        axis = np.array([math.sin(psi), -math.cos(psi), 0.0])  # joint -> foot
        ahead = np.array([math.cos(psi), math.sin(psi), 0.0])
        cm, _ = model.marker_pose(marker_id(p, "cm"))
        assert math.isclose((cm - joint) @ axis, ln.com_m, rel_tol=REL, abs_tol=1e-15)
        assert math.isclose((cm - joint) @ ahead, ln.com_off_axis_m, abs_tol=1e-13)
        if ln.foot_m is not None:
            foot, _ = model.marker_pose(marker_id(p, "foot"))
            assert math.isclose((foot - joint) @ axis, ln.foot_m, rel_tol=REL)
        v, w = model.part_velocity(p)
        assert math.isclose(w[2], start.rates[ln.name], rel_tol=REL)
        if ln.parent == "hip":  # the hip's position and velocity from this link's frame
            assert _close(joint[:2], start.hip)
            r = cm - joint
            assert _close(v[:2] - w[2] * np.array([-r[1], r[0]]), start.hip_velocity,
                          rel=1e-11)
    # the stance foot sits on the pin's ground marker at the origin of the ground line, at
    # rest: its part's CM velocity and rate (VX, VY, WZ) carry the pinned start
    typ, i_m, j_m = model.joints()[PIN_JOINT]
    foot, _ = model.marker_pose(i_m)
    assert _close(foot, model.marker_pose(j_m)[0]) and _close(foot[:2], [0.0, 0.0])
    p = i_m // 100
    v, w = model.part_velocity(p)
    r = foot - model.marker_pose(marker_id(p, "cm"))[0]
    assert np.allclose(v + np.cross(w, r), 0.0, atol=1e-9)  # mm/s-scale values: ~1e-13
    return model, start


def test_paper_round_trip(paper):
    """scene -> .adm -> the paper walker's numbers (Table 1: 10 kg hip, 5 kg legs with
    their mass at 0.5 m, 1 m legs, zero inertia) and its start: the rigid gait unscaled
    (contact_sim.initial_rate_scale 1, 1), slope 0.0174 rad."""
    scene, mb, adm, _ = paper
    model, start = _round_trip(scene, mb, adm)
    assert model.part_mass(2) == 10.0
    assert [model.part_mass(p) for p in (3, 4)] == [5.0, 5.0]
    assert start.rate_scale == (1.0, 1.0)
    patches = [m for mid, m in model.by_kind["MARKER"].items() if mid > 1000]
    for m in patches:  # the tilted ground: REULER = -phi about z
        assert math.isclose(-m.numbers("REULER")[0], scene.slope.phi_rad, rel_tol=REL)
    # the leg angles lie on the heel-strike surface theta1 + theta2 = -2 phi (Eq. 11)
    assert math.isclose(start.angles["leg1"] + start.angles["leg2"],
                        -2 * scene.slope.phi_rad, abs_tol=1e-9)


def test_kneed_round_trip(kneed):
    """A kneed walker: thigh and shank parts, knee REVOLUTEs, knee stops and latches as
    SFORCEs (the latch's law: tests/test_export_adams_latch.py), nothing left out."""
    scene, mb, adm, _ = kneed
    model, _ = _round_trip(scene, mb, adm)
    kinds = [j[0] for j in model.joints().values()]
    assert kinds.count("REVOLUTE") == 4  # leg1 hip, two knees, the pin
    assert sorted(model.by_kind["SFORCE"]) == [1, 2, 3, 4]  # stops, then latches
    assert "Left out:" not in adm


def test_hip_spring_round_trip(tmp_path_factory):
    """The hip spring (Kuo 2002, 20 N m/rad, rest 0) as a rotational SPRINGDAMPER between
    the legs' hip markers: I on leg2, J on leg1 (delta = leg2 - leg1), KT in N mm/rad, no
    CT (its damping is 0; CT > 0 when given)."""
    scene, mb, adm, _ = _export("hip_spring", tmp_path_factory)
    model, _ = _round_trip(scene, mb, adm)
    (sd,) = model.by_kind["SPRINGDAMPER"].values()
    assert "ROTATIONAL" in sd.flags and "CT" not in sd.args
    assert sd.number("KT") == 20.0 * 1000 and sd.number("ANGLE") == 0.0
    ids = part_ids(mb)
    assert (sd.integer("I"), sd.integer("J")) == (marker_id(ids["leg2"], "joint"),
                                                  marker_id(ids["leg1"], "joint"))


def test_cli_writes_adm_and_acf(tmp_path):
    """``walkerlab export configs/powered_compass.yaml --format adm``: both files, the
    push-off written (GFORCE pulses, no warning), no temporary file left."""
    from typer.testing import CliRunner

    from walkerlab.cli import app

    r = CliRunner().invoke(app, ["export", str(ROOT / "configs" / "powered_compass.yaml"),
                                 "--format", "adm", "--runs-dir", str(tmp_path)])
    assert r.exit_code == 0, r.output
    folder = tmp_path / "powered_compass"
    assert f"wrote {folder / 'walker.adm'}" in r.output
    adm = (folder / "walker.adm").read_text()
    assert "NOT exported" not in adm and "warning" not in r.output
    assert set(read_adm(adm).by_kind["GFORCE"]) == {1, 2}
    assert parse_acf((folder / "walker.acf").read_text())
    assert not list(folder.glob(".*.tmp"))


def test_reader_refuses_outside_subset():
    with pytest.raises(AdmReadError, match="BEAM"):
        parse_adm("t\nBEAM/1, I=1, J=2\nEND\n")
    with pytest.raises(AdmReadError, match="QG"):
        parse_adm("t\nMARKER/1, PART=1, QG=0, 0, 0\nEND\n")


#: A pendulum written as Adams would: mm-kg-s, the part turned by REULER = 90D, 90D, 0D
#: (its x axis along ground y, y along ground z, z along ground x), its CM QP in the part's
#: frame (-500 mm along the part's x: 0.5 m straight below the pivot), IP about the CM with
#: the moment about ground z in the part's yy slot; a REVOLUTE about ground z at QG.
PENDULUM = """pendulum
UNITS/FORCE=NEWTON, MASS=KILOGRAM, LENGTH=MILLIMETER, TIME=SECOND
PART/1, GROUND
MARKER/10, PART=1, QP=100.0, 200.0, 0.0
ACCGRAV/IGRAVITY=0.0, JGRAVITY=-9810.0, KGRAVITY=0.0
PART/2, MASS=2.0, CM=21, IP=300000.0, 20000.0, 700000.0
, QG=100.0, 200.0, 0.0, REULER=90D, 90D, 0D, WY=0.002
MARKER/21, PART=2, QP=-500.0, 0.0, 0.0
MARKER/22, PART=2, QP=0.0, 0.0, 0.0, REULER=0D, -90D, 0D
JOINT/1, REVOLUTE, I=22, J=10
END
"""


def test_pendulum_period_closed_form():
    """The reader's pendulum swings with T = 2 pi sqrt((I_cm + m d^2) / (m g d)), m = 2 kg,
    d = 0.5 m, I_cm = 0.02 kg m^2 (the IP slot along ground z), g = 9.81: within 1e-6
    (the amplitude 1e-3 rad adds (a/4)^2 ~ 6e-8; the integration is at rtol 1e-11).  A
    reader that took REULER in radians, as 1-2-3 angles, QP in ground axes or IP about
    the part's origin gets another period (checked: the moment it would use differs)."""
    model = read_adm(PENDULUM)
    pivot, jrot = model.marker_pose(10)
    n = jrot[:, 2]  # the revolute's axis: the J marker's z
    i_pos, i_rot = model.marker_pose(22)
    assert _close(i_pos, pivot) and _close(abs(i_rot[:, 2] @ n), 1.0)  # I on the axis
    m = model.part_mass(2)
    cm, _ = model.marker_pose(21)
    r0 = cm - pivot
    inertia = n @ model.part_inertia(2) @ n + m * (r0 @ r0 - (r0 @ n) ** 2)
    g = model.gravity()
    _, w0 = model.part_velocity(2)

    def rhs(_t, y):  # rotate r0 about n by theta: the gravity torque about n
        th = y[0]
        r = (r0 * math.cos(th) + np.cross(n, r0) * math.sin(th)
             + n * (n @ r0) * (1 - math.cos(th)))
        return [y[1], np.cross(r, m * g) @ n / inertia]

    t_true = 2 * math.pi * math.sqrt((0.02 + 2.0 * 0.25) / (2.0 * 9.81 * 0.5))
    up = lambda t, y: y[1]  # noqa: E731 - the rate crosses zero going down once a period
    up.direction = -1
    sol = solve_ivp(rhs, (0, 3.2 * t_true), [0.0, w0 @ n], method="DOP853", rtol=1e-11,
                    atol=1e-14, events=up)
    crossings = sol.t_events[0]
    period = crossings[-1] - crossings[-2]
    assert abs(period / t_true - 1) < 1e-6
    # the semantics matter: the moment about ground z is IP's yy (0.02), not zz (0.7)
    assert math.isclose(n @ model.part_inertia(2) @ n, 0.02, rel_tol=1e-12)
    assert np.allclose(reuler_matrix(*np.radians([90, 90, 0])) @ [1, 0, 0], [0, 1, 0])
