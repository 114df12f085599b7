"""The straight-legged and kneed walkers' optimised steps replayed with the hip torque as a
function of the phase variable (walkerlab.optimal.replay.hip_phase, on the law and replay
shared with the five-link biped, walkerlab.optimal.replay.phase): the law on steps built by
hand, one law per phase, the one-line refusal, the passive gait under the law, the stored
records and the report's words.  The closed replays of the shipped optima are measured by
``walkerlab optimize`` (``optimize.phase_replay: true``); the powered one is the slow test
at the end."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from walkerlab.config import load_scene
from walkerlab.optimal.replay.hip_phase import (
    PiecewisePhaseLaw,
    hip_gains,
    hip_phase_law,
    hip_walker,
)
from walkerlab.walker.description import walker_data

CONFIGS = Path(__file__).resolve().parents[1] / "configs"


@pytest.fixture(scope="module")
def compass():
    """configs/compass_optimal.yaml's walker data and its actuators (no law yet)."""
    scene = load_scene(CONFIGS / "compass_optimal.yaml")
    data = walker_data(scene.walker, scene.slope.phi_rad)
    return scene, data, hip_walker(data, None).actuators


def _step(m: int = 41, turn: bool = False):
    """A compass step by hand (state order swing, stance, rates): the stance angle falls
    from 0.2 to -0.2 rad at -1 rad/s (``turn``: it turns back at the end), the swing leg
    ``-s + 0.1 sin(5 s)``, the torque ``3 cos(4 t)``."""
    t = np.linspace(0.0, 0.4, m)
    s, ds = 0.2 - t, np.full(m, -1.0)
    if turn:
        s[-3:], ds[-3:] = s[-4] + np.array([-0.001, 0.0, 0.001]), [-0.01, 0.2, 0.5]
    sw = -s + 0.1 * np.sin(5 * s)
    dsw = (-1 + 0.5 * np.cos(5 * s)) * ds
    return t, np.stack([sw, s, dsw, ds], axis=1), 3.0 * np.cos(4 * t)


def test_the_hip_law_gives_the_optimised_torque_on_the_collocated_step(compass):
    """At every collocation point the law (feed-forward + PD, any gains) gives the optimised
    torque to round-off (the PD part is zero on the step), and a hip 0.01 rad off its
    reference gets -K * 0.01 more: the hip angle is the one coordinate it regulates."""
    _scene, _data, acts = compass
    t, x, u = _step()
    law = hip_phase_law(acts, t, x, u, (150.0, 20.0))
    for xi, ui in zip(x, u):
        np.testing.assert_allclose(law(*acts.hip_angles(xi)), [ui], rtol=0, atol=1e-12)
    off = x[7].copy()
    off[0] += 0.01  # the swing leg: the hip angle 0.01 rad larger, the phase variable same
    np.testing.assert_allclose(law(*acts.hip_angles(off)) - law(*acts.hip_angles(x[7])),
                               [-1.5], rtol=1e-9)


def test_the_gains_give_the_hip_its_bandwidth(compass):
    """K / b and D / b (b the hip angle's acceleration per unit torque) are w^2 and 2 w at
    w = 4 sqrt(g / l) (critical damping); b from the mass matrix at the start, positive."""
    _scene, data, acts = compass
    x = _step()[1][0]
    K, D = hip_gains(data, acts, x)
    M = np.asarray(acts.fns["matrices"](x)[0], float)
    b = acts.ddelta_dq @ np.linalg.solve(M, acts.ddelta_dq)
    w = 4.0 * np.sqrt(9.81 / 1.0)
    assert b > 0 and K * b == pytest.approx(w * w, rel=1e-12)
    assert D * b == pytest.approx(2 * w, rel=1e-12)


def test_flat_feet_get_their_gains_from_the_flow():
    """Flat feet have a mass matrix per contact mode (no generated ``matrices``): the hip's
    mobility comes from the first phase's flow under a unit torque and under none, and
    gives gains of the compass walker's size (same legs and hip: ~187 N m/rad there)."""
    scene = load_scene(CONFIGS / "flat_feet_optimal.yaml")
    data = walker_data(scene.walker, scene.slope.phi_rad)
    w = hip_walker(data, None)
    assert "matrices" not in w.actuators.fns
    K, D = hip_gains(data, w.actuators, np.array([-0.347, 0.256, 0.0, -1.34, -1.19, -11.3]),
                     w)
    assert 100.0 < K < 300.0 and D == pytest.approx(2 * K / (4 * np.sqrt(9.81)), rel=1e-12)


