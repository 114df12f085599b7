"""The in-memory walker is the scene: ``wl.Walker`` / ``wl.ContactWalker`` give the numbers
of ``walkerlab fixedpoint``, ``walkerlab simulate`` and ``walkerlab contact-sim`` for a
shipped scene bit for bit (fixed point, Floquet multipliers, heel strikes, step table,
energy ledger, contact heel strikes and outcome), or refuse with the command's own line.

Both ways run the same library functions on the same numbers in the same order
(:func:`walkerlab.analysis.gait.scene.solve_scene`,
:func:`walkerlab.analysis.gait.rigid_run.walk_scene`,
:func:`walkerlab.analysis.contact.record.contact_walk`), so equality is exact: any
difference is a scene feature one of them does not take (a height profile walked as the
slope under it gave the API a constant 0.54585 s step where the command walks 0.535 to
0.554 s).

The quick suite compares a few scenes that exercise the ground (a profile, stairs,
footholds) and the contact view against the CLI's artifacts written once per module; the
slow one walks every ``configs/*.yaml``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml

import walkerlab as wl
from tests.cli_run import PAPER, run_cli
from walkerlab.config import SceneError
from walkerlab.io.runpaths import stage_artifact
from walkerlab.io.schemas.contact_sim import load_contact_sim
from walkerlab.io.schemas.fixedpoint import load_fixedpoint
from walkerlab.io.schemas.simulate import load_simulate

CONFIGS = Path(__file__).resolve().parents[1] / "configs"
SCENES = sorted(p.stem for p in CONFIGS.glob("*.yaml"))

#: step-table columns compared (numbers, then words)
RIGID_STEPS = ("t_start", "t_end", "period", "step_length", "hip_speed", "impact_energy_loss",
               "transition_energy_change", "midstance_time")
RIGID_WORDS = ("termination", "event", "stance_leg", "swing_leg", "phases")
#: contact step-table columns stored by contact_sim.h5
CONTACT_STEPS = ("period", "stance_slip_mm", "double_support_creep_mm",
                 "stance_slip_path_mm", "friction_work_j")


class CliRuns:
    """``walkerlab STAGE configs/NAME.yaml --runs-dir ROOT``, each run once: its exit code
    and error line, and the artifact's path."""

    def __init__(self, root: Path):
        self.root = root
        self.done: dict = {}

    def run(self, name: str, stage: str) -> tuple[int, str, Path]:
        if (name, stage) not in self.done:
            code, err, _ = run_cli("-q", stage, CONFIGS / f"{name}.yaml",
                                   "--runs-dir", self.root)
            self.done[name, stage] = (code, err)
        scene = wl.load_scene(CONFIGS / f"{name}.yaml")
        path = stage_artifact(scene, self.root, stage.replace("-", "_"))
        return (*self.done[name, stage], path)


@pytest.fixture(scope="module")
def cli(tmp_path_factory) -> CliRuns:
    return CliRuns(tmp_path_factory.mktemp("cli_runs"))


def _same_fixed_point(w: wl.Walker, cli: CliRuns, name: str):
    """The API's gait equals ``fixedpoint.h5``'s bit for bit (or both refuse with one
    line); returns the gait (None: refused)."""
    from walkerlab.analysis.gait.search import GaitNotFound

    code, err, path = cli.run(name, "fixedpoint")
    if code != 0:
        with pytest.raises((GaitNotFound, ValueError)) as exc:
            w.fixed_point()
        # the same line; the command shortens the search's notes in brackets (all of them
        # with WALKERLAB_DEBUG=1), the exception keeps them; a headline past 300 characters
        # puts them on a second line of their own (walkerlab.cli.errors.one_line)
        headline = str(exc.value).split(" [", 1)[0]
        first, *rest = err.splitlines()
        assert headline in first and (rest == [] or (
            len(rest) == 1 and rest[0].startswith("  [") and rest[0].endswith("]"))), \
            (err, exc.value)
        return None
    art = load_fixedpoint(path)
    gait = w.fixed_point()
    assert gait.label == art.gait
    assert np.array_equal(gait.x, art.x), gait.x - art.x
    assert gait.map_period == art.period_s
    assert np.array_equal(gait.multipliers, art.multipliers)
    assert gait.residual == art.residual
    return gait


