"""The one-step transcription's constraints and objectives on walkers whose step is a
sequence of phases (``walkerlab.optimal.phased_collocation``): the stance foot's ground
reaction (checked against an independent Newton-Euler computation and the rigid model's own
normal forces) in its friction cone, the cost of transport by slack variables, and starting
guesses read from artifacts."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from walkerlab.config import load_scene
from walkerlab.config.actuation import Actuation, JointTorque, TorqueLaw
from walkerlab.models.hybrid.actuated import actuate
from walkerlab.models.hybrid.rigid import make_rigid_walker
from walkerlab.walker.description import walker_data

CONFIGS = Path(__file__).resolve().parents[1] / "configs"
FLAT_ORDER = [("heel_contact:early_swing", "foot_slap", -1),
              ("foot_flat:early_swing", "midstance", 1),
              ("foot_flat:late_swing", "heel_off", -1),
              ("heel_off:late_swing", "heel_strike", -1)]


def _walker(name: str):
    scene = load_scene(CONFIGS / name)
    data = walker_data(scene.walker, scene.slope.phi_rad)
    return scene, data, make_rigid_walker(data)


@pytest.fixture(scope="module")
def kneed():
    pytest.importorskip("casadi")
    from walkerlab.optimal.phases import mode_functions

    scene, data, walker = _walker("kneed_optimal.yaml")
    return scene, data, walker, mode_functions(data, walker)


def _torqued(data, u: float):
    spec = Actuation(torques=[JointTorque(joint="hip", law=TorqueLaw(constant_n_m=u),
                                          max_torque_n_m=1e6)])
    return actuate(make_rigid_walker(data), data, spec)


def _com_acceleration(com, q, dq, qdd, r: float = 0.05, m: int = 32):
    """``d^2/dt^2 com(q(t))`` at ``t = 0`` where ``q(t) = q + t dq + t^2 qdd / 2``, exactly
    (to round-off ~1e-13): the Cauchy integral ``f''(0) = 2 / (2 pi i) oint f(z) / z^3 dz``
    on ``m`` points of the circle ``|z| = r`` (the trapezoidal rule, spectrally accurate for
    an analytic ``f``; Lyness & Moler 1967), with ``com`` (numpy, complex-safe) the rigid
    model's own generated point positions."""
    z = r * np.exp(2j * np.pi * np.arange(m) / m)
    vals = np.stack([com(q + zk * dq + 0.5 * zk ** 2 * qdd) for zk in z])  # (m, 2)
    return np.real(2.0 / m * np.sum(vals / z[:, None] ** 2, axis=0))


def _newton_euler(walker, data, x, qdd, shift=None):
    """The ground's resultant on the walker ``M (a_com + g y)`` [N] along the slope's normal
    and tangent, from the rigid model's point positions (``walker.points``, the masses by
    the ``m_<body>`` convention) and accelerations ``qdd`` (the rigid flow's); ``shift``:
    a point whose position is subtracted (the pinned point of another kinematics)."""
    p = walker.params
    n = x.size // 2
    pts0 = walker.points(walker.layout().zeros())
    masses = {"hip": float(p.get("M_hip", 0.0))}
    for name in pts0:
        for role in ("stance_", "swing_"):
            if name.startswith(role) and f"m_{name[len(role):]}" in p:
                masses[name] = float(p[f"m_{name[len(role):]}"])
    total = sum(masses.values())
    assert total == pytest.approx(float(walker.total_mass_kg), rel=1e-14)

    def com(qc):
        X = np.concatenate([qc, np.zeros(n)]).astype(complex)[:, None]
        pts = walker.points(walker.layout().state_rows(X))
        c = sum(m * np.asarray(pts[k]).ravel() for k, m in masses.items()) / total
        return c - (np.asarray(pts[shift]).ravel() if shift else 0.0)

    a = _com_acceleration(com, x[:n].astype(complex), x[n:].astype(complex),
                          np.asarray(qdd, complex))
    F = total * (a + np.array([0.0, float(data.gravity_m_per_s2)]))
    g = data.slope_rad
    return np.array([np.sin(g) * F[0] + np.cos(g) * F[1], np.cos(g) * F[0] - np.sin(g) * F[1]])


def test_the_kneed_ground_reaction_is_newton_eulers(kneed):
    """Both phases, with a hip torque, at random states: the CasADi resultant equals
    ``M (a_com + g)`` from the rigid model's own points and torqued flow (the Cauchy
    integral's exact second derivative) to 1e-10 of the weight."""
    _, data, walker, fns = kneed
    u = 0.4
    torqued = _torqued(data, u)
    weight = float(walker.total_mass_kg) * float(data.gravity_m_per_s2)
    rng = np.random.default_rng(11)
    for _ in range(4):
        x = rng.normal(0.0, [0.2, 0.2, 0.2, 1.0, 1.0, 1.0])
        for mp, ph in zip(fns["phases"], torqued.phases):
            want = _newton_euler(walker, data, x, ph.flow(0.0, x)[3:])
            got = mp.grf(x, u).full().ravel()
            np.testing.assert_allclose(got, want, rtol=0, atol=1e-10 * weight)
