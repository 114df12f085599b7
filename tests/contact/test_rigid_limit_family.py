"""The one rigid-limit family (walkerlab.models.contact.rigid_limit): its exponents, and the scene's
``stiffness_family: rigid_limit`` is the same family (not a second definition)."""

import pytest

from walkerlab.config.contact import ContactSettings, KneeStopSettings
from walkerlab.models.contact.laws import contact_params_si, knee_stop_si
from walkerlab.models.contact.rigid_limit import contact_si, expected_order, scale


def test_family_exponents():
    c, k = contact_params_si(ContactSettings()), knee_stop_si(KneeStopSettings())
    kappa = 1e4
    c2, k2 = scale(c, k, kappa)
    p = 1 / (c.e + 1)  # 1/3.2
    assert c2.k == pytest.approx(c.k * kappa, rel=1e-15)
    assert c2.cmax == pytest.approx(c.cmax * kappa ** p, rel=1e-15)
    assert c2.dmax == pytest.approx(c.dmax * kappa ** -p, rel=1e-15)
    assert c2.v_s == pytest.approx(c.v_s * 1e-2, rel=1e-15)  # kappa^(-1/2)
    assert c2.v_d / c2.v_s == pytest.approx(c.v_d / c.v_s, rel=1e-15)
    assert (c2.mu_s, c2.mu_d) == (c.mu_s, c.mu_d)
    assert k2.latch_height == pytest.approx(k.latch_height * kappa ** -p, rel=1e-15)
    pk = 1 / (k.e + 1)
    assert k2.cmax == pytest.approx(k.cmax * kappa ** pk, rel=1e-15)
    assert expected_order(2.2) == pytest.approx(1 / 3.2)
    with pytest.raises(ValueError, match="kappa"):
        scale(c, k, 0.0)


def test_scene_family_is_the_one_family():
    """stiffness 1e7 N/mm^2.2 in the rigid_limit family = the reference contact scaled by
    kappa = 100, friction velocities included (the old config family left them)."""
    ref = ContactSettings()
    stiff = ContactSettings(stiffness_n_per_mm_pow_e=1e7, stiffness_family="rigid_limit")
    got, knee = contact_si(stiff)
    want, want_knee = scale(*contact_si(ref), 100.0)
    for f in ("k", "cmax", "dmax", "v_s", "v_d"):
        assert getattr(got, f) == pytest.approx(getattr(want, f), rel=1e-12), f
    assert knee.latch_height == pytest.approx(want_knee.latch_height, rel=1e-12)
    # the paper family keeps the numbers as written
    paper = ContactSettings(stiffness_n_per_mm_pow_e=1e7)
    assert contact_si(paper)[0].v_s == contact_params_si(ref).v_s
    # the reference written in SI is the same reference (kappa from the SI values)
    mixed = ContactSettings(stiffness_n_per_mm_pow_e=1e7, stiffness_family="rigid_limit",
                            reference_stiffness_n_per_m_pow_e=contact_params_si(ref).k)
    for f in ("k", "cmax", "dmax", "v_s", "v_d"):
        assert getattr(contact_si(mixed)[0], f) == pytest.approx(getattr(got, f), rel=1e-12), f
