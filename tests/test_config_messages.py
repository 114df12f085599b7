"""What a scene error says (issue 26, rough edges 8-11, 14): one line per mistake, naming the
field, with the likely unit mistake, once; scenes varied in Python by the CLI's dotted paths;
the command line's options refused alike."""

import math
from pathlib import Path

import pytest
import yaml
from typer.testing import CliRunner

import walkerlab as wl
from walkerlab import config
from walkerlab.cli import app
from walkerlab.config import SceneError, load_scene, scene_from_dict

ROOT = Path(__file__).resolve().parents[1]
PAPER = yaml.safe_load((ROOT / "configs" / "paper.yaml").read_text())
WALKER = PAPER["walker"]


def _errors(data: dict) -> list[str]:
    with pytest.raises(SceneError) as exc:
        scene_from_dict(data, "s.yaml")
    return str(exc.value).splitlines()


def _cli(*args):
    r = CliRunner().invoke(app, [str(a) for a in args])
    return r.exit_code, r.stderr.strip(), r.stdout


# --------------------------------------------------------------- 8: varying a loaded scene
def test_with_changes_sets_a_field_by_its_dotted_path():
    sc = wl.load_scene(ROOT / "configs" / "paper.yaml")
    steeper = wl.with_changes(sc, {"slope.angle_deg": 2})
    assert steeper.slope.phi_rad == pytest.approx(math.radians(2), rel=1e-15)
    assert steeper.slope.angle_rad is None  # the other spelling is replaced
    assert sc.slope.angle_rad == 0.0174  # the loaded scene is unchanged
    assert steeper.origin == sc.origin and steeper.name == sc.name
    kneed = wl.load_scene(ROOT / "configs" / "kneed.yaml")
    name = kneed.walker.leg.bodies[0].name
    k2 = wl.with_changes(kneed, {f"walker.leg.bodies.{name}.mass_kg": 0.4})
    assert k2.walker.leg.bodies[0].mass_kg == 0.4


@pytest.mark.parametrize("changes, says", [
    ({"slope.angle_dgg": 2}, "unknown field slope.angle_dgg (did you mean slope.angle_deg?)"),
    ({"slope.angle_deg": 200}, "slope.angle_deg: Input should be less than 90"),
    ({"walker.hip_mass_kg": "heavy"}, "walker.hip_mass_kg: Input should be a valid number"),
])
def test_with_changes_refuses_in_one_line(changes, says):
    sc = wl.load_scene(ROOT / "configs" / "paper.yaml")
    with pytest.raises(SceneError) as exc:
        wl.with_changes(sc, changes)
    msg = str(exc.value)
    assert "\n" not in msg and msg.startswith("with_changes") and says in msg


def test_a_loaded_scene_is_immutable_and_a_copy_is_validated():
    sc = wl.load_scene(ROOT / "configs" / "paper.yaml")
    with pytest.raises(Exception, match="frozen"):
        sc.slope = {"angle_deg": 2}
    with pytest.raises(Exception, match="frozen"):
        sc.slope.angle_rad = 0.1
    copy = sc.model_copy(update={"slope": {"angle_deg": 2}})
    assert copy.slope.phi_rad == pytest.approx(math.radians(2), rel=1e-15)  # not a dict
    with pytest.raises(SceneError, match="slope: give exactly one"):
        sc.model_copy(update={"slope": {"angle_deg": 2, "angle_rad": 0.1}})


# --------------------------------------------------------------- 9: unit mistakes
def test_degrees_given_as_radians_are_named():
    (line,) = _errors({"walker": WALKER, "slope": {"angle_rad": 3.0}})
    assert line.endswith("slope.angle_rad: Input should be less than 1.5707963267948966 "
                         "(3 rad = 172°; did you mean angle_deg?)")


def test_no_unit_hint_for_a_stiffness_damping_or_torque():
    """``*_per_rad`` / ``*_per_m`` are rates per angle or length and ``*_n_m`` a torque:
    a bound error there carries no "an angle in degrees?" or "a length in mm?" hint."""
    hip = yaml.safe_load((ROOT / "configs" / "hip_spring.yaml").read_text())
    for leaf, v in (("stiffness_n_m_per_rad", -1e-9), ("damping_n_m_s_per_rad", -0.5)):
        spring = {**hip["walker"]["springs"][0], leaf: v}
        (line,) = _errors({**hip, "walker": {**hip["walker"], "springs": [spring]}})
        assert leaf in line and "degrees" not in line and "°" not in line, line
    (line,) = _errors({"walker": WALKER, "slope": {"angle_deg": 1},
                       "optimize": {"max_torque_n_m": 1e6}})
    assert "max_torque_n_m" in line and " mm" not in line, line


