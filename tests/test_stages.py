"""Stages, caching, artifacts and the report (behaviour, not timing)."""

from pathlib import Path

import h5py
import numpy as np
import pytest
import yaml

from walkerlab.config import load_scene
from walkerlab.io.artifacts import ArtifactError, open_artifact
from walkerlab.io.trajectory import NamedTrajectory, write_samples

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture()
def ideal_scene(tmp_path):
    """The paper's walker, ideal model only (no contact / work-precision sections)."""
    d = yaml.safe_load((ROOT / "configs" / "paper.yaml").read_text())
    for k in ("contact", "terrain", "contact_sim", "contact_solver", "workprecision"):
        d.pop(k, None)
    d["simulate"]["strides"] = 1
    p = tmp_path / "ideal_only.yaml"
    p.write_text(yaml.safe_dump(d))
    return load_scene(p)


def test_stage_reuse_and_invalidation(ideal_scene, tmp_path):
    from walkerlab.stages import fixedpoint, pipeline

    runs = tmp_path / "runs"
    a = pipeline.run("simulate", ideal_scene, runs)
    assert not a.reused
    assert pipeline.run("simulate", ideal_scene, runs).reused
    assert fixedpoint.run(ideal_scene, runs).reused
    # change the slope: both stages that depend on it rerun
    d = ideal_scene.model_dump(mode="json", exclude_none=True)
    d["slope"] = {"angle_rad": 0.02}
    from walkerlab.config import scene_from_dict

    steeper = scene_from_dict(d)
    assert not fixedpoint.run(steeper, runs).reused
    assert not pipeline.run("simulate", steeper, runs).reused
    # a change of simulate-only settings leaves the fixed point alone
    d["simulate"]["sample_rate_hz"] = 100
    s2 = scene_from_dict(d)
    assert fixedpoint.run(s2, runs).reused
    assert not pipeline.run("simulate", s2, runs).reused


def test_simulate_artifact_is_named_and_physical(ideal_scene, tmp_path):
    from walkerlab.stages import pipeline

    out = pipeline.run("simulate", ideal_scene, tmp_path)
    with open_artifact(out.path, "simulate") as f:
        assert f["samples/coordinates/leg1_angle"].attrs["unit"] == "rad"
        assert f["samples/coordinates/leg2_rate"].attrs["unit"] == "rad/s"
        assert "scene_json" in f.attrs and f.attrs["wall_time_s"] > 0
        assert list(f["steps/termination"].asstr()[()]) == ["heel_strike"] * 2
        # total energy is constant within each step (PE from a fixed datum)
        tot, step = f["samples/energy/total"][()], f["samples/step_index"][()]
        for k in np.unique(step):
            e = tot[step == k]
            assert np.ptp(e) < 1e-8 * abs(e[0])
        # and drops at heel strike (plastic impact)
        assert tot[step == 1][0] < tot[step == 0][-1]


@pytest.mark.slow  # end to end: a whole report
def test_report_of_ideal_only_scene_has_no_contact_sections(ideal_scene, tmp_path):
    from walkerlab.stages import report

    html = report.run(ideal_scene, tmp_path, echo=lambda s: None)
    md = (html.parent / "report.md").read_text()
    assert "Fixed point" in md and "Table 3" in md
    for word in ("contact", "Fig. 8", "Table 2", "work-precision"):
        assert word not in md.replace("ours, ideal", "")
    figs = sorted(p.name for p in (html.parent / "figures").glob("*.png"))
    assert figs == ["energy_ledger.png", "fig10_energy.png", "fig2_stick_ideal.png",
                    "fig7_angles_rates.png", "fig9_limit_cycles.png"]
    assert "data:image/png;base64" in html.read_text()


def _fake_trajectory(n=200):
    t = np.linspace(0, 2, n)
    step = (t >= 1).astype(int)
    th = 0.2 * np.sin(np.pi * t)
    return NamedTrajectory(
        time=t, legs=["leg1", "leg2"],
        coordinates={"leg1_angle": th, "leg2_angle": -th, "leg1_rate": np.gradient(th, t),
                     "leg2_rate": -np.gradient(th, t)},
        units={"leg1_angle": "rad", "leg2_angle": "rad", "leg1_rate": "rad/s",
               "leg2_rate": "rad/s"},
        stance_leg=step.copy(), step_index=step, kinetic=1 + 0 * t, potential=100 + 0 * t,
        points={"hip": np.vstack([0.5 * t, 1 + 0 * t]),
                "leg1_foot": np.vstack([0.5 * t + np.sin(th), 1 - np.cos(th)]),
                "leg2_foot": np.vstack([0.5 * t - np.sin(th), 1 - np.cos(th)])})


