"""Issue 49: the ``terrain:`` section's ground kinds and the rigid walker on stairs.

Physics checks: down stairs whose riser is the slope gait's drop per step, the walker walks
its slope gait (same states, same step period: with absolute coordinates gravity does not
see the slope, only the heel-strike surface does, and the slope orbit meets the stair
surface at the same state); down other stairs its period-1 gait matches an independent
model (tests/independent/stairs_compass.py, its own equations and impact map).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from walkerlab.config import SceneError, load_scene, scene_from_dict
from walkerlab.config.terrain import TerrainSettings
from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]
TIGHT_STATE = 1e-9  # the "state and step period to 1e-9"
INDEPENDENT = 1e-8  # the "fixed points and multipliers ... to 1e-8"


def _on_stairs(scene, riser_m: float, tread_m: float = 0.4, **extra):
    d = scene.model_dump(mode="json")
    d["slope"] = {"angle_rad": 0.0}
    d["terrain"] = {"kind": "stairs", "riser_m": riser_m, "tread_m": tread_m, **extra}
    return scene_from_dict(d)


def _gait(scene):
    from walkerlab.analysis.gait.scene import solve_scene

    walker, search = solve_scene(scene, plant=Plant.from_scene(scene))
    return walker, search.result


def _drop_per_step(walker, x, scene):
    """The slope gait's swing-foot drop at heel strike [m] and its advance [m]."""
    from walkerlab.integrate.rigid import integrate_step
    from walkerlab.integrate.solver import Solver

    seg = integrate_step(walker, x, Solver.from_settings(scene.solver))
    foot = walker.points(seg.x_end)["swing_foot"]
    return -float(foot[1]), float(foot[0])


# -- the section ------------------------------------------------------------------------------

def test_terrain_section_reads_todays_lanes_and_writes_them_back():
    """``kind: checkerboard|continuous`` is the contact lanes on today's slope and is written
    back the same way (content hashes unchanged); the new kinds carry their own fields."""
    for lanes in ("checkerboard", "continuous"):
        t = TerrainSettings.model_validate({"kind": lanes, "patch_width_m": 0.2})
        assert (t.kind, t.lanes) == ("slope", lanes)
        assert t.model_dump() == {"kind": lanes, "patch_width_m": 0.2}
    assert TerrainSettings().model_dump() == {"kind": "checkerboard", "patch_width_m": 0.1}
    t = TerrainSettings.model_validate({"kind": "stairs", "riser_m": 0.1, "tread_m": 0.3,
                                        "direction": "up", "lanes": "continuous"})
    assert TerrainSettings.model_validate(t.model_dump()) == t
    assert t.model_dump()["riser_m"] == 0.1 and "profile_m" not in t.model_dump()
    t = TerrainSettings.model_validate({"kind": "profile", "profile_m": [[0, 0], [1, -0.1]]})
    assert t.profile_m == ((0.0, 0.0), (1.0, -0.1))


@pytest.mark.parametrize("terrain, words", [
    ({"kind": "stairs", "riser_m": 0.1}, "terrain.tread_m"),
    ({"kind": "slope", "riser_m": 0.1}, "terrain.riser_m: only for kind: stairs"),
    ({"kind": "checkerboard", "lanes": "continuous"}, "give lanes once"),
    ({"kind": "profile", "profile_m": [[0, 0], [1, 0], [0.5, 1]]},
     "must be a function of x"),
    ({"kind": "footholds", "foothold_heights_m": [0.1, 0], "foothold_slopes_rad": [0.1]},
     "2 heights"),
])
def test_impossible_ground_is_one_line(paper_scene, terrain, words):
    d = paper_scene.model_dump(mode="json")
    d["terrain"] = terrain
    with pytest.raises(SceneError) as err:
        scene_from_dict(d)
    assert words in str(err.value)
    assert "Traceback" not in str(err.value)


