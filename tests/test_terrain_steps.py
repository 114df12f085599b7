"""Issue 49, the rigid model on ground that differs from step to step: footholds of several
heights (a period-p Poincaré map, one walker per step), per-step random landing heights in
the MFPT study, and a replayable per-step ground (``simulate --terrain-seed``).

Physics checks against independent models (tests/independent/stairs_compass.py: its own
equations, impact map and heel-strike event, no walkerlab code).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from walkerlab.config import scene_from_dict
from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]
INDEPENDENT = 1e-8  # the "fixed points and multipliers ... to 1e-8"


def _independent():
    sys.path.insert(0, str(ROOT / "tests" / "independent"))
    try:
        import stairs_compass
    finally:
        sys.path.pop(0)
    return stairs_compass


def _on_footholds(scene, heights, slope_rad=0.0, **extra):
    d = scene.model_dump(mode="json")
    d["slope"] = {"angle_rad": slope_rad}
    d["terrain"] = {"kind": "footholds", "foothold_heights_m": list(heights), **extra}
    return scene_from_dict(d)


def test_periodic_two_height_footholds_give_a_period_2_gait_of_an_independent_model(
        paper_scene):
    """Level ground, landings 8 mm and 12 mm below in turn (1 cm a step on average, as the
    shipped stairs): the period-2 gait's fixed point, map period and multipliers match the
    independent compass walker stepping down the same list (to 1e-8)."""
    from walkerlab.analysis.gait.scene import solve_scene

    sc = _on_footholds(paper_scene, [-0.008, -0.012])
    walker, search = solve_scene(sc, plant=Plant.from_scene(sc))
    r = search.result
    assert walker.steps_per_map == 2 and r.residual < 1e-10
    ref = _independent().FootholdsCompass([0.008, 0.012])
    x = ref.fixed_point(r.x)
    assert np.max(np.abs(x - r.x)) < INDEPENDENT
    assert abs(ref.period(x) - r.period_s) < INDEPENDENT
    mu = np.sort_complex(ref.multipliers(x))
    assert np.max(np.abs(mu - np.sort_complex(r.multipliers_variational))) < INDEPENDENT
    # a period-2 orbit, not the stairs' period-1 gait run twice: the two steps differ
    assert abs(r.step_periods_s[0] - r.step_periods_s[1]) > 1e-3


def test_a_finite_foothold_list_ends_the_walk(paper_scene, paper_fixed_point):
    """``periodic: false``: a walk stops after the list's steps (here 3 of the 10 asked);
    footholds at the slope's own line reproduce the slope walk bit for bit."""
    from walkerlab.integrate.rigid import simulate_steps
    from walkerlab.integrate.solver import Solver
    from walkerlab.models.registry import build_walker

    phi = paper_scene.slope.phi_rad
    solver = Solver.from_settings(paper_scene.solver)
    sc = _on_footholds(paper_scene, [0.0, 0.0, 0.0], phi, periodic=False,
                       foothold_slopes_rad=[phi] * 3)
    w = build_walker(Plant.from_scene(sc))
    tr = simulate_steps(w, paper_fixed_point.x, 10, solver)
    ref = simulate_steps(build_walker(Plant.from_scene(paper_scene)), paper_fixed_point.x, 3,
                         solver)
    assert len(tr.segments) == 3 and tr.termination == "heel_strike"
    for a, b in zip(tr.segments, ref.segments):
        np.testing.assert_array_equal(a.x_next, b.x_next)



def _footholds_file(tmp_path, heights, **extra):
    """configs/footholds.yaml with other foothold heights (and ``extra`` terrain fields)."""
    import yaml

    d = yaml.safe_load((ROOT / "configs" / "footholds.yaml").read_text())
    d["terrain"] = {**d["terrain"], "foothold_heights_m": list(heights), **extra}
    f = tmp_path / "fh.yaml"
    f.write_text(yaml.safe_dump(d))
    return f


def _cli(*args):
    from typer.testing import CliRunner

    from walkerlab.cli import app

    r = CliRunner().invoke(app, [str(a) for a in args])
    return r.exit_code, r.stdout, r.stderr


