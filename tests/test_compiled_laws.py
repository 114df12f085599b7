"""Torque laws inside the compiled flows (``cyrk_compiled``; walkerlab.codegen.actuated and
walkerlab.codegen.torque_law): the law block evaluates the laws as
:class:`walkerlab.models.actuation.TorqueLaws` does; each actuated cfunc gives the Python
flow (generated passive flow + ``M^-1 B tau``) and its variational equations the Python
Jacobian (complex step through the law); steps on the compiled flows agree with the Python
path to the integrator's tolerance (phase reference, time table, saturation)."""

from __future__ import annotations

import ctypes

import numpy as np
import pytest

from walkerlab.codegen.torque_law import law_torque
from walkerlab.config import scene_from_dict
from walkerlab.integrate.python_step import needs_python_path
from walkerlab.integrate.rigid import simulate_steps
from walkerlab.integrate.solver import Solver
from walkerlab.models.registry import build_walker
from walkerlab.walker.plant import Plant

PHASE = [-0.18, -0.12, -0.06, 0.0, 0.06, 0.12, 0.18]
HIP = [0.3469, 0.3257, 0.2367, 0.0, -0.2367, -0.3257, -0.3469]  # the push-off gait's
X0 = np.array([-0.17346504, 0.17346504, -0.7654341, -0.86898011])  # its fixed point


def _scene(torques, push_off: float = 3.0) -> dict:
    return {"name": "t", "walker": {"model": "compass_gait", "leg_length_m": 1.0,
                                    "leg_mass_kg": 5.0, "hip_mass_kg": 10.0,
                                    "gravity_m_per_s2": 9.81, "leg_mass_from_foot_m": 0.5,
                                    "actuation": {"push_off": {"impulse_n_s": push_off},
                                                  "torques": torques}},
            "slope": {"angle_rad": 0.0},
            "solver": {"method": "DOP853", "rtol": 1e-11, "atol": 1e-11}}


def _pd(interpolation: str, limit: float | None = None, time_table: bool = False) -> list:
    table = ({"time_reference": {"time_s": [0.0, 0.2, 0.4, 0.6, 0.8],
                                 "angle_rad": [-0.35, -0.1, 0.15, 0.35, 0.3],
                                 "interpolation": interpolation}} if time_table else
             {"reference": {"phase_rad": PHASE, "angle_rad": HIP,
                            "interpolation": interpolation}})
    return [{"joint": "hip", "max_torque_n_m": limit,
             "law": {"stiffness_n_m_per_rad": 20.0, "damping_n_m_s_per_rad": 1.5, **table}}]


CASES = {"linear": _pd("linear"), "cubic": _pd("cubic"),
         "saturated": _pd("cubic", limit=1.0),
         "time_table": _pd("cubic", time_table=True),
         "two_laws": _pd("linear") + [{"joint": "hip", "law": {
             "constant_n_m": 0.3, "stiffness_n_m_per_rad": 1.0, "rest_angle_rad": 0.1}}]}


@pytest.mark.parametrize("name", sorted(CASES))
def test_the_law_block_evaluates_the_laws_as_torque_laws(name):
    """Plain Python (no numba): ``law_torque`` on the packed block against
    ``TorqueLaws.each``, its partial derivatives against the complex step through it."""
    sc = scene_from_dict(_scene(CASES[name]))
    w = build_walker(Plant.from_scene(sc))
    laws = w.actuators.laws
    b = laws.packed()
    rng = np.random.default_rng(5)
    for _ in range(20):
        delta, ddelta, s, ds = rng.normal(0, [0.3, 1.0, 0.15, 1.0])
        t = rng.uniform(0.0, 1.0)
        want = laws.each([delta] * len(laws.torques), [ddelta] * len(laws.torques), s, ds, t)
        for i, tau in enumerate(want):
            got = law_torque(b, i, delta, ddelta, s, ds, t)
            assert got[0] == pytest.approx(float(np.real(tau)), rel=1e-12, abs=1e-12)
            h = 1e-30
            for j, arg in enumerate(("delta", "ddelta", "s", "ds")):
                z = [delta, ddelta, s, ds]
                z[j] = z[j] + 1j * h
                d = np.imag(laws.each([z[0]] * len(laws.torques), [z[1]] * len(laws.torques),
                                      z[2], z[3], t)[i]) / h
                assert got[1 + j] == pytest.approx(d, rel=1e-9, abs=1e-9), (arg, i)


def _call(cfunc, y: np.ndarray, data: np.ndarray, m: int) -> np.ndarray:
    dy = np.zeros(m)
    p = ctypes.POINTER(ctypes.c_double)
    cfunc.ctypes(dy.ctypes.data_as(p), 0.3, np.ascontiguousarray(y).ctypes.data_as(p),
                 data.ctypes.data_as(p))
    return dy


