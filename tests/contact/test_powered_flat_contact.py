"""A hip torque on a flat-footed walker in the compliant-contact view (configs/flat_feet.yaml's
walker and contact law): it acts between the legs (``+tau`` on the swing leg's absolute
angle, ``-tau`` on the stance leg's, nothing on the feet), checked against the virtual work
of a force pair written here from the legs' geometry alone; its power is ``tau (omega_swing
- omega_stance)``; the power terms of the ledger (hip torque, ankle dampers, contacts) add up
to dE/dt, and a run's ledger closes; the flat-footed optimum's contact replay."""

from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from walkerlab.api.scenes import with_changes
from walkerlab.config import load_scene
from walkerlab.models.contact.actuation import FLAT_HIP_WORK_NAMES, powered_rhs
from walkerlab.models.contact.scene import contact_setup
from walkerlab.walker.plant import Plant

CONFIGS = Path(__file__).resolve().parents[2] / "configs"
#: a constant hip torque with a damper on the hip angle's rate [N m, N m s/rad]
LAW = {"constant_n_m": 0.5, "damping_n_m_s_per_rad": 0.2}


def _scene(law=LAW, **changes):
    base = load_scene(CONFIGS / "flat_feet.yaml")
    return with_changes(base, {"walker.actuation": {"torques": [{"joint": "hip", "law": law}]},
                               "contact_sim": {"n_strides": 1, "sample_rate_hz": 500},
                               **changes})


@pytest.fixture(scope="module")
def gait():
    import walkerlab as wl

    return wl.Walker.from_scene(load_scene(CONFIGS / "flat_feet.yaml")).fixed_point()


@pytest.fixture(scope="module")
def start(gait):
    """The contact walker with the hip torque and its state at the rigid gait's start (leg2
    in stance, heel contact), the legs and feet moving."""
    from walkerlab.analysis.contact.sim import scene_start

    sc = _scene()
    walker, x, _, _ = scene_start(contact_setup(sc, plant=Plant.from_scene(sc)), gait.x, 1)
    return walker, x


def _leg_point(q, leg: int, r: float):
    """A point ``r`` [m] from the hip along leg ``leg``'s (0, 1) axis, written here from the
    geometry (the hip at ``(q0, q1)``, absolute leg angles ``q2``, ``q3`` from the slope's
    normal, ``(sin, -cos)``), complex-safe."""
    th = q[2 + leg]
    return np.array([q[0] + r * np.sin(th), q[1] - r * np.cos(th)])


def _virtual_work_force(q, tau: float, swing: int, r: float = 0.5) -> np.ndarray:
    """Generalised force (nq,) of a hip actuator as forces: on each leg a force ``tau / r``
    perpendicular to it at ``r`` from the hip (turning the swing leg the way its angle
    grows, the stance leg the other way) and their sum's opposite at the hip, so the net
    force and the net moment are zero; ``Q_j = sum_k F_k . d p_k / d q_j`` with the
    derivatives by complex step (exact to round-off)."""
    n = q.size
    pts = [lambda z, leg=leg: _leg_point(z, leg, r) for leg in (0, 1)]
    pts.append(lambda z: np.array([z[0], z[1]]))  # the hip
    forces = []
    for leg, sign in ((swing, 1.0), (1 - swing, -1.0)):
        th = q[2 + leg]
        forces.append(sign * tau / r * np.array([np.cos(th), np.sin(th)]))
    forces = [forces[0], forces[1]] if swing == 0 else [forces[1], forces[0]]
    forces.append(-(forces[0] + forces[1]))
    Q = np.zeros(n)
    h = 1e-30
    for j in range(n):
        dq = q.astype(complex)
        dq[j] += 1j * h
        Q[j] = sum(F @ (p(dq).imag / h) for p, F in zip(pts, forces))
    return Q


def test_the_leg_points_written_here_are_the_generated_ones(start):
    """The geometry the virtual work is computed from is the generated walker's (each leg's
    point mass, 0.5 m from the hip)."""
    walker, x = start
    pts = walker.points(x)
    for leg in (0, 1):
        got = np.asarray(pts[f"leg{leg + 1}_mass"], float).ravel()
        np.testing.assert_allclose(_leg_point(x[:walker.nq], leg, 0.5), got, rtol=0,
                                   atol=1e-14)


