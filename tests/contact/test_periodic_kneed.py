"""The kneed walker's own contact periodic gait (issue 17 part 3): the mid-stance section by
state name (the proximal links cross), continuous ground, knee states in the section."""

from pathlib import Path

import numpy as np
import pytest

from walkerlab.analysis.contact.periodic import find_contact_periodic_gait
from walkerlab.analysis.contact.sim import simulate_contact
from walkerlab.analysis.contact.step_map import StepMap
from walkerlab.analysis.gait.scene import solve_variant
from walkerlab.config import SolverSettings, load_scene
from walkerlab.integrate.solver import Solver
from walkerlab.models.contact.scene import build
from walkerlab.walker.plant import Plant

SCENE = Path(__file__).resolve().parents[2] / "configs" / "kneed.yaml"

#: The fixed point found by find_contact_periodic_gait (defaults, warm-up 12 steps; residual
#: 2.3e-9 scaled), to 10 digits, in StepMap.names order.
FIXED_POINT = {
    "theta_stance_thigh": 0.02661576375, "theta_stance_shank": 0.02661936332,
    "theta_swing_shank": -0.5036604307, "dtheta_swing_thigh": 2.315544785,
    "dtheta_swing_shank": 0.7838773315, "dtheta_stance_thigh": -0.573299316,
    "dtheta_stance_shank": -0.5714832928, "delta_stance": 1.880387469e-05,
    "v_t_stance": 0.004537643047, "ddelta_stance": -1.462934203e-05}
PERIOD_S, STEP_M = 0.5505094193, 0.4687958598


@pytest.fixture(scope="module")
def kneed():
    scene = load_scene(SCENE)
    ideal = solve_variant(scene, "derived", plant=Plant.from_scene(scene))[1]
    walker, _ = build(scene, ideal.x, 2, plant=Plant.from_scene(scene))
    return ideal, walker


def test_kneed_section_is_named_and_the_fixed_point_maps_to_itself(kneed):
    """One step of the map from the stored fixed point returns to it.

    The map at rtol 1e-10 (odeint) returns 1.3e-6 (scaled: rad, rad/s, static penetration,
    mm/s) from the 10-digit fixed point (measured; the search ran at 1e-12), while 12 map
    steps from the rigid gait still leave 4e-2: a 1e-4 bound tells a fixed point from a point
    of the attractor's neighbourhood by two orders either way.  Period and step length are
    read at the same tolerance: 1e-6 s / m is 30x their measured change from rtol 1e-12.
    """
    _, walker = kneed
    P = StepMap(walker, solver=Solver("odeint", 1e-10, 1e-12))
    assert P.names == tuple(FIXED_POINT)
    assert P.walker.continuous  # the scene's continuous ground is kept (no footfall lanes)
    z = np.array(list(FIXED_POINT.values()))
    z1, T, ell = P(z)
    assert np.max(np.abs((z1 - z) / P.scale)) < 1e-4
    assert T == pytest.approx(PERIOD_S, abs=1e-6)
    assert ell == pytest.approx(STEP_M, abs=1e-6)
    # physics on the section: stance knee held straight by its latched stop (pushing), swing
    # knee flexed, so the swing foot clears the continuous ground (a straight leg scuffs)
    x = P.to_state(z)
    knee = walker.knee_stop_quantities(x[None])
    assert abs(knee["leg2"]["extension"][0]) < 1e-4 and knee["leg2"]["torque"][0] > 0
    assert knee["leg1"]["extension"][0] < -0.3
    assert walker.contact_quantities(x[None])["leg1"]["penetration"][0] < -0.02
    # an independent check of the map: a plain contact run (heel strikes found on 1 kHz
    # samples, not by the map's section) started on the fixed point repeats the period
    r = simulate_contact(walker, x, 4.2 * T, SolverSettings.for_contact(rtol=1e-10, atol=1e-12))
    assert r.termination == "t_final"
    dT = np.diff(r.heel_strike_times)
    assert len(dT) >= 3 and np.all(np.abs(dT - T) < 2e-3)


@pytest.mark.slow
def test_kneed_contact_gait_and_multipliers_match_the_rigid_ones(kneed):
    """The full search (about 5 s without the FD-step check) from the rigid fixed point.

    Measured: contact 0.55051 s, 0.46880 m, multipliers 0.469 +- 0.498j (|.| 0.684) and 0.113;
    rigid 0.54585 s, 0.4747 m, 0.548 +- 0.499j (|.| 0.741) and 0.108.  Like the paper walker
    the contact gait is slightly slower (+0.9 %) and shorter (-6 mm) and has the rigid
    walker's three slow multipliers (the other seven, contact and knee-stop modes, are
    damped within milliseconds: < 1e-3).  Bounds: a few times those differences.
    """
    ideal, walker = kneed
    g = find_contact_periodic_gait(walker, ideal.x, warmup_steps=12, check_fd=False)
    assert g.converged and g.stable
    assert g.period_s == pytest.approx(PERIOD_S, abs=1e-6)
    assert 0 < g.period_s - ideal.period_s < 0.03 * ideal.period_s
    rigid = np.abs(ideal.multipliers_variational)
    slow = g.multipliers[np.abs(g.multipliers) > 1e-3]
    assert len(slow) == np.sum(rigid > 1e-3) == 3
    assert abs(slow[0].imag) > 0.3  # the complex pair, as in the rigid gait
    assert abs(g.max_multiplier - rigid.max()) < 0.15
    assert abs(abs(slow[2]) - np.sort(rigid)[-3]) < 0.03
