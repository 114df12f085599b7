"""Feet curved in both directions (``walker.leg.foot.kind: toroidal``) on 3D locking knees
(``space: 3d``, ``knee.lock: plastic``; Collins, Wisse & Ruina 2001, "A three-dimensional
passive-dynamic walking robot with two legs and knees", IJRR 20(7)): the rigid model's
Chaplygin reduction (:func:`walkerlab.codegen.rolling_feet.reduce_rolling`) on the kneed
tree, the stance foot rolling on the straight (locked) stance leg, the swing foot on the
swing shank.  Against references that share no rolling code with the 3D generator:

- the planar kneed walker on arc feet of the fore-aft radius (configs/kneed.yaml with
  ``foot: {kind: arc}``: the planar tree, the arc foot's holonomic rolling): with zero hip
  width, no arms and an upright start the 3D walker walks its gait (the lateral radius does
  not enter an upright walk);
- the energy: ``T + V`` with the potential at the contact's true travel along the fall line
  (its rolling rate ``-(R - R_l + R_l cos phi) beta'`` integrated alongside, not the
  printed potential's holonomic reference ``-R beta``) constant over each passive phase.

The Collins scene with knees, configs/collins2001_knees.yaml: its gait (slow).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml
from scipy.integrate import solve_ivp

from tests.test_parts_3d import _guess, _planar_embedding, _walker
from walkerlab.config.schema import Scene
from walkerlab.integrate.solver import Solver
from walkerlab.walker.kinds import KINDS, kind_of

ROOT = Path(__file__).resolve().parents[1]
SOLVER = Solver(method="DOP853", rtol=1e-12, atol=1e-12)
#: the feet's fore-aft radius (configs/kneed_round_feet_3d.yaml's: the planar kneed gait
#: on arc feet folds at 0.124 m) and a lateral radius [m]
R_FOOT, R_LAT = 0.1, 0.05
EXTRAS = ("contact", "terrain", "contact_sim", "contact_solver")


def _raw(name: str) -> dict:
    raw = yaml.safe_load((ROOT / "configs" / name).read_text())
    for key in EXTRAS:
        raw.pop(key, None)
    return raw


def _kneed_torus(width: float = 0.0) -> dict:
    """configs/kneed_round_feet_3d.yaml (configs/kneed.yaml's walker in 3D) on toroidal
    feet of fore-aft radius :data:`R_FOOT` and lateral radius :data:`R_LAT`."""
    raw = _raw("kneed_round_feet_3d.yaml")
    raw["walker"]["hip_width_m"] = width
    raw["walker"]["leg"]["foot"] = {"kind": "toroidal", "radius_m": R_FOOT,
                                    "lateral_radius_m": R_LAT}
    return raw


def test_toroidal_feet_on_locking_knees_validate_as_the_locking_knees_3d_kind():
    """A 3D walker on locking knees takes toroidal feet (the shanks' feet): the kind
    ``locking_knees_3d``, the planar kneed walker's roles with the lean first."""
    from walkerlab.walker.description import walker_data

    scene = Scene.model_validate(_kneed_torus(0.1))
    data = walker_data(scene.walker, scene.slope.angle_rad)
    assert kind_of(data.structure) is KINDS["locking_knees_3d"]
    assert data.structure.foot == "toroidal"
    assert data.structure.roles == ("lean", "swing_thigh", "swing_shank", "stance")


@pytest.mark.slow   # ~1 min cold: the planar and the 3D kneed derivations on curved feet
def test_the_kneed_walker_on_toroidal_feet_upright_walks_the_planar_kneed_gait_on_arc_feet():
    """Zero hip width, no arms, started upright: the 3D kneed walker on toroidal feet
    (radii 0.1 m fore-aft, 0.05 m across) has the planar kneed walker's fixed point on arc
    feet of 0.1 m and its step period to 1e-9 relative, the lean and its rate 0 and the
    planar multipliers among the 3D ones (measured: 2e-13 on the state, 1e-13 s on the
    period 0.536830 s; the lean's multiplier 6.11 a step, the discs' 6.50)."""
    from walkerlab.analysis.gait.poincare import find_fixed_point

    raw = _raw("kneed.yaml")
    raw["walker"]["leg"]["foot"] = {"kind": "arc", "radius_m": R_FOOT}
    flat_scene = Scene.model_validate(raw)
    scene = Scene.model_validate(_kneed_torus())
    flat, w3 = _walker(flat_scene), _walker(scene)
    start = _guess(scene, w3.state_names())[[1, 2, 3, 5, 6, 7]]
    f = find_fixed_point(flat, start, SOLVER, fd_check=False)
    s = _planar_embedding(flat, f, w3, tiny=1e-6)
    assert abs(s.period_s - 0.53683) < 1e-5
    assert np.max(np.abs(s.multipliers_variational)) > 1.0   # the lean: unstable


@pytest.mark.slow   # the derivation with hip width (~30 s cold), then two 0.3 s integrations
def test_the_kneed_walker_on_toroidal_feet_conserves_energy_over_each_passive_phase():
    """Hip width 0.1 m, leaning: over 0.3 s of each passive phase (the knee free, the knee
    locked) ``T + V`` at the contact's true travel (the rolling rate of
    :mod:`walkerlab.codegen.rolling_feet` integrated alongside) is constant to 1e-12 J
    (DOP853 at 1e-13; measured 2e-14 and 2e-13), while the printed potential's holonomic
    reference drifts by ~1e-6 J (the rolling is not holonomic); the locked phase keeps the
    knee straight."""
    w = _walker(Scene.model_validate(_kneed_torus(0.1)))
    raw = _kneed_torus(0.1)
    g, gamma = raw["walker"]["gravity_m_per_s2"], raw["slope"]["angle_rad"]
    x0 = np.array([0.08, -0.25, -0.35, 0.2, -0.6, -0.2, 0.5, -1.2])
    for phase in w.phases:
        x = x0.copy()
        if phase.name == "locked_swing":   # the shank with the thigh
            x[2], x[6] = x[1], x[5]

        def flow(t, y, phase=phase):
            rate = -(R_FOOT - R_LAT + R_LAT * np.cos(y[0])) * y[7]   # beta' = stance'
            return np.r_[phase.flow(t, y[:8]), rate]

        sol = solve_ivp(flow, (0.0, 0.3), np.r_[x, 0.0], method="DOP853", rtol=1e-13,
                        atol=1e-13, dense_output=True)
        ys = sol.sol(np.linspace(0.0, 0.3, 31))
        kinetic, potential = (np.asarray(e) for e in w.energies(ys[:8]))
        reference = -R_FOOT * (ys[3] - ys[3, 0])   # the printed potential's travel
        true = kinetic + potential - w.total_mass_kg * g * np.sin(gamma) * (ys[8] - reference)
        assert np.ptp(true) < 1e-12, phase.name
        assert np.ptp(kinetic + potential) > 1e-8, phase.name   # not holonomic
        if phase.name == "locked_swing":
            assert np.max(np.abs(ys[2] - ys[1])) < 1e-12



@pytest.mark.slow   # the two arms' trees (straight and kneed): a minute or more cold
def test_the_collins_walker_with_its_knee_locked_is_the_straight_legged_collins_walker():
    """configs/collins2001_knees.yaml's thigh and shank with the knee locked are
    configs/collins2001.yaml's straight leg (1.5 kg, centre 0.25 m below the hip, 0.045 kg
    m^2: the scene's header), so with the swing knee straight the kneed walker's locked
    flow, heel strike and energies are the straight-legged walker's (itself checked against
    a Newton-Euler reference, tests/test_collins2001.py) at every state, leaning, on the
    hip width, arms and toroidal feet: to 1e-12 (measured 1e-14), the knee's rate kept 0
    and the new swing knee straight."""
    kneed = _walker(Scene.model_validate(_raw("collins2001_knees.yaml")))
    straight = _walker(Scene.model_validate(_raw("collins2001.yaml")))
    locked = next(p for p in kneed.phases if p.name == "locked_swing")
    rows = [0, 1, 3, 4, 5, 7]   # the kneed state's lean, thigh, stance and their rates
    rng = np.random.default_rng(1)
    for _ in range(4):
        z = np.array([0.05, -0.3, 0.25, 0.3, -0.8, -1.5]) + 0.05 * rng.standard_normal(6)
        x = np.array([z[0], z[1], z[1], z[2], z[3], z[4], z[4], z[5]])
        f = locked.flow(0.0, x)
        assert np.max(np.abs(f[rows] - straight.phases[0].flow(0.0, z))) < 1e-12
        assert abs(f[6] - f[5]) < 1e-12
        after = kneed.reset(x)
        assert np.max(np.abs(after[rows] - straight.reset(z))) < 1e-12
        assert after[2] == after[1] and after[6] == after[5]
        for ours, theirs in zip(kneed.energies(x), straight.energies(z)):
            assert abs(float(ours) - float(theirs)) < 1e-12


# --- configs/collins2001_knees.yaml -----------------------------------------------------------

#: the straight-legged walker's lateral multiplier a stride (configs/collins2001.yaml,
#: tests/test_collins2001.py)
STRAIGHT_LATERAL = 1.473069


@pytest.fixture(scope="module")
def collins_knees():
    from walkerlab.analysis.gait.poincare import find_fixed_point, poincare_map

    scene = Scene.model_validate(_raw("collins2001_knees.yaml"))
    walker = _walker(scene)
    x = _guess(scene, walker.state_names())
    start = poincare_map(walker, x, SOLVER)[0] - x
    return walker, x, start, find_fixed_point(walker, x, SOLVER, fd_check=False)


@pytest.mark.slow   # the arms' tree on knees and toroidal feet: minutes cold
def test_the_collins_walker_with_knees_ships_its_gait_and_is_laterally_unstable(collins_knees):
    """configs/collins2001_knees.yaml: the shipped guess is the stride's fixed point to 1e-9
    (its map's residual there); step period 0.608591 s, step 0.426403 m, 0.7006 m/s
    against the robot's 0.51 m/s; the multipliers a stride 2.1186 (real: the lateral mode,
    lean and lean rate), 0.5992, |0.0033 +- 0.2300i|, 0.0303 and three 0s (the section and
    the knee locked at heel strike): unstable, as the straight-legged walker
    (configs/collins2001.yaml: a complex pair of 1.473 a stride).  To 1e-5 relative."""
    walker, x, start, res = collins_knees
    assert np.max(np.abs(start)) < 1e-9
    assert np.max(np.abs(res.x - x)) < 1e-9
    step = res.period_s / 2
    length = res.step_lengths_m[0]
    assert abs(step - 0.6085908) < 1e-5 * step
    assert abs(length - 0.4264030) < 1e-5 * length
    assert abs(length / step / 0.51 - 1.3738) < 1e-3     # the robot's 0.51 m/s
    mu = res.multipliers_variational
    lead = mu[np.argmax(np.abs(mu))]
    assert abs(lead.imag) < 1e-9 and abs(lead.real - 2.118550) < 1e-5 * 2.118550
    assert lead.real > STRAIGHT_LATERAL                 # the knees raise it
    assert np.sort(np.abs(mu))[-2] < 1.0                # the rest inside the unit circle
