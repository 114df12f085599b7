"""The rigid view's compiled control step (:class:`walkerlab.gym.rigid_view.RigidView`,
``compiled_step=True``) against the scene's own solver on Python flows
(``compiled_step=False``): the same heel strikes, states and energy ledger.

Tolerances: the scenes integrate at rtol = atol = 1e-11 (LSODA for the virtual-constraint
scenes, DOP853 for the paper walker); the compiled step runs DOP853 at the same tolerances,
so two integrators' global errors over a few steps separate the runs: heel-strike times to
1e-9 s (the issue's bound), states to 1e-6 (rates amplified through a heel strike), the
ledger's sums to 1e-8 J plus 1e-8 of their size (the two runs' states part by the
integrators' errors, ~1e-9 in the angles at 1e-11 tolerances, which the work sums over the
periods; the held torques' exact work against 4-point Gauss-Legendre on 10 ms pieces adds
quadrature error far below that; measured: 1.3e-9 of RABBIT's 97 J over 300 periods).
"""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("gymnasium")
pytest.importorskip("CyRK")

from walkerlab.gym import WalkerEnv  # noqa: E402


def _episode(scene, compiled: bool, periods: int, action: str, policy=None, seed=1):
    env = WalkerEnv(scene, policy=policy, compiled_step=compiled)
    env.reset(seed=0)
    rng = np.random.default_rng(seed)
    space = env.action_space
    strikes, ends, obs, info = [], [], None, None
    for i in range(periods):
        a = (rng.uniform(space.low, space.high) * 0.2 if action == "random"
             else np.zeros(space.shape))
        obs, _r, term, trunc, info = env.step(a)
        strikes += info["heel_strike_times_s"]
        if term or trunc:
            ends.append((i, info["termination"]))
            env.reset(seed=0)
    ledger = {k: v for k, v in info.items() if k.startswith("ledger_")}
    return np.array(strikes), ends, obs, ledger, env


def _same_walk(a, b):
    sa, ea, oa, la, _ = a
    sb, eb, ob, lb, _ = b
    assert ea == eb  # the same falls, at the same periods
    assert sa.size == sb.size and sa.size > 0
    np.testing.assert_allclose(sb, sa, rtol=0, atol=1e-9)
    np.testing.assert_allclose(ob, oa, rtol=0, atol=1e-6)
    for k in la:
        assert abs(lb[k] - la[k]) <= 1e-8 + 1e-8 * abs(la[k]), k


def test_the_compiled_step_walks_the_paper_walkers_heel_strikes_to_1e9_s():
    """Zero action on configs/paper.yaml: 5 s, 7 heel strikes of the passive gait."""
    _same_walk(_episode("configs/paper.yaml", False, 500, "zero"),
               _episode("configs/paper.yaml", True, 500, "zero"))


@pytest.mark.slow
def test_a_random_action_on_the_three_link_walker_falls_at_the_same_periods_compiled():
    """Random torques (20 % of the bounds) on the three-link walker without its controller:
    the falls, heel strikes and the action's positive and negative work agree."""
    ref = _episode("configs/threelink_hzd.yaml", False, 350, "random")
    fast = _episode("configs/threelink_hzd.yaml", True, 350, "random")
    _same_walk(ref, fast)
    assert ref[3]["ledger_action_work_positive"] > 0.01  # the action did work
    assert ref[3]["ledger_action_work_negative"] < -0.01
    assert fast[4].sim.compiled_solver is not None


@pytest.mark.slow
def test_rabbit_under_its_scene_policy_walks_the_same_steps_compiled():
    """RABBIT (five links) under its virtual-constraint controller held per period, with a
    small random action on top: 300 periods, heel strikes to 1e-9 s."""
    _same_walk(_episode("configs/rabbit_hzd.yaml", False, 300, "random", policy="scene"),
               _episode("configs/rabbit_hzd.yaml", True, 300, "random", policy="scene"))