def test_figures_are_drawn_from_a_hand_built_artifact(tmp_path, ideal_scene):
    """Plot from a small artifact written by hand (no simulation involved)."""
    import walkerlab.io.artifacts as A
    from walkerlab.stages import plot

    path = tmp_path / "ideal_only" / "simulate.h5"
    A.write_artifact(path, "simulate", ideal_scene, "x",
                     lambda f: write_samples(f, _fake_trajectory()),
                     0.0)
    written = plot.run(ideal_scene, tmp_path)
    assert {p.name for p in written} >= {"fig7_angles_rates.png", "fig9_limit_cycles.png",
                                         "fig10_energy.png", "fig2_stick_ideal.png"}
    assert all(p.stat().st_size > 5000 for p in written)


def test_compare_of_a_trajectory_with_itself_is_zero():
    from walkerlab.comparison.errors import aligned_errors, limit_cycle_distance

    tr = _fake_trajectory()
    t, err = aligned_errors(tr, tr)
    assert set(err) == {"leg1_angle", "leg2_angle", "leg1_rate", "leg2_rate"}
    assert all(np.max(np.abs(v)) == 0 for v in err.values())
    assert limit_cycle_distance(tr, tr, "leg1_angle", "leg1_rate") == 0


def test_table3_is_recomputed_from_the_artifact(tmp_path, ideal_scene):
    from walkerlab.comparison.tables import gait_metrics

    tr = _fake_trajectory()
    m = gait_metrics(tr)
    assert m["t_left_s"] == pytest.approx(1.0, abs=0.02)  # step boundary at t = 1 s
    assert m["v_com_m_per_s"] == pytest.approx(0.5, rel=1e-9)  # hip x = 0.5 t
    assert m["E_avg_J"] == pytest.approx(101.0)


