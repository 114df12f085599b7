"""One verdict from a contact run's steps (issue 51, item 2): a trip or fall after the heel
strikes asked for is named and the run does not "walk"; a checkerboard whose patches do
not suit the gait's step is said; steps that shorten monotonically are no steady gait."""

from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from tests.contact.conftest import FP, STEP_LENGTH
from walkerlab.analysis.contact.sim import initial_state_from_ideal, simulate_contact
from walkerlab.analysis.contact.terrain_fit import PatchFit
from walkerlab.analysis.contact.verdict import Outcome, step_trend, walk_verdict
from walkerlab.config import ContactSettings, TerrainSettings
from walkerlab.models.contact import ContactWalker
from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[2]


def test_a_trip_after_the_strides_asked_for_is_named_and_is_no_walk(monkeypatch):
    """The paper walker's run (5 heel strikes asked for: 4 made, the cap at the 5th) given
    a trip after all its samples, as the powered compass at 2.5 N s meets one after its 12
    heel strikes.  Before: "walked: 4 heel strikes (the number asked for)" and nothing
    else.  Now the outcome keeps the cap's kind (the strides were made) but names the trip
    after them, and the verdict from the steps is: does not walk."""
    import dataclasses

    from walkerlab.analysis.contact import sim

    w = ContactWalker.from_settings(ContactSettings(), TerrainSettings(patch_width_m=0.10),
                                    step_length=STEP_LENGTH, n_steps=12)
    real = sim.integrate_contact

    def tripping(*a, **k):
        run = real(*a, **k)
        k_end = len(run.t)
        return dataclasses.replace(
            run, termination="trip", event=("trip", k_end, float(run.t[-1]), "leg2", 1.5),
            message="trip: leg2's foot entered a patch from its side")

    monkeypatch.setattr(sim, "integrate_contact", tripping)
    r = simulate_contact(w, initial_state_from_ideal(w, *FP), 5.0, max_heel_strikes=5)
    out = r.outcome
    assert out.kind == "heel_strike" and out.walked, out
    assert out.after == "trip" and out.after_time_s == pytest.approx(float(r.t[-1]))
    assert "the number asked for), then tripped at t = " in out.message
    assert "trip: leg2's foot entered a patch from its side" in out.message
    walks, why = r.verdict
    assert not walks and "then tripped" in why


def test_walk_verdict_from_the_steps():
    steps = [SimpleNamespace(period=T) for T in
             (0.583, 0.5776, 0.5742, 0.5706, 0.5669, 0.5626, 0.5573, 0.5498, 0.5373, 0.5091,
              np.nan)]  # the run: push-off 4 N s, hip spring 10 N m/rad
    walks, why = walk_verdict(Outcome("heel_strike", message="walked"), steps)
    assert not walks
    assert why.startswith("its steps shorten monotonically (0.583 → 0.509 s")
    # a solver's failure after the strides is named in the message, not a fall
    steady = [SimpleNamespace(period=0.7) for _ in range(6)]
    walks, why = walk_verdict(Outcome("heel_strike", after="solver_failure"), steady)
    assert walks and why == ""
    assert not walk_verdict(Outcome("heel_strike", after="fall", after_time_s=1.0), steady)[0]
    assert not walk_verdict(Outcome("fall", message="fall: hip low"), steps)[0]


@pytest.mark.parametrize("periods", [
    # powered_compass.yaml's run (settles to 0.699 s), asymmetric_legs.yaml's (a period-2
    # gait: steps alternate), paper.yaml's (a transient that dies out)
    (0.6993, 0.7069, 0.7095, 0.7079, 0.7048, 0.7021, 0.7002, 0.6993, 0.6987, 0.6987, 0.6987,
     0.6989, 0.699),
    (0.6857, 0.735, 0.6861, 0.7242, 0.6826, 0.7223, 0.6835, 0.7235, 0.6835, 0.7233),
    (0.5845, 0.6155, 0.6581, 0.7152, 0.744, 0.7204, 0.7081, 0.7071, 0.7095, 0.7112)])
def test_steps_of_the_shipped_walking_runs_settle(periods):
    assert step_trend(periods) == ""


def test_the_patches_that_do_not_suit_the_step_are_named():
    """The powered compass at 2.5 N s on 0.30 m patches laid out at the rigid step
    (0.3144 m): its contact steps are ~0.30 m, the footfalls drift ~14 mm a step and the
    12th lands 0.147 m short of its patch's centre (±0.15 m).  At 1.5 N s (0.2424 m steps)
    the swing foot has only ±0.092 m over its lane's gap beside the stance foot."""
    off = np.array([0.0007, -0.002, -0.009, -0.020, -0.034, -0.049, -0.064, -0.081, -0.097,
                    -0.114, -0.131, -0.147])
    fit = PatchFit(0.3144, 0.15, off, np.full(12, 0.3021))
    note = fit.note()
    assert fit.drift_m_per_step == pytest.approx(-0.0140, abs=1e-3)
    assert "do not suit this gait's step" in note and "heel strike 12 landed -0.147 m" in note
    assert "±0.15 m on its patch" in note and "±0.164 m over its lane's gap" in note
    fit = PatchFit(0.2424, 0.15, np.array([0.0003, -0.0023, -0.010, -0.022, -0.037, -0.055,
                                           -0.075]), np.full(7, 0.23))
    assert fit.margin_m == pytest.approx(0.0924)
    assert "±0.0924 m over its lane's gap" in fit.note()
    # footfalls near their patches' centres: nothing to say
    assert PatchFit(0.3144, 0.15, np.array([0.001, -0.002, 0.003]), np.full(3, 0.31)).note() == ""


