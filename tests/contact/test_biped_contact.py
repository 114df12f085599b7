"""A ``model: biped`` scene with a contact section through ``walkerlab contact-sim`` and
``walkerlab compare`` (issue 17 part 3: this crashed with an AttributeError on
``leg_length_m``), kept fast: one stride of ``configs/paper_rods.yaml``."""

from pathlib import Path

import h5py
import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from walkerlab.cli import app

ROOT = Path(__file__).resolve().parents[2]


def _scene(tmp_path, name="paper_rods", strides=1):
    d = yaml.safe_load((ROOT / "configs" / f"{name}.yaml").read_text())
    d["name"] = name
    d["simulate"]["strides"] = strides
    d["contact_sim"].update(n_strides=strides, periodic_gait=False)
    p = tmp_path / f"{name}.yaml"
    p.write_text(yaml.safe_dump(d))
    return p


@pytest.mark.slow  # in `pytest -m slow`: the quick suite keeps to its CPU budget
def test_biped_scene_contact_sim_and_compare(tmp_path):
    scene, runs = _scene(tmp_path), tmp_path / "runs"
    r = CliRunner().invoke(app, ["contact-sim", str(scene), "--runs-dir", str(runs)])
    assert r.exit_code == 0, r.output
    with h5py.File(runs / "paper_rods" / "contact_sim.h5", "r") as f:
        # the stride asked for (2 heel strikes) is made by the end time
        assert str(f.attrs["outcome"]) == "t_final", f.attrs["outcome_message"]
        coords = [str(c) for c in f["samples"].attrs["coordinates"]]
        periods = f["steps/period"][()]
        slip = f["summary/max_abs_stance_slip_mm"][()]
        rates = [str(v) for v in f["rate"][()].astype(str)]
    # named like the rigid walker's trajectory (by leg), the rates the adjustment scales named
    assert coords == ["leg1_angle", "leg1_rate", "leg2_angle", "leg2_rate"]
    assert rates == ["dtheta1", "dtheta2"]
    # one stride = 2 heel strikes after the start: 2 complete steps, then the cap
    assert np.isfinite(periods[:2]).all()
    # the rigid gait's step period (fixedpoint) within 15 %: the first steps still carry the
    # start's transient (the contact periodic gait, 0.89175 s, is 0.12 % above the rigid one;
    # 0.9009 s, +1.15 %, at ADAMS's 100 mm/s stiction velocity)
    from walkerlab.io.schemas.fixedpoint import load_fixedpoint

    T = load_fixedpoint(runs / "paper_rods" / "fixedpoint.h5").step_period_s
    assert np.all(np.abs(periods[:2] / T - 1) < 0.15), (periods, T)
    assert 0 <= slip < 5.0  # mm: the feet grip (mu 0.9); a sliding foot would show cm

    r = CliRunner().invoke(app, ["compare", str(scene), "--runs-dir", str(runs)])
    assert r.exit_code == 0, r.output
    with h5py.File(runs / "paper_rods" / "compare.h5", "r") as f:
        names = [str(n) for n in f["errors"].attrs["coordinates"]]
        max_angle = float(f["errors/max_abs_angle"][()])
    assert names == coords, names
    # ideal vs contact over one stride: the contact walker follows the rigid one (measured
    # 0.15 rad with the start once shipped, swing rate x1.5 at ADAMS's friction velocities;
    # a walker that fell or stepped out of phase would show ~0.4 rad, the inter-leg angle at
    # heel strike)
    assert max_angle < 0.25


def test_massless_walker_contact_sim_is_one_line(tmp_path):
    d = yaml.safe_load((ROOT / "configs" / "simplest.yaml").read_text())
    paper = yaml.safe_load((ROOT / "configs" / "paper.yaml").read_text())
    for k in ("contact", "terrain", "contact_sim", "contact_solver"):
        d[k] = paper[k]
    p = tmp_path / "simplest.yaml"
    p.write_text(yaml.safe_dump(d))
    r = CliRunner().invoke(app, ["contact-sim", str(p), "--runs-dir", str(tmp_path / "runs")])
    assert r.exit_code == 1
    err = [ln for ln in r.output.splitlines() if ln.startswith("error")]
    assert len(err) == 1 and "positive leg masses" in err[0], r.output
    assert "Traceback" not in r.output


@pytest.mark.parametrize("name", ["paper_rods", "round_feet", "goswami1996", "kneed"])
def test_shipped_biped_scenes_have_contact(name):
    """The shipped walkers with masses carry a contact section (issue 17 part 3)."""
    from walkerlab.config import load_scene

    assert load_scene(ROOT / "configs" / f"{name}.yaml").contact is not None
