"""Bifurcation (continuation) over any numeric scene field (issue 18 part 2).

``walkerlab bifurcation --param FIELD=start:stop:step`` continues the period-1 gait over a
field other than the slope - a body's mass by name - and writes ``bifurcation_<FIELD>.h5``
whose parameter coordinate is named by the field and carries its unit and path; the figure
and the report name the axis by the field and unit.  ``--slopes`` keeps its artifact.
"""

from __future__ import annotations

from pathlib import Path

import h5py
import numpy as np
import pytest
from typer.testing import CliRunner

from walkerlab.cli import app
from walkerlab.config import load_scene
from walkerlab.stages import bifurcation as bif_stage
from walkerlab.studies.params import SweepError, axis_unit, parse_param

ROOT = Path(__file__).resolve().parents[1]
SHANK = "walker.leg.bodies.shank_mass.mass_kg"


def test_bifurcation_over_a_body_mass_by_name(tmp_path):
    """The kneed walker's shank mass (the body by name), coarse grid: the artifact's
    coordinate is the field with unit kg, and the step period grows with the mass - more
    mass low on the swing leg (0.65 m from the hip, against the thigh mass at 0.3 m)
    lengthens its equivalent pendulum (sum m d^2 / sum m d), so it swings slower (the same
    direction as the sweep in tests/test_gaits.py)."""
    import xarray as xr

    from walkerlab.io.schemas.bifurcation import load_bifurcation
    from walkerlab.plotting.sweep_figures import bifurcation_figure, plt
    from walkerlab.report.study_sections import bifurcation_section
    from walkerlab.stages.report import load_inputs
    from walkerlab.stages.report_inputs import existing_artifacts

    scene = load_scene(ROOT / "configs" / "kneed.yaml")
    grid = parse_param(f"{SHANK}=0.03:0.07:0.02").values
    out = bif_stage.run(scene, grid, tmp_path, n_transient=6, n_keep=3, workers=1,
                        param=SHANK)
    assert out.path.name == f"bifurcation_{SHANK}.h5"
    assert not (out.path.parent / "bifurcation.h5").exists()
    with xr.open_dataset(out.path, engine="h5netcdf") as ds:
        c = ds[SHANK]
        assert c.attrs["units"] == "kg" and c.attrs["path"] == SHANK
        np.testing.assert_allclose(c.values, [0.03, 0.05, 0.07])
    with xr.open_dataset(out.path, engine="h5netcdf", group="fixed_point") as ds:
        assert ds["step_period"].dims == (SHANK,)
        period = ds["step_period"].values
        assert list(ds["outcome"].values) == ["ok"] * 3
    assert np.all(np.diff(period) > 1e-3), period
    data = load_bifurcation(out.path)
    assert data["parameter_unit"] == "kg" and data["parameter_path"] == SHANK
    assert list(data["steady_state/outcome"]) == ["walks"] * 3
    # the kneed walker's gait is stable here (Hsu Chen 2007): no period doubling on the grid
    assert np.isnan(out.summary["onset"]) and out.summary["unit"] == "kg"
    fig = bifurcation_figure(data)
    assert fig.axes[1].get_xlabel() == f"{SHANK} [kg]"
    plt.close(fig)
    assert (tmp_path / "kneed" / "report" / "figures" / f"bifurcation_{SHANK}.png").is_file()
    # the report finds the artifact and names the grid by field and unit
    inputs = load_inputs(scene, existing_artifacts(scene, tmp_path), tmp_path)
    text = "\n".join(bifurcation_section(inputs.artifacts, inputs.bifurcation_onsets))
    assert f"## Bifurcation over `{SHANK}`" in text and "0.03–0.07 kg (3 values" in text
    # a rerun with the same grid reuses the artifact
    assert bif_stage.run(scene, grid, tmp_path, n_transient=6, n_keep=3, workers=1,
                         param=SHANK).reused


@pytest.mark.parametrize("args, words", [
    (["--param", "walker.leg.bodies.shank_mas.mass_kg=0.03:0.07:0.02"],
     ["did you mean 'shank_mass'"]),
    (["--param", "walker.leg.bodies.shank_mass.mass=0.03,0.05"],
     ["did you mean walker.leg.bodies.shank_mass.mass_kg"]),
    (["--param", "walker.leg.bodies.shank_mass.mass_kg=-1,0.05"],
     ["value -1.0 is not valid", "greater than or equal to 0"]),
    (["--param", "solver.method=RK45,DOP853"], ["a bifurcation needs numbers"]),
    (["--slopes", "1:2:0.5", "--param", f"{SHANK}=0.03,0.05"], ["exclude each other"]),
])
def test_unknown_or_bad_fields_are_refused(tmp_path, args, words):
    """One line, rc 1, before anything runs (no artifact written)."""
    r = CliRunner().invoke(app, ["bifurcation", str(ROOT / "configs" / "kneed.yaml"), *args,
                                 "--runs-dir", str(tmp_path)])
    assert r.exit_code == 1, r.output
    assert len(r.output.strip().splitlines()) == 1, r.output
    assert all(w in r.output for w in words), r.output
    assert not list(tmp_path.rglob("*.h5"))


