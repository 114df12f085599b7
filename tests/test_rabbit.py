"""configs/rabbit.yaml: RABBIT under virtual constraints on level ground - its references are
those of scripts/rabbit_references.py (an HZD-consistent design: the role swap maps their end
onto their start), one step from its fixed point returns to it, the phase variable is
monotonic, and the energy ledger closes with the cost of transport from the positive work."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from tests.scripts_loader import load_file
from walkerlab.analysis.gait.energy import step_ledger
from walkerlab.config import load_scene
from walkerlab.integrate.rigid import simulate_steps
from walkerlab.integrate.solver import Solver
from walkerlab.models.registry import build_walker
from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]
#: the gait's step period [s] (walkerlab fixedpoint configs/rabbit.yaml; the closing note)
STEP_PERIOD_S = 0.37093


def _design():
    return load_file("scripts/rabbit_references.py")


@pytest.fixture(scope="module")
def scene():
    return load_scene(ROOT / "configs" / "rabbit.yaml")


@pytest.fixture(scope="module")
def step(scene):
    w = build_walker(Plant.from_scene(scene))
    x0 = scene.fixedpoint.initial_guess.as_array(w.state_names())
    traj = simulate_steps(w, x0, 1, Solver.from_settings(scene.solver), max_step_time=2.0)
    return w, x0, traj.segments[0]


def test_references_are_the_scripts_hzd_design(scene):
    design = _design()
    phase, refs = design.joint_references()
    torques = scene.walker.actuation.torques
    assert [t.joint for t in torques] == list(design.JOINTS)
    for t in torques:
        np.testing.assert_allclose(t.law.reference.phase_rad, phase, atol=1e-12)
        np.testing.assert_allclose(t.law.reference.values_rad, refs[t.joint], atol=5e-7)
    # the heel strike's role swap maps the designed end configuration onto the start
    th0 = design.DESIGN["theta0_rad"]
    end, start = design.configuration(-th0), design.configuration(th0)
    np.testing.assert_allclose(end[[3, 2, 1, 0, 4]], start, atol=1e-15)
    assert scene.slope.phi_rad == 0.0 and scene.walker.actuation.push_off is None


@pytest.mark.slow  # in `pytest -m slow`: the quick suite keeps to its CPU budget
def test_one_step_from_the_fixed_point_returns_to_it(step):
    w, x0, seg = step
    assert w.total_mass_kg == pytest.approx(32.0)  # 12 + 2 (6.8 + 3.2) kg (Table I)
    assert seg.termination == "heel_strike"
    # the guess is the fixed point to 10 digits; the map's Jacobian has |multipliers| < 0.7
    np.testing.assert_allclose(seg.x_next, x0, atol=1e-8)
    assert seg.t_end - seg.t_start == pytest.approx(STEP_PERIOD_S, abs=1e-5)
    ts = np.linspace(seg.t_start, seg.t_end, 200)
    s = []
    for _ph, sol, (ta, tb) in seg.pieces:
        for t in ts[(ts >= ta) & (ts <= tb)]:
            s.append(float(w.leg_angles(np.asarray(sol(t)).ravel()[:10])["stance_angle"]))
    assert np.all(np.diff(s) < 0)  # the phase variable decreases through the step


def test_ledger_closes_and_cost_of_transport_is_the_positive_work(step):
    w, _x0, seg = step
    led = step_ledger(w, seg)
    ke = float(w.energies(seg.x_start)[0])
    assert abs(led["closure"]) <= 1e-9 * ke
    d = float(np.linalg.norm(w.points(seg.x_end)["swing_foot"]))
    assert led["cost_of_transport"] == pytest.approx(
        led["actuator_work_positive"] / (32.0 * 9.81 * d), rel=1e-12)
    # a periodic level-ground step: the actuators' net work pays the heel strike
    net = led["actuator_work_positive"] + led["actuator_work_negative"]
    assert net == pytest.approx(led["heel_strike_loss"], rel=1e-6)
    assert led["push_off_work"] == 0.0 and led["slope_energy"] == 0.0