def test_a_phase_variable_that_turns_back_is_refused_in_one_line(compass):
    """The references need a monotonic phase variable: a step whose stance angle turns
    back gets one line; a step of phases names the phase that turns back."""
    _scene, _data, acts = compass
    t, x, u = _step(turn=True)
    with pytest.raises(ValueError, match="not monotonic over the optimised step") as exc:
        hip_phase_law(acts, t, x, u, (1.0, 1.0))
    assert "\n" not in str(exc.value)
    xs = x.copy()
    xs[-3:, 3] = -1e-3  # the rate keeps its sign; the angle does not move: phase 1 stalls
    xs[-3:, 1] = xs[-4, 1]
    idx = np.r_[0:21, 20:41]  # two phases, the boundary point repeated
    with pytest.raises(ValueError, match="phase late_swing") as exc:
        hip_phase_law(acts, t[idx], xs[idx], u[idx], (1.0, 1.0), np.array([0, 21]),
                      ("early_swing", "late_swing"))
    assert "\n" not in str(exc.value)


def test_a_step_of_phases_gets_one_law_per_phase_chosen_by_the_phase_variable(compass):
    """Two phases (points 0..20 and 20..40, the boundary point repeated as a phase's
    first): each phase's law gives its own torques at its points, the law in force is the
    one whose stretch of s holds the present value (s falls: the second from s = 0)."""
    _scene, _data, acts = compass
    t, x, u = _step()
    idx = np.r_[0:21, 20:41]  # the boundary point twice, as a phased transcription's
    u2 = np.where(np.arange(idx.size) < 21, u[idx], u[idx] + 1.0)  # the torque jumps
    law = hip_phase_law(acts, t[idx], x[idx], u2, (50.0, 5.0), np.array([0, 21]),
                        ("a", "b"))
    assert isinstance(law, PiecewisePhaseLaw)
    assert law.breaks[0] == pytest.approx(x[20, 1]) and law.sign == -1.0
    for k in (3, 15, 25, 40):
        j = k if k < 21 else k + 1
        np.testing.assert_allclose(law(*acts.hip_angles(x[k])), [u2[j]], atol=1e-12)
    assert law.law_at(x[19, 1]) is law.laws[0] and law.law_at(x[22, 1]) is law.laws[1]


def _kneed_step():
    """A kneed step by hand in two phases (points 0..20 and 20..40; state order swing thigh,
    swing shank, stance, rates): the stance angle falls from 0.2 to -0.2 rad at -1 rad/s,
    the swing thigh ``-s + 0.1 sin(5 s)``, the shank 0.1 rad behind it, the torque
    ``3 cos(4 t)`` and 1 N m more in the second phase."""
    t = np.linspace(0.0, 0.4, 41)
    s, ds = 0.2 - t, np.full(t.size, -1.0)
    th = -s + 0.1 * np.sin(5 * s)
    dth = (-1 + 0.5 * np.cos(5 * s)) * ds
    x = np.stack([th, th - 0.1, s, dth, dth, ds], axis=1)
    idx = np.r_[0:21, 20:41]
    u = 3.0 * np.cos(4 * t[idx]) + (np.arange(idx.size) >= 21)
    return t[idx], x[idx], u, np.array([0, 21])


