"""Gait finding that helps (issue 18 part 2) and sweeps over any scene field (issue 19 item 8).

- Without ``fixedpoint.initial_guess`` the gait is found from scale-free seeds: the same fixed
  point as from the printed guess (paper Eq. 11; Tedrake's kneedCompassGait.m guess).
- Where two period-1 gaits exist (Goswami et al. 1996, Garcia et al. 1998) both are found
  and the stable one is chosen by default; ``fixedpoint.gait`` picks another.
- A failed search says in one line what was tried and what to try next.
- Sweeps address list items by name or index and refuse unknown fields before starting.
"""

from __future__ import annotations

from pathlib import Path

import h5py
import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from walkerlab.analysis.gait.search import GaitNotFound, find_gaits
from walkerlab.analysis.gait.starts import state_from_legs
from walkerlab.cli import app
from walkerlab.config import SceneError, load_scene, scene_from_dict
from walkerlab.integrate.solver import Solver
from walkerlab.io.schemas.fixedpoint import load_fixedpoint
from walkerlab.io.sweep_store import load_sweep
from walkerlab.models.registry import build_walker
from walkerlab.stages import sweep as sweep_stage
from walkerlab.studies.params import SweepError, check_axes, parse_param
from walkerlab.studies.points import evaluate
from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]

#: the heavy-hip rod walker of issue 18: 20 kg hip, uniform 4 kg 1 m rods, 2 deg slope
HEAVY_HIP = {
    "name": "heavy_hip",
    "walker": {"model": "biped", "hip_mass_kg": 20.0,
               "leg": {"length_m": 1.0, "bodies": [
                   {"kind": "rod", "name": "rod", "mass_kg": 4.0, "com_from_hip_m": 0.5,
                    "inertia_about_com_kg_m2": 4.0 / 12.0}]}},
    "slope": {"angle_deg": 2.0},
    "solver": {"method": "DOP853", "rtol": 1e-12, "atol": 1e-12},
    # configs/paper_rods.yaml's guess: from it the root finder lands on the short-period gait
    "fixedpoint": {"initial_guess": {"swing_angle_rad": -0.221, "stance_angle_rad": 0.186,
                                     "swing_rate_rad_per_s": -0.668,
                                     "stance_rate_rad_per_s": -0.831}},
}


def _plant(base: dict) -> Plant:
    """The plant of a scene mapping (the study's, as its stage builds it)."""
    return Plant.from_scene(scene_from_dict(base))


def _without_guess(name: str):
    d = yaml.safe_load((ROOT / "configs" / f"{name}.yaml").read_text())
    d["name"] = name
    del d["fixedpoint"]["initial_guess"]
    return scene_from_dict(d)


def _solve(scene):
    walker = build_walker(Plant.from_scene(scene))
    fp = scene.fixedpoint
    guess = None if fp.initial_guess is None else fp.initial_guess.as_array(walker.state_names())
    return find_gaits(walker, Solver.from_settings(scene.solver), guess, policy=fp.gait,
                      other_gait=fp.other_gait, xtol=fp.tolerance,
                      max_step_time=fp.max_step_time_s, fd_check=False)


@pytest.mark.parametrize("name", ["paper", "kneed"])
def test_automatic_guess_finds_the_printed_guess_gait(name):
    """No initial guess: the seeds find the gait the printed guess gives (paper Eq. 11 for
    the compass gait; Tedrake's guess for the kneed walker), step period and Floquet
    multipliers to 1e-9 (both roots are converged to xtol 1e-12, so they agree to ~1e-11)."""
    printed = _solve(load_scene(ROOT / "configs" / f"{name}.yaml"))  # with the guess
    auto = _solve(_without_guess(name))
    ref, got = printed.result, auto.result
    assert auto.gait.source == "seed"
    assert abs(got.period_s - ref.period_s) < 1e-9
    assert np.max(np.abs(got.multipliers_variational - ref.multipliers_variational)) < 1e-9
    assert np.max(np.abs(got.x - ref.x)) < 1e-9
    assert got.stable  # both shipped walkers walk stably (the default choice: stable)


