"""Physics invariants of the derived compass-gait model (cf. Drake's compass_gait_test.cc)."""

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from walkerlab.codegen.legged import derive_legged as derive
from walkerlab.models.hybrid.printed_equations import (
    energies,
    flow,
    impact,
    make_compass_gait,
    swing_foot_height,
)
from walkerlab.walker.description import compass_gait_structure

P = (5.0, 10.0, 1.0, 0.5, 9.81)  # m, M_H, L, a, g (Table 1)
PHI = 0.0174


def test_energy_constant_in_swing_derived():
    """Total energy along a swing phase is constant to the solver tolerance (rtol 1e-12)."""
    x0 = np.array([-0.2042, 0.1694, -0.6058, -0.8610])
    sol = solve_ivp(flow, (0, 0.7), x0, args=(P, "derived"), rtol=1e-12, atol=1e-12,
                    method="DOP853", dense_output=True)
    X = sol.sol(np.linspace(0, 0.7, 200))
    ke, pe = energies(X, P)
    e = ke + pe
    # |E| ~ 147 J; DOP853 at rtol 1e-12 keeps the relative drift near 1e-12 over 0.7 s.
    assert np.max(np.abs(e - e[0])) / abs(e[0]) < 1e-10


def test_energy_rate_zero_symbolically():
    """dE/dt = 0 along the derived equations, exactly (sympy), as Drake checks to 2e-13."""
    import sympy as sp

    d = derive(compass_gait_structure())
    q, dq = sp.Matrix(d.q), sp.Matrix(d.dq)
    qdd = d.M.LUsolve(-d.C * dq - d.G)
    E = d.kinetic + d.potential
    dE = sum(sp.diff(E, qi) * dqi for qi, dqi in zip(q, dq)) + \
        sum(sp.diff(E, dqi) * qddi for dqi, qddi in zip(dq, qdd))
    assert sp.simplify(dE) == 0


def test_appendix_a_flow_does_not_conserve_energy():
    """The printed A.5 sign makes energy drift during swing (why 'derived' is the default)."""
    x0 = np.array([-0.2042, 0.1694, -0.6058, -0.8610])
    sol = solve_ivp(flow, (0, 0.7), x0, args=(P, "appendix_a"), rtol=1e-12, atol=1e-12,
                    method="DOP853", dense_output=True)
    ke, pe = energies(sol.sol(np.linspace(0, 0.7, 50)), P)
    assert np.ptp(ke + pe) > 1e-3  # J; ~1e9 times the derived model's drift


def test_angular_momentum_about_new_stance_foot_conserved_through_impact(paper_walker):
    """Through the plastic impact the walker's angular momentum about the new stance foot is
    conserved (the impulse acts there).  Positions and velocities are built here from the
    geometry (A.1-A.3), independently of the impact equations; round-off level is ~1e-15
    of |H| ~ 10 kg m^2/s."""
    m, mh, L, a, g = P
    b = L - a
    t2, w1, w2 = -0.2042, -0.7, -0.9
    t1 = -2 * PHI - t2
    xm = np.array([t1, t2, w1, w2])
    assert _heel_strike_fires(paper_walker, np.array([t1, t2, 0.5, -0.9]))
    xp = impact(xm, P, "derived")
    assert xp[0] == t2 and xp[1] == t1  # roles swapped, positions unchanged

    def e(t):  # unit vector hip -> foot of a leg at angle t
        return np.array([np.sin(t), -np.cos(t)])

    def de(t):  # d e / d t
        return np.array([np.cos(t), np.sin(t)])

    hip = -L * e(t2)
    foot = hip + L * e(t1)
    pos = (hip + b * e(t2), hip, hip + b * e(t1))
    hip_v = -L * de(t2) * w2
    vel_minus = (-a * de(t2) * w2, hip_v, hip_v + b * de(t1) * w1)
    W_sw, W_st = xp[2], xp[3]  # new swing (old stance leg, angle t2), new stance (angle t1)
    hip_v = -L * de(t1) * W_st
    vel_plus = (hip_v + b * de(t2) * W_sw, hip_v, -a * de(t1) * W_st)

    def H(vel):
        return sum(mass * ((r - foot)[0] * v[1] - (r - foot)[1] * v[0])
                   for mass, r, v in zip((m, mh, m), pos, vel))

    assert abs(H(vel_plus) - H(vel_minus)) < 1e-13 * abs(H(vel_minus))
    # and the new stance foot is at rest, by construction of the extended system (Eq. 7)