@pytest.mark.slow  # in `pytest -m slow`: the quick suite keeps to its CPU budget
def test_the_kneed_walkers_compiled_flows_run_the_piecewise_law():
    """The replays run the law inside the compiled flows (``cyrk_compiled``): the law block
    (kind PIECEWISE, plain Python ``law_torque``) gives the law's torque on both sides of
    the break (1e-12 N m), and both phases' cfuncs - the free knee and the locked knee
    (``[S^T M; J_k]`` rows) - give the Python flow (the constrained ``M^-1 (B tau + a
    lam)``) to 1e-12 of its largest entry and their variational equations ``J Phi`` with
    ``J`` the complex step through the law, at states around the gait."""
    import ctypes

    from walkerlab.codegen.torque_law import law_torque
    from walkerlab.integrate.solver import Solver
    from walkerlab.optimal.replay.hip_phase import LIMIT_N_M, replay_solver

    pytest.importorskip("numba")
    scene = load_scene(CONFIGS / "kneed_optimal.yaml")
    data = walker_data(scene.walker, scene.slope.phi_rad)
    acts = hip_walker(data, None).actuators
    t, x, u, start = _kneed_step()
    law = hip_phase_law(acts, t, x, u, (80.0, 9.0), start, ("unlocked_swing", "locked_swing"))
    w = hip_walker(data, law)
    assert replay_solver(w, Solver("DOP853", 1e-12, 1e-12)).backend == "cyrk_compiled"
    b = law.packed(LIMIT_N_M)
    x0 = scene.fixedpoint.initial_guess.as_array(w.state_names())
    rng = np.random.default_rng(4)
    states = x0 + rng.normal(0, [0.05, 0.05, 0.15, 0.3, 0.3, 0.3], (12, 6))
    assert min(z[2] for z in states) < 0.0 < max(z[2] for z in states)  # both pieces
    p = ctypes.POINTER(ctypes.c_double)
    for ph in w.phases:
        cf = ph.compiled
        mod = cf.module()
        n_extra = cf.guard_columns()[0]
        for z in states:
            d, dd, s_, ds_ = acts.hip_angles(z)
            assert law_torque(b, 0, d, dd, s_, ds_, 0.0)[0] == pytest.approx(
                law(d, dd, s_, ds_)[0], abs=1e-12)
            Phi = rng.normal(size=(6, 6))
            dy = np.zeros(6 + 36 + n_extra)
            y, dv = np.concatenate([z, Phi.ravel()]), cf.data()
            mod.cfunc_of(f"{cf.name}_variational").ctypes(
                dy.ctypes.data_as(p), 0.0, y.ctypes.data_as(p), dv.ctypes.data_as(p))
            want = np.asarray(ph.flow(0.0, z))
            np.testing.assert_allclose(dy[:6], want, rtol=0, atol=1e-12 * np.abs(want).max())
            JP = ph.jacobian(0.0, z) @ Phi
            np.testing.assert_allclose(dy[6:42].reshape(6, 6), JP, rtol=0,
                                       atol=1e-12 * np.abs(JP).max())
    assert [ph.compiled.name for ph in w.phases] == ["flow", "flow_locked"]


def test_the_passive_gait_walks_on_under_the_phase_law(compass):
    """compass_optimal's optimum is its passive gait (torque zero): fed its own step
    (sampled at 41 times), the feed-forward law (zero) steps from the passive fixed point
    back to it (within 1e-8: DOP853 at 1e-10 against the fixed point's 1e-12), and so does
    the feed-forward + PD law (the Hermite reference's O(h^4) error drives a torque of
    ~1e-4 N m: within 1e-6)."""
    import walkerlab as wl
    from walkerlab.integrate.rigid import integrate_step
    from walkerlab.integrate.solver import Solver

    scene, data, acts = compass
    w = wl.Walker.from_scene(scene)
    g = w.fixed_point()
    t = np.linspace(0.0, g.step_period, 41)
    walk = w.simulate(g.x, strides=1, sample_rate_hz=2000.0)
    first = walk.stance_leg == walk.stance_leg[0]
    x = np.stack([np.interp(t, walk.t[first], col) for col in walk.x[first].T], axis=1)
    x[0] = g.x
    solver = Solver(method="DOP853", rtol=1e-10, atol=1e-10)
    for gains, tol in (((0.0, 0.0), 1e-8), (hip_gains(data, acts, g.x), 1e-6)):
        law = hip_phase_law(acts, t, x, np.zeros(t.size), gains)
        seg = integrate_step(hip_walker(data, law), g.x, solver,
                             max_step_time=3 * g.step_period)
        assert seg.termination == "heel_strike"
        assert np.max(np.abs(seg.x_next - g.x)) <= tol


