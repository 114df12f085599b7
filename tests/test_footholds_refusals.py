"""Footholds of several heights outside the rigid model (issue 58): the contact model and the
MJCF export lay their patches at the rigid period-n gait's footfalls, so ``contact-sim`` and
``report`` run them (before: one line, "footholds that differ from step to step run in the
rigid model only"; before that an internal "heights1: ..." message); what still refuses them
says so in one line naming the scene key (the contact periodic gait, a one-step map; the
Adams dataset, by the capability table's cell; footholds of their own slopes; the OpenSim
model takes them since, tests/test_export_opensim.py), and no view points the user to
another view that refuses the same scene."""

from __future__ import annotations

import copy

import numpy as np
import pytest
import yaml
from cli_run import ROOT, run_cli

from walkerlab.config import scene_from_dict
from walkerlab.walker.capability_cells import FOOTHOLD_SLOPES, SEVERAL_FOOTHOLDS
from walkerlab.walker.kinds import KINDS
from walkerlab.walker.plant import Plant

#: configs/footholds_two.yaml: the paper walker on footholds of two heights (stable rigid
#: gait) with the paper's contact law and 0.3 m patches
TWO = yaml.safe_load((ROOT / "configs" / "footholds_two.yaml").read_text())
INTERNAL = ("heights1", "heights2", "lane1", "lane2", "shape (")


def _scene_file(tmp_path, d=None, name="footholds2"):
    p = tmp_path / f"{name}.yaml"
    p.write_text(yaml.safe_dump(d or TWO))
    return p


def _with(**sections):
    d = copy.deepcopy(TWO)
    for k, v in sections.items():
        d[k] = {**d[k], **v}
    return d


def test_every_view_of_point_and_arc_feet_takes_footholds_of_several_heights():
    for kind in ("straight_legs", "locking_knees"):
        for view in ("rigid", "contact", "mjcf", "osim", "adams", "gym"):
            assert KINDS[kind].supports("footholds", view), view
    # what a refusal tells the user to do names views that take them
    assert "contact-sim" in SEVERAL_FOOTHOLDS and "MJCF" in SEVERAL_FOOTHOLDS
    assert "OpenSim" in SEVERAL_FOOTHOLDS


@pytest.mark.slow  # ~6 s: the whole report (figures)
def test_report_runs_contact_sim_on_footholds_of_two_heights(tmp_path):
    """The refusal is gone: ``walkerlab report`` runs every stage, the contact walker makes
    its heel strikes (contact_sim.n_strides: 2 here, 4 heel strikes, to stay fast) and the
    report has its contact sections."""
    d = _with(contact_sim={"n_strides": 2})
    rc, err, _ = run_cli("-q", "report", _scene_file(tmp_path, d), "--runs-dir",
                         tmp_path / "r")
    assert rc == 0, err
    run = tmp_path / "r" / "footholds2"
    assert (run / "contact_sim.h5").is_file()
    md = (run / "report" / "report.md").read_text()
    assert "Contact walker walks" in md and "Contact walker (MSC ADAMS-style model)" in md
    assert not any(s in md for s in INTERNAL)


def test_a_start_from_the_contact_periodic_gait_on_two_heights_is_one_line(tmp_path):
    from walkerlab.models.contact.scene import SEVERAL_STEPS_PERIODIC

    rc, err, _ = run_cli("contact-sim", _scene_file(tmp_path, _with(contact_sim={
        "start": "periodic_gait"})), "--runs-dir", tmp_path / "r")
    assert rc == 1 and "\n" not in err
    assert err == f"error: scene 'footholds2': {SEVERAL_STEPS_PERIODIC}"
    assert "start: ideal, periodic_gait: false" in err  # what to do


def test_the_contact_periodic_gait_asked_on_two_heights_is_recorded_as_not_found(tmp_path):
    """configs/paper.yaml's contact_sim asks for the periodic gait too
    (``periodic_gait: true``): the run walks, and the gait is stored as not found with the
    reason (the one-step map), as a gait the search did not find is."""
    import h5py

    from walkerlab.models.contact.scene import SEVERAL_STEPS_PERIODIC

    d = _with(contact_sim={"periodic_gait": True, "n_strides": 2})
    rc, err, _ = run_cli("-q", "contact-sim", _scene_file(tmp_path, d), "--runs-dir",
                         tmp_path / "r")
    assert rc == 0, err
    with h5py.File(tmp_path / "r" / "footholds2" / "contact_sim.h5") as f:
        assert f["periodic_gait"].attrs["outcome"] == "several_steps"
        assert f["periodic_gait"].attrs["message"] == SEVERAL_STEPS_PERIODIC
        assert int(f["summary/heel_strikes"][()]) >= 4