def test_a_three_height_foothold_gait_is_written_and_read_back(tmp_path):
    """Issue 56 item 2: footholds of three heights (a period-3 map, the legs taking turns
    leg1, leg2, leg1) were refused by the writer ("/steps/swing_leg: dimension 'step'
    exists with another length": two leg names for three steps); now fixedpoint writes the
    gait, the artifact reads back each step and simulate walks from it."""
    from walkerlab.io.schemas.fixedpoint import load_fixedpoint

    f = _footholds_file(tmp_path, [-0.005, 0.0, -0.01])
    code, out, err = _cli("fixedpoint", f, "--runs-dir", tmp_path / "runs")
    assert code == 0, err
    fp = load_fixedpoint(tmp_path / "runs" / "fh" / "fixedpoint.h5")
    assert fp.step_swing_legs == ("leg1", "leg2", "leg1")
    assert len(fp.step_periods_s) == len(fp.step_lengths_m) == 3
    # the map's period is its three steps' (to rounding of three additions)
    assert abs(sum(fp.step_periods_s) - fp.stride_period_s) < 1e-12
    assert fp.residual < 1e-10
    code, out, err = _cli("simulate", f, "--runs-dir", tmp_path / "runs")
    assert code == 0, err
    assert out.startswith("simulated 5 strides: 10 heel strikes")


def test_a_finite_foothold_list_of_one_height_ends_the_walk(tmp_path):
    """Issue 56 item 3: ``periodic: false`` with every foothold at one height was walked as
    endless ground (10 heel strikes of a 3-foothold list); now the walk ends after the list,
    as with heights that differ, and says so in one line.  The gait is the one-height
    ground's (one step a map), bit for bit."""
    from walkerlab.config import load_scene
    from walkerlab.io.schemas.fixedpoint import load_fixedpoint
    from walkerlab.io.schemas.simulate import load_simulate
    from walkerlab.models.registry import build_walker

    f = _footholds_file(tmp_path, [-0.005] * 3, periodic=False)
    code, out, err = _cli("simulate", f, "--runs-dir", tmp_path / "runs")
    assert code == 0, err
    sim = load_simulate(tmp_path / "runs" / "fh" / "simulate.h5")
    assert sim.heel_strike_count() == 3 and sim.termination == "heel_strike"
    assert out.splitlines()[0] == ("the ground ends after its 3 footholds (terrain.periodic: "
                                   "false): 3 heel strikes of the 10 asked (5 strides)")
    sc = load_scene(f)
    w = build_walker(Plant.from_scene(sc))
    assert w.steps_per_map == 1 and w.ground_steps == 3
    (tmp_path / "endless").mkdir()
    endless = _footholds_file(tmp_path / "endless", [-0.005])  # periodic: true
    code, out, err = _cli("fixedpoint", endless, "--runs-dir", tmp_path / "r2")
    assert code == 0, err
    np.testing.assert_array_equal(
        load_fixedpoint(tmp_path / "runs" / "fh" / "fixedpoint.h5").x,
        load_fixedpoint(tmp_path / "r2" / "fh" / "fixedpoint.h5").x)

# -- per-step heights in the MFPT study --------------------------------------------------------

