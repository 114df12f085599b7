"""The capability table's evidence (:mod:`walkerlab.walker.capability_evidence`): every
supported cell has a reference case and a measurement beside the table, no ``✓`` is shown
without its number within its tolerance, and (slow) each stored number is still what the
code gives.
"""

from __future__ import annotations

import importlib.util
import json
import math

import pytest

from walkerlab.config import scene_from_dict
from walkerlab.walker.capability_evidence import cell_evidence, evidence, verified
from walkerlab.walker.capability_tables import SUPPORTED, grids
from walkerlab.walker.kinds import FEATURES, KINDS, VIEWS, table_rows
from walkerlab.walker.reference_cases import reference_scene

SUPPORTED_CELLS = [(r["kind"], r["feature"], r["view"]) for r in table_rows()
                   if r["supported"]]


def test_every_cell_of_every_kind_feature_and_view_has_a_reference_case_that_validates():
    """A kind, feature or view added without a reference case fails here: each cell's case
    is a shipped scene or one generated from the kind's base walker, and validates as a
    scene."""
    for kind in KINDS:
        for feature in FEATURES:
            for view in VIEWS:
                if not KINDS[kind].supports(feature, view):
                    continue
                case, d = reference_scene(kind, feature, view)
                assert case.startswith(("configs/", "generated: "))
                scene_from_dict(d)  # raises SceneError when the case is not a scene


def test_every_supported_cell_has_a_measurement_with_its_case_tolerance_and_commit():
    """No supported cell without its evidence (a measurement, or the reason nothing was
    measured), and no stored cell the table does not support."""
    cells = evidence()["cells"]
    missing = [c for c in SUPPORTED_CELLS if "/".join(c) not in cells]
    assert not missing, f"supported cells without evidence: {missing[:10]}"
    for key, e in cells.items():
        assert tuple(key.split("/")) in SUPPORTED_CELLS, f"{key}: evidence of a refused cell"
        assert e["case"] and e["quantity"] and e["commit"] and e["detail"], key
        assert e["tolerance"] > 0.0 and e["unit"] in ("relative", "m", "state"), key
        assert e["ok"] == (e["value"] is not None and abs(e["value"]) <= e["tolerance"]), key


def test_no_tick_is_shown_without_its_measured_number_within_tolerance():
    """The grids' ✓ cells each carry a number, and exactly the verified cells are ✓."""
    for g in grids():
        for feature, row in zip(g.features, g.rows):
            for view, cell in zip(g.views, row):
                ticked = cell.startswith(SUPPORTED)
                assert ticked == verified(g.kind.name, feature, view), (feature, view, cell)
                if ticked:
                    assert len(cell) > 2 and "n/a" not in cell, cell


def test_the_json_carries_each_supported_cells_case_measurement_and_tolerance():
    from typer.testing import CliRunner

    from walkerlab.cli import app

    r = CliRunner().invoke(app, ["capabilities", "--json"])
    rows = json.loads(r.output)
    for row in rows:
        if row["supported"]:
            e = cell_evidence(row["kind"], row["feature"], row["view"])
            assert row["case"] == e["case"] and row["tolerance"] == e["tolerance"]
            assert row["measured"] == e["value"] and row["verified"] == verified(
                row["kind"], row["feature"], row["view"])


