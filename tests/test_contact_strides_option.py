"""``walkerlab contact-sim --strides N`` as ``simulate --strides N`` (issue 58): the option
overrides ``contact_sim.n_strides``, the run walks that many strides, and a stored run of
another number of strides is not reused for it."""

from __future__ import annotations

import yaml
from cli_run import PAPER, run_cli


def _strides(path) -> tuple[int, int]:
    from walkerlab.io.schemas.contact_sim import load_contact_sim

    s = load_contact_sim(path).summary
    return int(s["strides_completed"][0]), int(s["heel_strikes"][0])


def test_contact_sim_strides_option_walks_that_many_and_is_not_a_stale_artifact(tmp_path):
    scene = tmp_path / "paper.yaml"
    scene.write_text(yaml.safe_dump(PAPER))
    runs = tmp_path / "runs"
    art = runs / "paper" / "contact_sim.h5"
    rc, err, out = run_cli("-q", "contact-sim", scene, "--strides", 1, "--runs-dir", runs)
    assert rc == 0, err
    assert _strides(art) == (1, 2)  # the scene asks for 5 strides (10 heel strikes)
    rc, err, out = run_cli("-q", "contact-sim", scene, "--strides", 2, "--runs-dir", runs)
    assert rc == 0, err
    assert "reused" not in out and _strides(art) == (2, 4)
    rc, err, out = run_cli("-q", "contact-sim", scene, "--strides", 2, "--runs-dir", runs)
    assert rc == 0 and "reused" in out  # the same option: the same inputs


def test_contact_sim_strides_out_of_bounds_is_one_line_naming_the_field(tmp_path):
    scene = tmp_path / "paper.yaml"
    scene.write_text(yaml.safe_dump(PAPER))
    rc, err, _ = run_cli("contact-sim", scene, "--strides", 0, "--runs-dir", tmp_path / "r")
    assert rc == 1
    assert err == ("error: --strides 0: input should be greater than or equal to 1 "
                   "(as contact_sim.n_strides)")
    assert not (tmp_path / "r" / "paper").exists()  # refused before the gait was searched
