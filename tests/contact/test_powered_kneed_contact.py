"""A hip torque on a kneed walker in the compliant-contact view (configs/kneed.yaml's walker
and contact law): it acts between the thighs (``+tau`` on the swing thigh's absolute angle,
``-tau`` on the stance thigh's, nothing on the shanks), its power is ``tau (omega_swing_thigh
- omega_stance_thigh)``, the energy ledger of a run closes with the knee stops' work as a
term of its own, and the kneed optimum's contact replay (configs/kneed_optimal.yaml, the
passive gait with a zero torque) steps at the rigid gait's period within 3 %."""

from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from walkerlab.api.scenes import with_changes
from walkerlab.config import load_scene
from walkerlab.models.contact.actuation import KNEE_WORK_NAMES, powered_rhs
from walkerlab.models.contact.scene import contact_setup
from walkerlab.walker.plant import Plant

CONFIGS = Path(__file__).resolve().parents[2] / "configs"
#: a small constant hip torque with a damper on the hip angle's rate [N m, N m s/rad]
LAW = {"constant_n_m": 0.02, "damping_n_m_s_per_rad": 0.05}


def _scene(law=LAW, **changes):
    base = load_scene(CONFIGS / "kneed.yaml")
    return with_changes(base, {"walker.actuation": {"torques": [{"joint": "hip", "law": law}]},
                               "contact_sim": {"n_strides": 1, "sample_rate_hz": 500},
                               **changes})


@pytest.fixture(scope="module")
def gait():
    import walkerlab as wl

    return wl.Walker.from_scene(load_scene(CONFIGS / "kneed.yaml")).fixed_point()


def test_the_hip_torque_acts_between_the_thighs(gait):
    """At the gait's start (leg2 in stance): the generalised force ``M (ddq - ddq_passive)``
    is ``+tau`` on leg1's thigh, ``-tau`` on leg2's, zero elsewhere; its power is ``tau
    (omega_leg1_thigh - omega_leg2_thigh)`` and ``Q . dq``; the knee stops' power is the
    ledger's last term."""
    from walkerlab.analysis.contact.sim import scene_start

    sc = _scene()
    walker, x, _, _ = scene_start(contact_setup(sc, plant=Plant.from_scene(sc)), gait.x, 1)
    n, names = walker.nq, walker.coordinate_names()
    th1, th2 = names.index("leg1_thigh_angle"), names.index("leg2_thigh_angle")
    assert walker.actuators.knee and walker.actuators.work_names == KNEE_WORK_NAMES
    dx, p = powered_rhs(walker, x, stance=1)
    Q = walker.mass_matrix(x) @ (dx[n:] - np.asarray(walker.rhs(0.0, x))[n:])
    ddelta = x[n + th1] - x[n + th2]
    tau = LAW["constant_n_m"] - LAW["damping_n_m_s_per_rad"] * ddelta
    expect = np.zeros(n)
    expect[th1], expect[th2] = tau, -tau
    assert np.allclose(Q, expect, rtol=0, atol=1e-12)  # M's condition: ~1e-14 relative
    assert p[0] + p[1] == pytest.approx(tau * ddelta, rel=1e-12)
    assert p[0] + p[1] == pytest.approx(Q @ x[n:], rel=1e-9)
    knee = walker.knee_stop_quantities(x[None])
    assert p[4] == pytest.approx(sum(knee[k]["power"][0] for k in knee), rel=1e-12, abs=0.0)