def test_seed_states_put_both_feet_on_the_slope():
    """A seed is a state on the heel-strike surface, by leg angle whatever the coordinates:
    the slope-relative simplest walker's seed has its legs at the asked absolute angles."""
    sc = load_scene(ROOT / "configs" / "simplest.yaml")
    w = build_walker(Plant.from_scene(sc))
    g = sc.slope.phi_rad
    x = state_from_legs(w, 0.2 - g, -0.2 - g, -0.2, -0.05)
    legs = w.leg_coordinates(x, w.legs[-1])
    assert abs(float(legs[f"{w.legs[-1]}_angle"]) - (0.2 - g)) < 1e-12
    assert abs(float(legs[f"{w.legs[0]}_angle"]) - (-0.2 - g)) < 1e-12
    assert abs(float(w.heel_strike_guard(0.0, x))) < 1e-12


def test_heavy_hip_walker_reports_both_gaits_and_picks_the_stable_one():
    """Issue 18: from the guess the root finder reaches the short-period gait (max
    |multiplier| 4.08, unstable); the long-period one (0.94 s) is stable.  Both are found,
    the stable one is chosen by default and the note says how to keep the other."""
    scene = scene_from_dict(HEAVY_HIP)
    search = _solve(scene)
    labels = {g.label: g for g in search.gaits}
    assert set(labels) == {"long_period", "short_period"}
    long, short = labels["long_period"].result, labels["short_period"].result
    assert long.period_s > short.period_s
    assert long.stable and np.max(np.abs(long.multipliers_variational)) < 1.0
    assert not short.stable
    assert abs(np.max(np.abs(short.multipliers_variational)) - 4.08) < 0.01
    assert max(long.residual, short.residual) < 1e-9
    assert labels["short_period"].source == "initial_guess"
    assert search.gait.label == "long_period"
    assert any("nearest_guess" in n for n in search.notes)
    for policy, want in (("nearest_guess", "short_period"), ("short_period", "short_period"),
                         ("long_period", "long_period")):
        sc = scene_from_dict({**HEAVY_HIP, "fixedpoint": {**HEAVY_HIP["fixedpoint"],
                                                          "gait": policy}})
        assert _solve(sc).gait.label == want


def test_sweep_point_chooses_the_gait_as_the_stage_does():
    """A sweep's first point (no neighbour yet) follows fixedpoint.gait like the stage: the
    heavy-hip walker's stable long-period gait, not the unstable one its guess reaches."""
    base = scene_from_dict(HEAVY_HIP).model_dump(mode="json")
    row, _ = evaluate("fixedpoint", base, ["slope.angle_deg"], (2.0,), 0, None, {},
                      plant=_plant(base))
    # the stable gait is the partner of the one the guess reaches (deflation): "search"
    assert row["outcome"] == "ok" and row["guess_source"] == "search"
    assert row["stable"] == 1.0 and 0.93 < row["step_period_s"] < 0.95
    nearest = dict(base, fixedpoint={**base["fixedpoint"], "gait": "nearest_guess"})
    row, _ = evaluate("fixedpoint", nearest, ["slope.angle_deg"], (2.0,), 0, None, {},
                      plant=_plant(nearest))
    assert row["stable"] == 0.0 and abs(row["max_abs_multiplier"] - 4.08) < 0.01


def test_fixedpoint_artifact_records_every_gait(tmp_path):
    """fixedpoint.h5: the selected gait at the top (what downstream stages read), every
    gait found under gaits/<label>, and the CLI prints both with the choice."""
    path = tmp_path / "heavy_hip.yaml"
    path.write_text(yaml.safe_dump(HEAVY_HIP))
    r = CliRunner().invoke(app, ["fixedpoint", str(path), "--runs-dir", str(tmp_path / "runs")])
    assert r.exit_code == 0, r.output
    assert "period-1 gaits found: 2" in r.output and "UNSTABLE" in r.output
    assert "selected (fixedpoint.gait: stable): long-period gait" in r.output
    fp = load_fixedpoint(tmp_path / "runs" / "heavy_hip" / "fixedpoint.h5")
    with h5py.File(tmp_path / "runs" / "heavy_hip" / "fixedpoint.h5") as f:
        assert sorted(f["gaits"]) == ["long_period", "short_period"]
        assert f.attrs["gait"] == "long_period"
        assert f["gaits/long_period/step_period"][()] == fp.step_period_s
        assert not f["gaits/short_period/floquet/stable"][()]
    assert fp.stable and 0.9 < fp.step_period_s < 1.0
    assert fp.gaits["long_period"].step_period_s == fp.step_period_s