def _independent_walk(ref, x0, gamma, heights, max_steps=2000, t_cap=5.0):
    """Heel strikes of one walk of the independent compass ``ref`` on the slope ``gamma``
    [rad], step ``k`` landing ``heights[k]`` [m] above the slope line through the stance
    foot: each step integrated to mid-stance (the swing foot passing the stance foot), then
    to the swing foot meeting the landing's line (downward), its swing leg falling back or
    the hip reaching the ground (a fall).  Its own events on its own equations."""
    from scipy.integrate import solve_ivp

    L = ref.L
    x = np.asarray(x0, float)

    def foot(y):
        return (L * (np.sin(y[0]) - np.sin(y[1])), L * (np.cos(y[1]) - np.cos(y[0])))

    def mid(t, y):  # the swing foot passing the stance foot (leg angles equal)
        return y[0] - y[1]

    def back(t, y):  # ... and back again in late swing: its swing leg falls back
        return y[0] - y[1]

    def hip(t, y):
        return np.cos(y[1] - gamma)

    hip.terminal, hip.direction = True, -1
    mid.terminal, mid.direction = True, 1
    back.terminal, back.direction = True, -1
    for k in range(max_steps):
        h = heights[k]

        def land(t, y, h=h):
            xf, yf = foot(y)
            return xf * np.sin(gamma) + yf * np.cos(gamma) - h * np.cos(gamma)

        land.terminal, land.direction = True, -1
        s1 = solve_ivp(ref.rhs, (0, t_cap), x, method="DOP853", rtol=1e-10, atol=1e-10,
                       events=(mid, hip))
        if not s1.t_events[0].size:
            return k
        s2 = solve_ivp(ref.rhs, (0, t_cap - s1.t[-1]), s1.y_events[0][0], method="DOP853",
                       rtol=1e-10, atol=1e-10, events=(land, back, hip))
        if not s2.t_events[0].size:
            return k
        x = ref.reset(s2.y_events[0][0])
    return max_steps


@pytest.mark.slow
def test_mfpt_on_per_step_heights_matches_an_independent_monte_carlo(paper_scene,
                                                                      paper_fixed_point):
    """The paper walker on its slope, each landing a normal height (sd 2 mm) above the slope
    line: walkerlab's compiled Monte Carlo MFPT within 3 combined standard errors of the
    independent compass walker's Monte Carlo (its own random numbers and step map)."""
    from walkerlab.studies.mfpt import monte_carlo

    sd, walks = 0.002, 300
    mc = monte_carlo(paper_scene, paper_fixed_point.x, 0.0, walks, 2000, 3,
                     heights=("normal", sd), plant=Plant.from_scene(paper_scene))
    m, se = mc.mfpt
    assert mc.fell.all()
    ref = _independent().StairsCompass(0.0)
    rng = np.random.default_rng(20261123)
    gamma = paper_scene.slope.phi_rad
    n = np.array([_independent_walk(ref, paper_fixed_point.x, gamma,
                                    sd * rng.standard_normal(2000)) for _ in range(walks)])
    m_ref, se_ref = n.mean(), n.std(ddof=1) / np.sqrt(n.size)
    print(f"MFPT {m:.3f} +/- {se:.3f} (walkerlab), {m_ref:.3f} +/- {se_ref:.3f} (independent)")
    assert abs(m - m_ref) < 3 * np.hypot(se, se_ref), (m, se, m_ref, se_ref)
    assert 5 < m < 50  # metastable: tens of steps at 2 mm (the 4 mrad slope sd gives ~30)


# -- a replayable per-step ground --------------------------------------------------------------

def _rough(scene, seed, strides=3):
    d = scene.model_dump(mode="json")
    d["terrain"] = {"kind": "checkerboard", "per_step": {
        "slope_sd_rad": 0.001, "height_sd_m": 0.0005, "seed": 0}}
    d["simulate"] = {"strides": strides, "terrain_seed": seed}
    return scene_from_dict(d)


def test_terrain_seed_walks_the_same_ground_bit_for_bit(paper_scene, paper_fixed_point):
    """``simulate.terrain_seed`` (``--terrain-seed``): the same seed walks the same drawn
    ground again, bit for bit (every state of every step); another seed another ground; the
    ground is walk 0 of the MFPT's streams of that seed (slopes and heights)."""
    from walkerlab.analysis.gait.rigid_run import (
        rough_ground_steps,
        rough_ground_walker,
        simulate_scene,
    )
    from walkerlab.analysis.robustness.mfpt import draw_slopes

    runs = []
    for seed in (11, 11, 12):
        sc = _rough(paper_scene, seed)
        plant = Plant.from_scene(sc)
        runs.append(simulate_scene(sc, rough_ground_walker(sc, 6, plant=plant),
                                   paper_fixed_point.x, plant=plant))
    a, b, c = ([s.x_next for s in r.trajectory.segments] for r in runs)
    assert len(a) == 6 and all(s.termination == "heel_strike"
                               for s in runs[0].trajectory.segments)
    for u, v in zip(a, b):
        np.testing.assert_array_equal(u, v)
    np.testing.assert_array_equal(runs[0].steps["period"], runs[1].steps["period"])
    assert max(np.max(np.abs(u - v)) for u, v in zip(a, c)) > 1e-6
    steps = rough_ground_steps(_rough(paper_scene, 11), 6)
    np.testing.assert_array_equal([g for _, g in steps],
                                  draw_slopes(11, 0, 6, paper_scene.slope.phi_rad, 0.001))
    assert 1e-5 < np.std([d for d, _ in steps]) < 2e-3