def test_millimetres_given_as_metres_are_named():
    (line,) = _errors({"walker": {**WALKER, "leg_length_m": 1000, "leg_mass_from_foot_m": 500},
                       "slope": {"angle_deg": 1}})
    assert "walker.leg_length_m:" in line and "1000 mm = 1 m" in line


def test_a_slope_below_a_tenth_of_a_degree_is_warned(tmp_path, capsys):
    """0.0174 is the paper's slope in radians; as degrees it validates, with a warning."""
    p = tmp_path / "tiny.yaml"
    p.write_text(yaml.safe_dump({"walker": WALKER, "slope": {"angle_deg": 0.0174}}))
    load_scene(p)
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "slope.angle_deg" in err[0] and "write angle_rad: 0.0174" in err[0]
    p.write_text(yaml.safe_dump({"walker": WALKER, "slope": {"angle_deg": 1.0}}))
    load_scene(p)
    assert capsys.readouterr().err == ""


def test_a_number_yaml_reads_as_text_says_how_to_write_it(tmp_path):
    p = tmp_path / "e4.yaml"
    p.write_text("walker: {model: compass_gait, leg_length_m: 1, leg_mass_kg: 1e4, "
                 "hip_mass_kg: 10, leg_mass_from_foot_m: 0.5}\nslope: {angle_deg: 1}\n")
    with pytest.raises(SceneError) as exc:
        load_scene(p)
    assert str(exc.value).endswith("(got '1e4'); YAML reads 1e4 as text: write 1.0e+4")
    assert yaml.safe_load("x: 1.0e+4")["x"] == 1e4  # the advice is what YAML reads


@pytest.mark.parametrize("form,plain", [("0x10", "16"), ("1_0.0", "10.0"), ("010", "8"),
                                        ("0b11", "3"), ("1:20", "80")])
def test_a_yaml_1_1_number_form_is_refused_naming_the_field(tmp_path, form, plain):
    """Issue 56 item 16: PyYAML reads YAML 1.1's hex, underscore, octal, binary and base-60
    forms as numbers (``hip_mass_kg: 0x10`` was a 16 kg hip); the field refuses them, in
    one line, with the number YAML 1.1 would have read."""
    p = tmp_path / "y11.yaml"
    p.write_text("walker: {model: compass_gait, leg_length_m: 1, leg_mass_kg: 5, "
                 f"hip_mass_kg: {form}, leg_mass_from_foot_m: 0.5}}\nslope: {{angle_deg: 1}}\n")
    with pytest.raises(SceneError) as exc:
        load_scene(p)
    msg = str(exc.value)
    assert "\n" not in msg and "walker.hip_mass_kg" in msg and f"(got '{form}')" in msg
    assert msg.endswith(f"YAML 1.1 reads {plain})")
    p.write_text(p.read_text().replace(f"hip_mass_kg: {form}", "hip_mass_kg: 10"))
    assert load_scene(p).walker.hip_mass_kg == 10  # a plain decimal is read


@pytest.mark.parametrize("quoted", ['"10.0"', "'10'", '"1.0e+1"'])
def test_a_quoted_number_is_told_to_lose_its_quotes_not_its_yaml_1_1_form(tmp_path, quoted):
    """Issue 64 item 5: a quoted plain number (``hip_mass_kg: "10.0"``) was told it is "a
    YAML 1.1 number form (hex, binary, octal, base 60, underscores)"."""
    p = tmp_path / "q.yaml"
    p.write_text("walker: {model: compass_gait, leg_length_m: 1, leg_mass_kg: 5, "
                 f"hip_mass_kg: {quoted}, leg_mass_from_foot_m: 0.5}}\nslope: {{angle_deg: 1}}\n")
    with pytest.raises(SceneError) as exc:
        load_scene(p)
    msg = str(exc.value)
    assert "\n" not in msg and "walker.hip_mass_kg" in msg and "YAML 1.1" not in msg
    assert msg.endswith("is written in quotes, which makes it text: write it without them")