def test_the_records_and_the_refusal_are_stored_and_said(tmp_path):
    """optimize.h5 keeps a straight-legged walker's phase replays as the five-link's
    (replay/phase_<law>/) and the refusal's line (attribute phase_replay_outcome); the
    report gives both and keeps the contact model's words for the time law."""
    from walkerlab.io.artifacts import write_artifact
    from walkerlab.io.schemas.optimize import STAGE, OptimizeData, PhaseReplayData, load, write
    from walkerlab.report.figures_section import optimize_lines

    t = np.linspace(0.0, 0.7, 5)
    reps = {"feedback": PhaseReplayData(1e-7, 1e-7, 6e-11, 0.73, 1e-3,
                                        np.array([0.39 + 0j, 0.0 + 0j]), True),
            "feedforward": PhaseReplayData(2e-8, 0.0, 2e-8, 0.73, 0.0,
                                           np.array([0.58 + 0j, 0.0 + 0j]), False)}
    scene = load_scene(CONFIGS / "compass_optimal.yaml")
    for phases, note in ((reps, ""), ({}, "not replayed: optimize: the stance leg's angle "
                                          "... is not monotonic")):
        d = OptimizeData(t, {"a": t.copy()}, np.zeros(5), 0.7, 0.5, 0.0, 0.0, 1e-8,
                         np.array([0.58 + 0j]), True, "Solve_Succeeded", 6, 1.0, {"a": "rad"},
                         contact_step_period_s=0.74, contact_outcome="heel_strike",
                         phase_replays=phases, phase_replay_outcome=note)
        path = tmp_path / f"o{len(phases)}.h5"
        write_artifact(path, STAGE, scene, "k", lambda f, d=d: write(f, d), 0.0)
        got = load(path)
        assert set(got.phase_replays) == set(phases) and got.phase_replay_outcome == note
        text = " ".join(optimize_lines(got))
        assert ("virtual constraints" in text) == bool(phases)
        assert "(the feed-forward + PD law)" not in text
        assert ("not monotonic" in text) == (not phases)


def test_the_phase_replay_is_off_by_default_but_for_a_five_link_biped():
    """optimize.phase_replay: unset (None) means on for a five-link biped (its virtual
    constraints), off for the others (the law runs in Python: ~20 step maps)."""
    from walkerlab.config.optimize import OptimizeSettings

    assert OptimizeSettings().phase_replay is None
    assert OptimizeSettings(phase_replay=True).phase_replay is True


@pytest.mark.slow
def test_a_powered_optimum_closes_under_the_phase_law():
    """powered_compass made to walk at 0.55 m/s by the least hip torque (the torque not
    zero): under the feed-forward + PD law of the phase variable the step closes (scipy's
    root finder) to <= 1e-6; the PD law regulates the hip (its two multipliers and the
    heel-strike surface's below 1e-2, the feed-forward's second largest ~0.7 at the
    default speed), what is left is the zero dynamics' multiplier (inside the unit circle;
    the stance leg is not actuated, so it need not be below the feed-forward's largest:
    0.82 against 0.74 at the default speed).  ~2 min of CPU."""
    pytest.importorskip("casadi")
    import walkerlab as wl
    from walkerlab.codegen import legged
    from walkerlab.integrate.solver import Solver
    from walkerlab.optimal.replay.hip_phase import hip_phase_replays
    from walkerlab.optimal.transcription.mode_sequence import collocate_step
    from walkerlab.optimal.transcription.step import CollocationSpec, torque_of_time

    scene = load_scene(CONFIGS / "powered_compass.yaml")
    w = wl.Walker.from_scene(scene)
    g = w.fixed_point()
    walk = w.simulate(g.x, strides=1, sample_rate_hz=2000.0)
    first = walk.stance_leg == walk.stance_leg[0]
    data = walker_data(scene.walker, scene.slope.phi_rad)
    res = collocate_step(data, legged.derive_legged(data.structure),
                         CollocationSpec(intervals=40, push_off_n_s=3.0,
                                         target_speed_m_per_s=0.55), walk.t[first],
                         walk.x[first])
    r = hip_phase_replays(data, res, torque_of_time(res), Solver.from_settings(scene.solver))
    fb, ff = r["feedback"], r["feedforward"]
    assert fb.closed and fb.return_error <= 1e-6
    mu_fb, mu_ff = np.abs(fb.multipliers), np.abs(ff.multipliers)  # sorted: largest first
    assert mu_fb[0] < 1.0 and np.all(mu_fb[1:] < 1e-2) and mu_fb[1] < mu_ff[1]
    assert fb.torque_error < 0.05 * np.max(np.abs(res.u))