def test_tread_shorter_than_the_foot_and_a_slope_under_stairs_are_refused():
    flat = load_scene(ROOT / "configs" / "flat_feet.yaml")
    foot = flat.walker.leg.foot
    d = flat.model_dump(mode="json")
    d["slope"] = {"angle_rad": 0.0}
    d["terrain"] = {"kind": "stairs", "riser_m": 0.01, "tread_m": 0.5 * (foot.heel_m + foot.toe_m)}
    with pytest.raises(SceneError, match="terrain.tread_m: .* shorter than the walker's foot"):
        scene_from_dict(d)
    d["slope"] = {"angle_rad": 0.01}
    d["terrain"]["tread_m"] = 1.0
    with pytest.raises(SceneError, match="stairs has level treads"):
        scene_from_dict(d)


def test_shipped_stairs_scene_parses():
    sc = load_scene(ROOT / "configs" / "stairs.yaml")
    assert sc.terrain.kind == "stairs" and sc.terrain.direction == "down"
    # the ground is part of what the rigid stages hash; a slope scene's hash has no ground
    assert '"ground"' in sc.section_json("walker", "slope")
    assert '"ground"' not in load_scene(ROOT / "configs" / "paper.yaml").section_json("slope")


# -- the rigid walker on stairs ---------------------------------------------------------------

def test_paper_walker_down_stairs_of_its_drop_is_its_slope_gait(paper_scene, paper_walker,
                                                                paper_fixed_point):
    """Riser = the slope gait's drop per step: the same gait (state and step period to 1e-9)."""
    fp = paper_fixed_point
    drop, advance = _drop_per_step(paper_walker, fp.x, paper_scene)
    assert drop == pytest.approx(advance * np.tan(paper_scene.slope.phi_rad), rel=1e-12)
    _, r = _gait(_on_stairs(paper_scene, drop, tread_m=advance))
    assert np.max(np.abs(r.x - fp.x)) < TIGHT_STATE
    assert abs(r.period_s - fp.period_s) < TIGHT_STATE
    assert r.residual < 1e-10


def _independent():
    sys.path.insert(0, str(ROOT / "tests" / "independent"))
    try:
        from stairs_compass import StairsCompass
    finally:
        sys.path.pop(0)
    return StairsCompass


def _check_against_independent(paper_scene, riser_m):
    StairsCompass = _independent()
    _, r = _gait(_on_stairs(paper_scene, riser_m))
    ref = StairsCompass(riser_m)  # the paper walker's numbers, its own equations
    x = ref.fixed_point(r.x)
    _, period = ref.step(x)
    assert np.max(np.abs(x - r.x)) < INDEPENDENT
    assert abs(period - r.period_s) < INDEPENDENT
    mu = np.sort_complex(ref.multipliers(x))
    assert np.max(np.abs(mu - np.sort_complex(r.multipliers_variational))) < INDEPENDENT
    return r


def test_paper_walker_down_1cm_stairs_matches_an_independent_model(paper_scene):
    r = _check_against_independent(paper_scene, 0.01)
    assert r.period_s == pytest.approx(0.70998445, abs=1e-8)


@pytest.mark.slow
@pytest.mark.parametrize("riser_m", [0.002, 0.005, 0.02])
def test_paper_walker_down_other_stairs_matches_an_independent_model(paper_scene, riser_m):
    _check_against_independent(paper_scene, riser_m)


@pytest.mark.slow
def test_kneed_walker_down_stairs_of_its_drop_is_its_slope_gait():
    sc = load_scene(ROOT / "configs" / "kneed.yaml")
    w, r0 = _gait(sc)
    drop, advance = _drop_per_step(w, r0.x, sc)
    _, r = _gait(_on_stairs(sc, drop, tread_m=advance))
    assert np.max(np.abs(r.x - r0.x)) < TIGHT_STATE
    assert abs(r.period_s - r0.period_s) < TIGHT_STATE
    _, r2 = _gait(_on_stairs(sc, 0.03))  # and another riser: a stable period-1 gait
    assert r2.residual < 1e-10 and np.max(np.abs(r2.multipliers_variational)) < 1