@pytest.mark.parametrize("name", ["cubic", "saturated", "time_table"])
@pytest.mark.slow  # in `pytest -m slow`: the quick suite keeps to its CPU budget
def test_the_actuated_cfuncs_are_the_python_flow_and_jacobian(name):
    """At states around the gait: the flow to 1e-13 (the same equations, the torque added
    before or after the solve) and ``(J + chain) Phi`` to 1e-11 of the complex-step
    Jacobian; the guards' outputs are the Python guards'."""
    pytest.importorskip("numba")
    sc = scene_from_dict(_scene(CASES[name]))
    w = build_walker(Plant.from_scene(sc))
    w.actuators.begin_step(0.1)
    for ph in w.phases:
        cf = ph.compiled
        assert cf is not None and not cf.batchable
        mod = cf.module()
        ng = len(mod.GUARDS)
        n_extra, cols, offs = cf.guard_columns()
        rng = np.random.default_rng(6)
        for _ in range(4):
            x = X0 + rng.normal(0, [0.05, 0.05, 0.3, 0.3])
            out = _call(mod.cfunc_of("flow"), x, cf.data(), 4 + ng)
            np.testing.assert_allclose(out[:4], ph.flow(0.3, x), rtol=0, atol=1e-13)
            for g, c, o in zip(ph.guards, cols, offs):
                assert out[4 + c] + o == pytest.approx(g.function(0.3, x), abs=1e-14)
            P = rng.normal(size=(4, 4))
            out = _call(mod.cfunc_of("flow_variational"), np.concatenate([x, P.ravel()]),
                        cf.data(), 20 + ng)
            np.testing.assert_allclose(out[4:20].reshape(4, 4), ph.jacobian(0.3, x) @ P,
                                       rtol=0, atol=1e-11)


@pytest.mark.parametrize("name", ["cubic", "time_table", "saturated"])
def test_steps_on_compiled_laws_agree_with_the_python_path(name):
    """Two steps (the time table restarts at the second heel strike) on each path: the
    same heel strikes to the integrator's tolerance (rtol = atol = 1e-11 per step; the
    paths take different steps and locate the guards on different dense outputs)."""
    pytest.importorskip("numba")
    sc = scene_from_dict(_scene(CASES[name]))
    w = build_walker(Plant.from_scene(sc))
    assert needs_python_path(w)  # the batched map would run the passive cfuncs
    runs = [simulate_steps(w, X0, 2, Solver("DOP853", 1e-11, 1e-11, None, b))
            for b in ("cyrk", "cyrk_compiled")]
    for a, c in zip(*(r.segments for r in runs)):
        assert a.termination == c.termination == "heel_strike"
        assert abs(a.t_end - c.t_end) < 1e-9
        np.testing.assert_allclose(c.x_next, a.x_next, rtol=0, atol=1e-9)


@pytest.mark.slow
def test_rabbit_runs_its_virtual_constraints_on_compiled_flows():
    """RABBIT (five links, four saturated PD virtual constraints on cubic phase tables): its
    compiled flow is the Python one at states near its gait, and one step on DOP853 with
    compiled laws lands where the scene's LSODA step lands (both at rtol 1e-11).  Slow: the
    five-link cfuncs take minutes to compile on a cold cache (seconds from numba's cache)."""
    pytest.importorskip("numba")
    from walkerlab.config import load_scene

    sc = load_scene("configs/rabbit.yaml")
    w = build_walker(Plant.from_scene(sc))
    x0 = sc.fixedpoint.initial_guess.as_array(w.state_names())
    cf = w.phases[0].compiled
    mod = cf.module()
    rng = np.random.default_rng(8)
    for _ in range(3):
        x = x0 + rng.normal(0, 0.02, x0.size)
        out = _call(mod.cfunc_of("flow"), x, cf.data(), x0.size + len(mod.GUARDS))
        want = np.asarray(w.phases[0].flow(0.3, x))
        np.testing.assert_allclose(out[:x0.size], want, rtol=0, atol=1e-11 * np.abs(want).max())
    lsoda = simulate_steps(w, x0, 1, Solver.from_settings(sc.solver)).segments[0]
    comp = simulate_steps(w, x0, 1, Solver("DOP853", 1e-11, 1e-11, None, "cyrk_compiled"))
    c = comp.segments[0]
    assert c.termination == lsoda.termination == "heel_strike"
    assert abs(c.t_end - lsoda.t_end) < 1e-8
    np.testing.assert_allclose(c.x_next, lsoda.x_next, rtol=0, atol=1e-8)
