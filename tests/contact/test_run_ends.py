"""How a run ends (issue 19 items 6 and 9): a walker that flies away or never moves gets a
typed outcome and exit code 1, and the wall-time limit holds inside a chunk."""

from pathlib import Path

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from tests.contact.conftest import FP, STEP_LENGTH
from walkerlab.analysis.contact.sim import (
    initial_state_from_ideal,
    named_trajectory,
    simulate_contact,
)
from walkerlab.cli import app
from walkerlab.config import ContactSettings, SolverSettings, TerrainSettings
from walkerlab.integrate.contact import ContactLimits
from walkerlab.integrate.ends import CONTACT_WALKED, RUN_END_NAMES
from walkerlab.models.contact import ContactWalker
from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[2]


def _paper():
    return ContactWalker.from_settings(ContactSettings(), TerrainSettings(patch_width_m=0.10),
                                       step_length=STEP_LENGTH, n_steps=12)


def test_walker_that_flies_away_is_airborne_not_completed():
    """Rates x1000 (the issue's ``initial_rate_scale: [1000, 1000]``): the stance leg
    throws the hip up at ~860 m/s.  Before: outcome 'completed' with 0 heel strikes and the
    hip 870 m up.  Now: 'airborne' once the hip passes 1.5 leg lengths, which no walking
    state reaches (a foot touches the ground only while the hip is within one leg length)."""
    w = _paper()
    x0 = initial_state_from_ideal(w, *FP, rate_scale=(1000.0, 1000.0))
    r = simulate_contact(w, x0, 1.0)
    assert r.outcome.kind == r.termination == "airborne", r.outcome
    assert r.walked_steps == 0 and not r.outcome.walked
    assert w.hip_height(r.x[-1:])[0] == pytest.approx(1.5 * w.L, rel=1e-6)  # cut at the event
    assert "airborne" in r.outcome.message and "\n" not in r.outcome.message


def test_run_without_a_heel_strike_is_no_heel_strike():
    """A run that reaches its end time without a step is not a walk."""
    w = _paper()
    r = simulate_contact(w, initial_state_from_ideal(w, *FP), 0.3)  # first step ends ~0.7 s
    assert r.termination == "t_final"
    assert r.outcome.kind == "no_heel_strike" and not r.outcome.walked


def test_a_one_sample_run_maps_onto_the_named_layout():
    """``[1e10, 1]`` used to end as 'internal error (IndexError)': a run with a single
    sample made the foot positions (2, 2) instead of (1, 2, 2).  A run stopped at its first
    sample (here by a wall-time limit already spent) maps onto the named layout."""
    w = _paper()
    x0 = initial_state_from_ideal(w, *FP)
    r = simulate_contact(w, x0, 1.0, SolverSettings.for_contact(method="odeint"),
                         ContactLimits(wall_time_limit_s=1e-9))
    assert r.t.size == 1 and r.outcome.kind == "time_limit"
    tr = named_trajectory(w, r)
    assert tr.points["leg1_foot"].shape == (2, 1)
    assert set(tr.coordinates) == {"leg1_angle", "leg1_rate", "leg2_angle", "leg2_rate"}


# the quick suite's CPU budget (README): a longer run, in `pytest -m slow`
@pytest.mark.slow
@pytest.mark.parametrize("method", ["cyrk_bdf", "odeint"])
def test_wall_time_limit_holds_inside_a_chunk(method):
    """Rates x1e6 (issue 19 item 9: a 120 s limit computed for 182 s, one 1 s chunk of
    CyRK's BDF took ~150 s).  The limit is now checked inside the chunk: a 2 s limit stops
    the run within a few seconds of it, with outcome time_limit.  The flight test is off so
    that only the limit can end this run."""
    limit = 2.0
    w = _paper()
    x0 = initial_state_from_ideal(w, *FP, rate_scale=(1e6, 1e6))
    r = simulate_contact(w, x0, 1.0, SolverSettings.for_contact(method=method),
                         ContactLimits(wall_time_limit_s=limit, airborne_hip_height_m=np.inf))
    assert r.outcome.kind == "time_limit", r.outcome
    assert r.wall_time_s < limit + 3.0  # "a few seconds": the chunk is cut, not finished


