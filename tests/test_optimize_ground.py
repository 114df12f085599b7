"""``walkerlab optimize`` on the scene's ground (issue 63): the one-step transcription's heel
strike at the next tread of stairs (:mod:`walkerlab.optimal.transcription.landing`), the
gait advancing one tread a step, replayed on the stairs by the rigid model; what it does not
transcribe is refused in one line naming ``terrain.kind``.

Physics checks: on stairs whose tread is the passive stair gait's advance, the least-effort
gait is that passive gait (shooting on the rigid model, ``walkerlab fixedpoint``: the
independent check of the transcription's guard and periodicity); the paper walker on 1 cm
and on 5 cm risers of one tread has two different optima, each closing on its stairs to the
optimize view's 1e-6.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from walkerlab.config import load_scene, scene_from_dict
from walkerlab.walker.plant import Plant

CONFIGS = Path(__file__).resolve().parents[1] / "configs"
#: the optimize view's tolerance: the replay returns to its start within it
REPLAY = 1e-6


def _paper_on_stairs(riser_m: float, tread_m: float = 0.41, direction: str = "down",
                     **optimize):
    """configs/paper.yaml on level-tread stairs, with compass_optimal.yaml's optimize
    section (least effort, 40 intervals) and ``optimize``'s extra fields."""
    d = load_scene(CONFIGS / "paper.yaml").model_dump(mode="json", exclude_none=True)
    d["slope"] = {"angle_rad": 0.0}
    d["terrain"] = {"kind": "stairs", "riser_m": riser_m, "tread_m": tread_m,
                    "direction": direction, "lanes": "checkerboard", "patch_width_m": 0.3}
    d["optimize"] = {"objective": "effort", "intervals": 40, **optimize}
    d.pop("published", None)
    return scene_from_dict(d)


def _optimum(scene):
    from walkerlab.analysis.gait.scene import solve_scene
    from walkerlab.optimal.driver import optimize_scene

    r = solve_scene(scene,
            plant=Plant.from_scene(scene))[1].result  # the fixedpoint stage's gait: the start
    return r, optimize_scene(scene, np.asarray(r.x, float), float(r.period_s),
                         plant=Plant.from_scene(scene))


@pytest.mark.slow  # two optimisations with their fixed points and replays (~20 s)
def test_the_paper_walker_on_1_cm_and_5_cm_risers_has_two_optima_each_a_gait_on_its_stairs():
    """Each optimum closes on its stairs (rigid replay <= 1e-6), advances one tread a step
    (0.41 m to 1e-9) and they differ: on 1 cm risers the passive stair gait advances
    414.09 mm, so the tread's 410 mm costs little (effort 0.0098 N^2 m^2 s, 0.17 N m); on 5 cm
    the passive gait would advance 616 mm, and the 5 x larger potential energy the walker
    gains per step (M g h = 9.81 J) must leave through 410 mm steps: heel strikes at a
    higher speed or the hip's negative work, at a larger effort (385 N^2 m^2 s, 84 N m)."""
    pytest.importorskip("casadi")
    out = {}
    for h in (0.01, 0.05):
        _, o = _optimum(_paper_on_stairs(h))
        assert o.gait and o.replay_error <= REPLAY, (h, o.status, o.replay_error)
        assert o.step_length_m == pytest.approx(0.41, abs=1e-9)
        out[h] = o
    e1, e5 = out[0.01].objective, out[0.05].objective
    t1, t5 = (float(np.max(np.abs(out[h].torque))) for h in (0.01, 0.05))
    assert e1 < 0.1 < 10.0 < e5, (e1, e5)  # measured 0.0098 and 385
    assert t1 < 1.0 < 10.0 < t5, (t1, t5)  # measured 0.17 N m and 84 N m


@pytest.mark.slow  # a fixed point and an optimisation (~6 s)
def test_on_stairs_of_the_passive_gaits_tread_the_least_effort_gait_is_the_passive_one():
    """The stairs' passive gait (1 cm risers: advance 414.092 mm, shooting) on treads of its
    advance: the collocation's guard and periodicity on the stairs give it back - effort
    <= 1e-8 N^2 m^2 s, the step period within 5e-6 (relative; Hermite-Simpson on 40
    intervals, the tread rounded to 1e-6 m: measured 1e-6 s of 0.709984 s), the replay
    on the stairs closing to 1e-6."""
    pytest.importorskip("casadi")
    r, o = _optimum(_paper_on_stairs(0.01, tread_m=0.414092))
    assert o.gait and o.replay_error <= REPLAY
    assert o.objective <= 1e-8
    assert o.step_period_s == pytest.approx(float(r.period_s), rel=5e-6)
    assert o.step_length_m == pytest.approx(0.414092, abs=1e-9)


@pytest.mark.slow  # the stairs' fixed point and two replays (~3 s)
def test_the_replay_of_the_stairs_gait_returns_to_its_start_on_the_stairs_only():
    """The rigid replay lands the heel strike on the next tread: the passive stair gait
    (zero torque, 1 cm risers) returns to its start within 1e-6 replayed on its stairs, and
    misses it by far replayed on the slope's heel strike (the landing is what closes it)."""
    from walkerlab.analysis.gait.scene import solve_scene
    from walkerlab.optimal.transcription.step import CollocationResult, replay
    from walkerlab.walker.description import walker_data

    scene = _paper_on_stairs(0.01)
    r = solve_scene(scene, plant=Plant.from_scene(scene))[1].result
    T = float(r.period_s)
    t = np.linspace(0.0, T, 81)
    res = CollocationResult(t=t, x=np.tile(np.asarray(r.x, float), (t.size, 1)),
                            u=np.zeros(t.size), step_period_s=T, step_length_m=0.414,
                            push_off_n_s=0.0, objective=0.0, status="Solve_Succeeded",
                            iterations=0, wall_time_s=0.0)
    data = walker_data(scene.walker, scene.slope.phi_rad)
    on_stairs, _ = replay(data, res, drop_m=0.01)
    on_slope, _ = replay(data, res)
    assert on_stairs <= REPLAY
    assert on_slope > 1e-3