def _fake_gait(period, x, mult, stable, ground_ok):
    """A found gait with just what the ordering and the choice read (no root finding)."""
    from types import SimpleNamespace

    from walkerlab.analysis.gait.search import Gait

    res = SimpleNamespace(period_s=period, x=np.array(x, float), stable=stable,
                          multipliers_variational=np.array([mult, 0.1]))
    return Gait("period_1", res, "seed", np.array(x, float),
                SimpleNamespace(ok=ground_ok))


@pytest.mark.parametrize("order", [(0, 1), (1, 0)])
def test_the_chosen_gait_does_not_depend_on_the_order_the_gaits_were_found_in(order):
    """The 50 N s powered compass: an unstable short-period gait that needs the ground to
    pull (|lambda| 89.3) and an unstable long-period one on real ground (|lambda| 17.8);
    either found first, the long one is listed first and chosen, the short one is listed
    with its verdict and left out with a note."""
    from walkerlab.analysis.gait.search import GaitSearch, order_gaits, select_gait

    gaits = [_fake_gait(0.926018, [-0.78, 0.78, 2.87, -2.92], 17.8, False, True),
             _fake_gait(0.524552, [-0.74, 0.74, 2.88, -3.55], 89.3, False, False)]
    found = order_gaits([gaits[k] for k in order])
    assert [g.label for g in found] == ["long_period", "short_period"]
    search = GaitSearch(found, 0, "stable")
    assert select_gait(search) == 0
    assert any("short-period gait (needs the ground to pull" in n for n in search.notes)


def test_a_stable_gait_that_needs_the_ground_to_pull_is_not_chosen_over_one_on_real_ground():
    from walkerlab.analysis.gait.search import GaitSearch, order_gaits, select_gait

    found = order_gaits([_fake_gait(0.9, [0.1, 0.2], 0.5, True, False),
                         _fake_gait(0.5, [0.3, 0.4], 3.0, False, True)])
    search = GaitSearch(found, 0, "stable")
    assert found[select_gait(search)].result.period_s == 0.5
    # ... but asked for by label or by the guess it is chosen all the same
    assert select_gait(GaitSearch(found, 0, "long_period")) == 0
    # equal periods: ordered by the state, whichever came first
    a, b = _fake_gait(0.7, [0.2, 0.0], 2.0, False, True), _fake_gait(0.7, [0.1, 0.0], 2.0,
                                                                         False, True)
    assert order_gaits([a, b])[0] is b and order_gaits([b, a])[0] is b


def test_a_stable_gait_outside_the_friction_cone_is_not_chosen_over_one_inside():
    """Two stable gaits on real ground, the stable long-period one needing mu 3.1 against
    the ground's 0.9: fixedpoint.gait: stable takes the one inside the cone, with a note;
    when every gait is outside it the choice is as before (the most stable)."""
    from types import SimpleNamespace

    from walkerlab.analysis.gait.search import GaitSearch, order_gaits, select_gait

    def with_mu(g, ratio):
        g.ground = SimpleNamespace(ok=True, friction=SimpleNamespace(inside=ratio <= 0.9))
        return g

    found = order_gaits([with_mu(_fake_gait(0.9, [0.1, 0.2], 0.5, True, True), 3.1),
                         with_mu(_fake_gait(0.5, [0.3, 0.4], 0.8, True, True), 0.2)])
    search = GaitSearch(found, 0, "stable")
    assert found[select_gait(search)].result.period_s == 0.5
    assert any("long-period gait (needs more friction" in n for n in search.notes)
    both_out = order_gaits([with_mu(_fake_gait(0.9, [0.1, 0.2], 0.5, True, True), 3.1),
                            with_mu(_fake_gait(0.5, [0.3, 0.4], 0.8, True, True), 2.0)])
    assert both_out[select_gait(GaitSearch(both_out, 0, "stable"))].result.period_s == 0.9