def _same_walk(w: wl.Walker, gait, cli: CliRuns, name: str) -> None:
    """The API's walk from the stage's start equals ``simulate.h5``'s heel strikes, step
    table and energy ledger bit for bit."""
    from walkerlab.io.schemas.continuation import initial_state

    code, err, path = cli.run(name, "simulate")
    assert code == 0, err
    art = load_simulate(path)
    sim = w.scene.simulate
    x0 = (gait.x if sim.initial_state == "fixed_point"
          else initial_state(sim.initial_state, w.state_names()))
    walk = w.simulate(x0, sim.strides, sim.sample_rate_hz)
    assert walk.termination == art.termination
    assert len(walk.steps["period"]) == len(art.steps["period"]) > 0
    for k in RIGID_STEPS:
        assert np.array_equal(walk.steps[k], art.steps[k], equal_nan=True), k
    for k in RIGID_WORDS:
        assert list(walk.steps[k]) == list(art.steps[k]), k
    heel = art.steps["termination"] == "heel_strike"
    assert np.array_equal(walk.heel_strikes, art.steps["t_end"][heel])
    assert sorted(walk.ledger) == sorted(art.ledger)
    for k, v in art.ledger.items():
        assert np.array_equal(walk.ledger[k], v, equal_nan=True), k


def _same_contact_run(w: wl.Walker, cli: CliRuns, name: str) -> None:
    """The contact view's walk from the rigid gait equals ``contact_sim.h5``'s (samples'
    times, heel strikes, step table, outcome), or both refuse with the same line (a scene
    without a contact section runs both on the section's defaults)."""
    code, err, path = cli.run(name, "contact-sim")
    if code != 0 and not path.is_file():  # refused before any run
        with pytest.raises(ValueError) as exc:
            w.contact().simulate()
        assert str(exc.value) in err and len(err.splitlines()) == 1, (err, exc.value)
        return
    art = load_contact_sim(path)
    walk = w.contact().simulate()
    assert (walk.outcome, walk.termination) == (art.outcome, art.termination)
    assert walk.heel_strikes.size == art.heel_strike_times.size
    assert art.samples.time.size > 1  # a run (round_feet_3d on the defaults trips unstruck)
    assert np.array_equal(walk.heel_strikes, art.heel_strike_times)
    assert np.array_equal(walk.t, art.samples.time)
    for k in CONTACT_STEPS:
        assert np.array_equal(walk.steps[k], art.steps[k], equal_nan=True), k


#: quick: the grounds the API once missed or that build another walker (a height profile,
#: stairs, footholds below the slope), and one contact run (stairs: patches on the treads)
QUICK_RIGID = ["profile", "stairs", "footholds"]


@pytest.mark.parametrize("name", QUICK_RIGID)
def test_the_api_walks_the_scene_s_ground_as_the_commands(name, cli):
    w = wl.Walker.from_scene(CONFIGS / f"{name}.yaml")
    gait = _same_fixed_point(w, cli, name)
    _same_walk(w, gait, cli, name)


def test_the_api_walks_a_height_profile_not_the_slope_under_it(cli):
    # the hole this module closes: a profile's steps differ (0.535 to 0.554 s) where the
    # slope under it repeats one period
    w = wl.Walker.from_scene(CONFIGS / "profile.yaml")
    gait = w.fixed_point()
    walk = w.simulate(gait.x, 5)
    periods = walk.steps["period"]
    assert np.ptp(periods) > 0.01  # 18.8 ms spread; on the slope 0 (1e-12 at most)
    sections = yaml.safe_load((CONFIGS / "profile.yaml").read_text())
    on_slope = {k: v for k, v in sections.items() if k not in ("terrain", "contact",
                                                                "contact_sim",
                                                                "contact_solver")}
    flat = wl.Walker.from_scene(on_slope).simulate(gait.x, 5)
    assert np.ptp(flat.steps["period"]) < 1e-9


def test_the_contact_view_runs_the_contact_sim_stage_s_numbers(cli):
    w = wl.Walker.from_scene(CONFIGS / "stairs.yaml")
    _same_contact_run(w, cli, "stairs")


def test_a_ground_the_walk_cannot_read_is_refused_in_the_command_s_line(tmp_path):
    # a height profile walked by the printed Appendix A equations: the rigid walk on a
    # profile builds a walker per segment from the generated model only
    scene = {k: v for k, v in PAPER.items() if k in ("walker", "slope", "solver",
                                                      "fixedpoint", "simulate")}
    scene["ideal"] = {"variant": "appendix_a"}
    scene["terrain"] = {"kind": "profile",
                        "profile_m": [[-1.0, 0.05], [0.0, 0.0], [6.0, -0.3]]}
    w = wl.Walker.from_scene(scene)
    with pytest.raises(SceneError) as exc:
        w.simulate(w.fixed_point().x, 2)
    msg = str(exc.value)
    assert len(msg.splitlines()) == 1 and msg.startswith("terrain.kind: profile")
    assert "ideal.variant" in msg
    f = tmp_path / "printed_profile.yaml"
    f.write_text(yaml.safe_dump(scene))
    code, err, _ = run_cli("-q", "simulate", f, "--runs-dir", tmp_path / "runs")
    assert code != 0 and err == f"error: {msg}"


