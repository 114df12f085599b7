"""The five-link optimum replayed with its torques as a function of the phase variable
(walkerlab.optimal.replay.virtual_constraints): the law on tables built by hand, its stored records
(optimize.h5's ``replay/phase_<law>/``) and their words in the report.  The replays of the
shipped optimum itself are in tests/test_optimize_five_link.py (slow, they share its run)."""

from __future__ import annotations

import numpy as np
import pytest

from walkerlab.optimal.replay.phase import PhaseLaw
from walkerlab.optimal.replay.virtual_constraints import phase_law


def _table(m: int = 21, k: int = 2):
    """A step whose phase variable falls linearly from 0.3 to -0.3 rad at -0.9 rad/s, its
    joint angles ``delta_j = a_j sin(2 s) + b_j s^2`` and torques ``u_j = c_j cos(3 s)``."""
    s = np.linspace(0.3, -0.3, m)
    ds = np.full(m, -0.9)
    a, b, c = np.array([0.4, -0.2])[:k], np.array([1.0, 0.5])[:k], np.array([20.0, -7.0])[:k]
    delta = a * np.sin(2 * s)[:, None] + b * (s ** 2)[:, None]
    slope = 2 * a * np.cos(2 * s)[:, None] + 2 * b * s[:, None]
    u = c * np.cos(3 * s)[:, None]
    return s, ds, delta, slope, u, (a, b, c)


def test_the_pd_part_vanishes_on_the_collocated_step():
    """At every table point, on the step (delta = h(s), ddelta = h'(s) ds) the law gives the
    optimised torque to round-off: the PD part is zero there, whatever the gains."""
    s, ds, delta, slope, u, _ = _table()
    law = PhaseLaw(s, delta, slope, u, [2000.0, 500.0], [120.0, 60.0])
    for i in range(len(s)):
        got = law.each(delta[i], slope[i] * ds[i], s[i], ds[i])
        np.testing.assert_allclose(got, u[i], rtol=0, atol=1e-10 * np.abs(u).max())


def test_the_law_interpolates_at_the_splines_order_and_feeds_back_with_its_sign():
    """Between the points the reference is the Hermite cubic (error O(h^4): below 1e-6 rad
    on this 21-point table of a smooth curve, measured ~1e-7), the feed-forward the
    not-a-knot spline (below 1e-4 N m of a 20 N m torque); a joint 0.01 rad above its
    reference at rest in s gets -K * 0.01 more, one moving 0.1 rad/s too fast -D * 0.1."""
    s, ds, delta, slope, u, (a, b, c) = _table()
    K, D = np.array([2000.0, 500.0]), np.array([120.0, 60.0])
    law = PhaseLaw(s, delta, slope, u, K, D)
    for si in np.linspace(-0.29, 0.29, 17):
        h = a * np.sin(2 * si) + b * si ** 2
        np.testing.assert_allclose(law.h(si), h, atol=1e-6)
        np.testing.assert_allclose(law.ff(si), c * np.cos(3 * si), atol=1e-4)
        base = law.each(law.h(si), np.zeros(2), si, 0.0)
        np.testing.assert_allclose(law.each(law.h(si) + 0.01, np.zeros(2), si, 0.0) - base,
                                   -K * 0.01, rtol=1e-12)
        np.testing.assert_allclose(law.each(law.h(si), np.full(2, 0.1), si, 0.0) - base,
                                   -D * 0.1, rtol=1e-12)


def test_the_law_is_complex_step_safe():
    """The rigid model's variational equations differentiate the law by the complex step:
    d tau / d s from it equals central differences (to 1e-6 of the slope)."""
    s, ds, delta, slope, u, _ = _table()
    law = PhaseLaw(s, delta, slope, u, [2000.0, 500.0], [120.0, 60.0])
    x = (np.array([0.01, -0.02]), np.array([0.3, -0.1]), 0.123, -0.8)
    h = 1e-20
    cs = np.imag(law.each(x[0], x[1], x[2] + 1j * h, x[3])) / h
    e = 1e-6
    fd = (law.each(x[0], x[1], x[2] + e, x[3]) - law.each(x[0], x[1], x[2] - e, x[3])) / (2 * e)
    np.testing.assert_allclose(cs, fd, rtol=1e-6, atol=1e-6 * np.abs(fd).max())


class _Acts:
    """Actuators whose joint angles are read off the state: ``x = (s, ds, deltas, ddeltas)``."""

    def joint_angles(self, x):
        return list(x[2:4]), list(x[4:6]), x[0], x[1]


