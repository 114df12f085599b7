"""Footholds of several heights outside the rigid model (issue 58): the shipped
``configs/footholds.yaml`` with ``configs/paper.yaml``'s contact sections is refused by the
contact model in one line naming the scene key and what to do (no internal name such as
``heights1``), ``walkerlab report`` names the stage that refused, and no view points the user
to another view that refuses the same scene."""

from __future__ import annotations

import copy

import numpy as np
import pytest
import yaml
from cli_run import PAPER, ROOT, run_cli

from walkerlab.config import scene_from_dict
from walkerlab.walker.kinds import GYM_FOOTHOLDS, SEVERAL_FOOTHOLDS

#: configs/footholds.yaml with configs/paper.yaml's contact sections (its lanes and
#: patches too), the footholds at two heights
FOOTHOLDS = yaml.safe_load((ROOT / "configs" / "footholds.yaml").read_text())
SCENE = {**FOOTHOLDS, **{k: PAPER[k] for k in ("contact", "contact_sim", "contact_solver")},
         "terrain": {**FOOTHOLDS["terrain"], "foothold_heights_m": [-0.005, -0.01],
                     "lanes": "checkerboard", "patch_width_m": 0.10}}
INTERNAL = ("heights1", "heights2", "lane1", "lane2", "shape (")


def _scene_file(tmp_path):
    p = tmp_path / "footholds2.yaml"
    p.write_text(yaml.safe_dump(SCENE))
    return p


def test_contact_sim_on_footholds_of_two_heights_is_one_line_naming_the_key(tmp_path):
    rc, err, _ = run_cli("contact-sim", _scene_file(tmp_path), "--runs-dir", tmp_path / "r")
    assert rc == 1 and "\n" not in err
    assert err == ("error: scene 'footholds2': terrain.foothold_heights_m: "
                   + SEVERAL_FOOTHOLDS)
    assert "give footholds of one height" in err  # what to do
    assert not any(s in err for s in INTERNAL)


def test_report_names_the_stage_that_refused(tmp_path):
    rc, err, out = run_cli("-q", "report", _scene_file(tmp_path), "--runs-dir", tmp_path / "r")
    assert rc == 1 and "\n" not in err
    assert err.startswith("error: report stopped at contact-sim: scene 'footholds2': "
                          "terrain.foothold_heights_m: ")
    # the rigid stages before it ran: the rigid model walks these footholds
    assert (tmp_path / "r" / "footholds2" / "simulate.h5").is_file()


def test_a_contact_walker_laid_on_new_lanes_drops_the_old_patch_heights():
    """The internal "heights1: one finite height [m] per patch of lane1" came from a walker
    on a terrain laid out again (new lanes, the old heights kept)."""
    from walkerlab.analysis.gait.scene import solve_scene
    from walkerlab.models.contact.scene import contact_setup

    d = copy.deepcopy(SCENE)
    d["terrain"]["foothold_heights_m"] = [-0.005]  # one height: the contact model's
    sc = scene_from_dict(d)
    _, search = solve_scene(sc)
    walker, step = contact_setup(sc).build(search.result.x, 10)
    assert walker.heights1 is not None and walker.heights1.size == walker.lane1.size
    again = walker.on_terrain(sc.terrain, step_length=step, n_steps=40)
    assert again.heights1.size == again.lane1.size > walker.lane1.size
    # each footfall 5 mm lower along the slope's normal, as the first lay-out
    n = min(walker.heights1.size, 4)
    assert np.array_equal(again.heights1[:n], walker.heights1[:n])


def test_the_gym_names_no_view_that_refuses_the_same_footholds():
    from walkerlab.gym.env import _check_rigid_ground

    with pytest.raises(ValueError) as err:
        _check_rigid_ground(scene_from_dict(SCENE))
    assert str(err.value) == ("walkerlab.gym: terrain.foothold_heights_m: " + GYM_FOOTHOLDS)
    assert "view='contact'" not in str(err.value)