def test_the_report_says_the_verdict_from_the_steps():
    from walkerlab.io.schemas.contact_sim import ContactSimArtifact
    from walkerlab.report.sections import summary_section
    from walkerlab.report.text import contact_text
    from walkerlab.units import Units

    c = ContactSimArtifact(path=Path("x"), units=Units(), termination="heel_strike",
                           outcome="heel_strike", outcome_message="walked: 10 heel strikes",
                           walks=False, walks_reason="its steps shorten monotonically",
                           heel_strike_times=np.arange(10.0))
    lines = summary_section(SimpleNamespace(units="SI", fixedpoint=None),
                            SimpleNamespace(artifacts={"contact-sim": c}, gait_columns={}),
                            None)
    assert any("**Contact walker walks**: no" in s and "shorten monotonically" in s
               for s in lines), lines
    assert "walks: no (its steps shorten monotonically)" in contact_text(c)


@pytest.mark.slow
@pytest.mark.parametrize("impulse, strides, heel_strikes, patches", [
    (2.5, 4, 9, "the footfalls drift on the patches"),
    (1.5, 3, 8, "do not suit this gait's step")])
def test_the_powered_compass_off_its_patches(tmp_path, impulse, strides, heel_strikes,
                                             patches):
    """configs/powered_compass.yaml at 2.5 and 1.5 N s from the rigid gait: the strides asked
    for, then a fall into a gap, named (before: "walked: N heel strikes (the number asked
    for)" and nothing more); both name the patches: at 2.5 N s the last footfall is still on
    its patch (-0.132 m from its centre, ±0.15 m on it), so the footfalls' drift is named,
    not a patch that does not suit the step (issue 82 item 11); at 1.5 N s it is off.  (The
    issue's 12 and 8 heel strikes were made with the old 5 ms pulse from touchdown; with the
    pulse ending at touchdown the footfalls drift ~17 and ~14 mm a step, and the runs fall
    after 9 and 7.)  The paper's friction velocities (100 and 1000 mm/s, the scene's before
    its friction moved 10x closer to Coulomb's) make the steps shrink into the gaps.  (On the
    scene's compiled contact run, cyrk_bdf, the 1.5 N s walker makes an 8th heel strike at its
    patch's edge, -0.150 m from its centre, scuffs and falls: 8, not the LSODA run's 7.)"""
    from walkerlab.analysis.contact.periodic import ideal_gait
    from walkerlab.analysis.contact.sim import simulate_from
    from walkerlab.api.scenes import with_changes
    from walkerlab.config import load_scene
    from walkerlab.models.contact.scene import contact_setup

    scene = with_changes(load_scene(ROOT / "configs" / "powered_compass.yaml"),
                         {"walker.actuation.push_off.impulse_n_s": impulse,
                          "fixedpoint.initial_guess": None, "contact_sim.n_strides": strides,
                          "contact.stiction_velocity_mm_per_s": 100.0,
                          "contact.friction_velocity_mm_per_s": 1000.0})
    ideal = ideal_gait(scene, plant=Plant.from_scene(scene))
    _, res, _, _ = simulate_from(contact_setup(scene,
            plant=Plant.from_scene(scene)), ideal.x, ideal.period_s)
    # at 1.5 N s the last heel strike lands on its patch's very edge (-0.150 m from the
    # centre of a +-0.15 m patch): whether it is made is decided by round-off (the planar
    # contact kernel's friction written as the 3D one's, equal to round-off, moved it from 8
    # to 7, its swing foot then meeting the patch's side: "then the solver failed" there)
    assert heel_strikes - (impulse < 2) <= len(res.heel_strike_times) <= heel_strikes
    assert "then fell" in res.outcome.message or (
        impulse < 2 and "then the solver failed" in res.outcome.message)
    assert "after the strides asked for" in res.outcome.message
    assert patches in res.outcome.message
    assert not res.verdict[0]


def test_a_footfall_still_on_its_patch_is_not_blamed_on_the_patches():
    """0.1 m patches at 0.37 m spacing (the paper's checkerboard): the footfall's room is its
    patch (±0.05 m; the swing foot has ±0.32 m over the gap).  A last footfall 0.03 m from
    its patch's centre has used most of it, but landed on it: the note says so and does not
    say the patches do not suit the step (a steep slope's unstable gait falls from there)."""
    fit = PatchFit(0.37, 0.05, np.array([0.0, 0.004, 0.012, 0.03]), np.full(4, 0.375))
    note = fit.note()
    assert "the last still on its patch" in note and "heel strike 4 landed +0.030 m" in note
    assert "do not suit" not in note
    # off its patch: the patches are named
    off = PatchFit(0.37, 0.05, np.array([0.0, 0.02, 0.04, 0.06]), np.full(4, 0.39))
    assert "do not suit this gait's step" in off.note()