def test_tread_drift_and_the_footfall_that_misses(paper_scene):
    from walkerlab.analysis.gait.treads import steps_until_miss, tread_landing
    from walkerlab.integrate.solver import Solver

    assert steps_until_miss(0.2, 0.0, 0.4) == -1
    assert steps_until_miss(0.2, 0.05, 0.4) == 5  # u = 0.25 ... 0.40, 0.45 at the 5th
    assert steps_until_miss(0.2, -0.03, 0.4) == 7  # u = 0.17 ... -0.01 at the 7th
    sc = load_scene(ROOT / "configs" / "stairs.yaml")
    w, r = _gait(sc)
    fh = tread_landing(w, r.x, sc.terrain, Solver.from_settings(sc.solver))
    assert fh.drift_per_step_m == pytest.approx(fh.step_advance_m - 0.41, abs=1e-15)
    assert fh.step_advance_m == pytest.approx(0.414092, abs=1e-6)
    assert fh.steps_until_miss == 51  # 205 mm of tread ahead at 4.09 mm a step
    # the foot passes above the nosing ahead (no riser scuff); over the stance tread it
    # goes through by the point foot's mid-stance depth (as on a slope), tens of microns
    assert fh.riser_clearance_m > 0.01 and not fh.riser_scuff
    assert -1e-4 < fh.midstance_clearance_m < 0


def test_stairs_refused_where_not_modelled(paper_scene):
    from walkerlab.models.registry import build_walker

    d = _on_stairs(paper_scene, 0.01).model_dump(mode="json")
    d["ideal"] = {"variant": "appendix_a"}
    with pytest.raises(ValueError, match="ideal.variant: derived"):
        sc = scene_from_dict(d)
        build_walker(Plant.from_scene(sc))


def test_stairs_drawn_as_a_polyline_under_the_walker():
    from walkerlab.plotting.animation import stairs_polyline

    x, y = stairs_polyline(0.01, 0.4, "down", 0.1, np.array([-0.5, 0.9]))
    # the first stance foot (origin) stands 0.1 m into its tread, at height 0
    i = np.flatnonzero((x[::2] <= 0) & (x[1::2] >= 0))[0]
    assert (x[2 * i], x[2 * i + 1], y[2 * i]) == pytest.approx((-0.1, 0.3, 0.0))
    assert np.all(np.diff(y[::2]) == pytest.approx(-0.01)) and x.min() <= -0.5 <= 0.9 <= x.max()


def test_footholds_of_one_height_are_a_landing_and_others_are_refused(paper_scene):
    from walkerlab.models.registry import build_walker

    sc = load_scene(ROOT / "configs" / "footholds.yaml")
    w = build_walker(Plant.from_scene(sc))
    assert w.params["landing_drop_m"] == 0.005  # 5 mm below: the guard's offset
    x = np.array([0.25, -0.2, -0.6, -0.9])
    slope = build_walker(Plant.from_scene(paper_scene))
    # the heel strike: the swing foot 5 mm below the slope line (along its normal)
    assert w.heel_strike_guard(0.0, x) == pytest.approx(
        _clearance(slope, x) + 0.005 * np.cos(paper_scene.slope.phi_rad), abs=1e-15)
    d = sc.model_dump(mode="json")
    # footholds that differ from step to step: one walker per step of a period-p map
    # (tests/test_terrain_steps.py); on the printed equations: refused in one line
    for terrain, period in (({"kind": "footholds", "foothold_heights_m": [0.0, -0.01]}, 2),
                            ({"kind": "footholds", "foothold_slopes_rad": [0.01]}, 1)):
        d["terrain"] = terrain
        sc = scene_from_dict(d)
        assert build_walker(Plant.from_scene(sc)).steps_per_map == period
    d["ideal"] = {"variant": "appendix_a"}
    with pytest.raises(ValueError, match="footholds need ideal.variant: derived"):
        sc = scene_from_dict(d)
        build_walker(Plant.from_scene(sc))


def _clearance(walker, x):
    """The swing foot's lowest point above the slope line through the stance foot [m]."""
    p = walker.points(x)["swing_foot"]
    phi = walker.slope_rad
    return float(p[0] * np.sin(phi) + p[1] * np.cos(phi))


# -- no gait, and the seeds, on stairs (issue 56 item 8) ---------------------------------------