def test_one_vocabulary():
    """Contact outcomes, rigid terminations and the walked set are names of one tuple."""
    from walkerlab.analysis.contact.verdict import CONTACT_OUTCOMES
    from walkerlab.integrate.ends import RIGID_ENDS
    from walkerlab.studies.outcomes import OUTCOMES

    assert set(CONTACT_OUTCOMES) <= set(RUN_END_NAMES)
    assert set(RIGID_ENDS) <= set(RUN_END_NAMES)
    assert set(CONTACT_WALKED) <= set(RUN_END_NAMES)
    assert set(RUN_END_NAMES) - {"heel_strike", "t_final"} <= set(OUTCOMES)


def test_rigid_walker_that_never_moves_exits_1_in_one_line(tmp_path):
    """Slope 0, all-zero state: the legs stand upright on the heel-strike surface and never
    move.  Before: '10 heel strikes' of period 0 s, exit code 0 and a RuntimeWarning.  Now:
    termination no_heel_strike, exit code 1, one line (pytest turns any warning into an
    error)."""
    d = yaml.safe_load((ROOT / "configs" / "paper.yaml").read_text())
    d = {k: d[k] for k in ("walker", "slope", "solver")}
    d["name"] = "still"
    d["slope"] = {"angle_rad": 0.0}
    d["simulate"] = {"strides": 5, "initial_state": {
        "swing_angle_rad": 0.0, "stance_angle_rad": 0.0, "swing_rate_rad_per_s": 0.0,
        "stance_rate_rad_per_s": 0.0}}
    p = tmp_path / "still.yaml"
    p.write_text(yaml.safe_dump(d))
    r = CliRunner().invoke(app, ["simulate", str(p), "--runs-dir", str(tmp_path / "runs")])
    err = r.stderr.strip()
    assert r.exit_code == 1, r.stdout
    assert "no_heel_strike" in err and "\n" not in err
    # a run that did not walk: its count is in the error line, no summary (issue 26, item 5)
    assert "0 heel strikes" in err and "simulated" not in r.stdout


@pytest.mark.slow  # in `pytest -m slow`: the quick suite keeps to its CPU budget
def test_a_run_asked_for_n_strides_goes_on_until_it_makes_them_or_says_why_not():
    """configs/asymmetric_legs.yaml on its former 0.1 m patches: the contact model's steps
    are slower than the rigid ones the end time is sized by (5 rigid strides' time).
    Before: the run ended at that time after 9 heel strikes (4 strides) with outcome
    't_final', as if it had walked.  Now it goes on past that time (it is short of the 10
    heel strikes asked for) and says why it did not make them: its footfalls drift off the
    patches and it falls.  On the scene's 0.2 m patches it makes them."""
    from walkerlab.analysis.contact.periodic import ideal_gait
    from walkerlab.analysis.contact.sim import simulate_from
    from walkerlab.api.scenes import with_changes
    from walkerlab.config import load_scene
    from walkerlab.models.contact.scene import contact_setup

    scene = load_scene(ROOT / "configs" / "asymmetric_legs.yaml")
    ideal = ideal_gait(scene, plant=Plant.from_scene(scene))
    step = float(np.mean(ideal.step_periods_s))  # the stride map's two steps
    horizon = (2 * scene.contact_sim.n_strides + 0.5) * step
    narrow = with_changes(scene, {"terrain.patch_width_m": 0.10})
    _, res, _, _ = simulate_from(contact_setup(narrow,
                                               plant=Plant.from_scene(narrow)), ideal.x, step)
    assert res.t[-1] > horizon and res.outcome.kind == "fall", res.outcome
    assert "after 9 heel strikes" in res.outcome.message
    _, res, _, _ = simulate_from(contact_setup(scene, plant=Plant.from_scene(scene)), ideal.x, step)
    assert res.outcome.walked and len(res.heel_strike_times) >= 2 * scene.contact_sim.n_strides