@pytest.mark.parametrize("fmt, name", [("osim", "walker.osim"), ("adm", "walker.adm")])
def test_the_opensim_and_adams_exports_write_two_heights(tmp_path, fmt, name):
    """Both exports lay a patch at each footfall's own height (their geometry:
    tests/test_export_opensim.py, tests/test_export_adams_feet.py); before, both refused."""
    rc, err, _ = run_cli("export", _scene_file(tmp_path), "--format", fmt, "--runs-dir",
                         tmp_path / "r")
    assert rc == 0, err
    assert (tmp_path / "r" / "footholds2" / name).is_file()


def test_footholds_of_their_own_slopes_are_refused_by_the_contact_model_in_one_line():
    from walkerlab.models.contact.scene import ContactSceneError, contact_setup

    d = {**copy.deepcopy(TWO), "name": "footholds2"}
    d["terrain"] = {**d["terrain"], "foothold_heights_m": None,
                    "foothold_slopes_rad": [0.0174, 0.02]}
    d["terrain"] = {k: v for k, v in d["terrain"].items() if v is not None}
    with pytest.raises(ContactSceneError) as err:
        sc = scene_from_dict(d)
        contact_setup(sc, plant=Plant.from_scene(sc))
    assert str(err.value) == ("scene 'footholds2': terrain.foothold_slopes_rad: "
                              + FOOTHOLD_SLOPES)


def test_a_contact_walker_laid_at_a_fixed_spacing_on_two_heights_is_refused_in_one_line():
    """Footholds of several heights lie at the rigid gait's footfalls; a caller laying them
    at one spacing gets one line naming the key, not the patches' internal arrays."""
    from walkerlab.models.contact.scene import contact_setup

    sc = scene_from_dict(TWO)
    with pytest.raises(ValueError) as err:
        contact_setup(sc,
                plant=Plant.from_scene(sc)).build(np.array([-0.249, 0.187, -0.552, -0.966]), 10)
    assert str(err.value).startswith("terrain.foothold_heights_m: footholds of several "
                                     "heights are laid at the rigid gait's footfalls")
    assert not any(s in str(err.value) for s in INTERNAL)


def test_a_contact_walker_laid_on_new_lanes_drops_the_old_patch_heights():
    """The internal "heights1: one finite height [m] per patch of lane1" came from a walker
    on a terrain laid out again (new lanes, the old heights kept)."""
    from walkerlab.analysis.gait.scene import solve_scene
    from walkerlab.models.contact.scene import contact_setup

    d = copy.deepcopy(TWO)
    d["terrain"]["foothold_heights_m"] = [-0.005]  # one height: one spacing
    sc = scene_from_dict(d)
    _, search = solve_scene(sc, plant=Plant.from_scene(sc))
    walker, step = contact_setup(sc, plant=Plant.from_scene(sc)).build(search.result.x, 10)
    assert walker.heights1 is not None and walker.heights1.size == walker.lane1.size
    again = walker.on_terrain(sc.terrain, step_length=step, n_steps=40)
    assert again.heights1.size == again.lane1.size > walker.lane1.size
    # each footfall 5 mm lower along the slope's normal, as the first lay-out
    n = min(walker.heights1.size, 4)
    assert np.array_equal(again.heights1[:n], walker.heights1[:n])


def test_the_gym_takes_the_same_footholds():
    """The gym's views walk footholds of several heights (tests/test_gym.py: as simulate and
    contact-sim do): the table's cell is supported and the rigid view's ground check passes
    (before: one line, "the gym's views step one walker on a ground whose every step is
    alike")."""
    from walkerlab.gym.arguments import rigid_ground

    two = scene_from_dict(TWO)
    assert rigid_ground(two, Plant.from_scene(two)) is None  # the walker's own per-step cycle
    for kind in ("straight_legs", "locking_knees"):
        assert KINDS[kind].supports("footholds", "gym")
        assert KINDS[kind].supports("profile", "gym")
