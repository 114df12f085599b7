"""Issue 96: contact runs and their searches are bounded by work, the same answer on any
machine; a wall-clock limit is optional and a run it cuts short is never reused."""

from pathlib import Path

import h5py
import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from tests.contact.conftest import FP, STEP_LENGTH
from walkerlab.analysis.contact.sim import initial_state_from_ideal, simulate_contact
from walkerlab.cli import app
from walkerlab.config import ContactSettings, SolverSettings, TerrainSettings, load_scene
from walkerlab.config.contact_sim import ContactSimSettings
from walkerlab.integrate.contact import ContactLimits
from walkerlab.models.contact import ContactWalker

ROOT = Path(__file__).resolve().parents[2]


def _paper():
    return ContactWalker.from_settings(ContactSettings(), TerrainSettings(patch_width_m=0.10),
                                       step_length=STEP_LENGTH, n_steps=12)


@pytest.mark.parametrize("method", ["odeint", "cyrk_bdf"])
def test_work_bound_ends_a_run_the_same_way_twice(method):
    """A bound of 4,000 right-hand-side evaluations (the paper's walk takes ~28,000): the
    run ends with outcome work_limit, its samples and its count the same in both runs, the
    count within the bound for a Python right-hand side (counted at each call) and at most
    one chunk past it for a compiled one (asked between chunks); the message names the
    bound and the field that raises it."""
    w = _paper()
    x0 = initial_state_from_ideal(w, *FP)
    limits = ContactLimits(max_rhs_evaluations=4_000)
    sv = SolverSettings.for_contact(method=method)
    a, b = (simulate_contact(w, x0, 3.0, sv, limits) for _ in range(2))
    assert a.outcome.kind == b.outcome.kind == a.termination == "work_limit", a.outcome
    assert a.nfev == b.nfev and np.array_equal(a.t, b.t) and np.array_equal(a.x, b.x)
    if method == "odeint":
        assert a.nfev <= 4_000
    assert a.t[-1] < 3.0 and not a.outcome.walked
    assert "contact_sim.max_rhs_evaluations" in a.outcome.message
    assert "4,000 right-hand-side evaluations" in a.outcome.message


def test_default_work_bound_leaves_a_walk_unchanged():
    """The scene's default bound (contact_sim.max_rhs_evaluations) is far above a walk's
    work: the paper's run with it and with no bound at all is the same run."""
    w = _paper()
    x0 = initial_state_from_ideal(w, *FP)
    sv = SolverSettings.for_contact()
    bound = ContactSimSettings().max_rhs_evaluations
    a = simulate_contact(w, x0, 1.6, sv, ContactLimits(max_rhs_evaluations=bound))
    b = simulate_contact(w, x0, 1.6, sv, ContactLimits(max_rhs_evaluations=None))
    assert a.termination == b.termination != "work_limit"
    assert np.array_equal(a.x, b.x) and a.nfev == b.nfev < bound


def test_scene_defaults_have_no_wall_clock_limit_and_keep_their_serialisation():
    """No wall-clock limit by default (nor numbalsoda, whose chunks are sized in wall time,
    as the default method); the work bounds at their defaults are left out of the scene's
    serialisation (its content hash), a bound set is kept."""
    cs = ContactSimSettings()
    assert cs.wall_time_limit_s is None and cs.periodic_time_limit_s is None
    assert SolverSettings.for_contact().method != "numbalsoda"
    d = cs.model_dump()
    assert not {"max_rhs_evaluations", "periodic_max_step_maps",
                "adjust_max_contact_runs"} & set(d)
    assert ContactSimSettings(max_rhs_evaluations=10).model_dump()["max_rhs_evaluations"] == 10


@pytest.mark.parametrize("field,value", [("max_rhs_evaluations", 0),
                                         ("periodic_max_step_maps", -1),
                                         ("adjust_max_contact_runs", 0)])
def test_a_bad_work_bound_is_refused_naming_its_field(field, value):
    with pytest.raises(ValueError, match=field):
        ContactSimSettings(**{field: value})


