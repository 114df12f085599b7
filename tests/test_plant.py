"""The plant (:class:`walkerlab.walker.plant.Plant`): a scene's walker described once, by the
front (a stage, the API's walker), and handed down to the models, analyses and studies."""

from __future__ import annotations

import collections
from pathlib import Path

import walkerlab.walker.description as description
import walkerlab.walker.plant as plant_module
from walkerlab.api.walker import Walker
from walkerlab.config import load_scene
from walkerlab.walker.description import walker_data
from walkerlab.walker.plant import Plant

CONFIGS = Path(__file__).resolve().parents[1] / "configs"


def test_a_plant_is_its_scenes_description_and_keeps_each_other_slope():
    scene = load_scene(CONFIGS / "kneed.yaml")
    plant = Plant.from_scene(scene)
    ref = walker_data(scene.walker, scene.slope.phi_rad)
    assert plant.data.params == ref.params and plant.data.structure == ref.structure
    assert plant.kind == ref.structure.kind and plant.slope_rad == scene.slope.phi_rad
    assert plant.data_at(scene.slope.phi_rad) is plant.data  # its own slope: no new one
    g = scene.slope.phi_rad + 0.01
    assert plant.data_at(g) is plant.data_at(g)  # another slope: described once, kept
    assert plant.data_at(g).params == walker_data(scene.walker, g).params
    on = plant.on_slope(g)
    assert on.scene.slope.phi_rad == g and on.data is plant.data_at(g)
    assert on.scene.walker == scene.walker


def test_the_api_walker_describes_each_slope_of_a_profile_once(monkeypatch):
    """The gait search, its ground check and a walk over a height profile (a walker per
    landing segment's slope) share the walker's plant: each slope is described once (before
    the plant, each was described two to six times)."""
    calls = collections.Counter()
    real = description.walker_data

    def counted(walker_cfg, slope_rad):
        calls[repr(float(slope_rad))] += 1
        return real(walker_cfg, slope_rad)

    monkeypatch.setattr(description, "walker_data", counted)
    monkeypatch.setattr(plant_module, "walker_data", counted)
    w = Walker(load_scene(CONFIGS / "profile.yaml"))
    w.simulate(w.fixed_point().x, strides=2)
    assert len(calls) >= 3, calls  # the scene's slope and the profile's segments
    assert max(calls.values()) == 1, calls


def test_a_neighbour_on_the_same_walker_shares_the_plants_descriptions():
    """``Plant.with_``: a scene that changes only the slope, the solver or another section
    beside the walker reuses the description (the same object, no walker described again);
    a scene with another walker section is described anew, and its kind follows it."""
    scene = load_scene(CONFIGS / "kneed.yaml")
    plant = Plant.from_scene(scene)
    assert plant.with_(scene) is plant
    solver = scene.model_copy(update={"solver": scene.solver.model_copy(
        update={"rtol": scene.solver.rtol / 10})})
    assert plant.with_(solver).data is plant.data and plant.with_(solver).scene is solver
    g = scene.slope.phi_rad + 0.02
    sloped = plant.on_slope(g).scene
    near = plant.with_(sloped)
    assert near.data is plant.data_at(g) and near.data_at(plant.slope_rad) is plant.data
    assert near.data.params == walker_data(scene.walker, g).params

    paper = load_scene(CONFIGS / "paper.yaml")
    other = paper.model_copy(update={"walker": paper.walker.model_copy(
        update={"hip_mass_kg": 2 * paper.walker.hip_mass_kg})})
    moved = Plant.from_scene(paper).with_(other)
    assert moved.data.params == Plant.from_scene(other).data.params
    assert moved.data.params != Plant.from_scene(paper).data.params
    assert moved.scene is other
    assert plant.with_(paper).kind == Plant.from_scene(paper).kind != plant.kind


def test_a_plant_pickles_with_its_scene_and_description():
    """A worker task carries the plant: it survives pickle and cloudpickle round trips."""
    import pickle

    import cloudpickle

    plant = Plant.from_scene(load_scene(CONFIGS / "paper.yaml"))
    for dumps, loads in ((pickle.dumps, pickle.loads), (cloudpickle.dumps, pickle.loads)):
        back = loads(dumps(plant))
        assert back.scene == plant.scene and back.data.params == plant.data.params
        assert back.kind == plant.kind and back.data.structure == plant.data.structure


def test_a_plant_crosses_the_worker_pool_and_a_walker_pickles_as_its_plant():
    """A study's task carries the plant to a pool worker (walkerlab.execution) and back; the
    API's walker pickles as its plant and step work limit and is rebuilt of its class."""
    import pickle

    from walkerlab.execution.executor import make_executor, run_each
    from walkerlab.models.registry import state_layout

    plant = Plant.from_scene(load_scene(CONFIGS / "kneed.yaml"))
    with make_executor(2, pool=True) as ex:
        (_, got), = list(run_each(ex, state_layout, [(plant,)]))
    assert got == state_layout(plant)
    w = Walker(load_scene(CONFIGS / "paper.yaml"), step_evaluations=1234)
    back = pickle.loads(pickle.dumps(w))
    assert type(back) is Walker and back.step_evaluations == 1234
    assert back.scene == w.scene and back.plant.data.params == w.plant.data.params
    assert back.state_names() == w.state_names()
