"""Rough edges and reliability, round four: messages and the front door (one line naming
the field or file, and no more than a reader can use), the API making the CLI's checks,
figures and artifacts that say what they hold."""

from pathlib import Path

import pytest
import yaml
from typer.testing import CliRunner

from walkerlab.cli import app
from walkerlab.config import SceneError, load_scene, scene_from_dict

ROOT = Path(__file__).resolve().parents[1]
SIMPLEST = yaml.safe_load((ROOT / "configs" / "simplest.yaml").read_text())


def _cli(*args):
    r = CliRunner().invoke(app, [str(a) for a in args])
    return r.exit_code, r.stderr.strip(), r.stdout


# ------------------------------------------------------- 1: thousands of unknown keys
def test_thousands_of_unknown_keys_give_a_capped_list_and_few_suggestions(monkeypatch):
    import difflib

    from walkerlab.config import errors

    calls = []
    real = difflib.get_close_matches
    monkeypatch.setattr(difflib, "get_close_matches",
                        lambda *a, **k: calls.append(a[0]) or real(*a, **k))
    data = dict(SIMPLEST, **{f"zzunknown{i}": 1 for i in range(3000)})
    with pytest.raises(SceneError) as exc:
        scene_from_dict(data, "s.yaml")
    lines = str(exc.value).splitlines()
    assert len(lines) == errors.MAX_ERROR_LINES
    assert lines[0] == "s.yaml: zzunknown0: unknown field"
    assert lines[-1] == f"s.yaml: … and {3000 - errors.MAX_ERROR_LINES + 1} more errors"
    # a suggestion only for the lines printed: the work does not grow with the keys
    assert len(calls) <= errors.MAX_ERROR_LINES


def test_a_few_unknown_keys_are_all_listed_with_their_suggestion():
    data = dict(SIMPLEST, slop=SIMPLEST["slope"], zzz=1)
    del data["slope"]
    lines = str(pytest.raises(SceneError, scene_from_dict, data, "s.yaml").value).splitlines()
    assert lines == ["s.yaml: slop: unknown field (did you mean slope?)",
                     "s.yaml: zzz: unknown field"]


# ------------------------------------------------------------- 2: a NUL byte in a scene
def test_a_nul_byte_in_a_scene_is_one_line_naming_the_file_and_line(tmp_path):
    f = tmp_path / "nul.yaml"
    f.write_bytes((ROOT / "configs" / "simplest.yaml").read_bytes() + b"\nextra: 1\x00\n")
    code, err, _ = _cli("fixedpoint", f, "--runs-dir", tmp_path / "runs")
    assert code == 1
    lines = err.splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith(f"error: {f}: line ") and "0x00" in lines[0]
    with pytest.raises(SceneError, match=r"nul.yaml: line \d+: character 0x00 "):
        load_scene(f)


# ------------------------------------------------------- 3: --param of a continuation
def _one_line(*args) -> str:
    code, err, _ = _cli(*args)
    assert code == 1, (code, err)
    assert len(err.splitlines()) == 1, err
    return err


@pytest.mark.filterwarnings("error")
def test_a_continuation_to_infinity_is_one_line_and_no_numpy_warning(tmp_path):
    err = _one_line("continuation", ROOT / "configs" / "paper.yaml", "--param",
                    "slope.angle_deg=1:inf", "--runs-dir", tmp_path)
    assert err == "error: --param slope.angle_deg: stop inf is not a finite number"


@pytest.mark.parametrize("param2", ["slope.angle_deg=1:2", "slope.angle_rad=0.01:0.02"])
def test_param2_the_same_field_as_param_is_refused(tmp_path, param2):
    err = _one_line("continuation", ROOT / "configs" / "paper.yaml", "--param",
                    "slope.angle_deg=1:2", "--param2", param2, "--runs-dir", tmp_path)
    assert "the same field as --param slope.angle_deg" in err