def test_terrain_seed_without_a_per_step_ground_is_one_line(paper_scene):
    from walkerlab.config import SceneError
    from walkerlab.config.options import with_terrain_seed

    with pytest.raises(SceneError, match="--terrain-seed: the scene has no terrain.per_step"):
        with_terrain_seed(paper_scene, 3)
    with pytest.raises(SceneError, match="--terrain-seed -1: .*simulate.terrain_seed"):
        with_terrain_seed(_rough(paper_scene, None), -1)


# -- height profiles ---------------------------------------------------------------------------

def test_a_profile_of_constant_slope_walks_the_slope_gait(paper_scene, paper_fixed_point):
    """A profile that is one straight line of the paper's slope (level scene slope: the
    profile alone is the ground), in three collinear segments: the walk on it is the slope
    walk (every post-impact state to 1e-9, step periods to 1e-9) and its footfalls lie on
    the profile; a profile with a 2 cm drop half-way lands the walker lower there."""
    from walkerlab.analysis.gait.rigid_run import profile_walk
    from walkerlab.integrate.rigid import simulate_steps
    from walkerlab.integrate.solver import Solver
    from walkerlab.models.registry import build_walker

    phi = paper_scene.slope.phi_rad
    d = paper_scene.model_dump(mode="json")
    xs = np.array([-1.0, 0.9, 1.7, 40.0])
    d["terrain"] = {"kind": "profile", "profile_m": [[x, -x * np.tan(phi)] for x in xs]}
    d["slope"] = {"angle_rad": 0.0}
    sc = scene_from_dict(d)
    x0 = paper_fixed_point.x
    tr = profile_walk(sc, x0, 8, plant=Plant.from_scene(sc))
    ref = simulate_steps(build_walker(Plant.from_scene(paper_scene)), x0, 8,
                         Solver.from_settings(sc.solver))
    assert len(tr.segments) == 8 and tr.termination == "heel_strike"
    for a, b in zip(tr.segments, ref.segments):
        assert np.max(np.abs(a.x_next - b.x_next)) < 1e-9
        assert abs((a.t_end - a.t_start) - (b.t_end - b.t_start)) < 1e-9
        xw, yw = a.stance_foot_world
        assert abs(yw + xw * np.tan(phi)) < 1e-12  # every stance foot on the profile
    # a bend: the ramp steepens to 0.03 rad at x = 1.5 m: every footfall on the profile,
    # the later steps on the steeper ramp faster than the slope's
    P = np.array([[-1.0, np.tan(phi)], [1.5, -1.5 * np.tan(phi)], [40.0, 0.0]])
    P[2, 1] = P[1, 1] - (40.0 - 1.5) * np.tan(0.03)
    d["terrain"] = {"kind": "profile", "profile_m": P.tolist()}
    sc1 = scene_from_dict(d)
    tr = profile_walk(sc1, x0, 8, plant=Plant.from_scene(sc1))
    assert len(tr.segments) == 8
    for a in tr.segments:
        xw, yw = a.stance_foot_world
        assert abs(yw - np.interp(xw, P[:, 0], P[:, 1])) < 1e-9
    assert tr.segments[-1].x_next[3] < ref.segments[-1].x_next[3] - 0.01  # faster stance