def test_the_hip_torque_is_the_virtual_work_of_a_force_pair_between_the_legs(start):
    """At the gait's start (leg2 in stance): the generalised force the equations receive,
    ``M (ddq - ddq_passive)``, equals the virtual work of the force pair
    (:func:`_virtual_work_force`): ``+tau`` on leg1's angle, ``-tau`` on leg2's, nothing on
    the hip's position or the feet (1e-12 N m: M's round-off; measured ~1e-15); the
    actuator's own generalised force equals it to round-off; its power is ``tau
    (omega_leg1 - omega_leg2) = Q . dq``."""
    walker, x = start
    n = walker.nq
    acts = walker.actuators
    assert acts.work_names == FLAT_HIP_WORK_NAMES and acts.foot is not None
    dx, p = powered_rhs(walker, x, stance=1)
    Q = walker.mass_matrix(x) @ (dx[n:] - np.asarray(walker.rhs(0.0, x))[n:])
    names = walker.coordinate_names()
    ddelta = x[n + names.index("leg1_angle")] - x[n + names.index("leg2_angle")]
    tau = LAW["constant_n_m"] - LAW["damping_n_m_s_per_rad"] * ddelta
    Qv = _virtual_work_force(x[:n], tau, swing=0)
    assert Qv[names.index("leg1_angle")] == pytest.approx(tau, rel=1e-14)
    np.testing.assert_allclose(Q, Qv, rtol=0, atol=1e-12)
    np.testing.assert_allclose(acts.hip_torque(x, 1)[0], Qv, rtol=0, atol=1e-15)
    assert p[0] + p[1] == pytest.approx(tau * ddelta, rel=1e-12)
    assert p[0] + p[1] == pytest.approx(Q @ x[n:], rel=1e-9)
    # the roles swapped (leg1 in stance): the pair turns the other way
    np.testing.assert_allclose(acts.hip_torque(x, 0)[0],
                               _virtual_work_force(x[:n], tau_other := LAW["constant_n_m"]
                                                   + LAW["damping_n_m_s_per_rad"] * ddelta,
                                                   swing=1), rtol=0, atol=1e-15)
    assert tau_other != tau


def test_the_ledger_powers_add_up_to_the_energy_rate(start):
    """dE/dt (central difference of the kinetic + potential energy, the ankle springs' in
    it, along the powered flow, h = 1e-6 s) equals the sum of the ledger's powers (hip
    torque, ankle dampers, contact forces) at the gait's start (relative 1e-6: the
    difference's error); the dampers dissipate."""
    walker, x = start
    dx, p = powered_rhs(walker, x, 1)
    assert len(p) == len(FLAT_HIP_WORK_NAMES)
    h = 1e-6
    E = [walker.energies(x + s * h * dx)["total"][0] for s in (-1, 1)]
    rate = (E[1] - E[0]) / (2 * h)
    assert p[2] < 0.0
    assert rate == pytest.approx(np.sum(p), rel=1e-6, abs=1e-6 * np.sum(np.abs(p)))


def test_flat_hip_torques_take_push_offs_and_the_periodic_gait():
    """Hip torques on flat feet beside an ankle push-off and a push-off (refused before
    issue 48's contact actuation) are carried; the contact periodic gait is not refused."""
    for extra in ({"walker.actuation.ankle_push_off": {"constant_n_m": 10.0}},
                  {"walker.actuation.push_off": {"impulse_n_s": 0.1}},
                  {"contact_sim.periodic_gait": True}):
        sc = _scene(**extra)
        assert contact_setup(sc, plant=Plant.from_scene(sc)).actuators is not None


