"""The front door goes where the command line goes (``wl.optimize``, ``wl.target``,
``wl.export_scene``, ``wl.robustness``, with the commands' checks), ``walkerlab target`` refuses a
bad target or field at once in one line, and an export writes its files together: all or
none."""

from __future__ import annotations

import errno
import os
import time
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

import walkerlab as wl
from walkerlab.cli import app
from walkerlab.config import SceneError
from walkerlab.io.artifacts import ArtifactError
from walkerlab.studies.params import SweepError

CONFIGS = Path(__file__).resolve().parents[1] / "configs"
POWERED = str(CONFIGS / "powered_compass.yaml")
PUSH = "walker.actuation.push_off.impulse_n_s"


# ------------------------------------------------------------------ walkerlab target (14)
@pytest.mark.parametrize("args, says", [
    (["--speed-m-per-s", "0"], "speed_m_per_s (--speed-m-per-s) = 0.0: give a positive finite"),
    (["--speed-m-per-s", "nan"], "= nan: give a positive finite number [m/s]"),
    (["--step-length-m", "inf"], "step_length_m (--step-length-m) = inf: give a positive"),
    (["--step-period-s", "-1"], "= -1.0: give a positive finite number [s]"),
    ([], "give exactly one of --speed-m-per-s, --step-length-m, --step-period-s (got none)"),
    (["--speed-m-per-s", "0.5", "--step-length-m", "0.3", "--step-period-s", "0.6"],
     "(got 3)"),
    (["--speed-m-per-s", "0.5", "--vary", "simulate.strides"],
     "--vary 'simulate.strides': vary a numeric field of the walker or the slope"),
    (["--speed-m-per-s", "0.5", "--vary", "walker.actuation.push_off.impuls_n_s"],
     "target --vary 'walker.actuation.push_off.impuls_n_s': unknown field"),
])
def test_target_refuses_a_bad_target_or_field_at_once_in_one_line(args, says):
    vary = [] if "--vary" in args else ["--vary", PUSH]
    t = time.perf_counter()
    r = CliRunner().invoke(app, ["target", POWERED, *vary, *args])
    assert r.exit_code == 1 and r.stderr.count("error:") == 1, r.output
    assert "internal error" not in r.output and says in r.stderr, r.stderr
    assert time.perf_counter() - t < 3.0  # before any map (nan, inf, -1 searched 5-6 s)


