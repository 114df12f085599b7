"""The contact walker's own periodic gait (mid-stance step map) and its Floquet multipliers."""

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from walkerlab.analysis.contact.periodic import find_contact_periodic_gait
from walkerlab.analysis.contact.rigid_limit import convergence, observed_order
from walkerlab.analysis.contact.sim import simulate_contact
from walkerlab.analysis.contact.step_map import SECTION_NAMES, StepMap
from walkerlab.analysis.gait.scene import solve_variant
from walkerlab.config import SolverSettings, load_scene
from walkerlab.models.contact.model import checkerboard_lanes
from walkerlab.models.contact.rigid_limit import expected_order
from walkerlab.models.contact.scene import build
from walkerlab.walker.plant import Plant

SCENE = Path(__file__).resolve().parents[2] / "configs" / "paper.yaml"


@pytest.fixture(scope="module")
def setup():
    scene = load_scene(SCENE)
    ideal = solve_variant(scene, "derived", plant=Plant.from_scene(scene))[1]
    walker, _ = build(scene, ideal.x, 2, plant=Plant.from_scene(scene))
    return scene, ideal, walker


@pytest.fixture(scope="module")
def paper_gait(setup):
    _, ideal, walker = setup
    return find_contact_periodic_gait(walker, ideal.x)


def test_fixed_point_residual_and_multipliers(setup, paper_gait):
    """(a) The residual is at the map's noise floor.

    The map's own noise (adaptive-step jitter of LSODA at rtol 1e-11) is ~1e-9 in scaled
    coordinates (measured: a 1e-12 perturbation changes the output by ~6e-10), so 1e-8
    (scaled: rad, rad/s, static penetration, mm/s) is a converged fixed point; measured 4e-10.
    """
    g = paper_gait
    assert g.converged
    assert g.residual < 1e-8
    assert set(g.fixed_point) == set(SECTION_NAMES)
    assert g.stable and g.max_multiplier < 0.6
    # three slow multipliers (complex pair + real) and three fast ones ~ 0 (FD noise)
    assert np.sum(np.abs(g.multipliers) > 1e-3) == 3
    assert abs(g.multipliers[0].imag) > 0.3
    assert g.multiplier_fd_spread < 1e-4  # FD steps h*3, h/3 agree
    # the footfall-relative patches are never left: physically the fixed checkerboard
    assert g.patch_margin_m > 0.02
    # stance foot at its static penetration under the (nearly) full weight at mid-stance
    stat = setup[2].static_penetration()
    assert 0.95 * stat < g.fixed_point["delta_stance"] < 1.05 * stat


def test_period_close_to_ideal(setup, paper_gait):
    """(b) Contact step period within a few % of the ideal 0.7036 s (measured +1.0 %),
    and a direct simulation on a fixed checkerboard spaced by the gait's own step length,
    started on the fixed point, repeats it (independent event detection: 1 kHz samples)."""
    _, ideal, walker = setup
    g = paper_gait
    assert ideal.period_s == pytest.approx(0.7036, abs=1e-4)
    assert g.period_s == pytest.approx(ideal.period_s, rel=0.03)
    c1, c2 = checkerboard_lanes(g.step_length_m, 8)
    w = dataclasses.replace(walker, lane1=c1, lane2=c2, continuous=False)
    x0 = StepMap(walker).to_state(g.z)
    r = simulate_contact(w, x0, 6 * g.period_s, SolverSettings.for_contact(rtol=1e-10, atol=1e-13))
    assert r.termination == "t_final"
    T = np.diff(r.heel_strike_times)
    assert len(T) >= 4
    assert np.all(np.abs(T - g.period_s) < 2e-4)
    assert r.heel_strike_legs[:2] == ["leg1", "leg2"]


def test_periodic_gait_converges_to_rigid_along_the_family_with_observed_order(setup):
    """(c) Along the one rigid-limit family (walkerlab.models.contact.rigid_limit) the contact
    periodic gait's step period and step length reach the rigid ones at an observed order
    between the impact duration's 1/(e+1) = 0.3125 and the stance creep's 1/2 (measured on
    kappa = 1, 10, 100: period 0.47, 0.44; step length 0.505, 0.505; down to 0.37 / 0.56 at
    1e6, gap 0.023 ms / -0.008 mm there).  Bounds: 0.9 x the smaller, 1.15 x the larger
    exponent.  Every slow Floquet multiplier approaches its rigid partner (measured gap
    ratio kappa 1 -> 100: 0.13 for the complex pair, 0.57 for the real one, which dips first:
    0.236 -> 0.203 -> 0.204 against 0.216)."""
    _, ideal, walker = setup
    tab = convergence(walker, ideal, [1.0, 10.0, 100.0])
    assert tab.converged.all()
    lo, hi = 0.9 * expected_order(walker.contact.e), 1.15 * 0.5
    for gap in (tab.period_gap_s, tab.step_gap_m):
        assert np.all(np.sign(gap) == np.sign(gap[0]))
        order = observed_order(tab.kappa, gap)
        assert np.all((order > lo) & (order < hi)), order
    assert tab.multipliers.shape[1] == 3  # complex pair + real, the rigid nonzero ones
    assert np.all(tab.multiplier_gap[-1] < 0.65 * tab.multiplier_gap[0])
    assert np.all(tab.multiplier_gap[-1] < 0.015)