def test_a_push_off_walker_walks_the_same_steps_compiled():
    """configs/powered_compass.yaml (a push-off at each heel strike, the reset in Python):
    its phases run compiled with the random action, the heel strikes as the solver's."""
    a = _episode("configs/powered_compass.yaml", False, 300, "random")
    b = _episode("configs/powered_compass.yaml", True, 300, "random")
    assert any(v is not None for v in b[4].sim._compiled.values())
    _same_walk(a, b)


def test_a_walker_with_torque_laws_runs_its_own_phases_on_the_scene_solver():
    """configs/threelink.yaml's PD laws live in its flow: no compiled action step for its
    phases, and the walk is bit for bit the scene solver's."""
    a = _episode("configs/threelink.yaml", False, 60, "random")
    b = _episode("configs/threelink.yaml", True, 60, "random")
    sim = b[4].sim
    assert all(v is None for v in sim._compiled.values()) and sim._compiled
    np.testing.assert_array_equal(a[0], b[0])
    np.testing.assert_array_equal(a[2], b[2])


def test_flat_feet_keep_their_modes_python_flows():
    """A flat foot's modes have mass matrices of their own (the action's twins): the
    compiled step is off for them."""
    env = WalkerEnv("configs/flat_feet.yaml")
    assert env.sim.compiled_solver is None


def test_the_held_action_work_is_the_power_integrated_along_the_path():
    """:meth:`ActionTorques.held_work` between two states of a compiled period equals the
    Gauss-Legendre integral of the action's power on its dense output (20 nodes)."""
    env = WalkerEnv("configs/threelink_hzd.yaml")
    env.reset(seed=0)
    sim = env.sim
    acts = sim.acts[sim.leg]
    acts.u = np.array([3.0, -2.0])[:env.action_space.shape[0]]
    w, phase = sim.walker, sim.walker.phases[sim.k]
    fphase, laws, _ = sim._compiled_phase(w, phase, acts)
    laws[3 + 8 * np.arange(acts.u.size) + 1] = acts.u
    from walkerlab.integrate.rigid_phase import integrate_phase

    n2 = sim.x.size
    run = integrate_phase(fphase, 0.0, sim.x, None, 0.01, n2, sim.compiled_solver,
                          "cyrk_compiled", None, None, False)
    assert run.event is None
    xg, wg = np.polynomial.legendre.leggauss(20)
    ts = 0.5 * run.t_last * (xg + 1.0)
    X = run.dense(ts)[:n2]
    quad = 0.5 * run.t_last * sum(wk * acts.power(t, X[:, j])
                                  for j, (t, wk) in enumerate(zip(ts, wg)))
    exact = acts.held_work(sim.x, run.y_last[:n2])
    assert abs(quad) > 1e-4
    assert abs(exact - quad) <= 1e-9 * abs(quad)


def test_flat_feet_on_footholds_take_an_action_on_every_step_walker():
    """configs/flat_feet_footholds.yaml under a small random hip torque: each step's
    walker of the footholds' cycle gets its action twin from the stance leg's data (before:
    a TypeError at the first step walker that is neither the scene's walker nor its
    mirror), and walks its heel strikes."""
    strikes, ends, *_ = _episode("configs/flat_feet_footholds.yaml", True, 150, "random")
    assert strikes.size >= 1 and not ends


@pytest.mark.parametrize("scene", ["configs/paper.yaml", "configs/kneed.yaml",
                                   "configs/threelink_hzd.yaml", "configs/rabbit_hzd.yaml",
                                   "configs/torso_powered.yaml"])
