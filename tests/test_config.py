"""Scenes: every shipped file loads; bad input is a one-line error naming the field."""

from pathlib import Path

import pytest
import yaml

from walkerlab.config import SceneError, load_scene

ROOT = Path(__file__).resolve().parents[1]
CONFIGS = sorted((ROOT / "configs").glob("*.yaml"))


def test_there_are_configs():
    assert {p.name for p in CONFIGS} >= {"paper.yaml", "goswami1996.yaml"}


@pytest.mark.parametrize("path", CONFIGS, ids=lambda p: p.name)
def test_every_config_loads(path):
    scene = load_scene(path)
    assert scene.name == path.stem
    assert scene.source, "a published parameter set must cite its source"


def _write(tmp_path, data, name="bad.yaml"):
    p = tmp_path / name
    p.write_text(yaml.safe_dump(data))
    return p


def _paper(tmp_path):
    return yaml.safe_load((ROOT / "configs" / "paper.yaml").read_text())


@pytest.mark.parametrize(
    ("mutate", "field"),
    [
        (lambda d: d["walker"].update(colour="red"), "walker.colour"),
        (lambda d: d["walker"].update(leg_mass_kg=-5.0), "walker.leg_mass_kg"),
        (lambda d: d["slope"].update(angle_rad=1.6), "slope.angle_rad"),
        (lambda d: d.update(slope={"angle_deg": -95}), "slope.angle_deg"),
        (lambda d: d["solver"].update(method="Euler"), "solver.method"),
        (lambda d: d.update(unknown_section={}), "unknown_section"),
    ],
)
def test_bad_field_is_one_line_error_naming_it(tmp_path, mutate, field):
    d = _paper(tmp_path)
    mutate(d)
    with pytest.raises(SceneError) as exc:
        load_scene(_write(tmp_path, d))
    msg = str(exc.value)
    assert "\n" not in msg
    assert field in msg
    assert "bad.yaml" in msg


def test_malformed_yaml_names_file(tmp_path):
    p = tmp_path / "broken.yaml"
    p.write_text("walker: [unclosed\n")
    with pytest.raises(SceneError, match="broken.yaml.*malformed YAML"):
        load_scene(p)


def test_missing_file(tmp_path):
    with pytest.raises(SceneError, match="not found"):
        load_scene(tmp_path / "nope.yaml")


def test_sections_not_used_are_absent():
    """schwab_wisse2001 declares no contact sections: they stay None, not dummies."""
    scene = load_scene(ROOT / "configs" / "schwab_wisse2001.yaml")
    assert scene.contact is None and scene.terrain is None and scene.contact_sim is None


@pytest.mark.parametrize("section, value, line", [
    ("solver", {"method": "odeint"}, "solver.method: odeint integrates the contact model"),
    ("contact_solver", {"method": "RK23"}, "contact_solver.method: the contact model takes"),
    ("contact_solver", {"rtol": 1e-14}, "contact_solver.rtol: at least 1e-13"),
    ("contact_solver", {"backend": "cyrk"}, "contact_solver.backend: the contact model's "
                                            "library is its method"),
])
def test_solver_and_contact_solver_are_one_type_each_checked_for_its_model(tmp_path, section,
                                                                            value, line):
    """solver: and contact_solver: are one settings type (walkerlab.config.SolverSettings,
    mapping onto walkerlab.integrate.Solver); a contact_solver: is completed with the contact
    defaults (CyRK BDF at rtol 1e-8), and a method or setting the other model's integrator
    takes is one line naming the key."""
    from walkerlab.config import SolverSettings
    from walkerlab.integrate.solver import Solver

    base = yaml.safe_load((ROOT / "configs" / "paper.yaml").read_text())
    base.pop("contact_solver", None)
    ok = load_scene(_write(tmp_path, {**base, "contact_solver": {"rtol": 1e-9}}, "ok.yaml"))
    assert type(ok.contact_solver) is type(ok.solver) is SolverSettings
    assert Solver.from_settings(ok.contact_solver) == Solver("cyrk_bdf", 1e-9, 1e-10)
    assert Solver.from_settings(ok.solver) == Solver("DOP853", 1e-12, 1e-12)
    with pytest.raises(SceneError) as err:
        load_scene(_write(tmp_path, {**base, section: value}))
    msg = str(err.value)
    assert "\n" not in msg and line in msg