def _stairs_file(tmp_path, guess: bool = True, **terrain):
    """configs/stairs.yaml with other ``terrain`` fields (and without its initial guess)."""
    import yaml

    d = yaml.safe_load((ROOT / "configs" / "stairs.yaml").read_text())
    d["terrain"] = {**d["terrain"], **terrain}
    if not guess:
        del d["fixedpoint"]["initial_guess"]
    f = tmp_path / "st.yaml"
    f.write_text(yaml.safe_dump(d))
    return f


def _cli(*args):
    from typer.testing import CliRunner

    from walkerlab.cli import app

    r = CliRunner().invoke(app, [str(a) for a in args])
    return r.exit_code, r.stdout, r.stderr


@pytest.mark.parametrize("riser_m, guess", [(0.01, True), (0.05, True), (0.01, False)])
def test_stairs_going_up_end_in_the_no_gait_message(tmp_path, riser_m, guess):
    """Stairs up: the root finder's iterates left the post-impact surface (no posture of the
    legs reaches a landing that high) and Newton's failure ended as "internal error
    (RuntimeError): Failed to converge after 50 iterations"; now such an iterate is a failed
    map, and the search ends in the no-gait line with the physical reason and the advice."""
    f = _stairs_file(tmp_path, guess, direction="up", riser_m=riser_m)
    code, out, err = _cli("fixedpoint", f, "--runs-dir", tmp_path / "runs")
    lines = err.splitlines()  # the reason; what was tried, whole, on a second line
    assert code == 1 and len(lines) in (1, 2) and lines[-1].startswith(("error", "  [")), err
    assert err.startswith("error: fixedpoint: no period-1 gait found; a passive walker "
                          "cannot climb stairs")
    assert "walkerlab fixedpoint --from KNOWN_SCENE" in err
    assert "internal error" not in err and "WALKERLAB_DEBUG=1 for the traceback" not in err


def test_a_landing_out_of_the_legs_reach_is_off_the_section(paper_scene):
    """A 1 cm riser up with the stance leg 0.05 rad from the vertical: no swing-leg angle
    puts the old stance foot 1 cm below (L (cos 0.05 - 1) = -1.25 mm): OffSection, the
    failed map the root finder steps back from, not scipy's RuntimeError."""
    from walkerlab.models.hybrid.base import OffSection
    from walkerlab.models.registry import build_walker

    sc = _on_stairs(paper_scene, 0.01, direction="up")
    w = build_walker(Plant.from_scene(sc))
    with pytest.raises(OffSection, match="no post-impact state"):
        w.from_section(np.array([0.05, -0.6, -0.84]))
    x = w.from_section(np.array([0.1674, -0.6, -0.84]))  # reachable: on the surface
    assert _clearance(w, x) == pytest.approx(-0.01, abs=1e-12)


def test_a_high_riser_down_is_searched_without_an_internal_error(tmp_path):
    """A 0.2 m riser down ended in the same internal error; the search now finds this
    riser's period-1 gaits (both unstable: the selection says so) and the treads'
    verdict says the foot misses its tread."""
    from walkerlab.io.schemas.fixedpoint import load_fixedpoint

    f = _stairs_file(tmp_path, riser_m=0.2)
    code, out, err = _cli("fixedpoint", f, "--runs-dir", tmp_path / "runs")
    assert code == 0, err
    fp = load_fixedpoint(tmp_path / "runs" / "st" / "fixedpoint.h5")
    assert fp.residual < 1e-10 and not fp.stable
    assert "footfall 1 misses its tread" in out


def test_level_stairs_without_a_guess_find_their_gait_from_the_seeds(paper_scene):
    """The seeds were sized by the slope (0 on level treads: a 0.046 rad step angle) and
    all 45 fell; sized by the slope of the same drop per step (landing_slope) they find the
    shipped stairs' gait, the one the paper's guess gives (to the root finder's 1e-9)."""
    sc = load_scene(ROOT / "configs" / "stairs.yaml")
    d = sc.model_dump(mode="json")
    d["fixedpoint"].pop("initial_guess")
    _, seeded = _gait(scene_from_dict(d))
    _, guessed = _gait(sc)
    assert np.max(np.abs(seeded.x - guessed.x)) < TIGHT_STATE
