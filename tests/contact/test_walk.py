"""Gait-level checks: the paper walker on the checkerboard, pinning, falls, benchmark."""

from pathlib import Path

import numpy as np
import pytest

from tests.contact.conftest import FP, STEP_LENGTH
from walkerlab.analysis.contact.sim import initial_state_from_ideal, simulate_contact
from walkerlab.bench.contact import BAND_FACTORS, run_benchmark, run_scene_benchmark
from walkerlab.config import ContactSettings, SolverSettings, TerrainSettings
from walkerlab.integrate.contact import ContactLimits
from walkerlab.models.contact import ContactWalker
from walkerlab.walker.layout import StateIndex


def _paper(width, n_steps=12):
    return ContactWalker.from_settings(ContactSettings(), TerrainSettings(patch_width_m=width),
                                       step_length=STEP_LENGTH, n_steps=n_steps)


def _walk(width, scale=(1.0, 1.0), t_final=7.5, **kw):
    w = _paper(width)
    return w, simulate_contact(w, initial_state_from_ideal(w, *FP, rate_scale=scale), t_final,
                               SolverSettings.for_contact(rtol=1e-9, atol=1e-12), **kw)


def test_paper_walker_walks_five_strides_on_checkerboard():
    """Paper contact values (mm-kg-s), 10 cm patches, stance rate +10%: 10 heel strikes."""
    w, r = _walk(0.10, scale=(1.0, 1.1))
    assert r.termination == "t_final"
    assert r.walked_steps >= 10
    assert r.heel_strike_legs[:4] == ["leg1", "leg2", "leg1", "leg2"]
    done = [s for s in r.steps if np.isfinite(s.period)]
    periods = np.array([s.period for s in done])
    # the faster start gives short first steps (0.58 s, 0.62 s, ...), then the gait settles on
    # the contact model's own cycle: ~0.71 s (ideal 0.7036 s)
    assert periods[0] < 0.65
    assert np.all(np.abs(periods[-4:] - 0.71) < 0.01)
    assert all(0 < s.stance_slip_mm < 2.0 for s in done)  # creep of regularized friction
    assert all(s.bounce_count == 0 for s in done)
    pk = max(s.peak_penetration_m for s in done)
    assert w.static_penetration() < pk < 3 * w.static_penetration()  # ~0.06 mm static


def test_unscaled_ideal_state_drifts_off_narrow_patches():
    """Why the unscaled ideal state fails on 10 cm patches: the contact gait's steps are
    ~12 mm shorter than the ideal 0.372 m (regularized friction, v_s = 100 mm/s), so the
    footfalls drift out of the patches placed at the ideal footfalls; on 30 cm patches the
    same start walks 10 steps."""
    w, r = _walk(0.10)
    assert r.termination in ("fall", "trip") and r.walked_steps < 10
    w, r = _walk(0.30)
    assert r.termination == "t_final" and r.walked_steps >= 10
    s_td = [np.interp(t, r.t, r.feet[leg].s) for t, leg in
            zip(r.heel_strike_times, r.heel_strike_legs)]
    assert 0.355 < np.diff(s_td)[-1] < 0.365


@pytest.mark.slow  # in `pytest -m slow`: the quick suite keeps to its CPU budget
def test_pinned_first_step_and_odeint_vs_radau():
    w = _paper(0.3)
    x0 = initial_state_from_ideal(w, *FP)
    r = simulate_contact(w, x0, 1.0,
                         SolverSettings.for_contact(rtol=1e-9, atol=1e-12),
                         ContactLimits(pin_stance_until="first_touchdown"))
    assert 0.6 < r.pin_end_time < 0.8 and r.walked_steps == 1
    foot2 = w.foot_positions(r.x[r.t <= r.pin_end_time])[:, 1]
    assert np.ptp(foot2, axis=0).max() < 1e-12  # pinned
    a = simulate_contact(w, x0, 1.0,
                         SolverSettings.for_contact(method="odeint", rtol=1e-10, atol=1e-13))
    b = simulate_contact(w, x0, 1.0,
                         SolverSettings.for_contact(method="Radau", rtol=1e-10, atol=1e-13))
    q = StateIndex(w).coordinates  # hip position and leg angles
    assert np.abs(a.x[:, q] - b.x[:, q]).max() < 1e-7  # two independent integrators agree


def test_fall_is_detected():
    w = _paper(0.1)
    x0 = initial_state_from_ideal(w, *FP, rate_scale=(1.0, 0.3))  # too slow: falls back
    for method in ("odeint", "cyrk_bdf", "LSODA"):
        r = simulate_contact(w, x0, 5.0,
                             SolverSettings.for_contact(method=method, rtol=1e-8, atol=1e-11))
        assert r.termination == "fall" and r.fall_time is not None
        assert w.hip_height(r.x)[-1] == pytest.approx(0.5, abs=0.02)


def test_benchmark_runs():
    out = run_benchmark(n_strides=1, methods=("odeint", "LSODA"), rtols=(1e-8,), repeats=1)
    assert out["rhs_cost"]["rhs_numba_us"] > 0 and out["rhs_cost"]["jac_numba_us"] > 0
    for run in out["runs"]:
        assert run["heel_strikes"] >= 2 and run["max_angle_error_rad"] < 1e-4


def test_scene_benchmark_finds_the_band_reaching_the_target():
    """The scene benchmark (``walkerlab bench contact configs/kneed.yaml``), cut to one
    stride and a loose 1e-4 rad target so it runs in ~1 s: the band it reports is the
    loosest of its scan whose four runs all reach the target, and the scan shows a looser
    rtol missing it (so the search did search).  No time is asserted."""
    from walkerlab.config import load_scene

    scene = load_scene(Path(__file__).resolve().parents[2] / "configs" / "kneed.yaml")
    out = run_scene_benchmark(scene, n_strides=1, methods=("cyrk_bdf",),
                              target_error_rad=1e-4, repeats=1)
    assert out["reference"]["termination"] == "t_final"
    assert out["reference"]["heel_strikes"] >= 2
    t = out["target"]["cyrk_bdf"]
    assert t["reached"] and t["worst_error_rad"] <= 1e-4
    assert t["rtols"] == pytest.approx([t["rtols"][0] * f for f in BAND_FACTORS])
    scan = out["scan"]["cyrk_bdf"]
    assert any(r["error"] > 1e-4 and r["rtol"] > t["rtols"][0] for r in scan)
    assert t["median_wall_time_s"] > 0