@pytest.mark.slow  # ~10 s CPU: the 72-state variational system on odeint, Python RHS
def test_fd_jacobian_on_the_compiled_map_agrees_with_the_variational_one(setup, paper_gait):
    """The periodic gait's Jacobian (central differences of the step map on the compiled
    integrator, CyRK's BDF at rtol 1e-12) against dP/dz from the variational equations
    (sensitivity matrix integrated with the state, the moving section's correction): the
    two share neither the differencing nor the integrator.  Measured: 1.1e-5 largest scaled
    difference (the FD noise ~1e-10 / h=1e-4 ~ 1e-6 per entry, the fast rows more), slow
    multipliers within 2e-6; the variational fast multipliers are ~1e-14, the FD ones are
    FD noise (~1e-7)."""
    from walkerlab.analysis.contact.periodic import MAP_SOLVER
    from walkerlab.analysis.contact.variational import variational_jacobian

    g = paper_gait
    P = StepMap(setup[2], solver=MAP_SOLVER)
    Jv = variational_jacobian(P, g.z)
    s = P.scale
    assert np.max(np.abs((Jv - g.jacobian) * s[None, :] / s[:, None])) < 1e-4
    ev = np.sort_complex(np.linalg.eigvals(Jv))[::-1]
    slow_v = ev[np.abs(ev) > 1e-3]
    slow_fd = g.multipliers[np.abs(g.multipliers) > 1e-3]
    assert len(slow_v) == len(slow_fd) == 3
    assert np.max(np.abs(np.sort(np.abs(slow_v)) - np.sort(np.abs(slow_fd)))) < 2e-5


def _counting_grid(monkeypatch):
    """Record every run of the step map's grid integrator: (start state, sample times)."""
    from walkerlab.analysis.contact import step_map

    runs, real = [], step_map.contact_grid
    monkeypatch.setattr(step_map, "contact_grid", lambda w, x, tg, *a, **k: (
        runs.append((np.array(x, float), np.array(tg, float))) or real(w, x, tg, *a, **k)))
    return runs, real


def test_the_map_at_the_same_state_again_is_not_integrated_again(setup, paper_gait,
                                                                 monkeypatch):
    """The root finder's forward-difference Jacobian, the fixed point's last step and its
    patch margin evaluate the map where it was just evaluated: the second call integrates
    nothing and returns (copies of) the same bits, which a fresh map computes too."""
    from walkerlab.analysis.contact.periodic import MAP_SOLVER

    z = paper_gait.z
    P = StepMap(setup[2], solver=MAP_SOLVER)
    z1, T, ell = P(z)
    runs, _ = _counting_grid(monkeypatch)
    z2, T2, ell2 = P(z.copy())
    assert runs == [] and P.nfev == 1
    assert np.array_equal(z1, z2) and (T, ell) == (T2, ell2) and z1 is not z2
    P.patch_margin(z)  # its own grid over the step, after the step's crossing from memory
    assert len(runs) == 1 and len(runs[0][1]) == 2001
    monkeypatch.undo()
    z3, T3, ell3 = StepMap(setup[2], solver=MAP_SOLVER)(z)
    assert np.array_equal(z1, z3) and (T, ell) == (T3, ell3)


def test_the_crossing_state_is_brentqs_last_short_run_bit_for_bit(setup, paper_gait,
                                                                    monkeypatch):
    """The section state is the end of the short run brentq evaluated at its root (no run
    after the root finder), identical to a fresh run from the sample before the crossing."""
    from walkerlab.analysis.contact.periodic import MAP_SOLVER

    P = StepMap(setup[2], solver=MAP_SOLVER)
    runs, real = _counting_grid(monkeypatch)
    te, xe = P.next_section(P.to_state(paper_gait.z))
    short = [(x, tg) for x, tg in runs if len(tg) == 2]
    assert short and all(tg[-1] != tg[0] for _, tg in short)
    assert len({tg[-1] for _, tg in short}) == len(short)  # each evaluation once
    assert te in {tg[-1] for _, tg in short}
    xk, tk = short[0][0], short[0][1][0]
    fresh = real(P.walker, xk, np.array([tk, te]), P.solver, P._data)[0][-1]
    assert np.array_equal(xe, fresh)


def test_a_periodic_gait_search_that_falls_says_what_to_try(setup):
    """Issue 56 item 16: a search whose step map fell said only "step map: the walker fell
    (hip below L/2)"; it now says what to try.  The paper walker started from the rigid
    gait with its rates at 20 % falls in the first steps of the map."""
    from walkerlab.analysis.contact.step_map import PeriodicGaitError

    _, ideal, walker = setup
    with pytest.raises(PeriodicGaitError) as exc:
        find_contact_periodic_gait(walker, ideal.x, rate_scale=(0.2, 0.2), warmup_steps=2)
    msg = str(exc.value)
    assert exc.value.kind == "fall" and msg.startswith("step map: the walker fell (hip below "
                                                       "L/2): ")
    assert "walkerlab contact-sim" in msg and "stiffer" in msg and "periodic_gait(x0)" in msg
