"""Contact laws (STEP, IMPACT, Coulomb) and settings validation / unit conversion."""

import numpy as np
import pytest
from pydantic import ValidationError

from walkerlab.config import ContactSettings, ContactSimSettings, TerrainSettings
from walkerlab.models.contact import _kernels as K
from walkerlab.models.contact.laws import (
    adams_step,
    adams_step_derivative,
    contact_params_si,
    coulomb_friction_coefficient,
    impact_normal_force,
)
from walkerlab.walker.plant import Plant


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


def test_si_conversion_pins_units():
    """Each field converts from the unit its name says: the paper's mm-kg-s numbers and the
    same contact written in SI give the same SI law (an error of 1000^2.2 otherwise)."""
    si = contact_params_si(ContactSettings(stiffness_n_per_mm_pow_e=1e5, exponent=2.2,
                                           max_damping_n_s_per_mm=90))
    assert si.k == pytest.approx(1e5 * 1000**2.2, rel=1e-12)  # N/mm^2.2 -> N/m^2.2
    assert si.cmax == pytest.approx(9e4)  # N s/mm -> N s/m
    assert si.dmax == pytest.approx(1e-4)  # 0.1 mm
    assert si.v_s == pytest.approx(0.1) and si.v_d == pytest.approx(1.0)
    assert (si.mu_s, si.mu_d, si.e) == (0.9, 0.7, 2.2)
    same = contact_params_si(ContactSettings(
        stiffness_n_per_m_pow_e=si.k, max_damping_n_s_per_m=si.cmax,
        penetration_at_max_damping_m=si.dmax, stiction_velocity_m_per_s=si.v_s,
        friction_velocity_m_per_s=si.v_d))
    assert same == si
    # units may be mixed field by field: each name says its own
    mixed = contact_params_si(ContactSettings(stiffness_n_per_m_pow_e=si.k,
                                              max_damping_n_s_per_mm=90.0))
    assert (mixed.k, mixed.cmax, mixed.dmax) == (si.k, si.cmax, si.dmax)


@pytest.mark.parametrize("kw, field", [
    ({"stiffness_n_per_mm_pow_e": -1.0}, "stiffness_n_per_mm_pow_e"),
    ({"stiffness_n_per_m_pow_e": 2e12}, "stiffness_n_per_m_pow_e"),
    ({"mu_static": 0.5, "mu_dynamic": 0.7}, "mu_dynamic"),
    ({"exponent": 0.5}, "exponent"),
    ({"stiction_velocity_mm_per_s": 2000.0}, "stiction_velocity_mm_per_s"),
    # vs 0.5 m/s against the default vd 1000 mm/s = 1 m/s: fine; 2 m/s is not below it
    ({"stiction_velocity_m_per_s": 2.0}, "friction_velocity_mm_per_s"),
    ({"stiffness_n_per_mm_pow_e": 1e5, "stiffness_n_per_m_pow_e": 4e9},
     "give stiffness_n_per_mm_pow_e (mm-kg-s) or stiffness_n_per_m_pow_e (SI), not both"),
    ({"stifness": 1.0}, "stifness"),  # extra fields are forbidden
])
def test_bad_inputs_name_the_field(kw, field):
    with pytest.raises(ValidationError) as err:
        ContactSettings(**kw)
    assert field in str(err.value)


def test_other_settings():
    assert TerrainSettings().lanes == "checkerboard"
    with pytest.raises(ValidationError, match="patch_width_m"):
        TerrainSettings(patch_width_m=0)
    with pytest.raises(ValidationError, match="pin_stance_until"):
        ContactSimSettings(pin_stance_until="forever")
    assert ContactSimSettings().initial_rate_scale == (1.0, 1.0)


OLD_PAPER_CONTACT = """contact:
  unit_system: {system}
  stiffness: 1.0e+5
  max_damping: 90.0
"""