def test_an_index_past_an_unnamed_list_says_its_indices(tmp_path):
    err = _one_line("continuation", ROOT / "configs" / "asymmetric_legs.yaml", "--param",
                    "walker.legs.5.length_m=0.9:1", "--runs-dir", tmp_path)
    assert err.endswith("index 5 is out of range (the list has 2 items, indices 0-1)")
    assert "None" not in err


def test_a_continuation_over_a_whole_number_field_is_refused_as_typed(tmp_path):
    err = _one_line("continuation", ROOT / "configs" / "paper.yaml", "--param",
                    "simulate.strides=1:2", "--runs-dir", tmp_path)
    assert err.startswith("error: --param simulate.strides: the field takes whole numbers")
    assert "<sweep>" not in err and "2.0" not in err


def test_a_fall_is_named_once():
    from types import SimpleNamespace

    from walkerlab.analysis.continuation.gait_map import _cause

    walker = SimpleNamespace(phases=[])
    seg = SimpleNamespace(termination="event", event="fall", phase_times={})
    assert _cause(walker, seg) == "fall"
    seg.event = "stance_heel_touches_down"
    assert _cause(walker, seg) == "fall (stance_heel_touches_down)"


def test_an_initial_guess_from_a_fifo_is_not_a_regular_file(tmp_path):
    import os

    fifo = tmp_path / "branch.h5"
    os.mkfifo(fifo)
    data = yaml.safe_load((ROOT / "configs" / "simplest.yaml").read_text())
    data["fixedpoint"]["initial_guess"] = {"from": str(fifo), "at": 0.5}
    scene = tmp_path / "s.yaml"
    scene.write_text(yaml.safe_dump(data))
    err = _one_line("fixedpoint", scene, "--runs-dir", tmp_path / "runs")
    assert err.endswith(f"{fifo}: not a regular file; give an HDF5 artifact")


# ------------------------------------------- 4: the API makes the command line's checks
def test_mfpt_is_on_the_package_face():
    import walkerlab as wl

    assert "mfpt" in wl.__all__ and wl.mfpt is wl.api.mfpt


PAPER = ROOT / "configs" / "paper.yaml"


@pytest.mark.parametrize("call, says", [
    (lambda wl, r: wl.api.mfpt(ROOT / "configs" / "simplest.yaml", sigma_rad="0.004",
                               runs_dir=r), "--sigma-rad '0.004': give a sequence"),
    (lambda wl, r: wl.api.mfpt(ROOT / "configs" / "simplest.yaml", sigma_rad=0.004,
                               runs_dir=r), "--sigma-rad 0.004: give a sequence"),
    (lambda wl, r: wl.basin(ROOT / "configs" / "simplest.yaml", grid="10x10", runs_dir=r),
     "--grid '10x10': give a sequence"),
    (lambda wl, r: wl.continuation(PAPER, "slope.angle_deg", 1, 2,
                                   param2="walker.hip_mass_kg", runs_dir=r),
     "--param2 walker.hip_mass_kg: no range"),
    (lambda wl, r: wl.continuation(PAPER, "slope.angle_deg", 1, 2, param2="walker.hip_mass_kg",
                                   range2=(1.0,), runs_dir=r), "range2 must be two numbers"),
    (lambda wl, r: wl.continuation(PAPER, "slope.angle_deg", 1, 2, param2="walker.hip_mass_kg",
                                   range2="ab", runs_dir=r), "range2 must be two numbers"),
    (lambda wl, r: wl.continuation(PAPER, "slope.angle_deg", 1, 2, range2=(1, 2),
                                   runs_dir=r), "range2 given without param2"),
    (lambda wl, r: wl.continuation(PAPER, "slope.angle_deg", 1, 1, runs_dir=r),
     "start and stop are both 1"),
    (lambda wl, r: wl.continuation(PAPER, None, 1, 2, runs_dir=r),
     "--param: give a dotted numeric scene field"),
    (lambda wl, r: wl.continuation(PAPER, "slope.angle_deg", 1, float("inf"), runs_dir=r),
     "stop inf is not a finite number"),
], ids=["mfpt-str", "mfpt-float", "basin-str", "no-range2", "range2-short", "range2-str",
        "range2-alone", "start-eq-stop", "param-none", "inf"])