def test_a_wall_or_a_pit_under_the_swing_foot_ends_the_profile_walk_as_a_trip(
        paper_scene, paper_fixed_point):
    """The paper's walker on its slope written as a profile (level scene slope): the swing
    foot's path is checked against the profile between footfalls.  Plain, the walk is the
    slope's and only the straight legs' mid-stance foot-through is found (ignored as the
    ideal model ignores it; its depth reported, under 1 cm).  A 1 m wall half-way between
    footfalls 1 and 2 (before: the same walk as the plain profile) ends the walk in step 1
    as a trip at the wall's face, the steps before it unchanged; a 100 m pit under footfall
    2 ends it as a trip at the pit's side (the swing foot going into the ground there)."""
    from walkerlab.analysis.gait.profile_walk import profile_height
    from walkerlab.analysis.gait.rigid_run import profile_walk

    t = np.tan(paper_scene.slope.phi_rad)
    d = paper_scene.model_dump(mode="json")
    d["slope"] = {"angle_rad": 0.0}

    def walk(bumps):  # bumps: (x [m], height above the slope line [m]) vertices
        pts = sorted([(-1.0, 0.0), (0.0, 0.0), (20.0, 0.0), *bumps])
        d["terrain"] = {"kind": "profile", "profile_m": [[x, -x * t + h] for x, h in pts]}
        sc = scene_from_dict(d)
        return profile_walk(sc, paper_fixed_point.x, 4,
                            plant=Plant.from_scene(sc)), np.asarray(d["terrain"]["profile_m"])

    plain, _ = walk([])
    assert plain.termination == "heel_strike" and len(plain.segments) == 4
    assert plain.profile_trip is None and 0.0 < plain.midstance_scuff_depth_m < 0.01
    feet = [s.stance_foot_world[0] for s in plain.segments]
    x_w = 0.5 * (feet[1] + feet[2])  # a 1 m wall, 1 mm faces, 5 cm thick
    wall, P = walk([(x_w, 0.0), (x_w + 1e-3, 1.0), (x_w + 0.05, 1.0), (x_w + 0.051, 0.0)])
    assert wall.termination == "trip" and len(wall.segments) == 2
    tt, xt, yt = wall.profile_trip
    seg = wall.segments[-1]
    assert seg.t_start < tt == seg.t_end < plain.segments[1].t_end
    assert x_w <= xt <= x_w + 1e-3 and 0.0 < yt - (-xt * t) < 1.0  # on the wall's face
    assert abs(yt - profile_height(P, xt)) < 1e-9  # where it meets the profile
    assert np.array_equal(wall.segments[0].x_next, plain.segments[0].x_next)
    pit, P = walk([(feet[2] - 0.1, 0.0), (feet[2] - 0.099, -100.0), (feet[2] + 0.099, -100.0),
                   (feet[2] + 0.1, 0.0)])
    assert pit.termination == "trip" and len(pit.segments) == 2
    assert feet[2] - 0.1 <= pit.profile_trip[1] <= feet[2] + 0.1


