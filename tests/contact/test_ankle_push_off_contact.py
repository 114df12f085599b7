"""A flat-footed walker's ankle push-off in the compliant-contact view
(configs/flat_feet_push_off.yaml): the rigid view's torque as a force pair at the stance
ankle, switched on at the stance heel's lift-off (toe loaded) and off at the swing foot's
touchdown; the power terms of its ledger add up to dE/dt (ankle torque, ankle dampers,
contact forces: every sink named); over more than 10 heel strikes the contact run keeps
the rigid gait's step period within 3 % and its ledger closes to 1e-4 of the kinetic
energy."""

from pathlib import Path

import numpy as np
import pytest

from walkerlab.config import load_scene
from walkerlab.models.contact.actuation import ANKLE_WORK_NAMES, powered_rhs
from walkerlab.models.contact.scene import contact_setup
from walkerlab.walker.plant import Plant

SCENE = Path(__file__).resolve().parents[2] / "configs" / "flat_feet_push_off.yaml"


@pytest.fixture(scope="module")
def rigid():
    import walkerlab as wl

    w = wl.Walker.from_scene(load_scene(SCENE))
    return w, w.fixed_point()


@pytest.fixture(scope="module")
def contact_walker(rigid):
    from walkerlab.analysis.contact.sim import initial_state_from_ideal

    _, gait = rigid
    sc = load_scene(SCENE)
    walker, _ = contact_setup(sc, plant=Plant.from_scene(sc)).build(gait.x, 4)
    return walker, initial_state_from_ideal(walker, gait.x)


@pytest.mark.slow  # in `pytest -m slow`: the quick suite keeps to its CPU budget
def test_the_ankle_torque_is_a_force_pair_at_the_stance_ankle(contact_walker):
    """On a state in heel off (the stance foot turned 0.1 rad toe down from the leg's
    perpendicular, the legs moving): the push-off adds M^-1 tau (e_foot - e_leg) to the
    accelerations of the stance leg (leg2) with tau = -k_po (a - r_po) - tau_0, a = foot
    angle - leg angle, as the rigid view; off, it adds nothing."""
    walker, x0 = contact_walker
    acts = walker.actuators
    names = walker.coordinate_names()
    i_f, i_l = names.index("leg2_foot_angle"), names.index("leg2_angle")
    n = walker.nq
    x = x0.copy()
    x[i_f] = x[i_l] - 0.1
    x[n + i_f] = x[n + i_l] - 3.0
    off, _ = powered_rhs(walker, x, 1, ankle=False)
    on, p = powered_rhs(walker, x, 1, ankle=True)
    np.testing.assert_array_equal(off, walker.rhs(0.0, x))
    tau = -acts.ankle.stiffness_n_m_per_rad * (-0.1 - acts.ankle.rest_angle_rad) \
        - acts.ankle.constant_n_m
    assert tau == pytest.approx(-25.0)
    e = np.zeros(n)
    e[i_f], e[i_l] = 1.0, -1.0
    np.testing.assert_allclose(on[n:] - off[n:],
                               np.linalg.solve(walker.mass_matrix(x), tau * e), rtol=1e-12)
    assert p[0] == pytest.approx(tau * -3.0) and p[1] == 0.0  # tau < 0 turning toe down


@pytest.mark.parametrize("ankle", [False, True])
def test_the_ledger_powers_add_up_to_the_energy_rate(contact_walker, ankle):
    """dE/dt (central difference of the kinetic + potential energy along the powered
    flow, h = 1e-6 s) equals the sum of the ledger's powers, the ankle dampers' and the
    contact forces' named, on the rigid gait's start (heel contact, both feet's ankles
    turning) with the push-off on and off (relative 1e-6: the difference's error)."""
    walker, x0 = contact_walker
    x = x0.copy()
    dx, p = powered_rhs(walker, x, 1, ankle=ankle)
    assert len(p) == len(ANKLE_WORK_NAMES)
    h = 1e-6
    E = [walker.energies(x + s * h * dx)["total"][0] for s in (-1, 1)]
    rate = (E[1] - E[0]) / (2 * h)
    assert p[2] < 0.0  # the ankle dampers dissipate
    assert rate == pytest.approx(np.sum(p), rel=1e-6, abs=1e-6 * np.sum(np.abs(p)))


@pytest.fixture(scope="module")
def walk(rigid):
    """The shipped scene's contact run: 11 heel strikes from the rigid gait."""
    from walkerlab.analysis.contact.sim import simulate_from

    _, gait = rigid
    sc = load_scene(SCENE)
    walker, res, _, _ = simulate_from(contact_setup(sc, plant=Plant.from_scene(sc)), gait.x,
                                      gait.step_period)
    return walker, res


@pytest.mark.slow  # one contact run of 11 heel strikes on solve_ivp: ~60 s CPU (4-8 min wall
# on the shared 2-core machine)
def test_contact_step_period_and_ledger_of_the_ankle_push_off(rigid, walk):
    """More than 10 heel strikes at the rigid gait's step period (within 3 %); E(t) - E(0)
    = ankle push-off + ankle dampers + contact work at every sample, to 1e-4 of the kinetic
    energy; the push-off does positive work, the dampers and the contact forces take it."""
    _, gait = rigid
    walker, res = walk
    hs = np.asarray(res.heel_strike_times)
    assert len(hs) >= 11, res.message
    T = np.mean(np.diff(hs))
    assert abs(T / gait.step_period - 1.0) < 0.03, (T, gait.step_period)
    assert res.work is not None and res.work.shape == (len(res.t), len(ANKLE_WORK_NAMES))
    E = walker.energies(res.x)["total"]
    resid = (E - E[0]) - res.work.sum(axis=1)
    ke = float(walker.energies(res.x[:1])["kinetic"][0])
    assert np.max(np.abs(resid)) < 1e-4 * ke
    w = dict(zip(ANKLE_WORK_NAMES, res.work[-1]))
    assert w["ankle_torque_positive"] > 10.0 and w["damper"] < -5.0 and w["contact"] < 0.0