def test_the_api_refuses_what_the_command_refuses_in_one_line(tmp_path, call, says):
    import walkerlab as wl

    with pytest.raises(SceneError) as exc:
        call(wl, tmp_path)
    assert says in str(exc.value) and "\n" not in str(exc.value)
    assert not list(tmp_path.rglob("*.h5"))  # refused before anything ran


# ------------------------------------------------ 5: an uphill no-gait message, whole
def test_an_uphill_no_gait_message_ends_its_clauses(tmp_path):
    d = yaml.safe_load(PAPER.read_text())
    d["slope"] = {"angle_rad": -0.0174}
    scene = tmp_path / "uphill.yaml"
    scene.write_text(yaml.safe_dump(d))
    err = _one_line("fixedpoint", scene, "--runs-dir", tmp_path / "runs")
    assert "downhill slope" in err and "try a continuation" in err
    # what was tried is printed whole: no sentence or parenthesis left open
    assert "scale-free seeds (45 fell within the first step)" in err
    assert "[tried the initial guess and 0 of 45" in err


def test_a_long_detail_is_cut_between_clauses():
    from walkerlab.cli.errors import one_line

    advice = "no gait; " + "advice " * 38
    detail = "[tried a and b (3 fell within the first step); last: " + "word " * 40 + "]"
    line = one_line(advice + detail)
    assert line.startswith(advice + "[tried a and b (3 fell within the first step) ... rerun")


# --------------------------------------- 6: a knee at the walker's level, not the leg's
@pytest.mark.parametrize("scene, meant", [("asymmetric_legs.yaml", "legs.N.knee"),
                                          ("paper_rods.yaml", "leg.knee")])
def test_a_knee_given_to_the_walker_points_to_the_leg(scene, meant):
    d = yaml.safe_load((ROOT / "configs" / scene).read_text())
    d["walker"]["knee"] = {"thigh_length_m": 0.5}
    lines = str(pytest.raises(SceneError, scene_from_dict, d, "s.yaml").value).splitlines()
    assert lines == [f"s.yaml: walker.knee: unknown field (did you mean {meant}?)"]


# ------------------------------------ 7: the zero multipliers of this walker, not all
@pytest.mark.parametrize("scene, names, says, not_said", [
    ("kneed.yaml", ["swing_thigh_angle", "swing_shank_angle", "stance_angle"],
     "swing knee is straight and locked", ("flat foot", "no mass")),
    ("flat_feet.yaml", ["swing_angle", "stance_angle", "stance_ankle_angle"],
     "flat foot lands", ("knee", "no mass")),
    ("simplest.yaml", ["stance_angle", "hip_angle"], "swing leg has no mass",
     ("knee", "flat foot")),
])
def test_the_verdict_names_only_the_zero_multipliers_that_apply(scene, names, says, not_said):
    import json

    import numpy as np

    from walkerlab.config import load_scene
    from walkerlab.report.text import zero_multipliers_text

    sc = load_scene(ROOT / "configs" / scene)
    n0 = 1 + (1 if scene == "simplest.yaml" else 2)
    re = np.r_[np.zeros(n0), 0.5, 0.4]
    text = zero_multipliers_text(re, np.zeros_like(re), names,
                                 json.dumps(sc.model_dump(mode="json")))
    assert text.startswith(f"{n0} multipliers are 0 by construction")
    assert says in text and not any(w in text for w in not_said)
    assert "e.g." not in text