def test_the_flat_hip_ledger_closes(gait):
    """E(t) - E(0) = hip-torque + ankle-damper + contact work at every sample of one step
    and the next touchdown (LAW, 0.9 s: heel contact, foot slap, foot flat, heel off, heel
    strike; ~3 s CPU), to 1e-4 of the kinetic energy (12.2 J; measured 3.2e-6 of it: LSODA
    at rtol 1e-8, a flat foot's rates at 100 times atol); the torque does work both ways,
    the dampers and contacts take energy out."""
    from walkerlab.analysis.contact.sim import simulate_from

    sc = _scene(**{"contact_sim.t_final_s": 0.9})
    walker, res, _, _ = simulate_from(contact_setup(sc,
            plant=Plant.from_scene(sc)), gait.x, gait.step_period, strides=1)
    assert res.work.shape == (len(res.t), len(FLAT_HIP_WORK_NAMES))
    assert len(res.heel_strike_times) >= 1, res.message
    E = walker.energies(res.x)["total"]
    ke = float(walker.energies(res.x[:1])["kinetic"][0])
    assert np.max(np.abs((E - E[0]) - res.work.sum(axis=1))) < 1e-4 * ke
    w = dict(zip(FLAT_HIP_WORK_NAMES, res.work[-1]))
    assert w["hip_torque_positive"] > 0.0 > w["hip_torque_negative"]
    assert w["damper"] < 0.0 and w["contact"] < 0.0


@pytest.mark.slow
def test_contact_sim_of_a_flat_footed_walker_with_a_hip_torque_closes_its_ledger(tmp_path):
    """``walkerlab contact-sim`` on flat feet with a hip actuator (LAW, 0.9 s; the whole
    stage: ~4 min wall at a load of 15 on 2 cores): the artifact's ledger carries the hip
    torque's work both ways, the ankle dampers' and the contacts', and closes (as the
    run's, :func:`test_the_flat_hip_ledger_closes`)."""
    import yaml
    from typer.testing import CliRunner

    from walkerlab.cli import app
    from walkerlab.io.schemas.contact_sim import load_contact_sim

    raw = yaml.safe_load((CONFIGS / "flat_feet.yaml").read_text())
    raw["walker"]["actuation"] = {"torques": [{"joint": "hip", "law": LAW}]}
    raw["contact_sim"] = {"n_strides": 1, "sample_rate_hz": 500, "t_final_s": 0.9}
    path = tmp_path / "flat_hip.yaml"
    path.write_text(yaml.safe_dump(raw))
    r = CliRunner().invoke(app, ["contact-sim", str(path), "--runs-dir", str(tmp_path)])
    assert r.exit_code == 0, r.output
    c = load_contact_sim(tmp_path / "flat_hip" / "contact_sim.h5")
    led = c.ledger
    assert set(FLAT_HIP_WORK_NAMES) <= set(led) and "push_off" not in led
    assert led["hip_torque_positive"][-1] > 0.0 > led["hip_torque_negative"][-1]
    assert led["damper"][-1] < 0.0 and led["contact"][-1] < 0.0
    assert len(c.heel_strike_times) >= 1
    assert np.max(np.abs(led["residual"])) < 5e-4  # J
    from walkerlab.report.contact_sections import contact_section

    text = " ".join(contact_section(load_scene(path), {"contact-sim": c}))
    assert "hip torques +" in text and "ankle dampers" in text and "push-off" not in text


def optimum_gait():
    """(x (6,), step period [s]) of configs/flat_feet.yaml's rigid walker without its double
    support (``make_rigid_walker(data, double_support=False)``): the walker the phased
    transcription optimises and whose fixed point ``walkerlab optimize`` starts from
    (:func:`walkerlab.optimal.driver.optimize_scene`), so the least-effort optimum's gait
    (0.7576 s; 0.8102 s with the double support, ``walkerlab fixedpoint``'s)."""
    from walkerlab.analysis.gait.scene import solve_scene
    from walkerlab.models.hybrid.rigid import make_rigid_walker
    from walkerlab.walker.description import walker_data

    scene = load_scene(CONFIGS / "flat_feet.yaml")
    data = walker_data(scene.walker, scene.slope.phi_rad)
    r = solve_scene(scene, False, walker=make_rigid_walker(data, double_support=False),
                    plant=Plant.from_scene(scene))[1]
    return np.asarray(r.gait.result.x, float), float(r.gait.result.period_s)


