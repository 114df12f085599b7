"""The daily loop without friction (issue 26, rough edges 1-7, 13): what a researcher types
every day says what happened, in the scene's units, and keeps the work already done."""

from pathlib import Path

import h5py
import pytest
import yaml
from typer.testing import CliRunner

from walkerlab.cli import app
from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]
PAPER = yaml.safe_load((ROOT / "configs" / "paper.yaml").read_text())
#: the paper's walker and slope only: every other section left out
BARE = {"walker": PAPER["walker"], "slope": PAPER["slope"], "solver": PAPER["solver"]}


def _cli(*args):
    r = CliRunner().invoke(app, [str(a) for a in args])
    return r.exit_code, r.stderr.strip(), r.stdout


def _scene(tmp_path, data, name="scene") -> Path:
    p = tmp_path / f"{name}.yaml"
    p.write_text(yaml.safe_dump(data))
    return p


# --------------------------------------------------------------- 1: optional sections
def test_fixedpoint_without_a_fixedpoint_section_runs_on_defaults(tmp_path):
    """Every field of ``fixedpoint:`` is optional: leaving the section out is ``{}``, and
    finds the paper's gait (step period 0.7036 s, paper Sec. 3.3)."""
    rc, err, out = _cli("fixedpoint", _scene(tmp_path, BARE), "--runs-dir", tmp_path / "runs")
    assert rc == 0, err
    with h5py.File(tmp_path / "runs" / "scene" / "fixedpoint.h5") as f:
        assert f["step_period"][()] == pytest.approx(0.7036, abs=5e-5)


def test_api_fixed_point_of_a_mapping_without_the_section(tmp_path):
    wl = pytest.importorskip("walkerlab")
    pytest.importorskip("xarray")
    pytest.importorskip("h5netcdf")
    gait = wl.fixed_point(dict(BARE), runs_dir=tmp_path / "runs")
    assert float(gait.step_period) == pytest.approx(0.7036, abs=5e-5)


def test_a_scene_without_contact_sets_up_the_papers_contact_law():
    """Every field of ``contact:`` has a default: leaving the section out is ``contact: {}``,
    and both are the paper's contact law (Sec. 4, as configs/paper.yaml writes it out: k
    1e5 N/mm^2.2, 90 N s/mm at 0.1 mm, mu 0.9 / 0.7) with the ADAMS View defaults for the
    stiction and friction velocities the paper does not print (100 and 1000 mm/s;
    configs/paper.yaml sets 10 and 100 mm/s against the stance foot's creep), to the bit."""
    from walkerlab.config import scene_from_dict
    from walkerlab.models.contact.scene import contact_setup

    sc = scene_from_dict(BARE | {"name": "bare"})
    bare = contact_setup(sc, plant=Plant.from_scene(sc))
    sc1 = scene_from_dict(BARE | {"name": "empty", "contact": {}})
    empty = contact_setup(sc1, plant=Plant.from_scene(sc1))
    sc2 = scene_from_dict(BARE | {"name": "paper",
                                                  "contact": PAPER["contact"] | {
                                                      "stiction_velocity_mm_per_s": 100.0,
                                                      "friction_velocity_mm_per_s": 1000.0}})
    paper = contact_setup(sc2, plant=Plant.from_scene(sc2))
    assert bare.law == empty.law == paper.law
    assert bare.law_si == paper.law_si and bare.knee_stop == paper.knee_stop
    assert bare.solver == paper.solver  # contact_solver left out: the contact default


def test_the_report_runs_no_contact_sim_for_a_scene_without_contact():
    """The report produces what a scene's sections ask for: ``contact_sim`` alone (a section
    that configures the run) opts it into no contact run; ``contact: {}`` does."""
    from walkerlab.config import scene_from_dict
    from walkerlab.stages.pipeline import report_plan

    d = BARE | {"name": "s", "fixedpoint": {}, "contact_sim": {"n_strides": 1}}
    assert "contact-sim" not in report_plan(scene_from_dict(d))
    assert "contact-sim" in report_plan(scene_from_dict(d | {"contact": {}}))