def test_a_usage_error_is_spelled_error_as_every_other_error():
    """Issue 64 item 5: typer boxed a usage error under "Error" (click: ``Error: ...``)
    where every walkerlab error is ``error: ...``."""
    code, err, _ = _cli("fixedpoint", "--no-such-option")
    assert code == 2
    assert err.splitlines()[-1] == "error: No such option: --no-such-option"
    assert "Error" not in err


def test_a_vanishing_phase_scale_is_refused_naming_the_phase_not_the_outputs():
    """Issue 64 item 5: ``phase.coordinates: {stance: 1e-300}`` was blamed on the outputs
    ("the swing foot reaches the ground ... for no value of the phase variable")."""
    three = yaml.safe_load((ROOT / "configs" / "threelink_hzd.yaml").read_text())
    three["walker"]["actuation"]["virtual_constraints"]["phase"] = {
        "coordinates": {"stance": 1e-300}}
    (line,) = _errors(three)
    assert "walker.actuation.virtual_constraints.phase: coordinates:" in line
    assert "outputs" not in line and "1e-300" in line


# --------------------------------------------------------------- 10: said once
def test_messages_are_not_doubled():
    d = {"walker": {k: v for k, v in WALKER.items() if k != "leg_mass_from_foot_m"}
         | {"leg_mas_from_foot_m": 0.5}, "slope": {"angle_deg": 1, "angle_rad": 0.1}}
    lines = _errors(d)
    assert lines == [
        "s.yaml: walker.leg_mas_from_foot_m: unknown field (did you mean leg_mass_from_foot_m?)",
        "s.yaml: slope: give exactly one of angle_rad or angle_deg"]


def test_a_published_error_names_the_file_once():
    (line,) = _errors({"walker": WALKER, "slope": {"angle_deg": 1}, "published": "nope"})
    assert line.startswith("s.yaml: published: no module walkerlab.published.nope")


# --------------------------------------------------------------- 11: the command line
@pytest.mark.parametrize("n, says", [(0, "greater than or equal to 1"),
                                     (100000, "less than or equal to 1000")])
def test_strides_out_of_range_is_one_line_either_way(tmp_path, n, says):
    rc, err, _ = _cli("simulate", ROOT / "configs" / "paper.yaml", "--strides", n,
                      "--runs-dir", tmp_path)
    assert rc == 1 and err == f"error: --strides {n}: input should be {says} (simulate.strides)"


def test_a_bad_slopes_option_is_quoted_as_typed(tmp_path):
    rc, err, _ = _cli("bifurcation", ROOT / "configs" / "paper.yaml", "--slopes", "1:5",
                      "--runs-dir", tmp_path)
    assert rc == 1 and err == "error: --slopes '1:5': a range is START:STOP:STEP"


def test_help_lists_the_options_and_their_value_types():
    r = CliRunner().invoke(app, ["simulate", "--help"], env={"COLUMNS": "120"})
    assert r.exit_code == 0
    assert "--force" in r.stdout and "<int>" in r.stdout


def test_the_cli_uses_no_private_typer_names():
    """Before: the CLI replaced ``TyperOption.display_type_rich`` (typer's internals, to hide
    ``<bool>`` beside flags in ``--help``), and its import crashed on typer versions without
    it (0.27).  Now no method of typer's classes is the package's, and no source file of
    the package reads a private name (``._x``) of typer or click."""
    import re

    import typer.core

    for cls in (typer.core.TyperOption, typer.core.TyperArgument, typer.core.TyperCommand,
                typer.core.TyperGroup):
        for name, value in vars(cls).items():
            assert not getattr(value, "__module__", "").startswith("walkerlab"), (cls, name)
    private = re.compile(r"\b(typer|click|_click|core|rich_utils|Typer\w*)\._[a-z]")
    bad = [f"{f.relative_to(ROOT)}:{i}" for f in (ROOT / "walkerlab").rglob("*.py")
           for i, line in enumerate(f.read_text().splitlines(), 1) if private.search(line)]
    assert not bad, bad