def test_wl_target_is_walkerlab_target_in_memory(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    t = wl.target(POWERED, PUSH, speed_m_per_s=0.45)
    # the push-off that walks at 0.45 m/s (tests/test_powered.py: 2.4434 N s), nothing written
    assert t.value == pytest.approx(2.4434, abs=1e-4) and t.unit == "N s"
    assert t.gait.speed == pytest.approx(0.45, rel=1e-9)
    assert t.walker.scene.walker.actuation.push_off.impulse_n_s == t.value
    assert t.gait.cost_of_transport > 0 and not any(tmp_path.iterdir())
    with pytest.raises(SceneError, match="exactly one"):
        wl.target(POWERED, PUSH)
    with pytest.raises(SceneError, match="positive finite"):
        wl.target(POWERED, PUSH, step_length_m=True)


# -------------------------------------------------------------------------- export (13)
def test_an_export_writes_its_files_together_or_not_at_all(tmp_path, monkeypatch):
    """A folder in the second file's place, or a full disk while the second file is
    renamed: the first file keeps its old content (was: the new one beside the old other,
    while the message said "nothing was replaced")."""
    from walkerlab import safefs

    runs = tmp_path / "runs"
    adm = wl.export_scene(CONFIGS / "paper.yaml", "adm", runs_dir=runs)
    acf = adm.with_suffix(".acf")
    old_adm, old_acf = adm.read_bytes(), acf.read_bytes()
    adm.write_bytes(old_adm + b"! old\n")
    acf.unlink()
    acf.mkdir()  # a folder where walker.acf goes
    r = CliRunner().invoke(app, ["export", str(CONFIGS / "paper.yaml"), "--format", "adm",
                                 "--runs-dir", str(runs)])
    assert r.exit_code == 1 and "nothing was replaced" in r.stderr, r.output
    assert adm.read_bytes() == old_adm + b"! old\n" and acf.is_dir()
    acf.rmdir()
    acf.write_bytes(old_acf + b"! old\n")
    # a full disk at the second rename: the first file is put back as it was
    real = os.replace
    calls = []

    def full_at_second(src, dst):
        calls.append(dst)
        if len(calls) == 2:
            raise OSError(errno.ENOSPC, "No space left on device", str(dst))
        return real(src, dst)

    monkeypatch.setattr(safefs.os, "replace", full_at_second)
    with pytest.raises(ArtifactError, match="disk full.*nothing was replaced"):
        wl.export_scene(CONFIGS / "paper.yaml", "adm", runs_dir=runs)
    monkeypatch.setattr(safefs.os, "replace", real)
    assert adm.read_bytes() == old_adm + b"! old\n"
    assert acf.read_bytes() == old_acf + b"! old\n"
    assert sorted(p.name for p in adm.parent.iterdir()) == [".scene", "walker.acf",
                                                           "walker.adm"]  # no temp, no backup
    # and a good export replaces both
    wl.export_scene(CONFIGS / "paper.yaml", "adm", runs_dir=runs)
    assert adm.read_bytes() == old_adm and acf.read_bytes() == old_acf


def test_the_urdf_and_its_keyframe_are_written_together(tmp_path):
    runs = tmp_path / "runs"
    urdf = wl.export_scene(CONFIGS / "paper.yaml", runs_dir=runs)
    side = urdf.with_name("walker.gait.json")
    assert urdf.name == "walker.urdf" and side.is_file()
    urdf.write_text("old")
    side.unlink()
    side.mkdir()
    with pytest.raises(ArtifactError, match="walker.gait.json: cannot write.*nothing was repl"):
        wl.export_scene(CONFIGS / "paper.yaml", runs_dir=runs)
    assert urdf.read_text() == "old"


def test_export_scene_checks_its_arguments_and_the_export_package_stays_a_package(tmp_path):
    import types

    import walkerlab.export.adams  # noqa: F401 - the package imported first ...

    assert wl.api.export is wl.export_scene and callable(wl.export_scene)
    assert type(wl.export) is types.ModuleType and not callable(wl.export)
    assert wl.export.adams.__name__ == "walkerlab.export.adams"
    for kw, says in ((dict(fmt="stl"), "fmt='stl': one of urdf, mjcf, adm"),
                     (dict(fmt=None), "fmt=None"),
                     (dict(walker_only="yes"), "walker_only='yes': give True or False")):
        with pytest.raises(SceneError, match=says):
            wl.export_scene(CONFIGS / "paper.yaml", runs_dir=tmp_path, **kw)
    p = wl.export_scene(CONFIGS / "paper.yaml", "mjcf", walker_only=True, runs_dir=tmp_path)
    assert p.name == "walker.xml" and "<mujoco" in p.read_text()
    assert not any(tmp_path.rglob(".*.tmp"))


# ----------------------------------------------------------------- optimize, robustness
@pytest.mark.parametrize("kw, error, says", [
    (dict(design={"walker.hip_mass_kg": (20, 5)}), SceneError, "LO < HI"),
    (dict(design={"walker.hip_mass_kg": (5, float("nan"))}), SceneError, "two finite"),
    (dict(design={"walker.hip_mass_kg": ("5", 20)}), SceneError, "two finite"),
    (dict(design="walker.hip_mass_kg=5:20"), SceneError, "give a mapping"),
    (dict(design={"walker.hip_mas_kg": (5, 20)}), SweepError,
     "design field 'walker.hip_mas_kg': unknown field .*did you mean walker.hip_mass_kg"),
    (dict(design={"walker.hip_mass_kg": (5, 20)}, objective="nope"), SceneError,
     "objective='nope': one of step_period"),
    (dict(design={"walker.hip_mass_kg": (5, 20)}, maximize="yes"), SceneError, "maximize"),
    (dict(objective="speed"), SceneError, "give design="),
])
def test_wl_optimize_refuses_what_the_command_refuses_before_running(tmp_path, kw, error,
                                                                     says):
    with pytest.raises(error, match=says):
        wl.optimize(CONFIGS / "paper.yaml", runs_dir=tmp_path, **kw)
    assert not (tmp_path / "paper").exists()  # nothing ran


def test_wl_optimize_design_is_the_command_s_optimum(tmp_path):
    """As ``walkerlab optimize --design walker.hip_mass_kg=5:20`` (tests/test_optimize.py):
    the heaviest hip minimises the paper walker's largest multiplier (0.574 at 20 kg)."""
    d = wl.optimize(CONFIGS / "paper.yaml", design={"walker.hip_mass_kg": (5, 20)},
                    runs_dir=tmp_path)
    assert d.attrs["stage"] == "optimize_design" and float(d["values"][0]) == 20.0
    assert float(d["objective_value"]) == pytest.approx(0.5737, abs=1e-3)
    assert (tmp_path / "paper" / "optimize_design_walker.hip_mass_kg_max_abs_multiplier.h5"
            ).is_file()  # one artifact per fields and objective


@pytest.mark.parametrize("workers", [0, True, "2", 1.5])
def test_wl_robustness_checks_workers_before_the_gait_search(tmp_path, workers):
    t = time.perf_counter()
    with pytest.raises(SceneError, match="--workers"):
        wl.robustness(CONFIGS / "paper.yaml", workers=workers, runs_dir=tmp_path)
    assert time.perf_counter() - t < 1.0 and not (tmp_path / "paper").exists()


@pytest.mark.slow
def test_wl_optimize_gait_and_robustness_read_the_stage_artifacts(tmp_path):
    import yaml

    from walkerlab.io.schemas.optimize import load
    from walkerlab.io.schemas.robustness import load as load_robustness

    d = wl.optimize(CONFIGS / "compass_optimal.yaml", runs_dir=tmp_path)
    art = load(tmp_path / "compass_optimal" / "optimize.h5")
    assert d.attrs["stage"] == "optimize" and art.gait
    assert float(d["step_period"]) == art.step_period_s
    base = yaml.safe_load((CONFIGS / "paper.yaml").read_text())
    scene = {k: base[k] for k in ("walker", "slope", "ideal", "solver", "fixedpoint")}
    scene.update(name="rob", robustness={
        "sigma_rad": 0.008, "montecarlo_walks": 8, "montecarlo_max_steps": 40,
        "disturbances": ["slope"], "resolution_m": 0.004, "survival_steps": 10})
    r = wl.robustness(scene, runs_dir=tmp_path)
    stored = load_robustness(tmp_path / "rob" / "robustness.h5")
    assert float(r["gsn_slope"]) == stored.gsn["slope"] > 0
    assert np.isfinite(float(r["mfpt_steps"]))
