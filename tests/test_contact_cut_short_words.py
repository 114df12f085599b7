"""Issue 96: a contact run or periodic search cut short is named so wherever it is shown;
the rough edges around it (compare's E_avg note, the energy guard's words, a start offset
checked up front, no friction on a 3D walker)."""

from types import SimpleNamespace

import numpy as np
import pytest

from walkerlab.config import load_scene
from walkerlab.walker.plant import Plant


def test_periodic_search_cut_by_a_wall_clock_limit_is_named_so():
    """time_limit names the wall-clock field and says it is no property of the scene;
    work_limit names its work bound; other kinds stay their name."""
    from walkerlab.report.run_text import periodic_not_found

    t = periodic_not_found("time_limit")
    assert "contact_sim.periodic_time_limit_s" in t and "not a property of the scene" in t
    assert "contact_sim.periodic_max_step_maps" in periodic_not_found("work_limit")
    assert periodic_not_found("fall") == "fall"


def test_gait_table_note_says_why_the_periodic_gait_is_missing():
    """A scene whose periodic search was cut short: the gait table's note says so, never
    'the scene computes no contact periodic gait' (which it says only when none was asked
    for)."""
    from walkerlab.io.stage_files import CONTACT_SIM
    from walkerlab.report import sections

    cols = {"ours, ideal": {}, "ours, contact": {}}
    path = SimpleNamespace(name="x.h5")

    def note(periodic):
        arts = {CONTACT_SIM.name: SimpleNamespace(periodic=periodic, path=path)}
        inputs = SimpleNamespace(gait_columns=cols, artifacts=arts)
        return "\n".join(sections.gait_note(inputs))

    cut = note(SimpleNamespace(found=False, outcome="time_limit"))
    assert "computes no contact periodic gait" not in cut
    assert "contact_sim.periodic_time_limit_s" in cut
    assert "computes no contact periodic gait" in note(None)


def _comparison(ideal_steps, contact_steps, cut=""):
    from walkerlab.io.schemas.compare import Comparison
    from walkerlab.units import Units

    m = {"E_avg_J": 1.0}
    return Comparison(
        legs=["leg1"], time=np.array([0.0, 1.0]), errors={}, error_units={},
        limit_cycle_distance={}, max_abs_angle_rad=0.0, max_abs_rate_rad_per_s=0.0,
        metrics={"ideal": {**m, "E_avg_steps": ideal_steps},
                 "contact": {**m, "E_avg_steps": contact_steps}},
        metric_units={"E_avg_J": "J"}, units=Units(), contact_cut_short=cut)


def test_compare_note_gives_each_runs_own_energy_steps():
    """The E_avg note said 'the first 2 steps of each run' when the contact run's average
    covers 3: each run's own count now, and 'each run' only when they agree."""
    from walkerlab.report.run_text import compare_text

    assert ("the first 2 steps of the ideal run and the first 3 of the contact run"
            in compare_text(_comparison(2, 3)))
    assert "the first 2 steps of each run" in compare_text(_comparison(2, 2))


def test_compare_of_a_wall_limited_contact_run_says_so_first():
    from walkerlab.report.run_text import compare_text

    text = compare_text(_comparison(2, 2, cut="the contact run: contact_sim.wall_time_limit_s"))
    first = text.splitlines()[0]
    assert first.startswith("the contact run was cut short by a wall-clock limit")
    assert "time_limit" in first


def test_energy_guard_words_come_from_what_the_walker_has():
    """A passive walker 'cannot gain energy'; one whose joint law does work is not told
    so: its rise is more than the law can put in."""
    from walkerlab.integrate.contact import energy_source_words

    passive = SimpleNamespace(kernels=SimpleNamespace(STANCE_LAW=False))
    active = SimpleNamespace(kernels=SimpleNamespace(STANCE_LAW=True))
    assert "cannot gain energy" in energy_source_words(passive)
    assert "cannot gain energy" not in energy_source_words(active)
    assert "joint law" in energy_source_words(active)


def test_a_wrong_start_offset_state_is_refused_before_any_search_listing_every_name():
    """contact_setup (the stage's check, before the rigid gait search) refuses a name the
    walker does not have, in one line that lists all its states (the last one too; the
    list used to be cut)."""
    from walkerlab.config.studies import StateOffset
    from walkerlab.models.contact.scene import ContactSceneError, contact_setup

    scene = load_scene("configs/hip_width_stabilised.yaml")
    cs = scene.contact_sim.model_copy(update={"start_offset": StateOffset.model_validate(
        {"tilt_rate_rad_per_s": 1.0})})
    bad = scene.model_copy(update={"contact_sim": cs})
    with pytest.raises(ContactSceneError) as e:
        contact_setup(bad, plant=Plant.from_scene(bad))
    msg = str(e.value)
    assert "\n" not in msg and len(msg) < 300
    assert "contact_sim.start_offset.tilt_rate_rad_per_s: not a state" in msg
    assert msg.endswith("of the roles lean, swing, stance, pelvis_roll, swing_roll)")


def test_twist_without_friction_is_zero_not_a_division_by_zero():
    """contact.mu_static 0 on a 3D walker: the torsional moment is 0 (no friction), where
    the contact kernel divided by mu_s (internal error ZeroDivisionError)."""
    from walkerlab.models.contact.assembly import I_MUD, I_MUS, I_TOR, I_VD, I_VS, twist

    pc = np.zeros(max(I_MUD, I_MUS, I_TOR, I_VD, I_VS) + 1)
    pc[I_TOR], pc[I_VS], pc[I_VD] = 0.01, 0.1, 1.0
    assert twist.py_func(2.0, 100.0, pc) == 0.0
    pc[I_MUS], pc[I_MUD] = 0.9, 0.7
    assert twist.py_func(2.0, 100.0, pc) != 0.0
