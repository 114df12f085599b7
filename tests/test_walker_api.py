"""The in-memory walker (``wl.Walker``): the same gait as the ``fixedpoint`` stage bit for
bit, an exact Jacobian that matches finite differences of its own map, walks that agree
with the map, and nothing written."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest

import walkerlab as wl
from walkerlab.io.schemas.fixedpoint import load_fixedpoint
from walkerlab.numerics import fd_jacobian
from walkerlab.stages import pipeline

CONFIGS = Path(__file__).resolve().parents[1] / "configs"


def _files(folder: Path) -> set:
    return {p for p in folder.rglob("*") if p.is_file()}


@pytest.fixture(scope="module")
def paper():
    return wl.Walker.from_scene(CONFIGS / "paper.yaml")


@pytest.mark.parametrize("name", ["paper", "asymmetric_legs"])
def test_fixed_point_equals_the_stage_bit_for_bit_and_writes_nothing(name, tmp_path,
                                                                       monkeypatch):
    monkeypatch.chdir(tmp_path)  # a runs/ folder here would be a write
    before = _files(tmp_path)
    gait = wl.Walker.from_scene(CONFIGS / f"{name}.yaml").fixed_point()
    assert _files(tmp_path) == before and not (tmp_path / "runs").exists()
    art = load_fixedpoint(pipeline.run("fixedpoint", wl.load_scene(CONFIGS / f"{name}.yaml"),
                                       tmp_path / "stage_runs").path)
    assert np.array_equal(gait.x, art.x)  # bit for bit
    assert gait.step_period == art.step_period_s
    assert np.array_equal(gait.multipliers, art.multipliers)
    assert gait.label == art.gait
    assert list(gait.state) == art.state_names


def test_step_jacobian_and_floquet_of_the_paper_walker(paper):
    gait = paper.fixed_point()
    step = paper.step(gait.x)
    assert np.max(np.abs(step.x_next - gait.x)) < 1e-10
    assert step.period == pytest.approx(gait.step_period, abs=1e-10)
    assert [e[3] for e in step.events] == ["midstance", "heel_strike"]
    J = paper.jacobian(gait.x)
    # independent of the variational equations: central differences of the map itself
    Jfd = fd_jacobian(lambda z: paper.step(z).x_next, gait.x, 1e-6)
    assert np.max(np.abs(J - Jfd)) < 1e-6  # O(h^2) truncation + 1e-12 / 1e-6 noise
    lam = paper.floquet(gait.x)
    assert np.allclose(np.sort(np.abs(lam)), np.sort(np.abs(gait.multipliers)), atol=1e-12)
    # one multiplier is zero by construction (the map lands on the heel-strike surface)
    assert np.min(np.abs(lam)) < 1e-9


def test_simulate_returns_to_the_fixed_point_and_with_changes_is_a_new_walker(paper):
    gait = paper.fixed_point()
    walk = paper.simulate(gait.x, strides=2, sample_rate_hz=200)
    assert walk.termination == "heel_strike" and walk.heel_strikes.size == 4
    assert np.allclose(np.diff(walk.heel_strikes), gait.step_period, atol=1e-9)
    assert gait.map_period == gait.step_period
    assert walk.x.shape[1] == len(paper.state_names()) == walk.x.shape[1]
    heavier = paper.with_changes({"walker.hip_mass_kg": 12.0})
    assert heavier.scene.walker.hip_mass_kg == 12.0 and paper.scene.walker.hip_mass_kg == 10.0
    assert heavier.fixed_point().step_period != gait.step_period
    with pytest.raises(wl.api.scenes.SceneError if hasattr(wl.api.scenes, "SceneError")
                       else Exception, match="hip_mas"):
        paper.with_changes({"walker.hip_mas_kg": 12.0})


def test_no_write_outside_even_for_a_dict_scene(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    scene = {"walker": {"model": "compass_gait", "leg_length_m": 1.0, "leg_mass_kg": 5.0,
                        "hip_mass_kg": 10.0, "gravity_m_per_s2": 9.81,
                        "leg_mass_from_foot_m": 0.5},
             "slope": {"angle_rad": 0.0174}, "fixedpoint": {}}
    gait = wl.Walker.from_scene(scene).fixed_point()
    assert gait.stable and os.listdir(tmp_path) == []


def test_fixed_point_uses_the_walker_s_own_model_and_solver(paper, monkeypatch):
    # built once by the constructor; fixed_point rebuilds neither (it did: solve_scene)
    w = paper
    before = w.fixed_point()
    import walkerlab.analysis.gait.scene as gait_scene
    import walkerlab.analysis.gait.search as search
    import walkerlab.models.registry as registry

    def no(*a, **k):
        raise AssertionError("rebuilt from the scene")

    monkeypatch.setattr(registry, "build_walker", no)
    monkeypatch.setattr(gait_scene, "build_walker", no)
    used = []
    find = search.find_gaits
    monkeypatch.setattr(gait_scene, "find_gaits",
                        lambda walker, solver, *a, **k: used.append((walker, solver))
                        or find(walker, solver, *a, **k))
    gait = w.fixed_point()
    assert used == [(w.model, w.solver)] and used[0][0] is w.model
    assert np.array_equal(gait.x, before.x) and gait.step_period == before.step_period