@pytest.mark.parametrize("friction", [None, -1])
def test_a_missing_friction_verdict_is_not_counted_as_inside_the_cone(tmp_path, friction):
    """A fixed point without a friction verdict (a walker in 3D: no ``ground_contact/
    friction`` group; or one whose verdict was not made: ``inside`` -1) is read as not
    checked, never as inside the cone (before: "" = inside, and the rigid cell's quantity
    claimed the cone); a verdict inside / outside reads as such."""
    import h5py

    from walkerlab.api.capabilities import _friction_verdict

    with h5py.File(tmp_path / "fp.h5", "w") as f:
        g = f.create_group("ground_contact")
        g.attrs["not_checked"] = "a walker in 3D: its stance foot's reaction is not computed"
        if friction is not None:
            h = g.create_group("friction")
            h.attrs["inside"] = friction
            h.attrs["not_checked"] = "no friction coefficient"
        inside, why = _friction_verdict(f)
        assert inside is None and why.startswith("ground forces (the friction cone) not "
                                                 "checked: ")
        if friction is None:
            h = g.create_group("friction")
        h.attrs["inside"] = 1
        assert _friction_verdict(f) == (True, "")
        h.attrs["inside"] = 0
        h["max_ratio"], h["friction_coefficient"] = 1.2, 0.9
        assert _friction_verdict(f)[0] is False


def test_a_cells_quantity_names_only_what_was_checked_and_its_check_kind():
    """Every stored cell names the kind of check behind its number
    (:data:`~walkerlab.walker.capability_evidence.CHECK_KINDS`); a rigid cell names the
    friction cone in its quantity only when the fixed point's verdict was made (its detail
    says inside or outside): the 3D walkers and the 3D wheel have it (their stance foot's
    reaction from the floating view of their tree, the wheel's from its hub); a walk on a
    profile, which has none, says "not checked" beside its ✓ (a numbered note ending
    "(not part of the ✓)")."""
    from walkerlab.walker.capability_evidence import CHECK_KINDS, check_of, not_checked

    cells = evidence()["cells"]
    for key, e in cells.items():
        assert check_of(e) in CHECK_KINDS, key
        if key.endswith("/rigid") and e["ok"]:
            claims = "friction cone" in e["quantity"]
            assert claims != bool(not_checked(e)), key
            assert claims == ("inside the friction cone" in e["detail"]), key
    for key in ("straight_legs_3d/walk/rigid", "straight_legs_3d/hip_roll/rigid",
                "straight_legs_3d/round_feet_3d/rigid", "rolling_polygon_3d/walk/rigid"):
        assert "inside the friction cone" in cells[key]["detail"], key
        assert not not_checked(cells[key]), key
    profile = cells["straight_legs/profile/rigid"]
    assert "friction cone" not in profile["quantity"]
    assert "on a profile" in not_checked(profile)
    g = next(g for g in grids() if g.kind.name == "straight_legs")
    cell = g.rows[g.features.index("profile")][g.views.index("rigid")]
    assert cell.startswith(f"{SUPPORTED} ") and " reference (" in cell, cell
    note = g.reasons[int(cell.rsplit("(", 1)[1].rstrip(")")) - 1]
    assert "not checked" in note and note.endswith("(not part of the ✓)")


#: a re-measured number agrees with the stored one to this fraction of the tolerance (the
#: stored run and the re-run share the code; the slack absorbs a machine's last digits)
REPRODUCE = 0.1


@pytest.mark.slow
@pytest.mark.parametrize("kind,feature,view", SUPPORTED_CELLS)
def test_each_cells_stored_measurement_is_what_the_code_gives(kind, feature, view,
                                                                tmp_path):
    """Re-measure the cell (:func:`walkerlab.api.capabilities.measure`): a verified cell
    must stay within its tolerance and near its stored number; an unverified one must not
    have become silently verified (update the evidence: scripts/measure_capabilities.py)."""
    from walkerlab.api.capabilities import measure

    e = cell_evidence(kind, feature, view)
    if view == "osim" and not e["ok"] and "not importable" in e["detail"]:
        pytest.skip("OpenSim is not installed where the table was measured")
    if view == "osim" and importlib.util.find_spec("opensim") is None:
        pytest.skip("OpenSim (the osim extra, not in the test extra) is not installed here")
    m = measure(kind, feature, view, tmp_path)
    assert m.ok == e["ok"], (m.detail, e["detail"])
    if e["ok"]:  # what was measured, by which kind of check, and what did not run
        assert (m.quantity, m.check, m.not_checked) == (
            e["quantity"], e["check"], e.get("not_checked", "")), (m.quantity, e["quantity"])
    if e["ok"] and "return error" in e["quantity"]:
        # an optimum's replay error is the NLP's convergence noise (IPOPT with MUMPS on the
        # machine's BLAS: 6.7e-8 where the evidence was first written, 5.1e-7 here): the
        # claim is its bound, not its digits
        assert m.value <= e["tolerance"], (m.value, e["tolerance"])
    elif e["ok"]:
        assert math.isclose(m.value, e["value"], rel_tol=0.0,
                            abs_tol=REPRODUCE * e["tolerance"]), (m.value, e["value"])