def test_an_integer_field_over_a_range_of_whole_numbers(tmp_path):
    from walkerlab.studies.params import check_axes, parse_param

    axis = parse_param("simulate.strides=1:3:1")
    assert axis.values == (1, 2, 3) and all(type(v) is int for v in axis.values)
    check_axes(load_scene(ROOT / "configs" / "paper.yaml"), [axis])  # validates
    assert parse_param("slope.angle_deg=1:2:0.5").values == (1.0, 1.5, 2.0)
    rc, err, _ = _cli("bifurcation", ROOT / "configs" / "paper.yaml", "--param",
                      "simulate.strides=1,2", "--runs-dir", tmp_path)
    assert rc == 1 and "simulate.strides takes whole numbers" in err
    assert "got 1.0" not in err


# --------------------------------------------------------------- 14: the vocabulary's end
@pytest.mark.parametrize("walker", [
    {**WALKER, "torso": {"mass_kg": 1.0}},
    {**WALKER, "muscles": "hill_type"},
    {"model": "biped", "hip_mass_kg": 10, "leg": {
        "length_m": 1.0, "foot": {"kind": "wheel"},
        "bodies": [{"kind": "point_mass", "name": "m", "mass_kg": 5, "from_hip_m": 0.5}]}},
    {"model": "hexapod"},
])
def test_an_unknown_walker_part_says_what_a_walker_can_be(walker):
    vocabulary = getattr(config, "WALKER_VOCABULARY", "(none)")
    lines = _errors({"walker": walker, "slope": {"angle_deg": 1}})
    assert sum(vocabulary in ln for ln in lines) == 1
    # knee springs exist (knee.spring), and torques at any joint (issue 48)
    assert "torques at any joint the walker has" in vocabulary
    assert "elastic" not in vocabulary and "yet" not in vocabulary
    guide = (ROOT / "docs" / "user_guide" / "walkers.md").read_text()  # the README's section
    assert "a torque at any joint the walker has" in " ".join(guide.split())


# -------------------- reference tables bounded
# ------------------------------------------------------ 15: reference tables bounded
@pytest.mark.parametrize("where", ["angle_rad", "phase_rad"])
def test_a_reference_angle_beyond_two_turns_is_refused_naming_the_entry(where):
    d = yaml.safe_load((ROOT / "configs" / "rabbit.yaml").read_text())
    d["walker"]["actuation"]["torques"][0]["law"]["reference"][where][1] = 1e308
    with pytest.raises(SceneError) as exc:
        scene_from_dict(d, "s.yaml")
    assert str(exc.value) == (f"s.yaml: walker.actuation.torques.0.law.reference.{where}.1: "
                              "Input should be less than or equal to 6.3")


# -------------------- unknown keys, a NUL byte, a knee or a field one level too high
SIMPLEST = yaml.safe_load((ROOT / "configs" / "simplest.yaml").read_text())


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


# --------------------------------------- 6: a knee at the walker's level, not the leg's
@pytest.mark.parametrize("scene, meant", [("asymmetric_legs.yaml", "legs.N.knee"),
                                          ("paper_rods.yaml", "leg.knee")])
def test_a_knee_given_to_the_walker_points_to_the_leg(scene, meant):
    d = yaml.safe_load((ROOT / "configs" / scene).read_text())
    d["walker"]["knee"] = {"thigh_length_m": 0.5}
    lines = str(pytest.raises(SceneError, scene_from_dict, d, "s.yaml").value).splitlines()
    assert lines == [f"s.yaml: walker.knee: unknown field (did you mean {meant}?)"]


def test_a_field_given_one_section_too_high_points_to_its_section():
    d = dict(SIMPLEST, angle_deg=2.0)
    lines = str(pytest.raises(SceneError, scene_from_dict, d, "s.yaml").value).splitlines()
    assert lines == ["s.yaml: angle_deg: unknown field (did you mean slope.angle_deg?)"]


def test_every_command_in_the_top_level_help_is_one_sentence_on_one_line():
    """Issue 64 item 10: ``walkerlab --help`` cut the commands' help mid-sentence (each
    docstring's hard line breaks kept)."""
    from walkerlab.cli import COMMANDS

    r = CliRunner().invoke(app, ["--help"], env={"COLUMNS": "80"}, terminal_width=80)
    assert r.exit_code == 0
    box = [ln for ln in r.stdout.split("Commands")[1].splitlines() if ln.startswith("│")]
    names = [name for name, _ in COMMANDS]
    assert len(box) == len(names)  # no continuation lines
    for line, name in zip(box, names):
        help_ = line.strip("│ ").removeprefix(name).strip()
        assert help_.endswith(".") and help_.count(". ") == 0, line