def test_the_stage_refuses_an_unknown_field_too(tmp_path):
    scene = load_scene(ROOT / "configs" / "paper.yaml")
    with pytest.raises(SweepError, match="did you mean walker.hip_mass_kg"):
        bif_stage.run(scene, [9.0, 10.0], tmp_path, workers=1, param="walker.hip_mas_kg")
    assert not list(tmp_path.rglob("*.h5"))


def test_slope_path_keeps_its_artifact(tmp_path):
    """``--slopes`` (and the stage's default): ``bifurcation.h5``, coordinate ``slope`` [deg]
    (now also with its ``path``), onset in ``onset/onset_slope``, ``onset_deg`` in the
    summary - as before the ``--param`` option."""
    scene = load_scene(ROOT / "configs" / "paper.yaml")
    out = bif_stage.run(scene, [2.0, 2.5], tmp_path, workers=1, steady_state=False)
    assert out.path.name == "bifurcation.h5"
    assert "onset_deg" in out.summary and np.isnan(out.summary["onset_deg"])
    with h5py.File(out.path) as f:
        assert f["slope"].attrs["unit"] == "deg" and f["slope"].attrs["path"] == "slope.angle_deg"
        assert "onset/onset_slope" in f and "onset/onset_value" not in f
    import xarray as xr

    with xr.open_dataset(out.path, engine="h5netcdf", group="floquet") as ds:
        assert ds["real"].dims == ("slope", "multiplier")
    assert (tmp_path / "paper" / "report" / "figures" / "bifurcation.png").is_file()


def test_field_units_from_metadata_or_name():
    kneed = load_scene(ROOT / "configs" / "kneed.yaml")
    paper = load_scene(ROOT / "configs" / "paper.yaml")

    def unit(scene, path):
        return axis_unit(scene, parse_param(f"{path}=1"))

    assert unit(kneed, SHANK) == "kg"
    assert unit(kneed, "walker.leg.bodies.1.from_hip_m") == "m"
    assert unit(paper, "walker.hip_mass_kg") == "kg"
    assert unit(paper, "slope.angle_rad") == "rad"
    assert unit(paper, "walker.gravity_m_per_s2") == "m/s^2"
    assert unit(paper, "contact.stiffness_n_per_mm_pow_e") == "N/mm^e"  # the name says it
    assert unit(paper, "contact.stiffness_n_per_m_pow_e") == "N/m^e"
    assert unit(paper, "contact.stiction_velocity_mm_per_s") == "mm/s"
    assert unit(paper, "contact.mu_static") == "-"



def test_a_3d_bifurcation_over_hip_width_is_on_one_stride_map(tmp_path):
    """Issue 82 item 1, the bifurcation diagram's side: over a 3D walker's hip width from 0
    (its own map a step) to 0.1 m (a stride) every value is on the study's one map, a
    stride (126.1 at zero width: the step's 11.2303 squared, configs/paper_3d.yaml; 99.93
    at 0.1 m), the artifact records it and the figure's multiplier axis says "per
    stride"."""
    from walkerlab.io.schemas.bifurcation import load_bifurcation
    from walkerlab.plotting.sweep_figures import bifurcation_figure

    scene = load_scene(ROOT / "configs" / "hip_width.yaml")
    out = bif_stage.run(scene, [0.0, 0.1], tmp_path, n_transient=4, n_keep=2, workers=1,
                        param="walker.hip_width_m")
    data = load_bifurcation(out.path)
    assert data["steps_per_map"] == 2
    big = np.max(np.abs(data["floquet/real"] + 1j * data["floquet/imag"]), axis=1)
    assert big[0] == pytest.approx(11.2303 ** 2, rel=1e-5)
    assert big[1] == pytest.approx(99.9294, rel=1e-5)
    # the step period stays a step's (the stride's halved)
    assert data["fixed_point/step_period"][0] == pytest.approx(0.7035969, rel=1e-6)
    fig = bifurcation_figure(data)
    assert any("per stride" in ax.get_ylabel() for ax in fig.axes)