def test_a_kneed_walker_on_stairs_and_a_step_other_than_the_tread_are_refused_in_one_line():
    """Knees (a step of phases) are not transcribed on stairs: refused naming
    ``terrain.kind``; straight legs on stairs with a target step length other than the
    tread (the gait advances one tread a step) naming ``optimize.target_step_length_m``."""
    from walkerlab.optimal.driver import check_scene
    from walkerlab.optimal.transcription.landing import step_ground

    d = load_scene(CONFIGS / "kneed_optimal.yaml").model_dump(mode="json", exclude_none=True)
    d["slope"] = {"angle_rad": 0.0}
    d["terrain"] = {"kind": "stairs", "riser_m": 0.01, "tread_m": 0.41}
    with pytest.raises(ValueError, match=r"^terrain\.kind: stairs: ") as err:
        check_scene(scene_from_dict(d), Plant.from_scene(scene_from_dict(d)).data)
    assert "\n" not in str(err.value)
    with pytest.raises(ValueError, match=r"^optimize\.target_step_length_m: 0\.5 m, but on "
                                         r"stairs the gait advances one tread"):
        step_ground(_paper_on_stairs(0.01, target_step_length_m=0.5))
    assert step_ground(_paper_on_stairs(0.01, target_step_length_m=0.41)).advance_m == 0.41


def _compass_on_footholds(heights, **optimize):
    """configs/compass_optimal.yaml (0.0525 rad, least effort, 40 intervals) on periodic
    footholds of these heights [m] (step k lands ``-heights[k mod p]`` below its stance
    foot's level)."""
    d = load_scene(CONFIGS / "compass_optimal.yaml").model_dump(mode="json",
                                                                 exclude_none=True)
    d["terrain"] = {"kind": "footholds", "foothold_heights_m": list(heights),
                    "periodic": True, "lanes": "checkerboard", "patch_width_m": 0.3}
    d["optimize"] = {**d["optimize"], **optimize}
    return scene_from_dict(d)


@pytest.mark.slow  # two fixed points and an optimisation (~8 s)
def test_compass_optimal_on_2_mm_footholds_is_the_two_step_passive_gait_not_the_slopes():
    """On +-2 mm footholds the least effort is the footholds' passive two-step gait found by
    shooting (fixedpoint: steps of 0.764674 s and 0.689328 s): effort <= 1e-8, each step's
    period within 1e-6 s of it (Hermite-Simpson on 40 intervals a step, measured 6e-8 s),
    replayed on the footholds to 1e-6; not the slope's passive gait (0.734461 s a step)."""
    pytest.importorskip("casadi")
    from walkerlab.analysis.gait.scene import solve_scene
    from walkerlab.optimal.driver import optimize_scene

    scene = _compass_on_footholds([-0.002, 0.002])
    r = solve_scene(scene, plant=Plant.from_scene(scene))[1].result
    steps = np.asarray(r.step_periods_s, float)
    assert steps.size == 2
    o = optimize_scene(scene, np.asarray(r.x, float), float(r.period_s) / 2,
                         plant=Plant.from_scene(scene))
    assert o.gait and o.replay_error <= REPLAY, (o.status, o.replay_error)
    assert o.objective <= 1e-8 and o.steps == 2
    assert np.max(np.abs(np.asarray(o.phase_duration_s) - steps)) <= 1e-6
    sc = load_scene(CONFIGS / "compass_optimal.yaml")
    slope = solve_scene(sc, plant=Plant.from_scene(sc))[1].result
    assert abs(o.step_period_s - float(slope.period_s)) > 1e-3


@pytest.mark.slow  # a fixed point and an optimisation (~6 s)
def test_a_powered_gait_over_footholds_closes_on_them():
    """At 0.8 m/s (faster than the passive 0.735 m/s) over +-2 mm footholds the hip works
    (effort > 0) and the period of two steps, replayed on the footholds, returns to its
    start within 1e-6; the mean step keeps the target speed."""
    pytest.importorskip("casadi")
    from walkerlab.analysis.gait.scene import solve_scene
    from walkerlab.optimal.driver import optimize_scene

    scene = _compass_on_footholds([-0.002, 0.002], target_speed_m_per_s=0.8)
    r = solve_scene(scene, plant=Plant.from_scene(scene))[1].result
    o = optimize_scene(scene, np.asarray(r.x, float), float(r.period_s) / 2,
                         plant=Plant.from_scene(scene))
    assert o.gait and o.replay_error <= REPLAY, (o.status, o.replay_error)
    assert o.objective > 1e-3
    assert o.step_length_m / o.step_period_s == pytest.approx(0.8, rel=1e-9)


def test_footholds_of_their_own_slopes_are_refused_in_one_line():
    """The collocation lands on footholds of the scene's slope at their heights; footholds of
    their own slopes are refused before any stage runs, naming the field."""
    from walkerlab.optimal.driver import check_scene

    d = _compass_on_footholds([-0.002, 0.002]).model_dump(mode="json", exclude_none=True)
    d["terrain"]["foothold_slopes_rad"] = [0.05, 0.055]
    with pytest.raises(ValueError, match=r"^terrain\.foothold_slopes_rad: optimize "):
        check_scene(scene_from_dict(d), Plant.from_scene(scene_from_dict(d)).data)
