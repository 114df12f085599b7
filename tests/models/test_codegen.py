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


@pytest.mark.parametrize("scene", ["paper", "kneed", "rabbit", "threelink", "rimless_wheel",
                                   "asymmetric_legs"])
def test_the_generated_hip_x_is_the_points_hip_x_bit_for_bit(scene):
    """The generator's ``hip_x`` (the hip's x alone, the same printed expressions as
    ``points``' entry) equals ``points(x)["hip"][0]`` exactly, at one state and at states as
    columns, on straight legs, knees, five links, three links, a wheel and legs that differ
    (both step walkers); 0 ulp, since the gym's reward reads one where it read the other."""
    from pathlib import Path

    from walkerlab.api import Walker

    root = Path(__file__).resolve().parents[2]
    model = Walker.from_scene(str(root / "configs" / f"{scene}.yaml")).model
    rng = np.random.default_rng(7)
    for w in (model, model.mirror) if model.mirror is not None else (model,):
        assert w.hip_x is not None
        n = len(w.state_names())
        X = rng.normal(size=(n, 5)) * 0.3
        for x in X.T:
            assert w.hip_x(x) == w.points(x)["hip"][0]
        np.testing.assert_array_equal(w.hip_x(X), w.points(X)["hip"][0])


def test_the_christoffel_core_makes_dm_dt_minus_2c_skew_symmetric():
    """The one Coriolis matrix every generator reads (:func:`~walkerlab.codegen.lagrange.
    christoffel`): ``dM/dt - 2 C`` is skew-symmetric for a symmetric ``M(q)`` (the passivity
    property, Spong, Hutchinson & Vidyasagar 2006, Property 7.2), exactly in sympy, on a
    3-coordinate mass matrix with every entry depending on q; and ``C dq`` equals the
    Lagrangian's ``d/dt dT/ddq - dT/dq - M qdd``, derived here without it."""
    import sympy as sp

    from walkerlab.codegen.lagrange import christoffel

    q = sp.symbols("q0:3")
    dq = sp.symbols("dq0:3")
    ddq = sp.symbols("ddq0:3")
    M = sp.Matrix([[3 + sp.cos(q[1]), sp.sin(q[0] - q[2]), q[1] * q[2]],
                   [sp.sin(q[0] - q[2]), 2 + q[0] ** 2, sp.cos(q[2])],
                   [q[1] * q[2], sp.cos(q[2]), 4 + sp.sin(q[1]) ** 2]])
    C = christoffel(M, q, dq)
    Mdot = M.applyfunc(lambda e: sum(sp.diff(e, qk) * dqk for qk, dqk in zip(q, dq)))
    N = Mdot - 2 * C
    assert sp.simplify(N + N.T) == sp.zeros(3, 3)
    T = (sp.Matrix(dq).T * M * sp.Matrix(dq))[0] / 2
    dT = [sp.diff(T, v) for v in dq]
    ddt = [sum(sp.diff(e, a) * b for a, b in zip((*q, *dq), (*dq, *ddq))) for e in dT]
    lhs = sp.Matrix([ddt[i] - sp.diff(T, q[i]) for i in range(3)]) - M * sp.Matrix(ddq)
    assert sp.simplify(lhs - C * sp.Matrix(dq)) == sp.zeros(3, 1)
