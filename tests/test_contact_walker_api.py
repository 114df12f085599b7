"""The contact view in memory (``wl.ContactWalker``, ``wl.Walker(...).contact()``): its walk
and its own periodic gait are those of ``walkerlab contact-sim`` bit for bit (the same
library code, :func:`walkerlab.analysis.contact.record.contact_walk`), on the model it built
once; nothing is written; bad input is one line."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest

import walkerlab as wl
from walkerlab.config import SceneError
from walkerlab.io.schemas.contact_sim import load_contact_sim
from walkerlab.stages import pipeline

CONFIGS = Path(__file__).resolve().parents[1] / "configs"


def _same_as_the_stage(cw, walk, gait, runs: Path) -> None:
    """``walk`` and ``gait`` of ``cw`` equal the ``contact-sim`` artifact of its scene."""
    art = load_contact_sim(pipeline.run("contact-sim", cw.scene, runs).path)
    assert np.array_equal(walk.heel_strikes, art.heel_strike_times)  # bit for bit
    assert np.array_equal(walk.step_periods, art.steps["period"], equal_nan=True)
    assert np.array_equal(walk.t, art.samples.time)
    assert walk.termination == art.termination and walk.outcome == art.outcome
    assert art.periodic is not None and gait.period_s == art.periodic.step_period_s
    assert np.array_equal(gait.multipliers, art.periodic.multipliers)
    return art


def test_the_contact_walk_and_periodic_gait_equal_the_stage_s_and_write_nothing(
        tmp_path, monkeypatch):
    # paper.yaml, 2 strides (periodic_gait: true in the scene): the stage's run in memory
    monkeypatch.chdir(tmp_path)  # a runs/ folder here would be a write
    cw = wl.Walker.from_scene(CONFIGS / "paper.yaml").with_changes(
        {"contact_sim.n_strides": 2}).contact()
    assert isinstance(cw, wl.ContactWalker) and cw.contact_names() == ["leg1", "leg2"]
    walk = cw.simulate()
    gait = cw.periodic_gait()
    assert os.listdir(tmp_path) == []
    assert walk.walks and walk.heel_strikes.size == 4
    # the stance foot carries the walker at mid-step, the swing foot is off the ground
    mid = 0.5 * (walk.heel_strikes[:-1] + walk.heel_strikes[1:])
    for tm, swing, stance in zip(mid, walk.heel_strike_legs[1:], walk.heel_strike_legs):
        k = np.searchsorted(walk.t, tm)
        assert walk.normal_force[swing][k] == 0.0
        assert walk.normal_force[stance][k] > 0.3 * cw.model.total_mass * 9.81
    # the contact model's own gait is near the rigid one (paper: 0.711 s against 0.733 s)
    assert gait.stable and abs(gait.period_s / cw.rigid_gait().step_period - 1) < 0.05
    assert walk.x.shape == (walk.t.size, len(cw.state_names()))
    assert np.array_equal(walk.column("hip_x"), walk.x[:, 0])
    _same_as_the_stage(cw, walk, gait, tmp_path / "stage")


def test_the_contact_walker_builds_its_model_once(monkeypatch):
    cw = wl.ContactWalker.from_scene(CONFIGS / "paper.yaml").with_changes(
        {"contact_sim.n_strides": 1})

    def no(*a, **k):
        raise AssertionError("rebuilt from the scene")

    gait = cw.rigid_gait()
    import walkerlab.analysis.gait.scene as gait_scene
    import walkerlab.models.contact.scene as contact_scene
    import walkerlab.models.registry as registry

    for mod, name in ((contact_scene, "contact_setup"), (registry, "build_walker"),
                      (gait_scene, "build_walker")):
        monkeypatch.setattr(mod, name, no)
    walk = cw.simulate(gait.x, period_s=gait.step_period)  # the default start, given
    assert walk.walks and walk.heel_strikes.size >= 2
    assert np.array_equal(walk.x_ideal, gait.x)


@pytest.fixture(scope="module")
def paper_contact():
    return wl.ContactWalker.from_scene(CONFIGS / "paper.yaml")


@pytest.mark.parametrize("x0, says", [
    (np.ones(3), r"shape \(3,\).*4 numbers \(swing_angle, stance_angle, swing_rate, "
                 r"stance_rate\)"),
    (np.ones(8), r"shape \(8,\).*4 numbers"),  # the contact walker's own state: no start
    ([np.nan, 0, 0, 0], r"x0\[0\] \(swing_angle\) = nan"),
    ("abc", "x0='abc'")])
def test_a_bad_start_is_one_line_naming_the_states(paper_contact, x0, says):
    for call in (paper_contact.simulate, paper_contact.periodic_gait):
        with pytest.raises(SceneError, match=says) as err:
            call(x0)
        assert "\n" not in str(err.value)


@pytest.mark.parametrize("strides", [0, 1.5, True, "2", 10**9])
def test_strides_are_whole_and_within_the_field_s_range(paper_contact, strides):
    with pytest.raises(SceneError, match=r"strides=.*contact_sim.n_strides"):
        paper_contact.simulate(strides=strides)


def test_a_period_without_a_start_is_refused_and_a_scene_without_contact_has_defaults(
        paper_contact):
    with pytest.raises(SceneError, match="period_s goes with x0"):
        paper_contact.simulate(period_s=0.7)
    with pytest.raises(SceneError, match="period_s=-1"):
        paper_contact.simulate(np.zeros(4), period_s=-1)
    scene = {"walker": {"model": "compass_gait", "leg_length_m": 1.0, "leg_mass_kg": 5.0,
                        "hip_mass_kg": 10.0, "gravity_m_per_s2": 9.81,
                        "leg_mass_from_foot_m": 0.5},
             "slope": {"angle_rad": 0.0174}, "fixedpoint": {}}
    assert wl.ContactWalker is wl.api.ContactWalker is wl.api.walker.ContactWalker
    assert paper_contact.rigid.contact().rigid is paper_contact.rigid
    # no contact section: the contact view on the section's defaults, the paper's law with
    # the ADAMS View defaults for what the paper does not print (configs/paper.yaml sets its
    # stiction and friction velocities to 10 and 100 mm/s: only those differ)
    cw = wl.Walker.from_scene(scene).contact()
    assert cw.scene.contact == type(cw.scene.contact)()
    paper = paper_contact.scene.contact.model_dump()
    differ = {k for k, v in type(cw.scene.contact)().model_dump().items() if paper[k] != v}
    assert differ == {"stiction_velocity_mm_per_s", "friction_velocity_mm_per_s"}


@pytest.mark.slow
def test_a_powered_contact_walk_equals_the_stage_s(tmp_path):
    # powered_compass: hip torque and push-off pulse, started from its own periodic gait
    cw = wl.ContactWalker.from_scene(CONFIGS / "powered_compass.yaml").with_changes(
        {"contact_sim.n_strides": 1})
    walk = cw.simulate()
    assert walk.gait is not None and walk.work and walk.walks
    assert walk.work["push_off"][-1] > 0  # the pulse does positive work on the walker
    _same_as_the_stage(cw, walk, walk.gait, tmp_path)


def _stops_short(monkeypatch):
    """The contact periodic-gait search's root solve stops at its warm-up state (as hybr
    stops "not making good progress" above the residual asked for): a search that did
    not converge, whatever the machine."""
    from scipy.optimize import OptimizeResult

    from walkerlab.analysis.contact import periodic

    def warm_up_only(P, PC, coarse, z, *args, **kwargs):
        return OptimizeResult(x=z / P.scale, nfev=0, message="stopped short"), 0

    monkeypatch.setattr(periodic, "_solve_fixed_point", warm_up_only)


def test_a_contact_periodic_gait_that_did_not_converge_is_raised(paper_contact, monkeypatch):
    # issue 56 item 7: the search's result came back with converged False (a residual
    # 0.014 and a multiplier 79.7 from the map's Jacobian away from its fixed point)
    from walkerlab.analysis.contact.step_map import PeriodicGaitError

    _stops_short(monkeypatch)
    cw = paper_contact.with_changes({"contact_sim.n_strides": 1})
    with pytest.raises(PeriodicGaitError, match=r"did not converge \(scaled residual "
                       r"\S+ > 1e-08: stopped short\)") as err:
        cw.periodic_gait()
    assert err.value.kind == "not_converged" and "\n" not in str(err.value)