def test_the_kneed_ledger_closes_with_the_knee_stop_term(gait):
    """E(t) - E(0) = hip-torque + contact + knee-stop work at every sample of one step and
    the next touchdown, to 1e-4 of the kinetic energy (measured 1.7e-7: the integrator's
    tolerance); the torque does work both ways, the knee stops and contacts take energy
    out, no push-off."""
    from walkerlab.analysis.contact.sim import simulate_from

    sc = _scene(**{"contact_sim.t_final_s": 0.7})
    walker, res, _, _ = simulate_from(contact_setup(sc,
            plant=Plant.from_scene(sc)), gait.x, gait.step_period, strides=1)
    assert res.work.shape == (len(res.t), len(KNEE_WORK_NAMES))
    assert len(res.heel_strike_times) >= 1, res.message
    E = walker.energies(res.x)["total"]
    ke = float(walker.energies(res.x[:1])["kinetic"][0])
    assert np.max(np.abs((E - E[0]) - res.work.sum(axis=1))) < 1e-4 * ke
    w = dict(zip(KNEE_WORK_NAMES, res.work[-1]))
    assert w["hip_torque_positive"] > 0.0 > w["hip_torque_negative"]
    assert w["push_off"] == 0.0 and w["contact"] < 0.0 and w["knee_stop"] < 0.0


def test_a_kneed_walker_takes_a_push_off_and_the_periodic_gait():
    """A push-off on knees and the contact periodic gait (refused before issue 48's
    contact actuation) are carried."""
    sc1 = _scene(**{"walker.actuation.push_off": {"impulse_n_s": 0.1}})
    assert contact_setup(sc1, plant=Plant.from_scene(sc1)
                         ).actuators.spec.push_off is not None
    sc = _scene(**{"contact_sim.periodic_gait": True})
    assert contact_setup(sc, plant=Plant.from_scene(sc)).actuators is not None


def test_the_kneed_optimums_contact_replay_keeps_its_period(gait):
    """configs/kneed_optimal.yaml's contact replay with the optimum's torque (zero: the
    optimum is the passive gait) from the gait's start, one stride: the mean step period
    within 3 % of the rigid one (measured +1.99 %: the first two steps' start-up transient,
    configs/kneed.yaml's note; optimize's own replay of the collocated torque over 2
    strides: +1.26 %)."""
    from walkerlab.optimal.replay.contact import contact_replay_phased

    T = gait.step_period
    res = SimpleNamespace(t=np.array([0.0, T / 2, T]), u=np.zeros(3), x=gait.x[None],
                          phase_start=np.array([0]), phase_duration_s=np.array([T]),
                          step_period_s=T)
    optimal = load_scene(CONFIGS / "kneed_optimal.yaml")
    period, outcome = contact_replay_phased(optimal, res, plant=Plant.from_scene(optimal))
    assert outcome == "heel_strike"
    assert abs(period / T - 1.0) < 0.03, period


@pytest.mark.slow  # in `pytest -m slow`: the quick suite keeps to its CPU budget
def test_contact_sim_stores_the_knee_stop_work(tmp_path):
    """``walkerlab contact-sim`` on a kneed walker with a hip actuator (a zero torque law, so
    that the rigid gait it starts from is the passive one; 0.7 s): the artifact's ledger
    carries ``knee_stop`` beside the other terms and closes (as the run's)."""
    import yaml
    from typer.testing import CliRunner

    from walkerlab.cli import app
    from walkerlab.io.schemas.contact_sim import load_contact_sim

    raw = yaml.safe_load((CONFIGS / "kneed.yaml").read_text())
    raw["walker"]["actuation"] = {"torques": [{"joint": "hip", "law": {}}]}
    raw["contact_sim"] = {"n_strides": 1, "sample_rate_hz": 500, "t_final_s": 0.7}
    path = tmp_path / "kneed_hip.yaml"
    path.write_text(yaml.safe_dump(raw))
    r = CliRunner().invoke(app, ["contact-sim", str(path), "--runs-dir", str(tmp_path)])
    assert r.exit_code == 0, r.output
    led = load_contact_sim(tmp_path / "kneed_hip" / "contact_sim.h5").ledger
    assert set(KNEE_WORK_NAMES) <= set(led) and led["knee_stop"][-1] < 0.0
    assert np.max(np.abs(led["residual"])) < 1e-5  # J (kinetic energy ~0.9 J; 1.7e-7 rel.)
