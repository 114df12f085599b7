"""The one-step transcription's constraints and objectives on walkers whose step is a
sequence of phases (``walkerlab.optimal.transcription.mode_sequence``): the stance foot's ground
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
from walkerlab.walker.plant import Plant

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
    from walkerlab.optimal.transcription.phases import mode_functions

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


def _newton_euler(walker, data, x, qdd, shift=None, r: float = 0.05):
    """The ground's resultant on the walker ``M (a_com + g y)`` [N] along the slope's normal
    and tangent, from the rigid model's point positions (``walker.points``, the masses by
    the ``m_<body>`` convention) and accelerations ``qdd`` (the rigid flow's); ``shift``:
    a point whose position is subtracted (the pinned point of another kinematics); ``r``
    the Cauchy circle's radius (small enough that the points stay in one kinematics: flat
    feet's switch to the toe-pinned one where the foot turns heel up)."""
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
                          np.asarray(qdd, complex), r)
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


@pytest.fixture(scope="module")
def kneed_fast(kneed):
    """The kneed walker's least-effort step at 0.9 m/s (its passive gait: 0.870 m/s) on 60
    intervals from its passive gait's step, and that step (the guess)."""
    import walkerlab as wl
    from walkerlab.integrate.solver import Solver
    from walkerlab.optimal.transcription.mode_sequence import collocate_phases, phased_guess
    from walkerlab.optimal.transcription.step import CollocationSpec

    scene, data, walker, fns = kneed
    g = wl.Walker.from_scene(scene).fixed_point()
    guess = phased_guess(walker, g.x, g.step_period, Solver.from_settings(scene.solver), 60)[0]
    spec = CollocationSpec(intervals=60, target_speed_m_per_s=0.9)
    return g, guess, spec, collocate_phases(fns, spec, guess)


def _cone_ratios(fns, res):
    """``F_t / F_n`` and ``F_n`` [N] at every point of ``res`` (its phases' ``grf``)."""
    bounds = list(res.phase_start) + [res.t.size]
    out = []
    for mp, a, b in zip(fns["phases"], bounds[:-1], bounds[1:]):
        for k in range(a, b):
            F = mp.grf(res.x[k], res.u[k]).full().ravel()
            out.append((F[1] / F[0], F[0]))
    return np.array(out)


@pytest.mark.slow  # in `pytest -m slow`: the quick suite keeps to its CPU budget
def test_a_friction_cone_that_binds_changes_the_kneed_gait_and_it_replays(kneed, kneed_fast):
    """At 0.9 m/s the least-effort gait needs |F_t| / F_n up to 0.2569 (just after the heel
    strike); with mu = 0.9 of that the cone binds (the largest ratio is mu to 1e-8, now
    at the heel strike's end of the step), the effort rises (2.3e-5 -> 1.2e-3 N^2 m^2 s
    measured), the normal force stays positive and the replay on the rigid model still
    closes (<= 1e-6; 1.9e-7 seen)."""
    from dataclasses import replace

    from walkerlab.optimal.transcription.mode_sequence import collocate_phases, replay_phases

    _, data, _, fns = kneed
    _g, guess, spec, free = kneed_fast
    mu_free = np.max(np.abs(_cone_ratios(fns, free)[:, 0]))
    assert 0.2 < mu_free < 0.3
    mu = 0.9 * mu_free
    res = collocate_phases(fns, replace(spec, friction_coefficient=mu), guess)
    assert res.status == "Solve_Succeeded"
    r = _cone_ratios(fns, res)
    assert np.max(np.abs(r[:, 0])) == pytest.approx(mu, rel=1e-8)
    assert np.min(r[:, 1]) > 0.0
    assert res.objective > 10 * free.objective
    assert res.step_length_m / res.step_period_s == pytest.approx(0.9, rel=1e-9)
    assert replay_phases(data, res)[0] <= 1e-6