def test_the_action_joint_state_is_the_generated_leg_angles_affine_map(scene):
    """:attr:`ActionTorques.affine` (``delta = Bt q + c``, ``ddelta = Bt dq``), which the
    ledger reads each period, gives the joints' angles and rates of the generated
    ``leg_angles`` at states far from the probe's, and :meth:`rate_power` the generic
    :meth:`power` (hip-only straight legs, knees, a five-link biped, a torso).  Bound:
    round-off of sums of a few angles of order 1 (1e-12)."""
    env = WalkerEnv(scene)
    env.reset(seed=0)
    acts = env.sim.acts[env.sim.leg]
    assert acts.affine is not None
    rng = np.random.default_rng(3)
    n = acts.n
    X = rng.uniform(-2.0, 2.0, size=(2 * n, 6))
    acts.u = rng.uniform(-5.0, 5.0, size=acts.u.size)
    for j in range(X.shape[1]):
        d, dd = acts.joint_state(X[:, j])
        d0, dd0 = acts._generated_joint_state(X[:, j])
        np.testing.assert_allclose(d, d0, rtol=0, atol=1e-12)
        np.testing.assert_allclose(dd, dd0, rtol=0, atol=1e-12)
        assert abs(acts.rate_power(X)[j] - acts.power(0.0, X[:, j])) <= 1e-11


def test_a_negative_whole_power_in_a_compiled_flow_is_numbas_own_reciprocal_without_raising():
    """``x**(-k)`` in an actuated cfunc (a five-link biped's phase variable: ``_c2_3**(-2)``)
    raised ``ZeroDivisionError`` at a zero base inside the cfunc, whatever its
    ``error_model='numpy'`` (numba compiles the power's reciprocal with Python's error model),
    which the gym counted by swapping ``sys.unraisablehook``; the generator now writes it as
    the product numba forms and its reciprocal: the same number bit for bit wherever the
    power did not raise (here over 60,000 values from 1e-60 to 1e60, either sign, and the
    infinities), and ``inf`` at zero, as the cfunc's other divisions by zero."""
    from numba import njit

    from walkerlab.codegen.actuated import _NEGATIVE_POWER, _reciprocal_power

    rng = np.random.default_rng(3)
    x = np.concatenate([rng.standard_normal(60000) * 10.0 ** rng.integers(-60, 60, 60000),
                        [np.inf, -np.inf, np.nan, 1.0, -1.0]])
    for k in range(1, 6):
        old = f"def power(_c):\n    return _c**(-{k})\n"
        new = _NEGATIVE_POWER.sub(_reciprocal_power, old)
        assert "**" not in new
        scope_old, scope_new = {}, {}
        exec(old, scope_old)  # noqa: S102 - the generator's line, compiled as it is
        exec(new, scope_new)  # noqa: S102
        f_old = njit(error_model="numpy")(scope_old["power"])
        f_new = njit(error_model="numpy")(scope_new["power"])
        got = np.array([f_new(v) for v in x])
        assert np.array([f_old(v) for v in x]).tobytes() == got.tobytes(), k
        with pytest.raises(ZeroDivisionError):
            f_old(0.0)
        assert f_new(0.0) == np.inf and f_new(-0.0) == (np.inf if k % 2 == 0 else -np.inf)


@pytest.mark.slow
def test_rabbits_compiled_flows_hold_no_negative_literal_power_and_its_falls_raise_nothing(
        monkeypatch):
    """The five-link biped's compiled control step (its actuated module's cfuncs) has no
    ``x**(-k)`` left (module above), and its falls under the largest torques (where the
    phase variable's base reached zero: before, hundreds of ``ZeroDivisionError`` a 2000
    periods, counted by a swapped ``sys.unraisablehook``) write nothing to the hook in
    force."""
    import sys

    seen = []
    monkeypatch.setattr(sys, "unraisablehook", seen.append)
    env = WalkerEnv("configs/rabbit_hzd.yaml")
    env.reset(seed=0)
    rng = np.random.default_rng(0)
    falls = 0
    for k in range(300):
        *_, term, trunc, info = env.step(np.sign(rng.uniform(-1, 1, env.action_space.shape)))
        if term or trunc:
            falls += info["termination"] == "fall"
            env.reset(seed=k)
    assert falls > 0 and seen == []
    import inspect

    modules = {id(m): m for m in (v[0].compiled.module() for v in env.sim._compiled.values()
                                  if v is not None)}
    assert modules
    for module in modules.values():
        flows = inspect.getsource(module).split("def cfunc_of")[0].split("def flow(")[1]
        assert "(1/(" in flows and "**(-" not in flows