# ------------------------------------------------------------------- 8: README drift
def test_the_readme_names_every_api_function_and_the_basin_file_a_grid_writes():
    import walkerlab as wl
    from walkerlab.stages.basin import stem

    guide = ROOT / "docs" / "user_guide"  # the README's tables and API section live there
    text = " ".join((guide / "python_api.md").read_text().split())
    api = text[text.index("# Python API"):text.index("examples/walkerlab_tour.ipynb")]
    for name in wl.api.__all__:
        if name != "DEFAULT_RUNS":
            assert f"`{name}`" in api, name
    sc = load_scene(ROOT / "configs" / "paper.yaml")
    assert stem(sc, (40, 40)) == "basin_40x40" and stem(sc, None) == "basin"
    row = next(ln for ln in (guide / "commands.md").read_text().splitlines()
               if ln.startswith("| `walkerlab basin"))
    assert "`basin_<NX>x<NY>.h5`" in row and "`basin_40x40.h5`" in row


# ------------------------------------------------------------------- 9: figure nits
def test_fig9_caption_does_not_promise_a_panel_per_link_of_a_straight_leg():
    from walkerlab.report.figures_section import CAPTIONS

    cap = dict(CAPTIONS)["fig9_limit_cycles"]
    assert "one panel per link" not in cap and "both legs in each panel" in cap


def test_mfpt_log_axis_ticks_are_plain_numbers():
    import matplotlib

    matplotlib.use("Agg")
    import numpy as np

    from walkerlab.plotting.mfpt_figures import mfpt_figure

    class D(dict):
        sigma_rad = np.array([0.002, 0.003, 0.004])

    d = D(mfpt_steps_montecarlo=np.array([5.5, 4.2, 3.1]),
          mfpt_steps_montecarlo_stderr=np.array([0.2, 0.2, 0.1]),
          mfpt_steps_mesh=np.array([5.4, 4.1, 3.2]), mesh_converged=np.ones(3))
    fig = mfpt_figure(d)
    fig.canvas.draw()
    ax = fig.axes[0]
    labels = [t.get_text() for t in ax.get_yticklabels(minor=True) + ax.get_yticklabels()]
    shown = [s for s in labels if s]
    assert shown and not any("10^" in s or "times" in s or "×" in s for s in shown), shown
    assert {"3", "4", "5"} <= set(shown)


def test_table_2_comes_before_table_3_and_headings_are_capitalised(tmp_path, monkeypatch):
    from types import SimpleNamespace

    import numpy as np

    from walkerlab.report import build, contact_sections, sections

    monkeypatch.setattr(contact_sections, "initial_states_section",
                        lambda scene, arts: ["## Table 2 — initial states", ""])
    monkeypatch.setattr(sections, "gait_section",
                        lambda scene, inputs, pub: ["## Table 3 — gait characteristics", ""])
    scene = load_scene(PAPER)
    build.write_report(scene, build.ReportInputs({}), tmp_path, tmp_path)
    md = (tmp_path / "report.md").read_text()
    assert md.index("## Table 2") < md.index("## Table 3")
    c = SimpleNamespace(initial_rate_scale=np.array([1.0, 1.0]), rate_names=["leg1", "leg2"],
                        adjust=None, samples=SimpleNamespace(coordinates={"leg1_angle": [0.2]}))
    lines = contact_sections._initial_state_lines(c, {}, None, {})
    assert lines[0] == "## Initial states (ideal vs contact model)"


def test_limit_cycle_distance_column_has_a_unit():
    from types import SimpleNamespace

    import numpy as np

    from walkerlab.report.build import ReportInputs
    from walkerlab.report.contact_sections import compare_section

    c = SimpleNamespace(errors={"leg1_angle": np.array([0.01]), "leg1_rate": np.array([0.1])},
                        limit_cycle_distance={"leg1": 0.02}, time=np.array([0.0, 1.0]),
                        metrics={})
    scene = load_scene(PAPER).model_copy(update={"published": None})
    text = "\n".join(compare_section(scene, ReportInputs({"compare": c})))
    assert "mean limit-cycle distance [rad, rad/s: in the (angle, rate) plane]" in text