def test_a_phase_variable_that_turns_back_is_refused_in_one_line():
    """The references need a monotonic phase variable (Westervelt et al. 2003): a step
    whose stance angle turns back gets one line naming it."""
    s = np.array([0.3, 0.1, 0.0, 0.05])
    x = np.array([[si, dsi, 0.0, 0.0, 0.0, 0.0] for si, dsi in zip(s, [-1, -1, -0.1, 0.5])])
    with pytest.raises(ValueError, match="not monotonic") as exc:
        phase_law(_Acts(), x, np.zeros((4, 2)), [1.0, 1.0], [1.0, 1.0])
    assert "\n" not in str(exc.value)
    ok = x.copy()
    ok[:, 0], ok[:, 1] = [0.3, 0.1, 0.0, -0.05], -1.0
    law = phase_law(_Acts(), ok, np.ones((4, 2)), [1.0, 1.0], [1.0, 1.0])
    np.testing.assert_allclose(law.each([0.0, 0.0], [0.0, 0.0], 0.1, -1.0), [1.0, 1.0])


def _data(phase: bool):
    from walkerlab.io.schemas.optimize import OptimizeData, PhaseReplayData

    t = np.linspace(0.0, 0.7, 5)
    reps = {} if not phase else {
        "feedback": PhaseReplayData(2.8e-4, 2.9e-4, 3e-11, 0.69999, 0.04,
                                    np.array([0.39 + 0j, 0.02 - 0.01j, 0.02 + 0.01j]), True),
        "feedforward": PhaseReplayData(2.7, 0.0, 2.7, 0.688, 0.0,
                                       np.array([1.2e4 + 0j, 3.0 + 0j]), False)}
    return OptimizeData(
        t, {"a": t.copy(), "b": -t}, np.ones((5, 4)), 0.7, 0.5, 0.0, 130.0, 1e-8,
        np.array([1648.0 + 0j]), True, "Solve_Succeeded", 40, 3.0, {"a": "rad", "b": "rad/s"},
        torque_names=("stance_hip", "swing_hip", "stance_knee", "swing_knee"),
        contact_step_period_s=0.706, contact_outcome="heel_strike", phase_replays=reps)


@pytest.mark.parametrize("phase", [True, False])
def test_the_phase_replays_are_stored_and_read_back(tmp_path, phase):
    """optimize.h5 keeps both laws' records (units on every dataset) and reads them back;
    a file without them (the straight-legged walkers', earlier five-link ones) reads as
    none."""
    from pathlib import Path

    from walkerlab.config import load_scene
    from walkerlab.io.artifacts import write_artifact
    from walkerlab.io.schemas.optimize import STAGE, load, write

    d = _data(phase)
    path = tmp_path / "optimize.h5"
    scene = load_scene(Path(__file__).resolve().parents[1] / "configs" / "rabbit_optimal.yaml")
    write_artifact(path, STAGE, scene, "k", lambda f: write(f, d), 0.0)
    got = load(path)
    assert set(got.phase_replays) == set(d.phase_replays)
    for name, r in d.phase_replays.items():
        g = got.phase_replays[name]
        for key in ("collocated_start_error", "start_shift", "return_error", "step_period_s",
                    "torque_error", "closed"):
            assert getattr(g, key) == getattr(r, key), key
        np.testing.assert_array_equal(g.multipliers, r.multipliers)
    if phase:
        import h5py

        with h5py.File(path) as f:
            assert f["replay/phase_feedback/torque_error"].attrs["unit"] == "N m"
            assert f["replay/phase_feedback/step_period"].attrs["unit"] == "s"


def test_the_report_says_what_the_phase_replays_did():
    """The optimised step's paragraph gives the closed replay's return error, its largest
    multiplier and torque error, the feed-forward's for the record, and the contact
    model's period against the optimum's in %."""
    from walkerlab.report.figures_section import optimize_lines

    text = " ".join(optimize_lines(_data(True)))
    assert "virtual constraints" in text and "feed-forward alone" in text
    assert "0.39" in text and "(the feed-forward + PD law)" in text and "0.86 %" in text
    assert "virtual constraints" not in " ".join(optimize_lines(_data(False)))


def test_the_feed_forward_is_the_transcriptions_control_at_the_time_the_step_passes_s():
    """With the collocation times the feed-forward is ``u*(T(s))``: the Hermite-Simpson
    control (each interval's quadratic, control_of_time against torques_of_time to
    round-off) at the time the step passes ``s``; exact at the points, and between them
    within the Hermite spline ``T``'s O(h^4) of a step at constant ``ds`` (T exact)."""
    from walkerlab.optimal.replay.phase import control_of_time
    from walkerlab.optimal.transcription.free_joints import torques_of_time

    s, ds, delta, slope, _, _ = _table()
    t = (s[0] - s) / 0.9
    u = np.stack([np.sin(7 * t) * 30, t ** 3 - t], axis=1)
    U, tau = control_of_time(t, u), torques_of_time(t, u)
    for ti in np.linspace(0.0, t[-1] + 0.01, 37):
        np.testing.assert_allclose(U(ti), tau(ti), rtol=0, atol=1e-12)
    law = PhaseLaw(s, delta, slope, u, [2000.0, 500.0], [120.0, 60.0], t=t, ds=ds)
    for si in np.linspace(-0.31, 0.3, 23):
        np.testing.assert_allclose(law.ff(si), tau((s[0] - si) / 0.9), atol=1e-9)


