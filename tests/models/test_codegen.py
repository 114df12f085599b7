"""Generated Jacobians against central differences of the generated functions themselves."""

import numpy as np
import pytest

from walkerlab.codegen.cache import functions
from walkerlab.walker.description import BodySpec, Structure, WalkerData

CASES = {
    "compass": (Structure("absolute", (BodySpec("mass", "point_mass"),)),
                (9.81, 1.0, 0.0174, 10.0, 5.0, 0.5)),
    "rods": (Structure("absolute", (BodySpec("rod", "rod"),)),
             (9.81, 1.0, 0.0174, 10.0, 5.0, 0.5, 5.0 / 12)),
    "simplest": (Structure("slope_relative", (BodySpec("foot_mass", "point_mass", True),)),
                 (1.0, 1.0, 0.009, 1.0, 1.0)),
}


def _central(fun, x, h=1e-6):
    return np.stack([(fun(x + h * e) - fun(x - h * e)) / (2 * h) for e in np.eye(x.size)],
                    axis=1)


@pytest.mark.parametrize("case", sorted(CASES))
def test_flow_and_reset_jacobians_match_central_differences(case):
    """Central differences with h = 1e-6 are accurate to ~1e-9 here (third derivatives O(10),
    round-off 1e-16/1e-6); the generated Jacobians must agree to 1e-7 at random states."""
    s, p = CASES[case]
    f = functions(WalkerData(s, p, 1.0, 1.0, p[0], p[2], {}))
    rng = np.random.default_rng(3)
    for _ in range(3):
        x = rng.normal(size=4) * 0.3
        J = f["flow_jacobian"](0.0, x)
        fd = _central(lambda z: f["flow"](0.0, z), x)
        assert np.max(np.abs(J - fd)) < 1e-7 * (1 + np.max(np.abs(J)))
        R = f["reset_jacobian"](x)
        assert np.max(np.abs(R - _central(f["reset"], x))) < 1e-7 * (1 + np.max(np.abs(R)))


@pytest.mark.parametrize("case", sorted(CASES))
def test_variational_rhs_is_flow_and_jacobian_times_phi(case):
    """``flow_variational(t, [x, Phi])`` evaluates the same expressions as ``flow`` and
    ``flow_jacobian @ Phi``, only summed in another order: equal to round-off (1e-13
    relative; entries are O(10), products of 4 terms)."""
    s, p = CASES[case]
    f = functions(WalkerData(s, p, 1.0, 1.0, p[0], p[2], {}))
    rng = np.random.default_rng(5)
    for _ in range(3):
        x, Phi = rng.normal(size=4) * 0.3, rng.normal(size=(4, 4))
        ref = np.concatenate([f["flow"](0.0, x), (f["flow_jacobian"](0.0, x) @ Phi).ravel()])
        got = f["flow_variational"](0.0, np.concatenate([x, Phi.ravel()]))
        assert got.shape == (20,)
        assert np.max(np.abs(got - ref)) < 1e-13 * (1 + np.max(np.abs(ref)))