def _scene_file(tmp_path: Path, name: str, **changes) -> Path:
    """configs/paper.yaml's rigid walker with ``changes`` (section -> fields) written to
    ``tmp_path / name.yaml``."""
    scene = {k: dict(v) for k, v in PAPER.items() if k in ("walker", "slope", "solver",
                                                            "fixedpoint", "simulate",
                                                            "terrain")}
    for section, fields in changes.items():
        scene[section].update(fields)
    path = tmp_path / f"{name}.yaml"
    path.write_text(yaml.safe_dump(scene))
    return path


def test_a_rough_ground_drawn_from_the_scene_s_seed_is_the_command_s(tmp_path):
    # simulate.terrain_seed: the per-step slopes of terrain.per_step drawn from it; the
    # API walked the mean slope (every period 0.70360 s)
    f = _scene_file(tmp_path, "rough", terrain={"per_step": {"slope_sd_rad": 0.002}},
                    simulate={"terrain_seed": 7, "strides": 3})
    code, err, _ = run_cli("-q", "simulate", f, "--runs-dir", tmp_path / "runs")
    assert code == 0, err
    w = wl.Walker.from_scene(f)
    art = load_simulate(stage_artifact(w.scene, tmp_path / "runs", "simulate"))
    walk = w.simulate(w.fixed_point().x, 3)
    assert np.array_equal(walk.steps["period"], art.steps["period"])
    assert np.ptp(walk.steps["period"]) > 0.01  # 0.676 to 0.716 s on this ground
    other = w.simulate(w.fixed_point().x, 3, terrain_seed=8)  # another ground
    assert not np.array_equal(other.steps["period"], walk.steps["period"])


def test_a_gait_carried_from_fixedpoint_from_is_the_command_s(tmp_path):
    # no initial guess: the start is the paper walker's gait carried by homotopy to a
    # heavier hip, as `walkerlab fixedpoint` starts it
    f = _scene_file(tmp_path, "heavier", walker={"hip_mass_kg": 12.0},
                    fixedpoint={"from": str(CONFIGS / "paper.yaml")})
    scene = yaml.safe_load(f.read_text())
    scene["fixedpoint"].pop("initial_guess")
    f.write_text(yaml.safe_dump(scene))
    code, err, _ = run_cli("-q", "fixedpoint", f, "--runs-dir", tmp_path / "runs")
    assert code == 0, err
    w = wl.Walker.from_scene(f)
    art = load_fixedpoint(stage_artifact(w.scene, tmp_path / "runs", "fixedpoint"))
    assert any("by homotopy" in n for n in art.gait_notes)
    gait = w.fixed_point()
    assert np.array_equal(gait.x, art.x) and gait.step_period == art.step_period_s
    scene["fixedpoint"]["from"] = str(tmp_path / "missing.yaml")
    f.write_text(yaml.safe_dump(scene))
    with pytest.raises(SceneError, match="^fixedpoint.from: .*missing.yaml") as exc:
        wl.Walker.from_scene(f).fixed_point()
    code, err, _ = run_cli("-q", "fixedpoint", f, "--runs-dir", tmp_path / "runs")
    assert code != 0 and err == f"error: {exc.value}"


def test_a_terrain_seed_without_a_per_step_ground_is_refused_in_one_line():
    w = wl.Walker.from_scene(CONFIGS / "paper.yaml")
    with pytest.raises(SceneError, match=r"^simulate: terrain_seed=3: the scene has no "
                                            r"terrain\.per_step") as exc:
        w.simulate(w.fixed_point().x, 1, terrain_seed=3)
    assert len(str(exc.value).splitlines()) == 1


@pytest.mark.slow
@pytest.mark.parametrize("name", SCENES)
def test_every_shipped_scene_gives_the_commands_numbers_in_memory(name, cli):
    w = wl.Walker.from_scene(CONFIGS / f"{name}.yaml")
    gait = _same_fixed_point(w, cli, name)
    if gait is not None:
        _same_walk(w, gait, cli, name)
        _same_contact_run(w, cli, name)