def test_a_fall_on_continuous_ground_names_the_scuffs_and_the_checkerboard():
    """The paper walker on continuous ground: its swing foot scuffs at mid-stance and it
    falls within the first step.  Before: "fall: hip 0.500 m above ground ... after 0 heel
    strikes" only; now the message names the scuffs its own table counts and the remedy."""
    from walkerlab.analysis.contact.periodic import ideal_gait
    from walkerlab.analysis.contact.sim import simulate_from
    from walkerlab.api.scenes import with_changes
    from walkerlab.config import load_scene
    from walkerlab.models.contact.scene import contact_setup

    scene = with_changes(load_scene(ROOT / "configs" / "paper.yaml"),
                         {"terrain.kind": "continuous"})
    ideal = ideal_gait(scene, plant=Plant.from_scene(scene))
    _, res, _, _ = simulate_from(contact_setup(scene,
            plant=Plant.from_scene(scene)), ideal.x, ideal.period_s)
    assert res.outcome.kind == "fall"
    assert "scuffed the ground" in res.outcome.message
    assert "terrain.lanes: checkerboard" in res.outcome.message  # the field's own name


def _contact_walker(scene):
    """The scene's contact walker on its ground (patches 0.4 m apart: their spacing does
    not enter the advice)."""
    from walkerlab.models.contact.scene import contact_setup

    setup = contact_setup(scene, plant=Plant.from_scene(scene))
    n = 2 * len(setup.walker.structure.bodies) + 2  # a state of the walker's size
    return setup.build(np.zeros(max(n, 4)), 4, step_length_m=0.4)[0]


def test_a_fall_after_scuffs_is_advised_for_the_walker_and_its_ground():
    """Before, every fall after scuffs blamed a straight leg's mid-stance dip and suggested
    the checkerboard: also for a kneed walker whose latch is off (its stance knee buckles)
    and on a profile (where the checkerboard was refused).  Now the advice fits: the latch
    for a kneed walker without it, knees or (a profile flat at the footfalls) the
    checkerboard on a profile, the checkerboard
    (``terrain.lanes``) for straight legs on continuous slope."""
    from walkerlab.analysis.contact.verdict import scuff_cause
    from walkerlab.api.scenes import with_changes
    from walkerlab.config import load_scene

    kneed = load_scene(ROOT / "configs" / "kneed.yaml")
    unlatched = with_changes(kneed, {"contact.knee_stop.latch": False})
    why = scuff_cause(_contact_walker(unlatched))
    assert "contact.knee_stop.latch: true" in why
    assert "straight leg" not in why and "checkerboard" not in why
    assert scuff_cause(_contact_walker(kneed)) == ""  # latched: nothing general to name
    paper = load_scene(ROOT / "configs" / "paper.yaml")
    profile = yaml.safe_load((ROOT / "configs" / "profile.yaml").read_text())["terrain"]
    on_profile = paper.model_copy(update={"terrain": TerrainSettings(**profile)})
    why = scuff_cause(_contact_walker(on_profile))
    assert "straight leg" in why and "knees" in why  # the checkerboard: a flat profile's
    assert "flat across each footfall's patch" in why
    flat = with_changes(paper, {"terrain.kind": "continuous"})  # paper.yaml: kind: checkerboard
    assert "terrain.lanes: checkerboard" in scuff_cause(_contact_walker(flat))


def test_an_unlatched_kneed_walker_on_a_profile_falls_with_the_latch_advice(tmp_path):
    """configs/profile.yaml (a kneed walker) with its latch off: the stance knee buckles
    and the walker falls after one scuff.  Before: "a straight leg's swing foot passes below
    the ground line ...; terrain.kind: checkerboard gives it a gap there" (refused on a
    profile); now the latch."""
    text = (ROOT / "configs" / "profile.yaml").read_text()
    assert text.count("latch: true") == 1
    scene = tmp_path / "profile_unlatched.yaml"
    scene.write_text(text.replace("latch: true", "latch: false"))
    r = CliRunner().invoke(app, ["contact-sim", str(scene), "--runs-dir", str(tmp_path)])
    assert r.exit_code == 1 and "fall" in r.output, r.output
    assert "scuffed the ground" in r.output and "contact.knee_stop.latch: true" in r.output
    assert "checkerboard" not in r.output and "straight leg" not in r.output


