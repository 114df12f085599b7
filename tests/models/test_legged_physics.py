"""Physics of the generic symbolic derivation, for every shipped biped structure.

Drake's compass_gait_test.cc checks the same invariants for its one walker: the energy rate is
zero in swing (symbolically here) and the angular momentum about the new stance foot is
conserved through the plastic impact (computed here from positions and velocities of the bodies,
independently of the impact equations)."""

import numpy as np
import pytest
import sympy as sp

from walkerlab.codegen.cache import functions
from walkerlab.codegen.legged import derive_legged as derive
from walkerlab.walker.description import BodySpec, Structure, WalkerData

COMPASS = Structure("absolute", (BodySpec("mass", "point_mass"),))
RODS = Structure("absolute", (BodySpec("rod", "rod"),))
SIMPLEST = Structure("slope_relative", (BodySpec("foot_mass", "point_mass", massless=True),))


@pytest.fixture(scope="module", params=["compass", "rods", "simplest"])
def derived(request):
    s = {"compass": COMPASS, "rods": RODS, "simplest": SIMPLEST}[request.param]
    return s, derive(s)


def test_energy_rate_zero_in_swing_symbolically(derived):
    """dE/dt = dE/dq dq + dE/ddq qdd = 0 along the derived flow, exactly (massless limit too)."""
    _, d = derived
    q, dq = sp.Matrix(d.q), sp.Matrix(d.dq)
    qdd = d.M.LUsolve(-d.C * dq - d.G)
    E = d.kinetic + d.potential
    dE = sum(sp.diff(E, a) * b for a, b in zip(q, dq)) + sum(sp.diff(E, a) * b
                                                             for a, b in zip(dq, qdd))
    assert sp.simplify(sp.together(dE)) == 0


def test_rod_without_inertia_is_a_point_mass_exactly():
    """A rod with I = 0 gives the point-mass equations term by term (sympy, exact)."""
    a, b = derive(RODS), derive(COMPASS)
    sub = {sp.Symbol(f"{k}_rod", real=True): sp.Symbol(f"{k}_mass", real=True) for k in "md"}
    sub[sp.Symbol("I_rod", real=True)] = 0
    for name in ("M", "C", "G", "Mi", "B"):
        diff = getattr(a, name).subs(sub) - getattr(b, name)
        assert diff.applyfunc(sp.simplify) == sp.zeros(*diff.shape), name


def test_simplest_limit_equations_are_garcia_eq_2_3():
    """beta -> 0 limit, l = g = 1: theta'' = sin(theta - gamma) and
    phi'' = theta'' + theta'^2 sin(phi) - cos(theta - gamma) sin(phi) (Garcia et al. 1998)."""
    d = derive(SIMPLEST)
    P = {s: 1 for s in d.params if str(s) in ("g", "L", "M_hip", "d_foot_mass")}
    th, ph = d.q
    thd, _ = d.dq
    gam = next(s for s in d.params if str(s) == "gamma")
    qdd = d.M.subs(P).LUsolve(-d.C.subs(P) * sp.Matrix(d.dq) - d.G.subs(P))
    garcia_th = sp.sin(th - gam)
    garcia_ph = garcia_th + thd**2 * sp.sin(ph) - sp.cos(th - gam) * sp.sin(ph)
    assert sp.simplify(qdd[0] - garcia_th) == 0
    assert sp.simplify(qdd[1] - garcia_ph) == 0


def test_simplest_heel_strike_is_garcia_transition_rule():
    """Garcia et al. Eq. (4): theta+ = -theta-, phi+ = -2 theta-, theta'+ = cos(2 theta) theta'-,
    phi'+ = cos(2 theta) (1 - cos(2 theta)) theta'-, at a heel-strike state phi- = 2 theta-."""
    f = functions(WalkerData(SIMPLEST, (1.0, 1.0, 0.009, 1.0, 1.0), 1.0, 1.0, 1.0, 0.009, {}))
    th, thd, phd = -0.2, -0.21, 0.37
    xp = f["reset"](np.array([th, 2 * th, thd, phd]))
    c = np.cos(2 * th)
    expected = [-th, -2 * th, c * thd, c * (1 - c) * thd]
    np.testing.assert_allclose(xp, expected, rtol=0, atol=1e-15)


def _angular_momentum(f, params, x, inertia, masses):
    """Sum of m (r - r_o) x v + I w about the stance foot (origin of `points`), with the
    velocities from the positions by complex step (independent of the impact equations)."""
    n = x.size // 2
    h = 1e-30
    pts = f["points"](x)
    H = 0.0
    for name, m in masses.items():
        xc = x.astype(complex)
        xc[:n] += 1j * h * x[n:]
        v = np.imag(f["points"](xc)[name]) / h
        r = pts[name]
        H += m * (r[0] * v[1] - r[1] * v[0])
    if inertia:
        la = f["leg_angles"](x)
        # angles are measured from the downward vertical, positive foot ahead: the leg turns
        # counter-clockwise (positive z) when its angle grows
        H += inertia * (la["stance_rate"] + la["swing_rate"])
    return H


@pytest.mark.parametrize("which", ["compass", "rods"])
def test_angular_momentum_about_new_stance_foot_conserved_through_impact(which):
    """The impulse acts at the new stance foot: H about it is the same before and after (both
    legs' bodies and the hip); |H| ~ 10 kg m^2/s, round-off 1e-14."""
    gam = 0.0174
    if which == "compass":
        s, params, masses, inertia = COMPASS, (9.81, 1.0, gam, 10.0, 5.0, 0.5), None, 0.0
        masses = {"hip": 10.0, "stance_mass": 5.0, "swing_mass": 5.0}
    else:
        inertia = 5.0 / 12
        s, params = RODS, (9.81, 1.0, gam, 10.0, 5.0, 0.5, inertia)
        masses = {"hip": 10.0, "stance_rod": 5.0, "swing_rod": 5.0}
    f = functions(WalkerData(s, params, 20.0, 1.0, 9.81, gam, {}))
    st = -0.19
    xm = np.array([-2 * gam - st, st, -0.7, -0.9])  # on the heel-strike surface
    foot = f["points"](xm)["swing_foot"]
    xp = f["reset"](xm)
    # before impact, about the old swing foot: shift the origin of the positions
    n = 2
    hh = 1e-30
    H_minus = 0.0
    for name, m in masses.items():
        xc = xm.astype(complex)
        xc[:n] += 1j * hh * xm[n:]
        v = np.imag(f["points"](xc)[name]) / hh
        r = f["points"](xm)[name] - foot
        H_minus += m * (r[0] * v[1] - r[1] * v[0])
    la = f["leg_angles"](xm)
    H_minus += inertia * (la["stance_rate"] + la["swing_rate"])
    H_plus = _angular_momentum(f, params, xp, inertia, masses)
    assert abs(H_plus - H_minus) < 1e-13 * abs(H_minus)
    # and the positions do not jump: the new stance leg is the old swing leg
    np.testing.assert_allclose(f["points"](xp)["hip"], f["points"](xm)["hip"] - foot, atol=1e-15)