def test_appendix_a_literal_impact_breaks_momentum():
    """The printed A.55 y-sign gives a different, non-conserving impact."""
    xm = np.array([-2 * PHI + 0.2042, -0.2042, -0.7, -0.9])
    assert not np.allclose(impact(xm, P, "appendix_a_literal"), impact(xm, P, "derived"))


# ------------------------------------------------------------------------------ guard
def _guard(walker, phase: str, name: str):
    """The walker's generated guard ``name`` of ``phase`` (what integrate_step locates)."""
    ph = next(p for p in walker.phases if p.name == phase)
    return ph, next(g for g in ph.guards if g.name == name)


def _heel_strike_fires(walker, x, tol: float = 1e-9) -> bool:
    """Does the generated heel-strike guard end a step at ``x``, as integrate_step runs it?
    It is armed only in late swing (entered once the generated ``midstance`` guard,
    ``swing_foot_ahead``, crossed zero upward: the swing foot is ahead) and fires where it
    crosses zero in its direction along the generated flow."""
    _, ahead = _guard(walker, "early_swing", "midstance")
    late, heel = _guard(walker, "late_swing", "heel_strike")
    rate = float(np.asarray(heel.gradient(x)) @ np.asarray(late.flow(0.0, x)))
    return bool(ahead.function(0.0, x) > tol and abs(heel.function(0.0, x)) <= tol
                and np.sign(rate) == heel.direction)


def test_guard_fires_at_heel_strike_not_at_midstance_scuffing(paper_walker, paper_fixed_point):
    """One step from the fixed point: the swing foot height vanishes twice after the start -
    at mid-stance (legs aligned, scuffing: ignored) and at heel strike (the event)."""
    from tests.conftest import TIGHT
    from walkerlab.integrate.rigid import integrate_step

    seg = integrate_step(paper_walker, paper_fixed_point.x, TIGHT)
    assert seg.termination == "heel_strike" and seg.event == "heel_strike"
    t_mid = seg.phase_times["midstance"]
    assert 0.0 < t_mid < seg.t_end
    x_mid = seg.sample(np.array([t_mid]))[:, 0]
    # at mid-stance the point foot is on the ground line (scuffing) ...
    assert abs(swing_foot_height(x_mid, PHI, 1.0)) < 1e-9
    assert not _heel_strike_fires(paper_walker, x_mid)
    # ... but the step ends only at heel strike, with the swing foot ahead and descending
    assert _heel_strike_fires(paper_walker, seg.x_end)
    _, heel = _guard(paper_walker, "late_swing", "heel_strike")
    assert abs(heel.function(0.0, seg.x_end)) < 1e-10
    # right after the impact the state is on the guard surface but must not re-trigger
    assert abs(heel.function(0.0, seg.x_next)) < 1e-10
    assert not _heel_strike_fires(paper_walker, seg.x_next)


@pytest.mark.parametrize(
    ("x", "expected"),
    [
        (np.array([0.1694 - 2 * PHI + 0.0, -0.1694, 0.5, -0.9]), True),  # swing ahead, falling
        (np.array([0.05, 0.05, 0.9, -0.9]), False),  # legs aligned: scuffing
        (np.array([-0.2042, 0.2042 - 2 * PHI, -0.6, -0.86]), False),  # just after impact
        (np.array([0.1694 - 2 * PHI, -0.1694, 1.5, -0.5]), False),  # foot rising
    ],
)
def test_guard_sign_in_each_situation(paper_walker, x, expected):
    """The generated heel-strike guard (the one integrate_step locates), in the situations
    of Drake's compass_gait_test: it fires only with the swing foot ahead and descending."""
    assert _heel_strike_fires(paper_walker, x) is expected


def test_unknown_variant_is_rejected():
    with pytest.raises(ValueError, match="ideal.variant"):
        make_compass_gait(1, 5, 10, 9.81, 0.5, PHI, "bogus")
