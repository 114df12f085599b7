"""Actuation of a walker in 3D on compliant contact: the hip torque pair on the legs' pitch
joints and the push-off pulse along the trailing leg (Kuo 2002), through the planar
walkers' contact actuators (walkerlab.models.contact.actuation).

* Against ``tests/independent/floating_3d_contact.py`` (Newton's law on the point masses,
  complex-step kinematics, no walkerlab code): the hip motor pair's generalised force from
  the virtual power of a torque about the hip axis on each leg against the pelvis
  (``tau (w_swing - w_stance) . R_p z``, the angular velocities from ``Rdot R^T``), and the
  push-off's from the trailing foot's Jacobian and the line to that leg's own hip; the
  actuated accelerations must be the reference's with either leg in stance.
* The powered 3D walk (configs/hip_width_powered.yaml: the hip-roll law, a hip spring and a
  push-off) in contact against its rigid gait, its energy ledger closed with the hip-roll
  law's work as a term of its own.
"""

from __future__ import annotations

import numpy as np
import pytest

from tests.independent.floating_3d_contact import Floating3DContact
from tests.test_contact_3d import (
    TO_REF,
    _contact_walker,
    _continuous,
    _from_ref,
    _states,
    _to_ref,
)
from walkerlab.config import ContactSettings, Scene, load_scene
from walkerlab.models.contact import assembly as A
from walkerlab.models.contact.actuation import powered_rhs
from walkerlab.models.contact.powered_data import powered_data

#: the hip spring and the push-off of configs/hip_width_powered.yaml
ACTUATION = {"push_off": {"impulse_n_s": 1.0},
             "torques": [{"joint": "hip", "law": {"stiffness_n_m_per_rad": 5.0}}]}


@pytest.fixture(scope="module")
def powered_hip_width():
    """configs/hip_width.yaml's walker (no hip-roll law) with :data:`ACTUATION`, on
    continuous ground under the ADAMS View defaults (the regimes of
    ``tests/test_contact_3d.STATES``): (contact walker, start state, reference, perm)."""
    base = load_scene("configs/hip_width.yaml").model_copy(
        update={"contact": ContactSettings()})
    d = base.model_dump(mode="json", exclude_none=True)
    d["walker"]["actuation"] = ACTUATION
    cw, x0 = _contact_walker(_continuous(Scene.model_validate(d)))
    assert cw.actuators is not None and not cw.actuators.flow_law
    P = dict(zip(cw.structure.param_names, cw.walker_params))
    PC = cw.contact_params
    law = {"k": PC[A.I_K], "e": PC[A.I_E], "cmax": PC[A.I_CMAX], "dmax": PC[A.I_DMAX],
           "mus": PC[A.I_MUS], "mud": PC[A.I_MUD], "vs": PC[A.I_VS], "vd": PC[A.I_VD],
           "tau": PC[A.I_TOR]}
    ref = Floating3DContact(P["g"], P["L"], P["gamma"], P["M_hip"], P["m_leg"],
                            P["a_leg"], P["w_hip"], law)
    perm = np.array([TO_REF[n] for n in cw.coordinate_names()])
    return cw, x0, ref, perm