def test_failed_search_says_what_was_tried_in_one_line():
    """Level ground has no passive gait: the message names the attempts and the next step."""
    d = yaml.safe_load((ROOT / "configs" / "paper.yaml").read_text())
    d["slope"] = {"angle_rad": 0.0}
    with pytest.raises(GaitNotFound) as exc:
        _solve(scene_from_dict(d))
    msg = str(exc.value)
    assert "\n" not in msg
    assert "tried the initial guess and" in msg and "scale-free seeds" in msg
    assert "downhill slope" in msg and "try a continuation" in msg


def test_nearest_guess_without_a_guess_is_refused():
    d = yaml.safe_load((ROOT / "configs" / "paper.yaml").read_text())
    del d["fixedpoint"]["initial_guess"]
    d["fixedpoint"]["gait"] = "nearest_guess"
    with pytest.raises(SceneError, match="fixedpoint.gait: 'nearest_guess' needs"):
        scene_from_dict(d, "x.yaml")


# ----------------------------------------------------------------------------- sweeps
def test_sweep_over_a_body_mass_by_name(tmp_path):
    """A sweep over the kneed walker's shank mass, the body addressed by name: more mass low
    on the swing leg lengthens its pendulum (effective length sum m d^2 / sum m d grows as
    the 0.65 m shank mass grows against the 0.3 m thigh mass), so the step period grows.
    The same body by index gives the same point."""
    scene = load_scene(ROOT / "configs" / "kneed.yaml")
    p = sweep_stage.run(scene, ["walker.leg.bodies.shank_mass.mass_kg=0.03,0.05,0.07"],
                        "fixedpoint", workers=1, runs_root=tmp_path, progress=False)
    rows = load_sweep(p)["points"]
    assert list(rows["outcome"]) == ["ok"] * 3
    T = np.asarray(rows["step_period_s"])
    assert np.all(np.diff(T) > 1e-3), T
    row, _ = evaluate("fixedpoint", scene.model_dump(mode="json"),
                      ["walker.leg.bodies.1.mass_kg"], (0.07,), 0, None, {},
                      plant=Plant.from_scene(scene))
    assert row["outcome"] == "ok" and abs(row["step_period_s"] - T[-1]) < 1e-9
    # position along the leg, by name: the thigh mass lower -> longer swing, longer step
    lo, _ = evaluate("fixedpoint", scene.model_dump(mode="json"),
                     ["walker.leg.bodies.thigh_mass.from_hip_m"], (0.35,), 0, None, {},
                     plant=Plant.from_scene(scene))
    assert lo["outcome"] == "ok" and lo["step_period_s"] > T[1] + 1e-3


@pytest.mark.parametrize("param, words", [
    ("slope.angel_deg=1:3:0.5", ["unknown field slope.angel_deg", "did you mean slope.angle_deg"]),
    ("foo.bar=1", ["unknown field foo"]),
    ("solver.method=Euler", ["'Euler' is not valid", "solver.method"]),
    ("walker.hip_mas_kg=1", ["did you mean walker.hip_mass_kg"]),
    ("walker.leg_mass_kg=-1,2", ["value -1 is not valid", "walker.leg_mass_kg"]),
    ("slope.angle_deg.x=1", ["slope.angle_deg is a value"]),
])
def test_sweep_over_an_unknown_field_is_refused(tmp_path, param, words):
    """Issue 19 item 8: refused before anything runs (no artifact), one line, rc 1."""
    scene = load_scene(ROOT / "configs" / "paper.yaml")
    with pytest.raises(SweepError) as exc:
        sweep_stage.run(scene, [param], "fixedpoint", workers=1, runs_root=tmp_path,
                        progress=False)
    assert all(w in str(exc.value) for w in words), str(exc.value)
    assert "\n" not in str(exc.value)
    assert not list(tmp_path.rglob("sweep_*"))
    r = CliRunner().invoke(app, ["sweep", str(ROOT / "configs" / "paper.yaml"), "--param",
                                 param, "--runs-dir", str(tmp_path)])
    assert r.exit_code == 1 and len(r.output.strip().splitlines()) == 1, r.output