def test_truncated_artifact_is_a_clear_error(tmp_path):
    p = tmp_path / "simulate.h5"
    with h5py.File(p, "w") as f:
        f.attrs["stage"] = "simulate"
    data = p.read_bytes()
    p.write_bytes(data[: len(data) // 3])
    with pytest.raises(ArtifactError, match="simulate.h5.*truncated or damaged"):
        with open_artifact(p, "simulate"):
            pass


def _overwritten(good: bytes, off: int, path: Path) -> Path:
    """``path`` holding ``good`` with 64 bytes overwritten at ``off`` (0, 1, ..., 63)."""
    b = bytearray(good)
    b[off:off + 64] = bytes(range(64))
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_bytes(bytes(b))
    return path


@pytest.mark.slow  # in `pytest -m slow`: the quick suite keeps to its CPU budget
def test_a_fixedpoint_damaged_in_the_middle_is_recomputed_with_a_notice(
        ideal_scene, tmp_path, capfd):
    # issue 56 item 9: a fixedpoint.h5 with bytes overwritten in its middle still opens,
    # but HDF5 cannot walk its objects ("Object visitation failed", a RuntimeError); every
    # later command was an internal error; now the cache sees a damaged artifact
    import walkerlab.io.artifacts as A
    from walkerlab.io.schemas.fixedpoint import load_fixedpoint
    from walkerlab.stages import fixedpoint

    runs = tmp_path / "runs"
    first = fixedpoint.run(ideal_scene, runs)
    good, x, key = first.path.read_bytes(), load_fixedpoint(first.path).x, \
        A.verified_hash(first.path)
    # every 4 KiB of the middle half (data, object headers, symbol tables, heaps): the
    # cache's check gives the hash (bytes nothing reads) or None, the loader one line
    n = len(good)
    for off in range(n // 4, 3 * n // 4, 4096):
        p = _overwritten(good, off, tmp_path / f"sweep{off}" / "fixedpoint.h5")
        assert A.verified_hash(p) in (None, key)
        try:
            load_fixedpoint(p)
        except ArtifactError as err:
            assert "\n" not in str(err) and "fixedpoint.h5" in str(err)
    # the object header of the group nearest the file's middle: the file opens, its walk fails
    with h5py.File(first.path, "r") as f:
        heads = []
        f.visititems(lambda name, o: heads.append(h5py.h5o.get_info(o.id).addr)
                     if isinstance(o, h5py.Group) else None)
    mid = min(heads, key=lambda a: abs(a - n // 2))
    _overwritten(good, mid, first.path)
    with h5py.File(first.path, "r") as f, pytest.raises(RuntimeError):
        A.content_hash_of(f)  # what the cache's check met
    capfd.readouterr()
    again = fixedpoint.run(ideal_scene, runs)
    assert not again.reused and "damaged" in again.note
    assert f"recomputing {first.path} (it is damaged" in capfd.readouterr().err
    assert np.array_equal(load_fixedpoint(again.path).x, x)  # the same gait, rewritten
    assert fixedpoint.run(ideal_scene, runs).reused


def test_artifact_of_another_version_is_refused(tmp_path):
    p = tmp_path / "fixedpoint.h5"
    with h5py.File(p, "w") as f:
        f.attrs["stage"] = "fixedpoint"
        f.attrs["walkerlab_version"] = "0.0.1"
    with pytest.raises(ArtifactError, match="written by walkerlab 0.0.1"):
        with open_artifact(p, "fixedpoint"):
            pass


def test_failed_write_leaves_the_good_artifact(tmp_path, ideal_scene):
    import walkerlab.io.artifacts as A

    path = tmp_path / "x.h5"
    A.write_artifact(path, "simulate", ideal_scene, "good",
                     lambda f: f.create_dataset("a", data=1), 0)

    def boom(f):
        f.create_dataset("a", data=2)
        raise RuntimeError("crash mid-write")

    with pytest.raises(RuntimeError):
        A.write_artifact(path, "simulate", ideal_scene, "bad", boom, 0)
    with h5py.File(path) as f:
        assert f["a"][()] == 1 and f.attrs["input_hash"] == "good"
    assert not list(tmp_path.glob("*.tmp"))


def test_cli_fixedpoint_prints_named_state(tmp_path):
    from typer.testing import CliRunner

    from walkerlab.cli import app

    r = CliRunner().invoke(app, ["fixedpoint", str(ROOT / "configs" / "paper.yaml"),
                                 "--runs-dir", str(tmp_path)])
    assert r.exit_code == 0, r.output
    assert "stance_angle   (leg2, stance leg)" in r.output
    assert "rad/s" in r.output and "verdict: STABLE" in r.output


def test_cli_bad_scene_is_one_line_per_error(tmp_path):
    """Every validation error on its own line naming the file and the field, no traceback."""
    from typer.testing import CliRunner

    from walkerlab.cli import app

    p = tmp_path / "bad.yaml"
    p.write_text("walker: {leg_length_m: -1}\nslope: {angle_deg: 1}\n")
    r = CliRunner().invoke(app, ["fixedpoint", str(p), "--runs-dir", str(tmp_path)])
    assert r.exit_code == 1
    lines = r.output.strip().splitlines()
    assert all(ln.startswith(f"error: {p}: walker.") for ln in lines), lines
    assert any("walker.leg_length_m: Input should be greater than 0" in ln for ln in lines)
    assert "Traceback" not in r.output


def test_saved_figure_is_not_cropped(tmp_path):
    """``plotting.figures.save`` computes the tight box once for PNG and SVG; for a
    constrained-layout figure that box must be the one after the layout (as
    ``bbox_inches="tight"`` finds it), else tick labels and colorbars are cut off."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from walkerlab.plotting.figures import save

    def make():
        fig, axes = plt.subplots(1, 2, figsize=(8, 3), layout="constrained")
        im = axes[1].imshow([[0, 1], [2, 3]])
        fig.colorbar(im, ax=axes[1], label="steps")
        axes[0].set_ylabel("stance rate [rad/s]")
        return fig

    (png,) = [p for p in save(make(), tmp_path, "ours") if p.suffix == ".png"]
    ref = make()
    ref.savefig(tmp_path / "ref.png", dpi=150, bbox_inches="tight")
    plt.close(ref)
    h, w = plt.imread(png).shape[:2]
    hr, wr = plt.imread(tmp_path / "ref.png").shape[:2]
    assert abs(w - wr) <= 2 and abs(h - hr) <= 2, ((w, h), (wr, hr))


def test_a_run_begun_within_a_step_counts_neither_partial_step():
    """A contact run from the rigid gait's mid-stance begins within a step: the step
    periods, the speed and the step lengths come from the complete steps alone (here six
    steps of 0.8 s between a first of 0.4 s and a last of 0.3 s; the hip moves 0.5 m/s in
    the complete steps, 2 m/s in the partial ones)."""
    from walkerlab.comparison.tables import gait_metrics

    edges = np.array([0.0, 0.4, 1.2, 2.0, 2.8, 3.6, 4.4, 5.2, 5.5])
    t = np.linspace(0.0, 5.5, 5501)
    step = np.searchsorted(edges, t, side="right") - 1
    step[-1] = step[-2]
    stance = step % 2
    speed = np.where((t < 0.4) | (t > 5.2), 2.0, 0.5)
    hip = np.concatenate([[0.0], np.cumsum(speed[1:] * np.diff(t))])
    tr = NamedTrajectory(
        time=t, legs=["leg1", "leg2"], coordinates={}, units={}, stance_leg=stance,
        step_index=step, kinetic=1 + 0 * t, potential=100 + 0 * t,
        points={"hip": np.vstack([hip, 1 + 0 * t]),
                "leg1_foot": np.vstack([hip + 0.2, 0 * t]),
                "leg2_foot": np.vstack([hip - 0.2, 0 * t])})
    m = gait_metrics(tr)
    assert m["t_left_s"] == pytest.approx(0.8, abs=2e-3)
    assert m["t_right_s"] == pytest.approx(0.8, abs=2e-3)
    assert m["v_com_m_per_s"] == pytest.approx(0.5, rel=1e-3)
    assert m["n_steps"] == 8


# ------------------------------------------------------- the stages as objects (registry)
def test_every_registered_stage_has_its_module_and_its_artifacts_loader():
    """Each :class:`~walkerlab.stages.registry.Stage` names a module with a ``run``, an
    artifact whose schema module has its loader and whose file the run paths build, and
    upstream stages that are registered and never lead back to it (a wrong entry would
    fail the pipeline at run time, not here)."""
    import importlib

    from walkerlab.io.runpaths import stage_artifact
    from walkerlab.stages import pipeline
    from walkerlab.stages.registry import PHASES, STAGES

    scene = load_scene(ROOT / "configs" / "paper.yaml")
    for name, st in STAGES.items():
        assert callable(pipeline.stage_module(name).run), name
        assert st.phase in PHASES, name
        assert set(st.needs) <= set(STAGES), name
        assert name not in pipeline.order(name, scene)[:-1], name  # no circle
        if st.artifact is not None:
            module = importlib.import_module(f"walkerlab.io.schemas.{st.artifact.schema}")
            assert callable(getattr(module, st.artifact.loader)), name
            assert stage_artifact(scene, "runs", name).name == st.artifact.file


def test_the_reports_plan_and_what_it_shows_are_read_from_the_registry(monkeypatch):
    """A stage added to the registry alone (a plan predicate, a line for the report) is in
    the report's plan and among the artifacts it shows, with its reason when not run: no
    tuple elsewhere to edit."""
    from dataclasses import replace

    from walkerlab.io.stage_files import BASIN
    from walkerlab.stages import pipeline, registry, report_inputs

    scene = load_scene(ROOT / "configs" / "paper.yaml")
    new = replace(registry.STAGES[BASIN.name], name="new-stage", phase="after",
                  not_run="no 'new' section", in_plan=lambda scene, full, plan:
                  plan["fixedpoint"] and not full)
    monkeypatch.setitem(registry.STAGES, "new-stage", new)
    assert pipeline.report_plan(scene)[-1] == "new-stage"
    assert "new-stage" not in pipeline.report_plan(scene, full=True)
    assert "new-stage" in registry.shown()
    assert report_inputs.not_run(scene, "new-stage") == "no 'new' section"
    assert [s.name for s in registry.in_phase("after")][-1] == "new-stage"
