"""Contact laws (STEP, IMPACT, Coulomb) and settings validation / unit conversion."""

import numpy as np
import pytest
from pydantic import ValidationError

from walkerlab.config import ContactSettings, ContactSimSettings, TerrainSettings
from walkerlab.contact import _kernels as K
from walkerlab.contact.laws import (
    adams_step,
    adams_step_derivative,
    coulomb_friction_coefficient,
    impact_normal_force,
)


def test_step_values_and_derivative():
    x = np.linspace(-1, 3, 401)
    y = adams_step(x, 0.0, 2.0, 2.0, -1.0)
    assert y[0] == 2.0 and y[-1] == -1.0
    assert adams_step(1.0, 0.0, 2.0, 2.0, -1.0) == pytest.approx(0.5)  # midpoint = mean
    h = 1e-6  # central differences of a cubic: error ~h^2 * |y'''| ~ 1e-12
    fd = (adams_step(x + h, 0, 2, 2, -1) - adams_step(x - h, 0, 2, 2, -1)) / (2 * h)
    inside = (np.abs(x) > 2 * h) & (np.abs(x - 2) > 2 * h)
    np.testing.assert_allclose(adams_step_derivative(x, 0, 2, 2, -1)[inside], fd[inside],
                               atol=1e-8)
    for xi in x[::7]:
        v, d = K.step(xi, 0.0, 2.0, 2.0, -1.0)
        assert v == pytest.approx(adams_step(xi, 0, 2, 2, -1), abs=1e-15)
        assert d == pytest.approx(adams_step_derivative(xi, 0, 2, 2, -1), abs=1e-12)


def test_impact_force_never_pulls_and_is_continuous():
    k, e, cmax, dmax = 1e5, 2.2, 90.0, 0.1
    d = np.array([-0.1, 0.0, 1e-9, 0.05, 0.2, 0.2])
    dd = np.array([5.0, 5.0, -100.0, 0.0, 0.0, -1e6])
    f = impact_normal_force(d, dd, k, e, cmax, dmax)
    assert f[0] == 0 and f[1] == 0  # no contact
    assert f[2] >= 0 and f[2] < 1e-10  # continuous at touchdown (damping ramps in)
    assert f[3] == pytest.approx(k * 0.05**e)
    assert f[5] == 0.0  # strongly separating: clipped, never pulls
    for di, ddi in zip(d, dd):
        assert K.normal_force(di, ddi, k, e, cmax, dmax)[0] == pytest.approx(
            float(impact_normal_force(di, ddi, k, e, cmax, dmax)), rel=1e-14, abs=1e-14)


def test_friction_coefficient():
    args = (0.9, 0.7, 0.1, 1.0)
    v = np.array([0.0, 0.05, 0.1, 0.5, 1.0, 3.0])
    mu = coulomb_friction_coefficient(v, *args)
    assert mu[0] == 0.0
    assert mu[2] == pytest.approx(-0.9) and mu[4] == pytest.approx(-0.7)
    assert mu[5] == pytest.approx(-0.7) and np.all(mu[1:] < 0)
    np.testing.assert_allclose(coulomb_friction_coefficient(-v, *args), -mu)  # odd
    for vi in np.linspace(-2, 2, 41):
        assert K.friction_mu(vi, *args)[0] == pytest.approx(
            float(coulomb_friction_coefficient(vi, *args)), abs=1e-14)


def test_to_si_pins_units():
    si = ContactSettings(stiffness=1e5, exponent=2.2, max_damping=90).to_si()
    assert si.k == pytest.approx(1e5 * 1000**2.2, rel=1e-12)  # N/mm^2.2 -> N/m^2.2
    assert si.cmax == pytest.approx(9e4)  # N s/mm -> N s/m
    assert si.dmax == pytest.approx(1e-4)  # 0.1 mm
    assert si.v_s == pytest.approx(0.1) and si.v_d == pytest.approx(1.0)
    assert (si.mu_s, si.mu_d, si.e) == (0.9, 0.7, 2.2)
    same = ContactSettings(unit_system="SI", stiffness=si.k, max_damping=si.cmax,
                           penetration_at_max_damping=si.dmax, stiction_velocity=si.v_s,
                           friction_velocity=si.v_d).to_si()
    assert same == si


@pytest.mark.parametrize("kw, field", [
    ({"stiffness": -1.0}, "stiffness"),
    ({"mu_static": 0.5, "mu_dynamic": 0.7}, "mu_dynamic"),
    ({"exponent": 0.5}, "exponent"),
    ({"unit_system": "cgs"}, "unit_system"),
    ({"stiction_velocity": 2000.0}, "stiction_velocity"),
    ({"stifness": 1.0}, "stifness"),  # extra fields are forbidden
])
def test_bad_inputs_name_the_field(kw, field):
    with pytest.raises(ValidationError) as err:
        ContactSettings(**kw)
    assert field in str(err.value)


def test_other_settings():
    assert TerrainSettings().kind == "checkerboard"
    with pytest.raises(ValidationError, match="patch_width_m"):
        TerrainSettings(patch_width_m=0)
    with pytest.raises(ValidationError, match="pin_stance_until"):
        ContactSimSettings(pin_stance_until="forever")
    assert ContactSimSettings().initial_rate_scale == (1.0, 1.0)