def test_list_items_by_name_or_index_in_paths():
    scene = load_scene(ROOT / "configs" / "kneed.yaml")
    assert parse_param("walker.leg.bodies.1.mass_kg=0.1").path == "walker.leg.bodies.1.mass_kg"
    check_axes(scene, [parse_param("walker.leg.bodies.thigh_mass.from_hip_m=0.3")])
    for bad, word in (("walker.leg.bodies.shank_mas.mass_kg=0.1", "did you mean 'shank_mass'"),
                      ("walker.leg.bodies.5.mass_kg=0.1", "out of range"),
                      ("walker.leg.bodies.shank_mass.mass=0.1",
                       "did you mean walker.leg.bodies.shank_mass.mass_kg")):
        with pytest.raises(SweepError, match=word):
            check_axes(scene, [parse_param(bad)])


def test_a_walk_round_where_no_seed_lasts_its_steps_says_none_lasted(monkeypatch):
    """Issue 64 item 5: "23 seeds walked 20 steps (0 root-finder starts)" meant that none
    of the 23 lasted 20 steps."""
    from walkerlab.analysis.gait import search
    from walkerlab.analysis.gait.starts import WALK_STEPS

    seeds = [(1.0, "seed", np.zeros(4))] * 23
    monkeypatch.setattr(search, "screen_seeds", lambda *a: (seeds, 23, 0))
    monkeypatch.setattr(search, "walked_start", lambda *a: None)  # every one falls
    starts = search._RootStarts(None, None, {"max_step_time": 1.0})
    monkeypatch.setattr(starts, "attempt", lambda *a, **k: None)
    starts.from_seeds()
    assert starts.tried[-1] == f"23 seeds walked to last {WALK_STEPS} steps (none lasted them)"


def test_a_failed_search_names_the_fallback_starts_it_tried_and_says_each_in_a_notice():
    """A start tried after the guess (here none: the paper walker on level ground, no gait)
    is named in the failure message as what it was, not as "the initial guess", and said in
    one notice as it is tried (issue 82 item 9)."""
    from walkerlab import progress
    from walkerlab.analysis.gait.starts import FallbackStart

    class Notes:
        def __init__(self):
            self.notes = []

        def start(self, *a):
            pass

        update = finish = start

        def note(self, message):
            self.notes.append(message)

    d = yaml.safe_load((ROOT / "configs" / "paper.yaml").read_text())
    d["slope"] = {"angle_rad": 0.0}
    del d["fixedpoint"]["initial_guess"]
    scene = scene_from_dict(d)
    walker = build_walker(Plant.from_scene(scene))
    label = "the planar twin's gait carried in walker.hip_width_m"
    with progress.use(Notes()) as sink, pytest.raises(GaitNotFound) as exc:
        find_gaits(walker, Solver.from_settings(scene.solver), None, fd_check=False,
                   fallbacks=[FallbackStart(label, "planar_twin", lambda: None)])
    msg = str(exc.value)
    assert f"tried {label} (no start found) and" in msg and "scale-free seeds" in msg
    assert "the initial guess" not in msg
    assert sink.notes == [f"gait search: trying {label}"]