def test_the_3d_hip_torque_and_push_off_move_the_walker_as_the_independent_model_says(
        powered_hip_width):
    """At the contact start state and four double-support states (feet slipping and
    spinning in every regime of the friction law), with leg1 or leg2 in stance and with or
    without a 40 N push-off pulse at the trailing foot: the hip spring's torque is ``-5
    (theta_swing - theta_stance)`` N m from the reference's pitches, and the actuated
    accelerations equal the reference's ``qdd + M^-1 (Q_hip + Q_push)`` (``Q_push`` with the
    moment about the normal that holds the trailing foot's spin, as the rigid foot's yaw
    is held through the impulse: the reference's spin Jacobian; the reference's
    velocity-product term is a central difference: 1e-8 relative, as the passive flow's
    test, measured <= 3e-11); the torque's power is ``tau (dtheta_sw - dtheta_st)`` and the
    pulse's ``F e . v_foot + lam w_n`` from the reference's kinematics (1e-9).  Both forces are
    resolved: either left out moves the accelerations by over 100 times the tolerance."""
    cw, x0, ref, perm = powered_hip_width
    acts = cw.actuators
    nq = len(perm)
    worst = 0.0
    for name, (xr, _) in _states(ref, x0, perm).items():
        q, dq = xr[:7], xr[7:]
        x = _from_ref(xr, perm)
        M = ref.mass_matrix(q)
        passive = ref.accelerations(xr)
        for stance in (1, 2):
            swing = 3 - stance
            tau = -5.0 * (q[4 + swing] - q[4 + stance])  # pitch1, pitch2 at 5, 6
            assert abs(acts.torques(x, stance - 1)[0] - tau) < 1e-12 * (1 + abs(tau))
            Q_hip = ref.hip_torque_force(q, tau, stance)
            # the pulse with the moment about the normal that holds the trailing foot's
            # spin through it (the rigid view's yaw-held foot): a M^-1 (Q_po + lam a) = 0
            Q_po = ref.push_force(q, 40.0, stance)
            a = ref.spin_jacobian(stance, q)
            lam = -(a @ np.linalg.solve(M, Q_po)) / (a @ np.linalg.solve(M, a))
            Q_po = Q_po + lam * a
            assert abs(a @ np.linalg.solve(M, Q_po)) < 1e-9 * np.max(np.abs(Q_po))
            for push in (None, (stance - 1, 40.0)):
                Q = Q_hip + (0.0 if push is None else Q_po)
                want = passive + np.linalg.solve(M, Q)
                dx, pw = powered_rhs(cw, x, stance - 1, push)
                got = _to_ref(dx, perm)[7:]
                err = np.max(np.abs(got - want)) / np.max(np.abs(want))
                worst = max(worst, err)
                assert err < 1e-8, (name, stance, push, err)
                # the actuators' share is resolved: leaving either force out is seen
                for part in (Q_hip, Q - Q_hip):
                    if np.any(part):
                        off = passive + np.linalg.solve(M, Q - part)
                        assert np.max(np.abs(off - want)) > 100 * 1e-8 * np.max(np.abs(want))
                p_tau = tau * (dq[4 + swing] - dq[4 + stance])
                assert abs((pw[0] + pw[1]) - p_tau) < 1e-9 * (1 + abs(p_tau))
                if push is not None:
                    r = ref.positions(q)
                    e = r[f"leg{stance}_hip"] - r[f"leg{stance}_foot"]
                    v = ref.jacobian(f"leg{stance}_foot", q) @ dq
                    p_po = 40.0 * (e / np.linalg.norm(e)) @ v + lam * (a @ dq)
                    assert abs(pw[2] - p_po) < 1e-9 * (1 + abs(p_po))
    assert worst > 0 and nq == 7


def test_the_3d_compiled_powered_rhs_is_the_reference_arithmetic(powered_hip_width):
    """The compiled right-hand side of the 3D walker's actuators (the actuation block, the
    generated ``hips`` for the push-off's line) gives :func:`powered_rhs`'s accelerations
    and powers to 1e-12, either leg in stance, with and without a pulse."""
    cw, x0, ref, perm = powered_hip_width
    data = powered_data(cw)
    rng = np.random.default_rng(5)
    for trial in range(4):
        x = x0 + rng.normal(0.0, 0.01, x0.size)
        stance = trial % 2
        push = (stance, 60.0) if trial >= 2 else None
        dx, pw = powered_rhs(cw, x, stance, push, 0.1)
        want = np.concatenate([dx, pw])
        out = np.empty(data.ny)
        y = np.concatenate([x, np.zeros(data.ny - x.size)])
        data.rhs(0.1, y, data.data(stance, 0.0, push), out)
        np.testing.assert_allclose(out, want, rtol=1e-12, atol=1e-12 * np.max(np.abs(want)))