def _as_artifact(res, walker):
    """A phased result as the optimize.h5 reader returns it."""
    from walkerlab.io.schemas.optimize import OptimizeData

    names = list(walker.state_names())
    return OptimizeData(res.t, {n: res.x[:, k] for k, n in enumerate(names)}, res.u,
                        res.step_period_s, res.step_length_m, 0.0, res.objective, 1e-9,
                        np.zeros(6, complex), True, res.status, res.iterations, 0.1,
                        dict.fromkeys(names, "-"), phase_names=res.phase_names,
                        phase_start=res.phase_start, phase_duration_s=res.phase_duration_s)


def test_another_optimize_h5_of_the_walker_starts_the_phased_collocation(kneed, kneed_fast):
    """The 0.9 m/s optimum as the guess (its states and torque on its own mesh): IPOPT
    returns to it (the objective and step period to 1e-9) in a few iterations with the
    barrier started small (``warm_start``: 7 seen; IPOPT's default 0.1 took ~30, as from
    the passive gait), and resampled to 40 intervals it finds the same gait (step period to
    1e-6: the coarser mesh's O(h^4))."""
    from dataclasses import replace

    from walkerlab.optimal.transcription.mode_sequence import collocate_phases, optimized_guess

    _, _, walker, fns = kneed
    _g, _guess, spec, free = kneed_fast
    d = _as_artifact(free, walker)
    names = list(free.phase_names)
    guess, torque = optimized_guess(d, names, 60)
    assert [x.shape[0] for _n, _t, x in guess] == [x.shape[0] for _n, _t, x in _guess]
    again = collocate_phases(fns, replace(spec, warm_start=True), guess, torque)
    assert again.status == "Solve_Succeeded" and again.iterations <= 10
    assert again.objective == pytest.approx(free.objective, rel=1e-9)
    assert again.step_period_s == pytest.approx(free.step_period_s, rel=1e-9)
    guess, torque = optimized_guess(d, names, 40)
    assert sum((x.shape[0] - 1) // 2 for _n, _t, x in guess) == 40
    coarse = collocate_phases(fns, replace(spec, intervals=40), guess, torque)
    assert coarse.status == "Solve_Succeeded"
    assert coarse.step_period_s == pytest.approx(free.step_period_s, rel=1e-6)


def test_an_optimize_h5_without_the_walkers_phases_is_refused_in_one_line(kneed, kneed_fast):
    from walkerlab.optimal.transcription.mode_sequence import optimized_guess

    _, _, walker, _fns = kneed
    d = _as_artifact(kneed_fast[3], walker)
    for phases, why in ((("locked_swing", "unlocked_swing"), "are not the scene gait's"),
                        ((), "has no phases")):
        d.phase_names = phases
        with pytest.raises(ValueError, match="optimize.initial_guess") as e:
            optimized_guess(d, ["unlocked_swing", "locked_swing"], 60)
        assert why in str(e.value) and "\n" not in str(e.value)


@pytest.mark.slow
def test_the_flat_feet_ground_reaction_is_the_rigid_models_and_newton_eulers():
    """Every phase of the flat-footed gait, with a hip torque, near the gait: the normal
    component equals the rigid model's own generated ground force (heel pinned: ``N``,
    the heel's and toe's together in foot flat; toe pinned: ``N``) and both components
    ``M (a_com + g)`` from the rigid model's points (heel-pinned; toe-pinned: less the
    stance toe's acceleration) and torqued flow, to 1e-10 of the weight (~15 s: the flat
    feet's CasADi phases)."""
    pytest.importorskip("casadi")
    from walkerlab.codegen.cache import functions
    from walkerlab.optimal.transcription.phases import mode_functions

    _, data, walker = _walker("flat_feet_optimal.yaml")
    fns = mode_functions(data, walker, FLAT_ORDER)
    f = functions(data)
    u = 0.4
    torqued = {ph.name: ph for ph in _torqued(data, u).phases}
    weight = float(walker.total_mass_kg) * float(data.gravity_m_per_s2)
    rng = np.random.default_rng(13)
    x0 = np.array([-0.3, 0.2, -0.05, -1.3, -1.2, 1.2])
    for _ in range(3):
        x = x0 + rng.normal(0.0, 0.03, 6)
        for mp in fns["phases"]:
            qdd = torqued[mp.name].flow(0.0, x)[3:]
            toe = mp.name.startswith("heel_off")
            got = mp.grf(x, u).full().ravel()
            normal = (f["ground_toe"] if toe else f["ground_heel"])(x, qdd)[0]
            assert got[0] == pytest.approx(normal, abs=1e-10 * weight), mp.name
            want = _newton_euler(walker, data, x, qdd, "stance_toe" if toe else None, 5e-3)
            np.testing.assert_allclose(got, want, rtol=0, atol=1e-10 * weight,
                                       err_msg=mp.name)


def test_the_kneed_walkers_least_cost_of_transport_on_its_slope_is_its_passive_gait(
        kneed, kneed_fast):
    """Cost of transport (slack variables) with an effort weight of 1e-2 from the passive
    gait's step: CoT ~0 (1.1e-11 seen: the interior point's slack floor), the torque ~0
    (6e-5 N m seen), the step period within 1e-3 of the shooting gait's (1e-4 seen: the
    objective, ~1e-11 there, resolves no closer) and the replay closing (<= 1e-6)."""
    from walkerlab.optimal.transcription.mode_sequence import collocate_phases, replay_phases
    from walkerlab.optimal.transcription.step import CollocationSpec

    _, data, _, fns = kneed
    g, guess, _spec, _free = kneed_fast
    res = collocate_phases(fns, CollocationSpec(intervals=60, objective="cost_of_transport",
                                                cost_of_transport_effort_weight=1e-2), guess)
    assert res.status == "Solve_Succeeded"
    assert res.terms["cost_of_transport"] <= 1e-10
    assert np.max(np.abs(res.u)) < 1e-3
    assert res.step_period_s == pytest.approx(g.step_period, rel=1e-3)
    assert replay_phases(data, res)[0] <= 1e-6


@pytest.mark.slow
def test_the_cost_of_transport_does_not_drift_to_large_torques(kneed, kneed_fast):
    """At 0.9 m/s with the effort weight 1e-6 (~25 s): the least-CoT gait needs no
    positive work (CoT ~1e-11) and its torque stays the least-effort gait's size (< 0.1 N m;
    0.0096 seen); with IPOPT's default initial barrier it drifted to 100 N m torques
    chattering between the points and a replay that did not step
    (:func:`walkerlab.optimal.transcription.step.ipopt_options`)."""
    from dataclasses import replace

    from walkerlab.optimal.transcription.mode_sequence import collocate_phases, replay_phases

    _, data, _, fns = kneed
    _g, guess, spec, _free = kneed_fast
    res = collocate_phases(fns, replace(spec, objective="cost_of_transport",
                                        cost_of_transport_effort_weight=1e-6), guess)
    assert res.status == "Solve_Succeeded"
    assert res.terms["cost_of_transport"] <= 1e-10
    assert np.max(np.abs(res.u)) < 0.1
    assert replay_phases(data, res)[0] <= 1e-6


def _continuation(path, scene, names, slopes, X, periods):
    """A continuation artifact over the slope with the gaits ``X`` (rows) at ``slopes``."""
    from walkerlab.io.artifacts import put, write_artifact
    from walkerlab.io.schemas.continuation import STAGE

    def writer(f):
        f.attrs.update(parameter_path="slope.angle_rad", parameter_unit="rad",
                       state_names=names, parameter_start=float(np.mean(slopes)))
        g = f.create_group("branches/0")
        g.attrs["branch_period"] = 1
        put(g, "param", np.array(slopes), "rad")
        for k, n in enumerate(names):
            put(g, f"state/{n}", X[:, k], "rad")
            put(g, f"orbit/{n}", X[:, k:k + 1], "rad")
        put(g, "period", np.array(periods), "s")
        for part in ("real", "imag"):
            put(g, f"multipliers/{part}", np.zeros((2, len(names))), "-")
        put(g, "stable", np.ones(2, int), "-")
        s = f.create_group("special_points")
        for k in ("kind", "cause"):
            put(s, k, np.zeros(0, "S1"), "-")
        for k in ("param", "period", "branch"):
            put(s, k, np.zeros(0), "-")
        for n in names:
            put(s, f"state/{n}", np.zeros(0), "rad")
        for part in ("real", "imag"):
            put(s, f"multipliers/{part}", np.zeros((0, len(names))), "-")

    write_artifact(path, STAGE, scene, "x", writer, 0.0)


def test_the_phased_scene_reads_its_guess_from_artifacts(kneed, kneed_fast, tmp_path):
    """``optimize.initial_guess`` of a kneed scene: another phased optimize.h5 gives its
    states and torque phase by phase (the same mesh: exactly); a continuation artifact's
    branch at the scene's slope gives one step of the rigid walker from its gait there (the
    phases simulated from it); a one-step optimize.h5 is refused in one line."""
    from walkerlab.io.artifacts import write_artifact
    from walkerlab.io.schemas import optimize as schema
    from walkerlab.optimal.driver import starting_phases

    scene, _data, walker, _fns = kneed
    g, guess, _spec, free = kneed_fast
    names = list(walker.state_names())

    def with_guess(spec):
        d = scene.model_dump(mode="json", exclude_none=True)
        d["optimize"]["initial_guess"] = spec
        return type(scene).model_validate(d)

    d = _as_artifact(free, walker)
    path = tmp_path / "optimize.h5"
    write_artifact(path, schema.STAGE, scene, "x", lambda f: schema.write(f, d), 0.0)
    got, torque, order = starting_phases(with_guess({"from": str(path)}), walker, g.x,
                                        g.step_period, 60)
    assert [n for n, _g, _d in order] == list(free.phase_names)
    np.testing.assert_array_equal(np.concatenate([x for _n, _t, x in got]), free.x)
    np.testing.assert_array_equal(np.concatenate(torque), free.u)
    slope = scene.slope.phi_rad
    cpath = tmp_path / "continuation_slope.h5"
    _continuation(cpath, scene, names, [slope - 0.01, slope + 0.01], np.array([g.x, g.x]),
                  [g.step_period] * 2)
    got, torque, _order = starting_phases(with_guess({"from": str(cpath), "at": slope}),
                                         walker, np.zeros(6), g.step_period, 60)
    assert torque is None
    for (n1, t1, x1), (n2, t2, x2) in zip(got, guess):
        assert n1 == n2
        np.testing.assert_allclose(t1, t2, rtol=0, atol=1e-12)
        np.testing.assert_allclose(x1, x2, rtol=0, atol=1e-12)
    d.phase_names, d.phase_start = (), None
    write_artifact(path, schema.STAGE, scene, "x", lambda f: schema.write(f, d), 0.0)
    with pytest.raises(ValueError, match="optimize.initial_guess: the optimize.h5 has no "
                                         "phases") as e:
        starting_phases(with_guess({"from": str(path)}), walker, g.x, g.step_period, 60)
    assert "\n" not in str(e.value)


def test_an_ankle_push_off_is_refused_in_one_line():
    """Flat feet with an ankle push-off (configs/flat_feet_push_off.yaml): the phased
    transcription has a hip torque only (and the rigid flat feet take the two not
    together), so the scene is refused before any work, naming the field."""
    pytest.importorskip("casadi")
    from walkerlab.optimal.driver import optimize_scene

    scene = load_scene(CONFIGS / "flat_feet_push_off.yaml")
    d = scene.model_dump(mode="json", exclude_none=True)
    d["optimize"] = {"objective": "effort"}
    scene = type(scene).model_validate(d)
    with pytest.raises(ValueError, match="walker.actuation.ankle_push_off") as e:
        optimize_scene(scene, np.zeros(6), 0.75, plant=Plant.from_scene(scene))
    assert "\n" not in str(e.value)
