"""The contact view's one actuation for every walker (issue 48 item 1): joint torques as
generalised forces on the floating view's absolute link angles (``+tau`` on a joint's second
link, ``-tau`` on its first; the roles follow the stance leg), the push-off pulse at the
trailing foot's contact point (point foot; an arc foot's material point at its rolling
contact; a flat foot's toe, its ankle held) along the line to the hip, and the rigid gait's
step period and a closed energy ledger on an arc-footed, a kneed and a flat-footed walker."""

from pathlib import Path

import numpy as np
import pytest

from walkerlab.api.scenes import with_changes
from walkerlab.config import load_scene
from walkerlab.models.contact.actuation import powered_rhs
from walkerlab.models.contact.scene import ContactSceneError, contact_setup
from walkerlab.walker.plant import Plant

CONFIGS = Path(__file__).resolve().parents[2] / "configs"

ARC = ("round_feet.yaml", {"slope.angle_rad": 0.005,
                           "walker.actuation": {"push_off": {"impulse_n_s": 0.04}}})
KNEED = ("kneed.yaml", {"slope.angle_rad": 0.045,
                        "walker.actuation": {"push_off": {"impulse_n_s": 0.01}}})
#: flat feet with a hip spring and a toe push-off
FLAT = ("flat_feet.yaml", {"walker.actuation": {
    "push_off": {"impulse_n_s": 0.05},
    "torques": [{"joint": "hip", "law": {"stiffness_n_m_per_rad": 2.0}}]},
    "terrain.patch_width_m": 0.5})


def _scene(case, strides=2, **more):
    name, changes = case
    return with_changes(load_scene(CONFIGS / name), {
        **changes, "contact_sim": {"n_strides": strides, "sample_rate_hz": 1000}, **more})


def test_every_actuator_the_walker_allows_is_carried():
    """What the contact view refused for lack of code is carried: a push-off on arc feet,
    on knees (with knee and hip torques), on flat feet beside hip torques and an ankle
    push-off, on a free-jointed biped; a joint the walker lacks is one line naming it."""
    knee = {"joint": "stance_knee", "law": {"constant_n_m": 0.1}}
    for case in (ARC, (KNEED[0], {"walker.actuation": {
            "push_off": {"impulse_n_s": 0.01},
            "torques": [knee, {"joint": "hip", "law": {"constant_n_m": 0.01}}]}}),
            (FLAT[0], {"walker.actuation": {**FLAT[1]["walker.actuation"],
                                            "ankle_push_off": {"constant_n_m": 5.0}}}),
            ("rabbit.yaml", {"walker.actuation.push_off": {"impulse_n_s": 1.0}})):
        sc = _scene(case)
        acts = contact_setup(sc, plant=Plant.from_scene(sc)).actuators
        assert acts is not None and acts.spec.push_off is not None
    bad = (KNEED[0], {"walker.actuation": {"torques": [{"joint": "stance_ankle",
                                                        "law": {}}]}})
    with pytest.raises(ContactSceneError, match=r"^scene .*walker\.actuation\.torques\.0\."
                       r"joint: stance_ankle is not a joint of this walker[^\n]*$"):
        sc = _scene(bad)
        contact_setup(sc, plant=Plant.from_scene(sc))


def test_a_knee_torque_is_a_generalised_force_on_the_stance_shank_and_thigh():
    """A constant ``stance_knee`` torque: ``M (ddq - ddq_passive)`` is ``+tau`` on the
    stance leg's shank, ``-tau`` on its thigh, 0 elsewhere (round-off: M's condition), for
    either leg in stance; its power ``tau (omega_shank - omega_thigh)``."""
    import walkerlab as wl
    from walkerlab.analysis.contact.sim import scene_start

    tau = 0.3
    sc = _scene((KNEED[0], {"walker.actuation": {"torques": [
        {"joint": "stance_knee", "law": {"constant_n_m": tau}}]}}))
    gait = wl.Walker.from_scene(load_scene(CONFIGS / KNEED[0])).fixed_point()
    walker, x, _, _ = scene_start(contact_setup(sc, plant=Plant.from_scene(sc)), gait.x, 1)
    n, names = walker.nq, walker.coordinate_names()
    for stance in (1, 0):
        dx, p = powered_rhs(walker, x, stance=stance)
        Q = walker.mass_matrix(x) @ (dx[n:] - np.asarray(walker.rhs(0.0, x))[n:])
        leg = f"leg{stance + 1}"
        sh, th = names.index(f"{leg}_shank_angle"), names.index(f"{leg}_thigh_angle")
        expect = np.zeros(n)
        expect[sh], expect[th] = tau, -tau
        assert np.allclose(Q, expect, rtol=0, atol=1e-11)
        assert p[0] + p[1] == pytest.approx(tau * (x[n + sh] - x[n + th]), rel=1e-12)