def passive_contact_period(x, period_s: float, strides: int = 1) -> float:
    """Mean step period [s] of configs/flat_feet_optimal.yaml's passive contact model (its
    0.1 kg feet: configs/flat_feet.yaml's contact run has 0.01 kg ones) from the rigid
    state ``x`` (6,) (a gait's start of step period ``period_s`` [s]) over the
    ``2 strides + 1`` steps a powered replay of ``strides`` makes (the compiled passive run,
    < 1 s CPU; ``start: ideal``, from ``x`` as the replay starts, not the passive flat
    feet's default mid-stance): the reference the flat-footed contact replays are read
    against."""
    from walkerlab.analysis.contact.sim import simulate_from

    scene = load_scene(CONFIGS / "flat_feet_optimal.yaml")
    steps = 2 * strides + 1
    sc = with_changes(scene, {"contact_sim": {"n_strides": strides + 1, "sample_rate_hz": 500,
                                              "start": "ideal",
                                              "t_final_s": (steps + 1.6) * period_s}})
    _, res, _, _ = simulate_from(contact_setup(sc,
            plant=Plant.from_scene(sc)), x, period_s, strides=strides + 1)
    hs = np.asarray(res.heel_strike_times, float)[:steps + 1]
    assert hs.size == steps + 1, res.message
    return float(np.mean(np.diff(hs)))


@pytest.mark.slow
def test_the_flat_feet_optimums_contact_replay():
    """configs/flat_feet_optimal.yaml's contact replay of its optimum (the passive gait of
    the rigid walker without double support, :func:`optimum_gait`: a zero torque) from the
    gait's start, one stride (3 steps; ~15 s CPU): it walks, and its mean step period is the
    passive contact model's over the same steps (0.8121 s) within 1e-4 (relative, measured
    1.7e-5: the powered run's LSODA against the passive run's compiled BDF, each at rtol
    1e-8, the runs' heel strikes read on 2 ms samples) - the torque path adds nothing when
    the torque is zero.  Against the rigid optimum's 0.7576 s it is +7.2 %: the flat-footed
    contact model itself walks slower than the rigid one (configs/flat_feet_optimal.yaml's
    note), so the issue's 3 % is not met here.  (Started instead from ``walkerlab
    fixedpoint``'s gait, which has the double support since the rigid model took it, the
    replay reads 0.79445 s against the passive run's 0.79461 s: a different start, not the
    optimum's.)"""
    from walkerlab.optimal.replay.contact import contact_replay_phased

    x, T = optimum_gait()
    res = SimpleNamespace(t=np.array([0.0, T / 2, T]), u=np.zeros(3), x=x[None],
                          phase_start=np.array([0]), phase_duration_s=np.array([T]),
                          step_period_s=T)
    optimal = load_scene(CONFIGS / "flat_feet_optimal.yaml")
    period, outcome = contact_replay_phased(optimal, res, strides=1,
                                            plant=Plant.from_scene(optimal))
    assert outcome == "heel_strike"
    assert period == pytest.approx(passive_contact_period(x, T, 1), rel=1e-4)
    assert 0.06 < period / T - 1.0 < 0.08


@pytest.mark.parametrize("outcome", ["heel_strike", "time_limit"])
def test_the_report_names_a_contact_replay_that_ended_short(outcome):
    """A contact replay that ran out of time after one step (its mean period then reads
    that step alone) is named as such in the report's optimize lines; a replay that made
    its strides is not."""
    import dataclasses

    from walkerlab.io.schemas.optimize import OptimizeData
    from walkerlab.report.figures_section import optimize_lines

    t = np.linspace(0.0, 0.75, 5)
    d = OptimizeData(t, {"a": t.copy()}, np.zeros(5), 0.75, 0.6, 0.0, 0.0, 1e-7,
                     np.array([0.4 + 0j]), True, "Solve_Succeeded", 15, 3.0, {"a": "rad"})
    d = dataclasses.replace(d, contact_step_period_s=0.794, contact_outcome=outcome)
    text = " ".join(optimize_lines(d))
    assert "step period 0.794" in text
    assert ("ended short of its strides: time_limit" in text) == (outcome == "time_limit")