def test_periodic_search_work_bound_ends_it_the_same_way_twice():
    """A search bounded at 3 step-map integrations (the paper's takes hundreds) ends with
    kind work_limit, twice alike, the message naming the field to raise."""
    from walkerlab.analysis.contact.periodic import find_contact_periodic_gait
    from walkerlab.analysis.contact.step_map import PeriodicGaitError

    w = _paper()
    msgs = []
    for _ in range(2):
        with pytest.raises(PeriodicGaitError) as e:
            find_contact_periodic_gait(w, FP, max_step_maps=3)
        assert e.value.kind == "work_limit"
        msgs.append(str(e.value))
    assert msgs[0] == msgs[1] and "contact_sim.periodic_max_step_maps" in msgs[0]


def _scene(tmp_path, **sim) -> Path:
    d = yaml.safe_load((ROOT / "configs" / "paper.yaml").read_text())
    d = {k: v for k, v in d.items() if k not in ("workprecision", "basin")}
    d["name"] = "bounded"
    d["contact_sim"] = {**d["contact_sim"], "periodic_gait": False, "n_strides": 1, **sim}
    p = tmp_path / "bounded.yaml"
    p.write_text(yaml.safe_dump(d))
    load_scene(p)  # valid
    return p


@pytest.mark.slow  # four contact-sim commands (~16 s); tests/test_not_final_artifacts.py
# checks the cache's rule quickly
def test_a_wall_limited_run_is_stored_but_never_reused(tmp_path):
    """A run a wall-clock limit ends (a limit already spent: time_limit at its first
    sample) is written, marked not_final, and the next run recomputes it instead of saying
    'reused (inputs unchanged)'; a run the work bound ends is a result and is reused."""
    runs = tmp_path / "runs"
    p = _scene(tmp_path, wall_time_limit_s=1e-9)
    r1 = CliRunner().invoke(app, ["contact-sim", str(p), "--runs-dir", str(runs)])
    art = runs / "bounded" / "contact_sim.h5"
    with h5py.File(art) as f:
        assert f.attrs["outcome"] == "time_limit", r1.stdout
        assert "contact_sim.wall_time_limit_s" in str(f.attrs["not_final"])
    r2 = CliRunner().invoke(app, ["contact-sim", str(p), "--runs-dir", str(runs)])
    assert "(inputs unchanged)" not in r2.stdout + r2.stderr
    assert "cut short by a wall-clock limit" in r2.stderr, r2.stderr
    with h5py.File(art) as f:
        assert f.attrs["outcome"] == "time_limit" and "not_final" in f.attrs

    p = _scene(tmp_path, max_rhs_evaluations=2_000)  # the same scene, bounded by work
    r3 = CliRunner().invoke(app, ["contact-sim", str(p), "--runs-dir", str(runs)])
    with h5py.File(art) as f:
        assert f.attrs["outcome"] == "work_limit", r3.stdout
        assert "not_final" not in f.attrs
    r4 = CliRunner().invoke(app, ["contact-sim", str(p), "--runs-dir", str(runs)])
    assert "(inputs unchanged)" in r4.stdout + r4.stderr


@pytest.mark.slow  # two rigid gait searches and a kernel compile: ~100 s on a loaded machine
def test_a_stability_map_cell_without_work_left_says_work_limit_twice_alike():
    """A map cell whose searches may make 3 step-map integrations each (the default 2,000):
    its reason is work_limit, the same in a second computation; no clock decides it."""
    from walkerlab.studies.stability import REASONS, MapSpec, gait_row
    from walkerlab.walker.plant import Plant

    scene = load_scene(ROOT / "configs" / "paper.yaml")
    base, plant = scene.model_dump(mode="json"), Plant.from_scene(scene)
    spec = MapSpec("friction", (0.9,), (3.0,), max_step_maps=3)
    rows = [gait_row(base, spec, 0, plant) for _ in range(2)]
    assert [c["reason"] for c in rows[0]] == [c["reason"] for c in rows[1]] == ["work_limit"]
    assert "work_limit" in REASONS
    assert MapSpec("friction", (0.9,), (3.0,)).key() != spec.key()