def test_the_notebook_basin_panel_names_its_axes_and_colours():
    import json

    nb = json.loads((ROOT / "examples" / "walkerlab_tour.ipynb").read_text())
    cell = next("".join(c["source"]) for c in nb["cells"]
                if "basin.outcome.plot" in "".join(c["source"]))
    assert "ax[2].set_xlabel(" in cell and "ax[2].set_ylabel(" in cell  # not "cell centres"
    assert "OUTCOME_COLORS" in cell and "ax[2].legend(" in cell  # each colour named


# --------------------------------- 10: a continuation figure's stability is max|λ| < 1
def _branch_data(mmax, special=None):
    from types import SimpleNamespace

    import numpy as np

    p = np.arange(len(mmax), dtype=float)
    mult = np.c_[np.asarray(mmax, float), 0.1 * np.ones(len(mmax))].astype(complex)
    b = {"period": 1, "param": p, "states": {"stance_angle": 0.2 + 0.01 * p},
         "multipliers": mult, "stable": np.asarray(mmax) < 1}
    return SimpleNamespace(branches=[b], special=special or {}, state_names=["stance_angle"],
                           unit="deg", path="slope.angle_deg", start=0.0)


def test_a_branch_is_drawn_stable_only_where_its_largest_multiplier_is_below_one():
    import numpy as np

    from walkerlab.plotting.continuation_figures import continuation_figure, stability_pieces

    mmax = np.array([0.8, 0.9, 1.2, 1.1, 0.95])
    pieces = stability_pieces(np.arange(5.0), np.zeros((5, 1)), mmax)
    assert [st for *_x, st in pieces] == [True, False, True]
    assert pieces[0][0][-1] == pytest.approx(1 + 0.1 / 0.3)  # |λ| = 1, linearly between
    assert pieces[1][0][0] == pieces[0][0][-1] and pieces[1][2][0] == 1.0
    fig = continuation_figure(_branch_data(mmax))
    ax2 = fig.axes[1]
    for line in ax2.get_lines():
        y = np.asarray(line.get_ydata(), float)
        if line.get_linestyle() == "-" and y.size > 1:
            assert np.all(y <= 1.0 + 1e-12), y  # solid: stable
        if line.get_linestyle() == "--":
            assert np.all(y >= 1.0 - 1e-12), y


def test_special_point_labels_stay_inside_the_axes_clear_of_their_markers():
    import numpy as np

    from walkerlab.plotting.continuation_figures import continuation_figure

    # the third label of a point at the top: stacked highest, where it left the axes
    sp = {"kind": np.array(["period_doubling", "fold", "branch_end"]),
          "param": np.array([1.0, 2.0, 4.0]), "period": np.array([1, 1, 1]),
          "states": {"stance_angle": np.array([0.21, 0.22, 0.24])}}
    fig = continuation_figure(_branch_data([0.8, 0.9, 1.2, 1.1, 1.3], sp))
    fig.canvas.draw()
    ax = fig.axes[0]
    box = ax.get_window_extent()
    from matplotlib.text import Text

    for t in ax.texts:
        bb = Text.get_window_extent(t)  # the label itself, without its leader line
        assert box.y0 - 1 <= bb.y0 and bb.y1 <= box.y1 + 1, t.get_text()  # not clipped
        assert box.x0 - 1 <= bb.x0 and bb.x1 <= box.x1 + 1, t.get_text()
        x, y = ax.transData.transform((float(t.xy[0]), float(t.xy[1])))
        assert not (bb.x0 - 4 <= x <= bb.x1 + 4 and bb.y0 - 4 <= y <= bb.y1 + 4), t.get_text()


