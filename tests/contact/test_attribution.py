"""Energy per step by sink (issue 25 item 2, walkerlab.analysis.contact.attribution.energy_by_sink).

Independent check: on a periodic gait the walker returns to the same state one step further
down the slope, so everything its sinks dissipate in a step is the work of gravity over the
step's drop, ``M g l sin(phi)`` (l: the step length along the slope).  The sinks are summed
from the contact forces sample by sample; gravity's work from the step length alone.
"""

import numpy as np
import pytest

from tests.contact.test_periodic import SCENE
from walkerlab.analysis.contact.attribution import energy_by_sink
from walkerlab.analysis.contact.periodic import find_contact_periodic_gait
from walkerlab.analysis.gait.scene import solve_variant
from walkerlab.config import load_scene
from walkerlab.models.contact.scene import build
from walkerlab.walker.plant import Plant


@pytest.mark.slow  # in `pytest -m slow`: the quick suite keeps to its CPU budget
def test_sinks_add_up_to_gravity_work_over_the_step():
    """Measured on the paper's contact: damping 1.128 J, friction in the impact (double
    support) 0.007 J, stance creep 0.093 J; sum 1.2283 J against M g l sin(phi) = 1.2284 J.
    Tolerance 2e-3 relative: the trapezoidal rule on 20,000 samples of a step with ~10 ms
    impacts (measured agreement ~1e-4)."""
    sc = load_scene(SCENE)
    ideal = solve_variant(sc, "derived", plant=Plant.from_scene(sc))[1]
    walker, _ = build(sc, ideal.x, 2, plant=Plant.from_scene(sc))
    g = find_contact_periodic_gait(walker, ideal.x, check_fd=False)
    e = energy_by_sink(walker, g.z)
    assert all(v > 0 for v in e.values()), e  # every sink dissipates
    drop = walker.total_mass * walker.g * g.step_length_m * np.sin(walker.phi)
    assert sum(e.values()) == pytest.approx(drop, rel=2e-3)
    assert e["normal_damping"] > 10 * e["friction_stance"] > 10 * e["friction_impact"]
