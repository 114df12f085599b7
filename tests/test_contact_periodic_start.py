"""Contact runs started from the contact model's own periodic gait (issue 25, item 4)."""

from pathlib import Path

import numpy as np
import pytest

from walkerlab.config import load_scene, scene_from_dict
from walkerlab.walker.plant import Plant


@pytest.mark.slow  # a periodic-gait search (~3 s CPU) and a 2-stride contact run
def test_run_from_the_periodic_gait_has_constant_step_periods():
    """From the gait's mid-stance state every full step lasts the gait's period.

    Tolerance 5e-5 s: the periodic solve converges to a scaled residual < 1e-8 (here
    ~2e-11), so the orbit itself is periodic to far below 1 us; what remains is the run's
    integrator (the scene's contact solver, looser than the search's rtol 1e-12) and its
    heel-strike location: measured 6-7 us (spread ~1.5 us) at ADAMS's default stiction
    velocity, 11-22 us (spread 10 us) at configs/paper.yaml's 10 mm/s, whose friction law
    is ten times steeper.  The start from the ideal fixed point (x 1.1 rates) has a first
    step of 0.58 s against 0.71 s: 2500 times that tolerance."""
    from walkerlab.analysis.contact.periodic import ideal_gait, simulate_from_periodic_gait
    from walkerlab.models.contact.scene import contact_setup

    scene = load_scene("configs/paper.yaml")
    ideal = ideal_gait(scene, plant=Plant.from_scene(scene))
    _, res, _, _, gait = simulate_from_periodic_gait(contact_setup(scene,
            plant=Plant.from_scene(scene)), ideal.x,
                                                     strides=2)
    assert gait.converged and gait.residual < 1e-8
    hs = np.asarray(res.heel_strike_times)
    assert hs.size == 5 and res.heel_strike_legs[:2] == ["leg1", "leg2"]
    periods = np.diff(hs)  # full steps (the first heel strike ends a half step)
    assert np.all(np.abs(periods - gait.period_s) < 5e-5)
    assert np.ptp(periods) < 2e-5
    # the steady gait is the contact model's, not the rigid one (0.7036 s): 1.26 ms apart at
    # the 10 mm/s stiction velocity (+0.18 %; 7 ms at ADAMS's 100 mm/s), a thousand times
    # the periodic solve's accuracy
    assert abs(gait.period_s - ideal.period_s) > 1e-3


def test_start_setting_is_typed_and_the_default_keeps_the_scene_hash():
    """``contact_sim.start`` accepts the three starts only, and a scene that leaves it at
    the default serialises as before (its cached artifacts and shipped numbers stay)."""
    from walkerlab.config import SceneError

    scene = load_scene("configs/paper.yaml")
    assert scene.contact_sim.start == "ideal"
    assert "start" not in scene.section_json("contact_sim")
    d = scene.model_dump(mode="json")
    d["contact_sim"]["start"] = "periodic_gait"
    s2 = scene_from_dict(d)
    assert s2.contact_sim.start == "periodic_gait"
    assert '"start": "periodic_gait"' in s2.section_json("contact_sim").replace("\":\"", "\": \"")
    d["contact_sim"]["start"] = "steady"
    with pytest.raises((SceneError, ValueError), match="start"):
        scene_from_dict(d)


@pytest.mark.slow  # the contact-sim stage from the periodic gait (~5 s CPU)
def test_contact_sim_stage_starts_from_the_periodic_gait(tmp_path):
    """``contact_sim.start: periodic_gait`` through the stage: the artifact stores the gait
    it started from, the run walks, its first heel strike comes about half a period after
    the start (mid-stance) and every full step lasts the gait's period (tolerance as in
    the test above)."""
    import yaml

    from walkerlab.io.schemas.contact_sim import load_contact_sim
    from walkerlab.stages import pipeline

    d = yaml.safe_load(Path("configs/paper.yaml").read_text())
    d["contact_sim"].update({"start": "periodic_gait", "n_strides": 1})
    p = tmp_path / "paper_steady.yaml"
    p.write_text(yaml.safe_dump(d))
    out = pipeline.run("contact-sim", load_scene(p), tmp_path / "runs")
    assert not out.failure
    cs = load_contact_sim(out.path)
    assert cs.periodic is not None and cs.periodic.found
    hs = cs.heel_strike_times
    assert hs.size == 3 and hs[0] < 0.6 * cs.periodic.step_period_s  # started mid-stance
    assert np.all(np.abs(np.diff(hs) - cs.periodic.step_period_s) < 2e-5)