@pytest.mark.parametrize(("scene", "terrain", "reason"), [
    ("compass_optimal", {"kind": "profile", "lanes": "continuous",
                         "profile_m": [[-1.0, 0.05], [0.0, 0.0], [40.0, -2.1]]},
     "a profile's steps all differ"),
    ("kneed_optimal", {"kind": "stairs", "riser_m": 0.01, "tread_m": 0.4,
                       "direction": "down"}, "lands on the slope only"),
    ("kneed_optimal", {"kind": "footholds", "foothold_heights_m": [-0.002, 0.002],
                       "periodic": True}, "lands on the slope only")])
def test_optimize_refuses_a_ground_it_does_not_transcribe_naming_terrain_kind(scene, terrain,
                                                                             reason,
                                                                             tmp_path):
    """Before issue 63 every ground but the slope was refused (before that, optimised on the
    slope: the paper walker's least-effort step on 1 cm and 5 cm risers was the level
    ground's to every digit).  Straight legs now land on stairs and footholds
    (tests/test_optimize_ground.py); a profile (no periodic gait) and the other kinds'
    transcriptions on stairs and footholds are refused, in one line naming terrain.kind,
    before any stage runs."""
    import yaml
    from typer.testing import CliRunner

    from walkerlab.cli import app
    from walkerlab.config.loader import shipped_scene_path

    d = yaml.safe_load(shipped_scene_path(scene).read_text())
    d["name"] = "ground"
    d["terrain"] = terrain
    if terrain["kind"] == "stairs":
        d["slope"] = {"angle_rad": 0.0}
    path = tmp_path / "ground.yaml"
    path.write_text(yaml.safe_dump(d))
    r = CliRunner().invoke(app, ["optimize", str(path), "--runs-dir", str(tmp_path / "runs")])
    assert r.exit_code == 1
    assert f"terrain.kind: {terrain['kind']}" in r.output and reason in r.output
    assert not (tmp_path / "runs" / "ground").exists()


def test_a_torque_features_shipped_reference_case_drives_the_features_joint():
    """A shipped scene stands for a torque feature only if it has a law at that feature's
    joint (RABBIT's swing_hip law is its hip torque, its stance_hip law its torso torque):
    a case without the joint's law would measure the passive walk under the feature's
    name."""
    from walkerlab.walker.reference_cases import FIVE_LINK_JOINT, JOINT, SHIPPED, TORSO_HIPS

    checked = 0
    for (kind, feature), _ in SHIPPED.items():
        if feature not in JOINT:
            continue
        joint = (FIVE_LINK_JOINT.get(feature, JOINT[feature]) if kind in TORSO_HIPS
                 else JOINT[feature])
        if feature == "knee_torque":
            joints = {"stance_knee", "swing_knee"}
        else:
            joints = {joint}
        case, d = reference_scene(kind, feature, "rigid")
        laws = {t["joint"] for t in d["walker"]["actuation"]["torques"]}
        assert laws & joints, f"{kind}/{feature}: {case} has no law at {joints}"
        checked += 1
    assert checked >= 5