def test_a_profile_from_a_csv_is_its_points(tmp_path):
    """``terrain.profile_csv`` (issue 49: "inline or from a CSV"; before: refused at the walk):
    read relative to the scene's folder (a header row and ``#`` lines skipped) into
    ``profile_m``, so the scene equals the inline one (its content hash follows the numbers)
    and walks; a missing file or a row that is not two numbers gets one line naming the
    field and the line."""
    import yaml

    from walkerlab.analysis.gait.rigid_run import profile_walk
    from walkerlab.config import SceneError, load_scene

    base = yaml.safe_load((ROOT / "configs" / "paper.yaml").read_text())
    pts = [[-1.0, 0.0174], [0.9, -0.0157], [40.0, -0.70]]
    inline = dict(base, name="p", terrain={"kind": "profile", "profile_m": pts})
    (tmp_path / "inline.yaml").write_text(yaml.safe_dump(inline))
    (tmp_path / "ground").mkdir()
    (tmp_path / "ground" / "p.csv").write_text(
        "x_m, y_m\n# from a survey\n" + "".join(f"{x}, {y}\n" for x, y in pts))
    csv = dict(base, name="p", terrain={"kind": "profile", "profile_csv": "ground/p.csv"})
    (tmp_path / "csv.yaml").write_text(yaml.safe_dump(csv))
    a, b = load_scene(tmp_path / "inline.yaml"), load_scene(tmp_path / "csv.yaml")
    assert b.terrain.profile_m == tuple(tuple(p) for p in pts)
    assert b.model_dump(mode="json") == a.model_dump(mode="json")
    g = base["fixedpoint"]["initial_guess"]  # paper Eq. (11), near the gait
    x0 = np.array([g["swing_angle_rad"], g["stance_angle_rad"], g["swing_rate_rad_per_s"],
                   g["stance_rate_rad_per_s"]])
    assert len(profile_walk(b, x0, 2, plant=Plant.from_scene(b)).segments) == 2
    (tmp_path / "ground" / "p.csv").write_text("0, 0\n1, x\n")
    with pytest.raises(SceneError, match=r"terrain\.profile_csv: ground/p\.csv: line 2: give "
                       r"two numbers x, y \[m\] \(got '1,x'\)$"):
        load_scene(tmp_path / "csv.yaml")
    (tmp_path / "ground" / "p.csv").unlink()
    with pytest.raises(SceneError, match=r"terrain\.profile_csv: ground/p\.csv: file not "
                       r"found \(relative to the scene's folder\)$"):
        load_scene(tmp_path / "csv.yaml")


@pytest.mark.parametrize("command", [["basin"], ["robustness"], ["bifurcation"],
                                     ["continuation", "--param",
                                      "slope.angle_rad=0.04:0.06"]])
def test_studies_of_the_periodic_gait_refuse_a_profile(command, tmp_path):
    """configs/profile.yaml: a profile has no periodic gait (its steps all differ), so the
    studies of one refuse it in one line naming the field (before: basin, robustness and
    continuation ran on the scene's slope as if it were the profile's gait); fixedpoint
    says whose gait it reports."""
    from typer.testing import CliRunner

    from walkerlab.cli import app

    r = CliRunner().invoke(app, [*command[:1], str(ROOT / "configs" / "profile.yaml"),
                                 *command[1:], "--runs-dir", str(tmp_path)])
    assert r.exit_code != 0
    lines = [ln for ln in r.output.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("error: terrain.kind: profile: ")
    assert "is a study of a periodic gait" in lines[0]
    assert {p.name for p in tmp_path.rglob("*.h5")} <= {"fixedpoint.h5"}  # its upstream


def test_fixedpoint_on_a_profile_names_the_slopes_gait(tmp_path):
    from typer.testing import CliRunner

    from walkerlab.cli import app

    r = CliRunner().invoke(app, ["fixedpoint", str(ROOT / "configs" / "profile.yaml"),
                                 "--runs-dir", str(tmp_path)])
    assert r.exit_code == 0, r.output
    assert "ground: terrain.kind: profile: this is the gait of the scene's slope" in r.output


def test_a_stride_map_of_footholds_that_differ_does_not_blame_the_legs(tmp_path):
    """Issue 56 item 16: a period-2 gait of two foothold heights printed "(the map is a
    stride: the legs differ)" for a walker whose legs are the same."""
    import yaml
    from typer.testing import CliRunner

    from walkerlab.cli import app

    d = yaml.safe_load((ROOT / "configs" / "footholds.yaml").read_text())
    d["terrain"]["foothold_heights_m"] = [-0.005, -0.003]
    scene = tmp_path / "two_heights.yaml"
    scene.write_text(yaml.safe_dump(d))
    r = CliRunner().invoke(app, ["fixedpoint", str(scene), "--runs-dir", str(tmp_path)])
    assert r.exit_code == 0, r.output
    line = next(ln for ln in r.output.splitlines() if "stride period" in ln)
    assert line.endswith("(the map is a stride: the footholds differ)"), line