@pytest.mark.slow  # fixedpoint, a periodic-gait search (~3 s CPU) and a 2-stride contact run
def test_contact_sim_reads_the_scene_once(tmp_path, monkeypatch):
    """Issue 27: ``contact-sim`` turns the scene into its typed contact setup once
    (:func:`walkerlab.models.contact.scene.contact_setup`: walker data, the contact law in
    SI, terrain, run options, solver) and hands that on.  The start from the periodic gait
    builds two walkers (the search's probe, then the run's on the gait's patch spacing);
    each build used to read the scene and convert the contact law to SI again."""
    import yaml
    from typer.testing import CliRunner

    from walkerlab.cli import app
    from walkerlab.models.contact import scene as contact_scene

    root = Path(__file__).resolve().parents[1]
    d = yaml.safe_load((root / "configs" / "paper.yaml").read_text())
    d = {k: v for k, v in d.items() if k not in ("workprecision", "basin")}
    d["name"] = "once"
    d["contact_sim"] = {**d["contact_sim"], "n_strides": 2, "periodic_gait": False,
                        "start": "periodic_gait"}
    path = tmp_path / "once.yaml"
    path.write_text(yaml.safe_dump(d))
    calls = []
    real = contact_scene.contact_si
    monkeypatch.setattr(contact_scene, "contact_si", lambda c: calls.append(c) or real(c))
    r = CliRunner().invoke(app, ["contact-sim", str(path), "--runs-dir", str(tmp_path / "r")])
    assert r.exit_code == 0, r.stderr
    # once by the stage's check before any computation (a refusal the scene decides comes
    # first: issue 64 item 6), once by the run; not once more per walker built
    assert len(calls) == 2


def test_a_start_whose_periodic_gait_is_not_found_says_why_in_one_line(monkeypatch):
    """``start: periodic_gait`` whose search fails (here: its wall-time limit, as on a
    loaded machine) re-raises the search's error with its kind and the field named; it was
    re-raised with the message in place of the kind (a TypeError: an internal error)."""
    from types import SimpleNamespace

    from walkerlab.analysis.contact import periodic
    from walkerlab.analysis.contact.record import contact_sim_run
    from walkerlab.analysis.contact.step_map import PeriodicGaitError
    from walkerlab.models.contact.scene import contact_setup

    def fails(setup, x, strides=None, solver=None):
        raise PeriodicGaitError("time_limit", "periodic-gait search: wall-time limit reached")

    monkeypatch.setattr(periodic, "simulate_from_periodic_gait", fails)
    sc = load_scene("configs/torso_bhm.yaml")
    setup = contact_setup(sc, plant=Plant.from_scene(sc))
    with pytest.raises(PeriodicGaitError, match="contact_sim.start: periodic_gait") as e:
        contact_sim_run(setup, SimpleNamespace(x=np.zeros(4), step_period_s=np.nan))
    assert e.value.kind == "time_limit" and "wall-time limit" in str(e.value)


def test_a_periodic_gait_search_that_did_not_converge_is_a_gait_not_found(tmp_path,
                                                                          monkeypatch):
    """issue 56 item 7, the stage's side: ``start: periodic_gait`` from a search that did
    not converge is one line naming the field and exit 1 (it started the run from the
    unconverged state); ``periodic_gait: true`` stores it as not found (outcome
    ``not_converged``, its message), not as a gait with its multipliers."""
    import yaml
    from scipy.optimize import OptimizeResult
    from typer.testing import CliRunner

    from walkerlab.analysis.contact import periodic
    from walkerlab.cli import app
    from walkerlab.io.artifacts import open_artifact

    def warm_up_only(P, PC, coarse, z, *args, **kwargs):  # hybr stopping short, anywhere
        return OptimizeResult(x=z / P.scale, nfev=0, message="stopped short"), 0

    monkeypatch.setattr(periodic, "_solve_fixed_point", warm_up_only)
    d = yaml.safe_load(Path("configs/paper.yaml").read_text())
    runs = str(tmp_path / "runs")
    for name, start, found in (("steady", "periodic_gait", False), ("also", "ideal", True)):
        d["contact_sim"].update({"start": start, "n_strides": 1, "periodic_gait": True})
        p = tmp_path / f"paper_{name}.yaml"
        p.write_text(yaml.safe_dump(d))
        r = CliRunner().invoke(app, ["contact-sim", str(p), "--runs-dir", runs])
        if not found:
            assert r.exit_code == 1 and "Traceback" not in r.output
            line, = [ln for ln in r.output.splitlines() if ln.startswith("error:")]
            assert "contact_sim.start: periodic_gait" in line and "did not converge" in line
            continue
        assert r.exit_code == 0, r.output
        with open_artifact(Path(runs) / f"paper_{name}" / "contact_sim.h5") as f:
            g = f["periodic_gait"]
            assert g.attrs["outcome"] == "not_converged" and "multipliers" not in g
            assert "did not converge" in g.attrs["message"]