@pytest.mark.slow  # a whole contact-sim command (a stride): about 5 s CPU
def test_contact_sim_without_a_contact_section_runs_on_the_defaults(tmp_path):
    """``walkerlab contact-sim`` of a scene without ``contact`` walks (the paper's contact
    law), and its artifact is the one of ``contact: {}``: the same key, so the run with the
    section written out empty reuses it."""
    runs = tmp_path / "runs"
    rc, err, out = _cli("contact-sim", _scene(tmp_path, BARE), "--strides", "1",
                        "--runs-dir", runs)
    assert rc == 0, err
    with h5py.File(runs / "scene" / "contact_sim.h5") as f:
        assert bool(f.attrs["walks"]) and int(f["summary/heel_strikes"][()]) >= 2
        written = yaml.safe_load(f.attrs["scene_json"])["contact"]  # the law it ran on
    # the paper's law with the ADAMS View defaults where configs/paper.yaml departs from
    # them (its 10 / 100 mm/s stiction and friction velocities)
    defaults = PAPER["contact"] | {"stiction_velocity_mm_per_s": 100.0,
                                   "friction_velocity_mm_per_s": 1000.0}
    assert all(written[k] == v for k, v in defaults.items())
    rc, err, out = _cli("contact-sim", _scene(tmp_path, BARE | {"contact": {}}), "--strides",
                        "1", "--runs-dir", runs)
    assert rc == 0, err
    assert "reused" in out and "(inputs unchanged)" in out


# --------------------------------------------------------------- 2: no-gait advice whole
def test_no_gait_error_keeps_its_advice_whole(tmp_path):
    """An uphill slope has no passive gait: the error's first line ends the advice with what
    to give (fixedpoint.initial_guess); the solver's detail, whole, takes a second."""
    d = {**BARE, "slope": {"angle_deg": -1.0}, "fixedpoint": {}}
    rc, err, _ = _cli("fixedpoint", _scene(tmp_path, d), "--runs-dir", tmp_path / "runs")
    lines = err.splitlines()
    assert rc == 1 and len(lines) == 2 and lines[1].startswith("  [tried "), err
    assert "give fixedpoint.initial_guess" in lines[0]
    assert "downhill slope" in err and "give fixedpoint.initial_guess" in err
    assert "try a continuation from a walker whose gait is known" in err
    assert "more characters" not in err.split("give fixedpoint.initial_guess")[0]


# --------------------------------------------------------------- 4: units everywhere
def test_fixedpoint_printout_of_a_nondimensional_scene_has_no_seconds(tmp_path):
    """The simplest walker (Garcia et al. 1998) is nondimensional: every period printed,
    the gait list's included, is in √(l/g)."""
    rc, err, out = _cli("fixedpoint", ROOT / "configs" / "simplest.yaml",
                        "--runs-dir", tmp_path / "runs")
    assert rc == 0, err
    periods = [ln for ln in out.splitlines() if "step period" in ln]
    assert len(periods) == 3  # the fixed point's and the two gaits'
    assert all("√(l/g)" in ln and " s," not in ln and not ln.endswith(" s")
               for ln in periods), periods


@pytest.mark.parametrize("fmt, name", [("urdf", "walker.urdf"), ("mjcf", "walker.xml")])
def test_export_header_of_a_nondimensional_scene_names_its_units(tmp_path, fmt, name):
    rc, err, _ = _cli("export", ROOT / "configs" / "round_feet.yaml", "--format", fmt,
                      "--runs-dir", tmp_path / "runs")
    assert rc == 0, err
    comments = [ln for ln in (tmp_path / "runs" / "round_feet" / name).read_text().splitlines()
                if ln.startswith("<!--")]
    text = " ".join(comments)
    assert "m/s^2" not in text and "[m]" not in text and " m;" not in text
    assert "[l]" in text and "L = 1.2 l;" in text and "the hip's position" in text


# --------------------------------------------------------------- 5: a fall is not a success
def test_simulate_of_a_falling_scene_says_when_it_fell(tmp_path):
    """At 12° the paper's walker has only unstable gaits (largest |multiplier| ≈ 8): from
    its fixed point it falls within 20 strides.  No mean-step summary, one error line,
    exit code 1, the run kept in simulate.h5."""
    d = {**BARE, "slope": {"angle_deg": 12.0}, "fixedpoint": {},
         "simulate": {"strides": 20, "sample_rate_hz": 100}}
    rc, err, out = _cli("simulate", _scene(tmp_path, d), "--runs-dir", tmp_path / "runs")
    assert rc == 1
    lines = err.splitlines()
    assert len([ln for ln in lines if ln.startswith("error:")]) == 1
    n = int(lines[-1].split("fell after ")[1].split()[0])
    assert 0 < n < 40
    assert lines[-1] == (f"error: the walker fell after {n} heel strikes "
                         f"({n / 2:g} strides of the 20 asked)")
    assert "mean step" not in out and "simulated" not in out
    assert (tmp_path / "runs" / "scene" / "simulate.h5").is_file()