def test_a_walking_generated_case_carries_its_changes_and_says_why():
    """Each generated case changed so that it walks (reference_cases.WALKING) carries its
    changes in the scene every view measures, validates, and names why in its case."""
    from walkerlab.walker.reference_cases import WALKING

    for (kind, feature), (why, changes) in WALKING.items():
        for view in VIEWS:
            if not KINDS[kind].supports(feature, view):
                continue
            case, d = reference_scene(kind, feature, view)
            assert case.endswith(why) and case.startswith("generated: "), case
            for path, value in changes.items():
                node = d
                for k in path.split("."):
                    node = node[k]
                assert node == value, (kind, feature, view, path)
        scene_from_dict(reference_scene(kind, feature, "rigid")[1])


def test_an_optimize_generated_case_carries_its_changes_and_says_why():
    """Each generated case changed so that its optimisation has a gait to start from
    (reference_cases.WALKING_OPTIMIZE) carries its changes in the optimize cell's scene,
    validates, and names why in its case; the feature's other views keep their own."""
    from walkerlab.walker.reference_cases import WALKING_OPTIMIZE

    for (kind, feature), (why, changes) in WALKING_OPTIMIZE.items():
        case, d = reference_scene(kind, feature, "optimize")
        assert case.endswith(why) and case.startswith("generated: "), case
        for path, value in changes.items():
            node = d
            for k in path.split("."):
                node = node[k]
            assert node == value, (kind, feature, path)
        scene_from_dict(d)
        assert not reference_scene(kind, feature, "rigid")[0].endswith(why)


def test_the_stairs_cases_are_their_slopes_step_as_a_stair():
    """The rimless wheel's stairs are its slope's geometry: spokes 2 alpha apart (alpha =
    pi / n) landing a riser 2 l sin(alpha) sin(phi) below and a tread 2 l sin(alpha)
    cos(phi) ahead meet the ground at the slope's angles (Coleman, Chatterjee & Ruina 1997);
    the kneed walker's riser is its step's drop on the slope (0.4747 m x sin 0.0504)."""
    from walkerlab.walker.reference_cases import WALKING, _shipped

    w = _shipped("rimless_wheel")
    alpha, phi = math.pi / w["walker"]["spokes"], w["slope"]["angle_rad"]
    chord = 2.0 * w["walker"]["spoke_length_m"] * math.sin(alpha)
    ch = WALKING[("rolling_polygon", "stairs")][1]
    assert math.isclose(ch["terrain.riser_m"], chord * math.sin(phi), abs_tol=1e-4)
    assert math.isclose(ch["terrain.tread_m"], chord * math.cos(phi), abs_tol=1e-3)
    k = _shipped("kneed")
    ch = WALKING[("locking_knees", "stairs")][1]
    assert math.isclose(ch["terrain.riser_m"], 0.4747 * math.sin(k["slope"]["angle_rad"]),
                        abs_tol=5e-4)


#: (kind, feature) -> the walking case's rigid step period [s] as its comment states
WALKING_PERIODS = {("locking_knees", "stairs"): 0.5461442,
                   ("locking_knees", "hip_torque"): 0.5394385,
                   ("rolling_polygon", "stairs"): 1.0333695,
                   ("rolling_polygon_3d", "footholds"): 0.3962190}


@pytest.mark.slow
@pytest.mark.parametrize("kind,feature", sorted(WALKING_PERIODS))
def test_a_walking_generated_case_has_the_rigid_gait_its_comment_states(kind, feature,
                                                                         tmp_path):
    """The case's fixed point is found from its own start, with the step period its
    comment gives (to 1e-6 s: the period is printed to 7 digits)."""
    from walkerlab.io.artifacts import open_artifact
    from walkerlab.stages import pipeline

    _, d = reference_scene(kind, feature, "rigid")
    path = pipeline.run("fixedpoint", scene_from_dict(d), tmp_path).path
    with open_artifact(path) as f:
        period = float(f["step_period"][()])
    assert math.isclose(period, WALKING_PERIODS[(kind, feature)], abs_tol=1e-6)