# ------------------------------ 11: a two-parameter run keeps the one-parameter artifact
def test_a_two_parameter_continuation_has_its_own_artifact_name():
    from walkerlab.io.runpaths import continuation_stem

    one = continuation_stem("walker.leg.bodies.rod.mass_kg")
    two = continuation_stem("walker.leg.bodies.rod.mass_kg", "walker.hip_mass_kg")
    assert one == "continuation_walker.leg.bodies.rod.mass_kg"
    assert two == "continuation_walker.leg.bodies.rod.mass_kg+walker.hip_mass_kg"


@pytest.mark.slow
def test_switch_and_param2_runs_are_both_kept(tmp_path):
    from walkerlab.io.schemas.continuation import load_continuation

    scene, runs = ROOT / "configs" / "simplest.yaml", tmp_path / "runs"
    base = ["continuation", scene, "--param", "slope.angle_rad=0.0085:0.0095", "--runs-dir",
            runs]
    code, err, out = _cli(*base, "--switch")
    assert code == 0, err
    code, err, out2 = _cli(*base, "--param2", "walker.leg.length_m=0.95:1.05")
    assert code == 0, err
    d = runs / "simplest"
    one = load_continuation(d / "continuation_slope.angle_rad.h5")
    two = load_continuation(d / "continuation_slope.angle_rad+walker.leg.length_m.h5")
    assert not one.curves and {b["period"] for b in one.branches} >= {1}
    assert len(one.branches) >= len(two.branches)
    figs = d / "report" / "figures"
    assert (figs / "continuation_slope.angle_rad.png").is_file()
    assert (figs / "continuation_slope.angle_rad+walker.leg.length_m.png").is_file()
    assert "continuation_slope.angle_rad+walker.leg.length_m.h5" in out2


# ------------------------------------------- 12: demanding a stable gait (--require-stable)
def test_require_stable_refuses_an_unstable_gait_in_one_line_and_keeps_the_artifact(tmp_path):
    d = yaml.safe_load(PAPER.read_text())
    d["slope"] = {"angle_deg": 12.0}
    scene = tmp_path / "steep.yaml"
    scene.write_text(yaml.safe_dump(d))
    runs = tmp_path / "runs"
    code, err, out = _cli("fixedpoint", scene, "--runs-dir", runs)
    assert code == 0 and "verdict: UNSTABLE" in out  # as before: the gait found, exit 0
    code, err, out = _cli("fixedpoint", scene, "--runs-dir", runs, "--require-stable")
    assert code == 1 and "verdict: UNSTABLE" in out
    assert len(err.splitlines()) == 1, err
    assert err.startswith("error: --require-stable: the gait found is unstable (largest "
                          "|Floquet multiplier| ")
    assert "no stable period-1 gait was found" in err
    assert (runs / "steep" / "fixedpoint.h5").is_file()
    code, err, _ = _cli("fixedpoint", PAPER, "--runs-dir", runs, "--require-stable")
    assert code == 0, err


def test_require_stable_names_a_stable_gait_the_policy_passed_over():
    from types import SimpleNamespace

    import numpy as np

    from walkerlab.report.text import unstable_gait_line

    fp = SimpleNamespace(multipliers=np.array([2.4, 0.1]), step_period_s=0.61,
                         units=SimpleNamespace(time="s"), gait_policy="short_period",
                         gaits={"long_period": SimpleNamespace(stable=True),
                                "short_period": SimpleNamespace(stable=False)})
    line = unstable_gait_line(fp)
    assert "the long-period gait is stable: set fixedpoint.gait: stable" in line


def test_a_field_given_one_section_too_high_points_to_its_section():
    d = dict(SIMPLEST, angle_deg=2.0)
    lines = str(pytest.raises(SceneError, scene_from_dict, d, "s.yaml").value).splitlines()
    assert lines == ["s.yaml: angle_deg: unknown field (did you mean slope.angle_deg?)"]