def test_a_benchmark_never_reports_a_target_on_a_run_that_stopped_early():
    """``walkerlab bench contact``: a run (or the reference) that stops before the end time
    ("Excess work done", a fall) has no error over the span: infinite, never "reached"."""
    from types import SimpleNamespace

    from walkerlab.bench.contact import _Case

    case = _Case.__new__(_Case)
    case.t_final, case.limits, case.angles = 1.0, SimpleNamespace(sample_rate_hz=1000.0), [0]
    full = SimpleNamespace(t=np.linspace(0, 1.0, 1001), x=np.zeros((1001, 1)))
    short = SimpleNamespace(t=np.linspace(0, 0.8, 801), x=np.zeros((801, 1)))
    case.ref = full
    assert case.error(full) == 0.0
    assert case.error(short) == np.inf
    case.ref = short
    assert case.error(full) == np.inf


# the quick suite's CPU budget (README): a longer run, in `pytest -m slow`
@pytest.mark.slow
def test_the_upper_body_walker_makes_five_strides_from_its_contact_periodic_gait():
    """configs/torso_bhm.yaml: from the adjusted rigid start the footfalls drift off the
    0.1 m patches and a foot in a gap enters a patch's side at 8.69 s, where the solver
    stops (before: reported as a solver failure, "Excess work done"; now a trip).  From the
    contact model's own periodic gait (patches at its footfalls) it makes 5 strides."""
    from walkerlab.analysis.contact.periodic import ideal_gait, simulate_from_periodic_gait
    from walkerlab.config import load_scene
    from walkerlab.models.contact.scene import contact_setup

    scene = load_scene(ROOT / "configs" / "torso_bhm.yaml")
    assert scene.contact_sim.n_strides == 5 and scene.contact_sim.start == "periodic_gait"
    plant = Plant.from_scene(scene)
    _, res, *_ = simulate_from_periodic_gait(contact_setup(scene, plant=plant),
                                             ideal_gait(scene, plant=plant).x)
    assert res.outcome.kind == "heel_strike", res.outcome
    assert len(res.heel_strike_times) >= 10


@pytest.mark.parametrize("end", ["solver_failure", "time_limit"])
def test_a_run_that_fails_after_its_strides_asked_for_still_walked(monkeypatch, end):
    """configs/flat_feet_push_off.yaml's contact run made its 11 heel strikes, then LSODA
    stalled on a patch edge in the step after them (a powered run asks its strides cap at
    touchdowns, which it counts once samples follow them).  Before: outcome
    'solver_failure' and exit code 1, as if it had not walked; a trip there was already
    cut off as 'after the strides asked for'.  Now a solver failure or the wall-time limit
    after the strides asked for ends the run by the cap and names the failure; before them
    it is still a failure.  Here the paper walker's own run (2 strides, 5 heel strikes
    asked for) is given that end: after all its samples, and after its 2nd heel strike."""
    import dataclasses

    from walkerlab.analysis.contact import sim

    w = _paper()
    x0 = initial_state_from_ideal(w, *FP)
    cut = {"at": None}
    real = sim.integrate_contact

    def failing(*a, **k):
        run = real(*a, **k)
        assert run.termination == "heel_strike"  # the cap: 5 heel strikes were made
        k_end = len(run.t) if cut["at"] is None else int(np.searchsorted(run.t, cut["at"]))
        return dataclasses.replace(run, t=run.t[:k_end], X=run.X[:k_end],
                                   termination=end, message="the solver stalled")

    monkeypatch.setattr(sim, "integrate_contact", failing)
    limits = ContactLimits(wall_time_limit_s=600.0)  # (named by a time_limit's message)
    r = simulate_contact(w, x0, 5.0, limits=limits, max_heel_strikes=5)
    assert r.termination == "heel_strike" and r.outcome.walked, r.outcome
    assert len(r.heel_strike_times) == 5
    assert end.replace("_", " ") in r.message and "the solver stalled" in r.message
    cut["at"] = float(r.heel_strike_times[1]) + 0.05  # 2 heel strikes, short of the 4 asked
    r = simulate_contact(w, x0, 5.0, limits=limits, max_heel_strikes=5)
    assert r.termination == end and not r.outcome.walked, r.outcome
    assert len(r.heel_strike_times) == 2


