"""The generated floating compass gait equals the hand-written kernel it replaces (issue 17,
part 4): right-hand side and analytic Jacobian at random states, feet in and out of contact,
on continuous ground and on checkerboard lanes.

Tolerance 1e-12 relative (to the largest entry of each output): both evaluate the same
closed-form expressions in double precision, in a different order (block Schur solve vs a
Cholesky factor; cse'd symbolic vs hand-typed terms); the stance-contact Jacobian entries
reach ~1e9 (stiffness ~4e11 N/m^2.2 at 6e-5 m depth), so round-off alone is ~1e-16 of that.
"""

import numpy as np
import pytest

from walkerlab.contact import _kernels as K
from walkerlab.contact.config import ContactSettings
from walkerlab.contact.model import ContactWalker


def _states(w, n, rng):
    """Random states around a walking posture; half with a foot ~0..2 static penetrations
    deep (contact on), half with both feet up."""
    out = []
    d0 = w.static_penetration()
    for k in range(n):
        th = rng.uniform(-0.35, 0.35, 2)
        w_ = rng.normal(0, 1.5, 2)
        vh = rng.normal(0, 0.5, 2)
        foot = rng.integers(0, 2)
        depth = rng.uniform(0, 2 * d0) if k % 2 == 0 else -rng.uniform(1e-3, 0.05)
        s = (0.372 if foot == 0 else 0.0) + rng.uniform(-0.02, 0.02)  # on its lane's patch
        pf = s * w.tangent - depth * w.normal
        hip = pf - w.L * np.array([np.sin(th[foot]), -np.cos(th[foot])])
        out.append(np.array([hip[0], hip[1], th[0], th[1], vh[0], vh[1], w_[0], w_[1]]))
    return out


@pytest.mark.parametrize("continuous", [True, False])
def test_generated_compass_gait_equals_hand_kernel(continuous):
    rng = np.random.default_rng(17)
    w = ContactWalker(contact=ContactSettings().to_si(), lane1=np.array([0.372]),
                      lane2=np.array([0.0]), patch_half_width=0.05, continuous=continuous)
    P = np.empty(K.NPAR)
    c = w.contact
    P[K.I_L], P[K.I_M], P[K.I_MH], P[K.I_B], P[K.I_G], P[K.I_PHI] = (
        w.L, w.m, w.MH, w.L - w.a, w.g, w.phi)
    P[K.I_K], P[K.I_E], P[K.I_CMAX], P[K.I_DMAX] = c.k, c.e, c.cmax, c.dmax
    P[K.I_MUS], P[K.I_MUD], P[K.I_VS], P[K.I_VD] = c.mu_s, c.mu_d, c.v_s, c.v_d
    P[K.I_HW], P[K.I_CONT] = w.patch_half_width, 1.0 if continuous else 0.0
    worst_f = worst_j = 0.0
    n_contact = 0
    for x in _states(w, 200, rng):
        f_hand, f_gen = K.rhs(x, P, w.lane1, w.lane2), w.rhs(0.0, x)
        j_hand, j_gen = K.jac(x, P, w.lane1, w.lane2), w.jac(0.0, x)
        worst_f = max(worst_f, np.max(np.abs(f_gen - f_hand)) / np.max(np.abs(f_hand)))
        worst_j = max(worst_j, np.max(np.abs(j_gen - j_hand)) / np.max(np.abs(j_hand)))
        cq = w.contact_quantities(x)
        n_contact += any(cq[f]["normal_force"][0] > 0 for f in ("leg1", "leg2"))
    print(f"continuous={continuous}: worst relative rhs {worst_f:.2e}, jac {worst_j:.2e}, "
          f"{n_contact}/200 states in contact")
    assert n_contact >= 50  # the contact branch is exercised
    assert worst_f <= 1e-12
    assert worst_j <= 1e-12


def test_generated_pinned_dynamics_equal_hand_kernel():
    rng = np.random.default_rng(3)
    w = ContactWalker(contact=ContactSettings().to_si(), lane1=np.array([0.372]),
                      lane2=np.array([0.0]), continuous=False)
    P = np.empty(K.NPAR)
    c = w.contact
    P[K.I_L], P[K.I_M], P[K.I_MH], P[K.I_B], P[K.I_G], P[K.I_PHI] = (
        w.L, w.m, w.MH, w.L - w.a, w.g, w.phi)
    P[K.I_K], P[K.I_E], P[K.I_CMAX], P[K.I_DMAX] = c.k, c.e, c.cmax, c.dmax
    P[K.I_MUS], P[K.I_MUD], P[K.I_VS], P[K.I_VD] = c.mu_s, c.mu_d, c.v_s, c.v_d
    P[K.I_HW], P[K.I_CONT] = w.patch_half_width, 0.0
    worst = 0.0
    for _ in range(100):
        z = np.concatenate([rng.uniform(-0.35, 0.35, 2), rng.normal(0, 1.5, 2)])
        foot2 = np.array([rng.uniform(-0.02, 0.02), -6e-5])
        a = K.rhs_pinned(z, P, w.lane1, w.lane2, foot2[0], foot2[1])
        b = w.rhs_pinned(0.0, z, foot2)
        worst = max(worst, np.max(np.abs(a - b)) / np.max(np.abs(a)))
        np.testing.assert_allclose(w.pinned_to_full(z, foot2),
                                   ContactWalker.pinned_to_full_hand(w, z, foot2)
                                   if hasattr(ContactWalker, "pinned_to_full_hand") else
                                   _pinned_hand(w, z, foot2), rtol=0, atol=1e-15)
    print(f"pinned: worst relative {worst:.2e}")
    assert worst <= 1e-12


def _pinned_hand(w, z, foot2):
    t1, t2, w1, w2 = z
    L = w.L
    return np.array([foot2[0] - L * np.sin(t2), foot2[1] + L * np.cos(t2), t1, t2,
                     -L * np.cos(t2) * w2, -L * np.sin(t2) * w2, w1, w2])