def _run(case, strides):
    """Rigid gait and contact run (from it) of a case: ``(rigid period, heel-strike
    periods, ledger residual / mean kinetic energy, work names, final work)``."""
    import walkerlab as wl
    from walkerlab.analysis.contact.sim import simulate_from

    sc = _scene(case, strides)
    g = wl.Walker.from_scene(sc).fixed_point()
    walker, res, _, _ = simulate_from(contact_setup(sc,
            plant=Plant.from_scene(sc)), g.x, g.step_period, strides=strides)
    assert res.outcome.kind == "heel_strike", res.message
    E = walker.energies(res.x)
    resid = (E["total"] - E["total"][0]) - res.work.sum(axis=1)
    return (g.step_period, np.diff(res.heel_strike_times),
            float(np.abs(resid).max() / E["kinetic"].mean()),
            dict(zip(walker.actuators.work_names, res.work[-1])))


@pytest.mark.slow  # ~30 s: 5 heel strikes of the round-footed walker on solve_ivp
def test_a_pushed_arc_footed_walker_steps_at_its_rigid_period():
    """round_feet's walker at slope 0.005 with a 0.04 N s push-off (the pulse at the arc's
    material point at the rolling contact): every step within 3 % of the rigid gait's
    2.4297 s (measured +1.4..+2.0 %: the compliant collision), the ledger closed to 1e-4 of
    the kinetic energy (measured 2.4e-6), the push-off doing positive work."""
    T, periods, resid, work = _run(ARC, 2)
    assert len(periods) >= 4 and np.all(np.abs(periods / T - 1) < 0.03), periods / T
    assert resid < 1e-4 and work["push_off"] > 0.0 and work["contact"] < 0.0


@pytest.mark.slow  # ~25 s
def test_a_pushed_kneed_walker_steps_at_its_rigid_period():
    """configs/kneed.yaml's walker at slope 0.045 with a 0.01 N s push-off: the mean step
    period within 3 % of the rigid gait's 0.5330 s (measured +2.8, +3.1, +2.5, +1.7 % over
    the first four steps, the start-up transient of the passive kneed walker's contact run
    too: configs/kneed.yaml's note), the ledger with the knee stops' term closed to 1e-4
    (measured 3.4e-6)."""
    T, periods, resid, work = _run(KNEED, 2)
    assert len(periods) >= 4 and abs(np.mean(periods) / T - 1) < 0.03, periods / T
    assert resid < 1e-4 and work["knee_stop"] < 0.0 and work["contact"] < 0.0


@pytest.mark.slow  # ~2 min: two rigid gaits, two contact runs of flat feet
def test_flat_feet_with_a_hip_torque_and_a_toe_push_off():
    """configs/flat_feet.yaml's walker with a hip spring and a 0.05 N s push-off at the
    trailing toe (0.5 m patches: on the scene's 0.6 m ones a heel enters a patch from its
    side): the ledger (hip torque both ways, push-off, dampers, contacts) closes to 1e-4 of
    the kinetic energy, and after the first step (the start-up transient: -5 %) the steps
    come within 3 % of the rigid gait, which keeps its double support with torques
    (measured +2.7, +1.0, +2.2 %)."""
    T, periods, resid, work = _run(FLAT, 2)
    assert resid < 1e-4 and work["push_off"] > 0.0 and work["damper"] < 0.0
    assert work["hip_torque_positive"] > 0.0 > work["hip_torque_negative"]
    assert np.all(np.abs(periods[1:] / T - 1) < 0.03), periods / T
