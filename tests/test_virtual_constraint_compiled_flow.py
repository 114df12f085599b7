"""The rigid closed loop under virtual constraints compiled
(:mod:`walkerlab.codegen.virtual_constraint_flow`): its right-hand side and its variational
equations against the Python flow and Jacobian the walker's phases carry (the generated
numpy flow plus the controller's computed torque, its Jacobian by the complex step), and its
fixed point on CyRK's DOP853 (``backend: cyrk_compiled``) against the scene's own LSODA one.

Tolerances: the two right-hand sides share the law and the derivation, not the arithmetic
(numpy's generated flow against numba's LAPACK solve), so they agree to round-off: 1e-11
relative to the largest entry (measured 1.5e-13 on RABBIT, 2e-16 on the three-link walker).
The fixed points come from different integrators at the scene's rtol = atol = 1e-11 and the
search's tolerance 1e-10: the states within 1e-8, the step periods within 1e-8 s (measured
4e-10 s and 1.6e-11 s), the dominant Floquet multiplier within 1e-7 (the others are
round-off, below 1e-7 in modulus on both).
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from walkerlab.config import load_scene
from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module", params=["threelink_hzd", "rabbit_hzd"])
def walker_and_scene(request):
    from walkerlab.models.registry import build_walker

    scene = load_scene(ROOT / "configs" / f"{request.param}.yaml")
    return build_walker(Plant.from_scene(scene)), scene


def test_compiled_closed_loop_is_the_python_flow_and_jacobian(walker_and_scene):
    from walkerlab.integrate._compiled import callable_flow
    from walkerlab.models.compiled_flows import VirtualConstraintFlow

    walker, _ = walker_and_scene
    ctrl = walker.actuators.controller
    m = 2 * ctrl.n
    rng = np.random.default_rng(7)
    for ph in walker.phases:
        assert isinstance(ph.compiled, VirtualConstraintFlow)
        rhs, jac = callable_flow(ph.compiled, m, False)
        rhs_var, _ = callable_flow(ph.compiled, m, True)
        for _ in range(10):
            x = np.concatenate([ctrl.design.q_plus + 0.05 * rng.standard_normal(ctrl.n),
                                rng.standard_normal(ctrl.n)])
            f = ph.flow(0.0, x)
            np.testing.assert_allclose(rhs(0.0, x), f, rtol=0, atol=1e-11 * np.abs(f).max())
            A = ph.jacobian(0.0, x)
            np.testing.assert_allclose(jac(0.0, x), A, rtol=0, atol=1e-11 * np.abs(A).max())
            Phi = rng.standard_normal((m, m))
            out = rhs_var(0.0, np.concatenate([x, Phi.ravel()]))
            np.testing.assert_allclose(out[:m], f, rtol=0, atol=1e-11 * np.abs(f).max())
            AP = A @ Phi
            np.testing.assert_allclose(out[m:].reshape(m, m), AP, rtol=0,
                                       atol=1e-11 * np.abs(AP).max())


def test_the_scenes_lsoda_keeps_the_python_flow(walker_and_scene):
    """A scipy method runs the phases' Python flow (the shipped scenes' numbers as they
    were): the compiled closed loop is the compiled backend's."""
    from walkerlab.integrate.rigid import _runs_compiled_on_scipy

    walker, _ = walker_and_scene
    assert not any(_runs_compiled_on_scipy(ph) for ph in walker.phases)


@pytest.mark.slow
def test_compiled_fixed_point_is_the_lsoda_one(walker_and_scene):
    from walkerlab.analysis.gait.scene import solve_scene
    from walkerlab.integrate.solver import Solver

    walker, scene = walker_and_scene
    lsoda = solve_scene(scene, False, walker=walker, plant=Plant.from_scene(scene))[1].gait.result
    s = Solver.from_settings(scene.solver)
    compiled = solve_scene(scene, False, walker=walker, solver=replace(
        s, method="DOP853", backend="cyrk_compiled"), plant=Plant.from_scene(scene))[1].gait.result
    np.testing.assert_allclose(compiled.x, lsoda.x, rtol=0, atol=1e-8)
    assert abs(compiled.period_s - lsoda.period_s) < 1e-8
    a = np.asarray(lsoda.multipliers_variational)
    b = np.asarray(compiled.multipliers_variational)
    assert abs(np.max(np.abs(a)) - np.max(np.abs(b))) < 1e-7
    assert np.sort(np.abs(a))[-2] < 1e-7 and np.sort(np.abs(b))[-2] < 1e-7