# --------------------------------------------------------------- 6: a coarse basin map
@pytest.mark.slow
def test_basin_on_another_grid_keeps_the_scenes_own_map(tmp_path):
    """``basin --grid 3x3`` beside a scene whose basin.grid is 4x4: its own artifact and
    figure (basin_3x3), the report's basin.h5 untouched (same bytes)."""
    d = {**BARE, "fixedpoint": {**PAPER["fixedpoint"], "other_gait": False},
         "basin": {"grid": [4, 4], "max_steps": 3}}
    sc = _scene(tmp_path, d)
    runs = tmp_path / "runs"
    rc, err, _ = _cli("basin", sc, "--workers", 1, "--runs-dir", runs)
    assert rc == 0, err
    own = (runs / "scene" / "basin.h5").read_bytes()
    rc, err, out = _cli("basin", sc, "--grid", "3x3", "--workers", 1, "--runs-dir", runs)
    assert rc == 0, err
    assert (runs / "scene" / "basin.h5").read_bytes() == own
    with h5py.File(runs / "scene" / "basin_3x3.h5") as f:
        assert f["outcome"].shape == (3, 3)
    assert (runs / "scene" / "report" / "figures" / "basin_3x3.png").is_file()
    assert "basin_3x3.png" in out and "recomputing" not in err
    # the scene's own grid given explicitly is the scene's map, reused
    rc, err, out = _cli("basin", sc, "--grid", "4x4", "--workers", 1, "--runs-dir", runs)
    assert rc == 0 and "reused" in out and (runs / "scene" / "basin.h5").read_bytes() == own


# --------------------------------------------------------------- 7: what a sweep found
def test_sweep_prints_outcomes_and_result_ranges_and_draws_a_figure(tmp_path):
    """Slopes 0 (level ground: no passive gait) and 1-2° (the paper's gait, step period
    0.7036 s at 0.997°, rising with the slope)."""
    d = {**BARE, "fixedpoint": {**PAPER["fixedpoint"], "other_gait": False}}
    rc, err, out = _cli("sweep", _scene(tmp_path, d), "--param", "slope.angle_deg=0,1,2",
                        "--workers", 1, "--runs-dir", tmp_path / "runs")
    assert rc == 0, err
    lines = out.splitlines()
    assert lines[0] == "3 points: ok 2, no_fixed_point 1"
    rng = next(ln for ln in lines if ln.split()[0] == "step_period_s").split()
    lo, hi = float(rng[1]), float(rng[3])
    assert 0.70 < lo < hi < 0.73 and rng[4] == "s"
    fig = Path(lines[-1].removeprefix("figure: "))
    assert fig.is_file() and fig.suffix == ".png" and fig.with_suffix(".svg").is_file()
    art = Path(lines[-2].removeprefix("wrote "))
    assert fig.stem == art.stem


def test_the_swept_value_is_a_coordinate_of_the_points(tmp_path):
    xr = pytest.importorskip("xarray")
    pytest.importorskip("h5netcdf")
    from walkerlab.stages import sweep as stage

    d = {**BARE, "fixedpoint": {**PAPER["fixedpoint"], "other_gait": False}}
    path = stage.run(_scene(tmp_path, d), ["slope.angle_deg=1,2"], workers=1,
                     runs_root=tmp_path / "runs", progress=False, figure=False)
    with xr.open_dataset(path, engine="h5netcdf", group="points") as ds:
        assert "slope.angle_deg" in ds.coords
        assert ds["step_period_s"].coords["slope.angle_deg"].values.tolist() == [1.0, 2.0]
        assert ds["slope.angle_deg"].attrs["units"] == "deg"


# --------------------------------------------------------------- 13: the report shows them
def test_report_shows_a_bifurcation_over_another_field(tmp_path):
    """``bifurcation --param`` writes bifurcation_<field>.h5 beside the scene's artifacts;
    the scene's report shows it (as the README says), not 'an earlier standalone run'."""
    d = {**BARE, "fixedpoint": {**PAPER["fixedpoint"], "other_gait": False}}
    sc, runs = _scene(tmp_path, d), tmp_path / "runs"
    rc, err, _ = _cli("bifurcation", sc, "--param", "walker.hip_mass_kg=10,10.5",
                      "--transient", 4, "--keep", 2, "--workers", 1, "--runs-dir", runs)
    assert rc == 0, err
    assert (runs / "scene" / "bifurcation_walker.hip_mass_kg.h5").is_file()
    rc, err, out = _cli("report", sc, "--runs-dir", runs)
    assert rc == 0, err
    assert "leaves out" not in out + err
    md = (runs / "scene" / "report" / "report.md").read_text()
    assert "walker.hip_mass_kg" in md and "bifurcation_walker.hip_mass_kg" in md
