"""Equations of motion: numba kernels vs numpy reference, Jacobian vs finite differences."""

import math

import numpy as np
import pytest

from walkerlab.config.contact import ContactSettings
from walkerlab.models.contact import ContactWalker
from walkerlab.models.contact.laws import contact_params_si
from walkerlab.models.contact.model import checkerboard_lanes


def _walker(**kw):
    c1, c2 = checkerboard_lanes(0.372, 10)
    return ContactWalker(contact=contact_params_si(ContactSettings(**kw)), lane1=c1, lane2=c2,
                         continuous=False)


def _states(w, n=40, seed=1):
    """States with both feet near the ground in their patches, slip in all friction regimes."""
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(n):
        t1, t2 = rng.uniform(-0.3, 0.3, 2)
        pen = rng.uniform(-2e-5, 2e-4)  # leg2 foot from just above to 2 dmax deep
        foot2 = np.array([0.0, 0.0]) - pen * w.normal
        hip = foot2 + w.L * np.array([-np.sin(t2), np.cos(t2)])
        v = rng.normal(size=4) * np.array([0.5, 0.05, 1.0, 1.0]) * rng.choice([1e-3, 0.1, 1.0])
        out.append(np.concatenate([hip, [t1, t2], v]))
    return out


@pytest.mark.parametrize("mu", [(0.9, 0.7), (5.0, 5.0)])
def test_numba_matches_numpy_reference(mu):
    w = _walker(mu_static=mu[0], mu_dynamic=mu[1])
    for x in _states(w):
        # forces up to ~1e4 N; both evaluate the same formulas in different order
        np.testing.assert_allclose(w.rhs(0, x), _ref(w, x), rtol=1e-9, atol=1e-9)


def test_mass_matrix_and_energy():
    w = _walker()
    for x in _states(w, 5):
        M = w.mass_matrix(x[:4])
        np.testing.assert_allclose(M, M.T)
        assert np.all(np.linalg.eigvalsh(M) > 0)
        T = 0.5 * x[4:] @ M @ x[4:]
        assert w.energies(x)["kinetic"][0] == pytest.approx(T, rel=1e-12)


def test_jacobian_matches_finite_differences():
    w = _walker()
    for x in _states(w, 25, seed=3):
        J = w.jac(0, x)
        Jfd = np.zeros((8, 8))
        for k in range(8):
            h = 1e-8 if k < 2 else 1e-7  # positions are ~1e-4 deep in a stiff spring
            e = np.zeros(8)
            e[k] = h
            Jfd[:, k] = (w.rhs(0, x + e) - w.rhs(0, x - e)) / (2 * h)
        # central differences: relative error ~ h^2 f''' / f' ; states close to the kinks
        # (contact onset, force clip) may be straddled, so compare at 1e-4 of the largest entry
        np.testing.assert_allclose(J, Jfd, atol=1e-4 * np.abs(Jfd).max())


def _ref(w, x):
    """The independent numpy right-hand side (tests/independent/contact_reference.py)."""
    from independent.contact_reference import rhs_ref

    return rhs_ref(np.asarray(x, float), w.L, w.m, w.MH, w.a, w.g, w.phi, w.contact,
                   (w.lane1, w.lane2), w.patch_half_width, w.continuous)


def test_hip_height_is_numpy_the_hip_point_along_the_normal():
    """The fall and airborne test's hip height: the generated hip point dotted with the slope's
    normal, bit for bit, for one state and for rows; the generated module compiles no kernel
    for it (a per-structure numba compile for a dot product cost ~0.3 s in a fresh cache)."""
    w = _walker()
    X = np.array(_states(w, 7))
    hip = w.points(X)["hip"]
    sp, cp = math.sin(w.phi), math.cos(w.phi)
    assert np.array_equal(w.hip_height(X), hip[0] * sp + hip[1] * cp)
    assert w.hip_height(X[3]).shape == (1,) and w.hip_height(X[3])[0] == w.hip_height(X)[3]
    assert not hasattr(w.kernels, "hip_heights")