def test_an_integrators_stop_message_is_said_in_walkerlabs_words():
    """odeint's (ODEPACK's) "Excess work done on this call (perhaps wrong Dfun type)." is
    said as what happened (the step budget spent: a contact too stiff to step through) with
    the rigid-limit study's advice, the integrator's own words kept in brackets; a message
    walkerlab does not know passes unchanged, and a translated one is not translated
    twice."""
    from walkerlab.analysis.contact.step_map import FELL_ADVICE
    from walkerlab.integrate.ends import solver_words

    raw = "Excess work done on this call (perhaps wrong Dfun type)."
    said = solver_words(raw)
    assert said.startswith("the integrator spent its step budget")
    assert "walkerlab compare --rigid-limit" in said and said.endswith(f"[the integrator's "
                                                                      f"message: {raw}]")
    assert solver_words(said) == said
    assert solver_words("the walker fell") == "the walker fell"
    # the advice after a fall follows the rigid-limit study: not a stiffer law alone
    assert "make the contact law stiffer" not in FELL_ADVICE
    assert "rigid-limit family" in FELL_ADVICE and "elastic" in FELL_ADVICE


def test_a_trip_stays_the_diagnosis_when_the_solvers_words_inside_it_are_translated():
    """flat_feet_push_off's contact run ends in a trip (a heel entering a patch from its
    side), which CyRK met as "Required step size is less than spacing between numbers":
    the trip stays first, the solver's sentence is said in walkerlab's words where it
    stood (naming a patch's side beside a stiff law), its own words kept in brackets."""
    from walkerlab.integrate.ends import solver_words

    raw = ("trip: leg2_heel's foot, 0.00241 m below the patch tops in a gap, entered a patch "
           "from its side (the solver stopped there: the compiled solver stopped at t = "
           "9.164 s (Error in step size calculation: Required step size is less than "
           "spacing between numbers.))")
    said = solver_words(raw)
    assert said.startswith("trip: leg2_heel's foot") and said.endswith("]))")
    assert "a foot striking a patch's side" in said
    assert ("[the integrator's message: Required step size is less than spacing between "
            "numbers.]") in said
    assert solver_words(said) == said


@pytest.mark.slow  # ~20 s: the rigid gait and 4 s of contact walk
def test_a_contact_fall_from_an_unstable_rigid_gait_names_the_instability_first(tmp_path):
    """configs/paper.yaml on a 0.11 rad slope: its rigid gait is unstable (largest
    |multiplier| 2.59); the contact walk from it falls after 4 heel strikes.  The stage's
    failure names the unstable rigid gait first (before: only "fall ..."), then the fall."""
    from walkerlab.api.scenes import with_changes
    from walkerlab.config import load_scene
    from walkerlab.stages import pipeline

    scene = with_changes(load_scene(Path(__file__).resolve().parents[2] / "configs"
                                    / "paper.yaml"),
                         {"slope.angle_rad": 0.11, "fixedpoint.initial_guess": None,
                          "contact_sim.periodic_gait": False, "name": "steep"})
    out = pipeline.run("contact-sim", scene, tmp_path)
    assert out.failure.startswith("the rigid gait it starts from is unstable (largest "
                                  "|Floquet multiplier| 2.59"), out.failure
    assert "did not complete the run: fall" in out.failure
