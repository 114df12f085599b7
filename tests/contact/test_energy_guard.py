"""Energy as a guard on contact runs (issue 25 item 6).

paper_rods with ``mu_static: 0, mu_dynamic: 0`` ended "airborne (the hip rose 1.5 m)" with a
last sample of 1.25e10 J (150 J at the start).  Cause (walkerlab.models.contact.energy): the
frictionless stance foot slides off its patch, both feet sink into the gaps, and leg2's foot
enters the next patch from its side 0.27 m below its top, which the IMPACT law reads as a
0.27 m penetration.  Now the run ends as that trip, at the last trustworthy sample, and no
written sample has more energy than the start + the bound.
"""

import numpy as np
import pytest

from tests.contact.test_periodic import SCENE
from walkerlab.analysis.contact.sim import simulate_from
from walkerlab.analysis.gait.scene import solve_variant
from walkerlab.config import load_scene
from walkerlab.models.contact.energy import energy_rise_bound, total_energy
from walkerlab.models.contact.scene import contact_setup
from walkerlab.walker.plant import Plant

RODS = SCENE.parent / "paper_rods.yaml"


@pytest.mark.slow
def test_frictionless_rods_end_as_a_trip_without_blown_up_samples():
    sc = load_scene(RODS)
    # the start this finding was made from (paper_rods.yaml's rates before it took the
    # unscaled ideal start: from that one the frictionless walker falls before
    # its foot reaches a patch's side)
    sc = sc.model_copy(update={"contact": sc.contact.model_copy(
        update={"mu_static": 0.0, "mu_dynamic": 0.0}), "contact_sim": sc.contact_sim.model_copy(
        update={"initial_rate_scale": [1.506, 1.101]})})
    ideal = solve_variant(sc, "derived", plant=Plant.from_scene(sc))[1]
    walker, r, x0, _ = simulate_from(contact_setup(sc,
            plant=Plant.from_scene(sc)), ideal.x, ideal.period_s)
    E = total_energy(walker, r.x)
    bound = energy_rise_bound(walker, x0, sc.contact_solver.rtol)
    assert np.all(E <= E[0] + bound), E.max() - E[0]
    assert r.termination == "trip", r.message
    assert r.outcome.foot == "leg2"
    assert 0.40 < r.t[-1] < 0.42  # measured 0.409 s; the trip at 0.4096 s
    assert "side" in r.message
    assert np.all(np.abs(r.x) < 10)  # no blown-up state (it had rates of 2e4)


def test_total_energy_counts_the_stored_elastic_energy():
    """A point foot pressed into its patch by d stores k d^(e+1)/(e+1) (IMPACT's spring):
    total_energy exceeds kinetic + potential by exactly that (rtol 1e-12)."""
    from walkerlab.models.contact.scene import build

    sc = load_scene(SCENE)
    ideal = solve_variant(sc, "derived", plant=Plant.from_scene(sc))[1]
    walker, _ = build(sc, ideal.x, 2, plant=Plant.from_scene(sc))
    z = walker.link_state_from_ideal(ideal.x)
    d = 1e-4
    x = walker.pinned_to_full(z, -d * walker.normal)
    q = walker.contact_quantities(x[None])["leg2"]
    assert q["penetration"][0] == pytest.approx(d, rel=1e-9)
    c = walker.contact
    spring = c.k * q["penetration"][0] ** (c.e + 1) / (c.e + 1)
    E = walker.energies(x[None])["total"][0]
    assert total_energy(walker, x)[0] - E == pytest.approx(spring, rel=1e-12)
