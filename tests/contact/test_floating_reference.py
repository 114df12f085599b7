"""The generated floating compass gait against the independent numpy reference
(tests/independent/contact_reference.py, written from the Lagrangian by hand) and its analytic
Jacobian against central differences of its right-hand side.

Before the hand-written numba kernel retired (issue 17), the generated walker was shown equal
to it at 400 random states (half in contact, continuous ground and checkerboard lanes): worst
relative difference 5.2e-16 for the right-hand side, 1.8e-14 for the Jacobian, 1.2e-15 for the
pinned-foot dynamics (commit "Floating view generated ...", test_floating_equals_hand.py).
"""

import numpy as np
import pytest
from independent.contact_reference import rhs_ref

from walkerlab.config.contact import ContactSettings
from walkerlab.models.contact.laws import contact_params_si
from walkerlab.models.contact.model import ContactWalker


def _states(w, n, rng):
    """Random states around a walking posture; half with a foot up to two static penetrations
    deep on its patch, half with both feet up."""
    out = []
    d0 = w.static_penetration()
    for k in range(n):
        th = rng.uniform(-0.35, 0.35, 2)
        foot = rng.integers(0, 2)
        depth = rng.uniform(0, 2 * d0) if k % 2 == 0 else -rng.uniform(1e-3, 0.05)
        s = (0.372 if foot == 0 else 0.0) + rng.uniform(-0.02, 0.02)
        pf = s * w.tangent - depth * w.normal
        hip = pf - w.L * np.array([np.sin(th[foot]), -np.cos(th[foot])])
        out.append(np.concatenate([hip, th, rng.normal(0, 0.5, 2), rng.normal(0, 1.5, 2)]))
    return out


@pytest.mark.parametrize("continuous", [True, False])
def test_generated_rhs_equals_independent_reference(continuous):
    rng = np.random.default_rng(17)
    w = ContactWalker(contact=contact_params_si(ContactSettings()), lane1=np.array([0.372]),
                      lane2=np.array([0.0]), continuous=continuous)
    worst, n_contact = 0.0, 0
    for x in _states(w, 100, rng):
        ref = rhs_ref(x, w.L, w.m, w.MH, w.a, w.g, w.phi, w.contact, (w.lane1, w.lane2),
                      w.patch_half_width, w.continuous)
        worst = max(worst, np.max(np.abs(w.rhs(0.0, x) - ref)) / np.max(np.abs(ref)))
        n_contact += any(w.contact_quantities(x)[f]["normal_force"][0] > 0
                         for f in ("leg1", "leg2"))
    assert n_contact >= 25  # the contact branch is exercised
    # the same formulas in another order (np.linalg.solve vs a Cholesky factor): round-off
    assert worst <= 1e-12


def test_generated_jacobian_equals_central_differences():
    """Central differences, steps 1e-9 m / rad on the coordinates (1.6e-5 of the static
    penetration, the shortest length over which the force law bends) and 1e-7 m/s / rad/s
    on the rates (1e-6 of the stiction velocity): truncation (h / scale)^2 ~ 1e-10 and
    round-off eps |f| / h ~ 1e-8 of the largest entry; 1e-5 relative leaves margin and
    still catches a wrong term."""
    rng = np.random.default_rng(5)
    w = ContactWalker(contact=contact_params_si(ContactSettings()), continuous=True)
    for x in _states(w, 20, rng):
        J = w.jac(0.0, x)
        Jfd = np.empty_like(J)
        for k in range(8):
            h = 1e-9 if k < 4 else 1e-7
            dx = np.zeros(8)
            dx[k] = h
            Jfd[:, k] = (w.rhs(0.0, x + dx) - w.rhs(0.0, x - dx)) / (2 * h)
        assert np.max(np.abs(J - Jfd)) <= 1e-5 * np.max(np.abs(J))