@pytest.mark.parametrize("system, new", [
    ("mm-kg-s", "stiffness_n_per_mm_pow_e, max_damping_n_s_per_mm (mm-kg-s"),
    ("SI", "stiffness_n_per_m_pow_e, max_damping_n_s_per_m (SI"),
])
def test_old_contact_names_get_one_line_naming_the_new_ones(tmp_path, system, new):
    """A scene written before units were in every contact name (unit_system + stiffness)
    is refused in one line that names the file and the fields to write instead."""
    from pathlib import Path

    from walkerlab.config import SceneError, load_scene

    text = Path("configs/paper.yaml").read_text()
    head = text[:text.index("contact:")]
    rest = text[text.index("terrain:"):]
    p = tmp_path / "old.yaml"
    p.write_text(head + OLD_PAPER_CONTACT.format(system=system) + rest)
    with pytest.raises(SceneError) as err:
        load_scene(p)
    msg = str(err.value)
    assert "\n" not in msg and str(p.name) in msg
    assert "unit_system, stiffness, max_damping" in msg and new in msg


def test_old_knee_stop_names_get_the_new_names():
    from walkerlab.config.contact import KneeStopSettings

    with pytest.raises(ValidationError, match="stiffness_N_m_per_rad is now "
                       "stiffness_n_m_per_rad_pow_e"):
        KneeStopSettings(stiffness_N_m_per_rad=1e5)


def test_paper_scene_writes_table_2_as_printed():
    """configs/paper.yaml writes the paper's contact numbers (Sec. 4 / Fig. 4b, "1e5, 90,
    0.9 and 0.7") exactly as printed, under their mm-kg-s names, and its dumped contact
    section (what the content hash and the artifacts store) names only those fields."""
    from walkerlab.config import load_scene
    from walkerlab.published.paper import CONTACT

    c = load_scene("configs/paper.yaml").contact
    assert {k: getattr(c, k) for k in CONTACT} == CONTACT
    dumped = c.model_dump()
    assert "stiffness_n_per_m_pow_e" not in dumped and "unit_system" not in dumped
    assert dumped["stiffness_n_per_mm_pow_e"] == 1e5


def test_a_run_converts_its_contact_law_to_si_once(monkeypatch):
    """The contact model of a run is built with the law converted once (it was converted
    twice: once for the probe walker that measures the step length, once for the run's)."""
    from walkerlab.config import load_scene
    from walkerlab.models.contact import laws, rigid_limit
    from walkerlab.models.contact.scene import build

    calls = []
    real = laws.contact_params_si
    monkeypatch.setattr(rigid_limit, "contact_params_si",
                        lambda s: calls.append(s) or real(s))
    scene = load_scene("configs/paper.yaml")
    walker, step_length = build(scene, np.array([0.19, -0.19, -1.1, -0.4]), 10,
                                plant=Plant.from_scene(scene))
    assert len(calls) == 1
    assert walker.contact == real(scene.contact) and 0.3 < step_length < 0.45


def test_the_scalar_impact_law_is_the_array_law_bit_for_bit():
    """What the drop test's Python right-hand side calls per evaluation: the same number as
    the array law, to the last bit, on every branch (no contact, damping ramp, full damping,
    a pull clipped to zero)."""
    from walkerlab.models.contact.laws import impact_normal_force_scalar

    rng = np.random.default_rng(3)
    for k, e, cmax, dmax in ((1e5 * 1000**2.2, 2.2, 9e4, 1e-4), (4e9, 2.2, 3e3, 5e-5),
                             (1e3, 1.0, 10.0, 0.1)):
        d = np.concatenate([[-1e-3, 0.0, 1e-12, dmax, 2 * dmax], rng.uniform(-dmax, 3 * dmax, 200)])
        dd = np.concatenate([[1.0, 1.0, -1.0, 0.3, -1e4], rng.uniform(-2.0, 2.0, 200)])
        arr = impact_normal_force(d, dd, k, e, cmax, dmax)
        one = np.array([impact_normal_force_scalar(float(a), float(b), k, e, cmax, dmax)
                        for a, b in zip(d, dd)])
        assert np.array_equal(one, arr), np.max(np.abs(one - arr))
        assert (one == 0).any() and (one > 0).any()
