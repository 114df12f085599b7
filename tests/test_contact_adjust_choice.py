"""``contact-sim --adjust`` keeps the better start (issue 26, item 3): the adjusted rates
minimise the period and step-length mismatch, which does not promise a better walk; the run
kept is the one that walks better, and the command says which and why."""

import re
from pathlib import Path
from types import SimpleNamespace

import h5py
import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from walkerlab.analysis.contact import adjust as contact_adjust
from walkerlab.cli import app

ROOT = Path(__file__).resolve().parents[1]
PAPER = yaml.safe_load((ROOT / "configs" / "paper.yaml").read_text())


def _run(kind: str, steps: int, slip: float):
    return SimpleNamespace(outcome=SimpleNamespace(kind=kind), walked_steps=steps,
                           max_stance_slip_mm=slip)


@pytest.mark.parametrize("scene_run, adjusted_run, kept", [
    # the case: the scene's start walks to its end, the adjusted one scuffs
    (_run("t_final", 10, 1.4), _run("scuff", 10, 5.5), "scene"),
    (_run("trip", 5, 0.3), _run("heel_strike", 10, 2.0), "adjusted"),
    (_run("fall", 3, np.nan), _run("fall", 6, np.nan), "adjusted"),
    (_run("heel_strike", 10, 0.8), _run("heel_strike", 10, 1.2), "scene"),
    (_run("heel_strike", 10, 1.0), _run("heel_strike", 10, 1.0), "adjusted"),  # a tie
])
def test_the_better_walk_is_kept(scene_run, adjusted_run, kept):
    got, why = contact_adjust.better_start(scene_run, adjusted_run)
    assert got == kept
    assert why.startswith(f"adjusted start: {adjusted_run.outcome.kind} after "
                          f"{adjusted_run.walked_steps} heel strikes")
    assert f"the scene's start: {scene_run.outcome.kind}" in why


def _scene(tmp_path, scale) -> Path:
    d = {k: v for k, v in PAPER.items() if k not in ("workprecision", "basin")}
    d["contact_sim"] = {**d["contact_sim"], "periodic_gait": False, "initial_rate_scale": scale}
    p = tmp_path / "adj.yaml"
    p.write_text(yaml.safe_dump(d))
    return p


def _adjust_to(scale):
    def fake(scene, x_fp, period, grid=None):
        return {"scale": np.array(scale, float), "objective": 0.5, "evaluations": 1,
                "grid_best": np.array(scale, float)}
    return fake


@pytest.mark.slow
def test_adjust_keeps_the_scenes_start_when_the_adjusted_one_walks_worse(tmp_path,
                                                                        monkeypatch):
    """The paper's scene walks from rate scale (1, 1.1) (configs/paper.yaml); a search that
    lands on (0.5, 0.5) (half the gait's speed: no step) must not replace it."""
    monkeypatch.setattr(contact_adjust, "adjust_rates", _adjust_to((0.5, 0.5)))
    r = CliRunner().invoke(app, ["contact-sim", str(_scene(tmp_path, [1.0, 1.1])), "--adjust",
                                 "--runs-dir", str(tmp_path / "runs")])
    assert r.exit_code == 0, r.stderr
    line = next(ln for ln in r.stdout.splitlines() if ln.startswith("--adjust:"))
    assert line.startswith("--adjust: kept the scene's initial rate scale")
    assert "adjusted start: fall after" in line
    assert re.search(r"the scene's start: (t_final|heel_strike) after 1[01] heel strikes", line)
    with h5py.File(tmp_path / "runs" / "adj" / "contact_sim.h5") as f:
        assert f["initial_rate_scale"][()].tolist() == [1.0, 1.1]
        assert f["adjust"].attrs["kept"] == "scene"
        assert f.attrs["outcome"] in ("heel_strike", "t_final")  # walked (CONTACT_WALKED)


@pytest.mark.slow
def test_adjust_keeps_the_adjusted_start_when_it_walks_better(tmp_path, monkeypatch):
    """From the unscaled start the paper's contact walker drifts off its 10 cm patches and
    trips (configs/paper.yaml); the adjusted (1, 1.1) walks all 10 heel strikes."""
    monkeypatch.setattr(contact_adjust, "adjust_rates", _adjust_to((1.0, 1.1)))
    r = CliRunner().invoke(app, ["contact-sim", str(_scene(tmp_path, [1.0, 1.0])), "--adjust",
                                 "--runs-dir", str(tmp_path / "runs")])
    assert r.exit_code == 0, r.stderr
    line = next(ln for ln in r.stdout.splitlines() if ln.startswith("--adjust:"))
    assert line.startswith("--adjust: kept the adjusted initial rate scale")
    with h5py.File(tmp_path / "runs" / "adj" / "contact_sim.h5") as f:
        assert f["initial_rate_scale"][()].tolist() == [1.0, 1.1]
        assert f["adjust"].attrs["kept"] == "adjusted"