def test_the_phased_walker_runs_its_law_in_python_and_compiled():
    """The walker's Python torque is the law's; its compiled flows carry the law's block
    (:meth:`PhaseLaw.packed`), not the placeholder zero laws ``actuate`` packed."""
    from pathlib import Path

    from walkerlab.config import load_scene
    from walkerlab.optimal.replay.phase import LIMIT_N_M
    from walkerlab.optimal.replay.virtual_constraints import phased_walker
    from walkerlab.walker.description import walker_data

    scene = load_scene(Path(__file__).resolve().parents[1] / "configs" / "rabbit_optimal.yaml")
    data = walker_data(scene.walker, 0.0)
    s, ds, delta, slope, u, _ = _table(k=2)
    law = PhaseLaw(s, np.hstack([delta, delta]), np.hstack([slope, slope]),
                   np.hstack([u, u]), [1.0] * 4, [0.0] * 4)
    w = phased_walker(data, law)
    assert all(np.array_equal(ph.compiled.laws, law.packed(LIMIT_N_M)) for ph in w.phases)
    x = np.array([0.1, 0.3, -0.1, -0.3, -0.1, -1.0, 0.4, -1.2, -1.0, -0.5])
    deltas, ddeltas, sx, dsx = w.actuators.joint_angles(x)
    np.testing.assert_allclose(w.actuators.torques(0.0, x), law.each(deltas, ddeltas, sx, dsx),
                               rtol=1e-14)


@pytest.mark.parametrize("timed", [False, True])
def test_the_law_block_is_the_phase_law(timed):
    """Plain Python (no numba): the compiled flows' law (``law_torque`` on
    :meth:`PhaseLaw.packed`, kind FEEDFORWARD) against :meth:`PhaseLaw.each` inside the
    table and extrapolated past both ends (to 1e-13 of the torque: the same splines'
    coefficients, its own Horner sums), its partial derivatives against the complex step
    through ``each`` (1e-8: the complex step's first order), saturation at the limit."""
    from walkerlab.codegen.torque_law import law_torque

    s, ds, delta, slope, u, _ = _table()
    kw = {"t": (s[0] - s) / 0.9, "ds": ds} if timed else {}
    law = PhaseLaw(s, delta, slope, u, [2000.0, 500.0], [120.0, 60.0], **kw)
    b = law.packed()
    rng = np.random.default_rng(3)
    for si in np.concatenate([rng.uniform(-0.4, 0.4, 100), s]):
        de, dde, dsi = rng.normal(0, 0.3, 2), rng.normal(0, 1, 2), float(rng.normal(-1, 0.2))
        want = law.each(de, dde, float(si), dsi)
        for k in range(2):
            got = law_torque(b, k, de[k], dde[k], float(si), dsi, 0.0)
            assert got[0] == pytest.approx(want[k], rel=1e-13, abs=1e-11)
            h = 1e-30
            for j in range(4):
                z = [de.astype(complex), dde.astype(complex), complex(si), complex(dsi)]
                if j < 2:
                    z[j][k] += 1j * h
                else:
                    z[j] += 1j * h
                d = np.imag(law.each(*z)[k]) / h
                assert got[1 + j] == pytest.approx(d, rel=1e-8, abs=1e-8), (j, k)
    sat = law.packed(limit=1.0)
    assert law_torque(sat, 0, 5.0, 0.0, 0.1, -1.0, 0.0) == (-1.0, 0.0, 0.0, 0.0, 0.0)


@pytest.mark.parametrize("timed", [False, True])
def test_the_one_table_evaluation_gives_the_splines_own_numbers(timed):
    """At a real ``s`` the law reads h, h' and T (or the spline of u) from one stacked
    PPoly: bit for bit what the separate splines give (the padded zero coefficient adds an
    exact 0), inside the table and extrapolated past both ends."""
    s, ds, delta, slope, u, _ = _table()
    kw = {"t": (s[0] - s) / 0.9, "ds": ds} if timed else {}
    law = PhaseLaw(s, delta, slope, u, [2000.0, 500.0], [120.0, 60.0], **kw)
    rng = np.random.default_rng(5)
    for si in np.concatenate([rng.uniform(-0.35, 0.35, 200), s]):
        de, dde, dsi = rng.normal(0, 0.3, 2), rng.normal(0, 1, 2), float(rng.normal(-1, 0.2))
        want = law.ff(si) - law.K * (de - law.h(si)) - law.D * (dde - law.dh(si) * dsi)
        assert np.array_equal(law.each(de, dde, float(si), dsi), want)