def test_the_nearest_stored_gait_is_the_walker_with_fewest_and_smallest_differences():
    """Of stored walkers, the one differing from the scene in fewest fields, then by the
    smallest relative difference, is chosen; one of another structure never is."""
    from walkerlab.studies.warm_start import StoredGait, nearest_stored

    d = yaml.safe_load((ROOT / "configs" / "hip_width_stabilised.yaml").read_text())

    def scene(**gains):
        e = yaml.safe_load(yaml.safe_dump(d))
        e["walker"]["hip_roll"].update(gains)
        return scene_from_dict(e)

    planar = scene_from_dict(yaml.safe_load((ROOT / "configs" / "paper.yaml").read_text()))
    new = scene(lean_rate_gain_s=-0.25)
    stored = [StoredGait(planar, lambda: None, "planar"),
              StoredGait(scene(lean_rate_gain_s=-0.18, lean_gain=-0.9), lambda: None, "two"),
              StoredGait(scene(lean_rate_gain_s=-0.10), lambda: None, "far"),
              StoredGait(scene(lean_rate_gain_s=-0.18), lambda: None, "near")]
    got, fields = nearest_stored(new, stored)
    assert got.where == "near"
    assert fields == {"walker.hip_roll.lean_rate_gain_s": (-0.18, -0.25)}
    assert nearest_stored(new, stored[:1]) is None


def test_a_scene_whose_guess_fails_starts_from_the_gait_stored_for_a_nearby_walker(tmp_path):
    """The paper walker's run stored; the same walker at 3.5 deg with a guess far from any
    gait: ``walkerlab fixedpoint`` says it tries the stored gait (found through the runs
    folder: its scene read back from the artifact), carried over the slope, and the gait it
    records comes from it, on the section to the scene's tolerance."""
    runs = tmp_path / "runs"
    base = yaml.safe_load((ROOT / "configs" / "paper.yaml").read_text())
    base["name"] = "paper"
    (tmp_path / "paper.yaml").write_text(yaml.safe_dump(base))
    r = CliRunner().invoke(app, ["fixedpoint", str(tmp_path / "paper.yaml"), "--runs-dir",
                                 str(runs)])
    assert r.exit_code == 0, r.output
    steep = yaml.safe_load(yaml.safe_dump(base))
    steep["name"] = "steep"
    steep["slope"] = {"angle_deg": 3.5}
    steep["fixedpoint"]["initial_guess"] = {"swing_angle_rad": -0.9, "stance_angle_rad": 0.8,
                                            "swing_rate_rad_per_s": 2.0,
                                            "stance_rate_rad_per_s": 2.5}
    (tmp_path / "steep.yaml").write_text(yaml.safe_dump(steep))
    r = CliRunner().invoke(app, ["fixedpoint", str(tmp_path / "steep.yaml"), "--runs-dir",
                                 str(runs)])
    assert r.exit_code == 0, r.output
    assert ("gait search: trying the gait stored in paper/fixedpoint.h5, carried in "
            "slope.angle_rad") in r.stderr
    with h5py.File(runs / "steep" / "fixedpoint.h5") as f:
        assert f.attrs["gait_source"] == "stored_gait"
    fp = load_fixedpoint(runs / "steep" / "fixedpoint.h5")
    assert fp.residual < 1e-10


def test_the_root_finders_stop_message_is_said_in_walkerlabs_words_once():
    """A gait search's notes said MINPACK's "The iteration is not making good progress, as
    measured by the improvement from the last five Jacobian evaluations." as it stood; now
    what happened comes first, MINPACK's own sentence after it in brackets, the residual
    (given apart) left out, an unknown message unchanged, and a said one not said twice
    (issue 82 item 11)."""
    from walkerlab.analysis.gait.failure_text import solver_words

    raw = ("no fixed point found: The iteration is not making good progress, as measured by "
           "the improvement from the last five Jacobian evaluations. (residual 0.0096)")
    said = solver_words(raw)
    assert said == ("the root finder stalled: its last five Jacobians brought no progress "
                    "[MINPACK: The iteration is not making good progress, as measured by the "
                    "improvement from the last five Jacobian evaluations.]")
    assert solver_words(said) == said
    assert solver_words("The number of calls to function has reached maxfev = 400.") == (
        "the root finder ran out of map evaluations [MINPACK: The number of calls to "
        "function has reached maxfev = 400.]")
    assert solver_words("the map fails at the guess") == "the map fails at the guess"