@pytest.mark.slow
def test_the_powered_3d_walker_walks_and_finds_its_gait_in_contact_as_in_the_rigid_model(
        tmp_path):
    """``walkerlab contact-sim configs/hip_width_powered.yaml --strides 5`` (its scene asks
    for the contact periodic gait too), against the rigid gait the contact model does not
    compute:

    * the walk: at least 10 heel strikes, the last four steps' mean period within 1 % of
      the rigid step period (measured -0.23 %);
    * its ledger closes to the integrator's tolerance: ``E(t) - E(0)`` minus the works
      (hip spring, push-off, contact forces, the hip-roll law) below 2e-5 J over the run
      at rtol 1e-8 (measured 3.9e-6 J; 1.3e-7 J at rtol 1e-10; the hip-roll law's own term
      is 0.18 J a step, so a ledger without it would not close); the push-off pulse's work
      a step within 5 % of the rigid model's impulse (measured 0.0292 J against 0.0297 J:
      the 0.1 ms pulse takes over the foot's weight while it lasts; without the trailing
      foot's spin held through it, 0.0529 J); the positive work of the hip spring and the
      hip-roll law a step within 10 % of the rigid ledger's (which counts the law among
      the actuators: measured 0.735 J against 0.749 J);
    * the contact periodic gait (the stride map): step period and length within 1 % of
      the rigid ones (measured -0.23 %, -0.78 %), its largest multiplier but the heading's
      within 0.03 of the rigid stride's largest (0.662 against 0.668) and the heading's
      near-neutral (1.008 a stride)."""
    import h5py

    from walkerlab.stages import pipeline

    scene = load_scene("configs/hip_width_powered.yaml")
    out = pipeline.run("contact-sim", scene, tmp_path, strides=5)
    assert not out.failure
    with h5py.File(out.path) as f:
        periods = np.asarray(f["steps/period"][()], float)
        periods = periods[np.isfinite(periods)]
        strikes = int(f["summary/heel_strikes"][()])
        residual = np.abs(f["ledger/residual"][()]).max()
        works = set(f["ledger/work"])
        push = np.asarray(f["ledger/steps/push_off_work"][()])
        law = (f["ledger/work/hip_roll_positive"][()][-1]
               + f["ledger/work/hip_roll_negative"][()][-1]) / strikes
        pos = np.asarray(f["ledger/steps/actuator_work_positive"][()])
        g = f["periodic_gait"]
        assert bool(g["converged"][()])
        T_c, L_c = float(g["step_period"][()]), float(g["step_length"][()])
        mult = g["multipliers/real"][()] + 1j * g["multipliers/imag"][()]
        modes = [str(m) for m in g.attrs["multiplier_modes"]]
    with h5py.File(tmp_path / scene.name / "fixedpoint.h5") as f:
        T_r = float(f["step_period"][()])
        lam_r = f["floquet/variational/real"][()] + 1j * f["floquet/variational/imag"][()]
        L_r = float(np.mean(f["steps/length"][()]))
    with h5py.File(pipeline.run("simulate", scene, tmp_path, strides=1).path) as f:
        push_r = float(f["ledger/push_off_work"][()][0])
        pos_r = float(f["ledger/actuator_work_positive"][()][0])
    assert strikes >= 10
    assert abs(periods[-4:].mean() / T_r - 1) < 0.01
    assert {"hip_roll_positive", "hip_roll_negative", "push_off", "contact",
            "hip_torque_positive"} <= works
    assert residual < 2e-5 and abs(law) > 0.05
    assert np.all(np.abs(push / push_r - 1) < 0.05)
    # the positive work of the hip spring and the hip-roll law, as the rigid ledger counts it
    assert abs(pos[-4:].mean() / pos_r - 1) < 0.1
    assert abs(T_c / T_r - 1) < 0.01 and abs(L_c / L_r - 1) < 0.01
    heading = [abs(m) for m, name in zip(mult, modes) if name == "heading"]
    others = [abs(m) for m, name in zip(mult, modes) if name != "heading"]
    assert heading and abs(heading[0] - 1) < 0.02
    assert abs(max(others) - np.max(np.abs(lam_r))) < 0.03
