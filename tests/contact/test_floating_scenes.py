"""contact.scene.build makes the contact walker of every shipped walker (issue 17: it crashed
for ``model: biped`` scenes), and a massless walker gets one line."""

from pathlib import Path

import numpy as np
import pytest
import yaml

from walkerlab.analysis.contact.sim import initial_state_from_ideal
from walkerlab.config import scene_from_dict
from walkerlab.models.contact.scene import ContactSceneError, build
from walkerlab.models.registry import build_walker
from walkerlab.walker.plant import Plant

CONFIGS = Path(__file__).resolve().parents[2] / "configs"
CONTACT = ("contact", "terrain", "contact_sim", "contact_solver")


def _scene(name):
    d = yaml.safe_load((CONFIGS / f"{name}.yaml").read_text())
    paper = yaml.safe_load((CONFIGS / "paper.yaml").read_text())
    for k in CONTACT:
        d.setdefault(k, paper[k])
    return scene_from_dict(d, f"{name}.yaml")


@pytest.mark.parametrize("name", ["paper", "paper_rods", "kneed", "round_feet", "goswami1996"])
def test_build_any_walker(name):
    sc = _scene(name)
    rigid = build_walker(Plant.from_scene(sc))
    x = sc.fixedpoint.initial_guess.as_array(rigid.state_names())
    w, step = build(sc, x, 4, plant=Plant.from_scene(sc))
    n = 6 if name == "kneed" else 4
    assert len(w.state_names()) == 2 * n and len(w.state_units()) == 2 * n
    assert 0.2 < step < 0.8
    x0 = initial_state_from_ideal(w, *x)
    # the stance foot (leg2) sits at s = 0, its static penetration deep, at rest
    cq = w.contact_quantities(x0)["leg2"]
    assert cq["s"][0] == pytest.approx(0.0, abs=1e-12)
    assert cq["penetration"][0] == pytest.approx(w.static_penetration(), rel=1e-9)
    assert cq["slip_velocity"][0] == pytest.approx(0.0, abs=1e-12)
    # the link angles are the rigid state's (leg1 swing, leg2 stance)
    ang = x0[2:n]
    if name == "kneed":
        np.testing.assert_allclose(ang, [x[0], x[1], x[2], x[2]])
    else:
        np.testing.assert_allclose(ang, x[:2])


def test_massless_walker_one_line():
    with pytest.raises(ContactSceneError, match="needs positive leg masses") as err:
        sc = _scene("simplest")
        build(sc, np.zeros(4), 4, plant=Plant.from_scene(sc))
    assert "\n" not in str(err.value)
