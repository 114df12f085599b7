"""The exports' contact parameters derive from the one contact law.

The law is :mod:`walkerlab.models.contact.laws` (IMPACT normal force, ADAMS regularised
Coulomb friction); the Adams dataset writes it in mm-kg-s, the MJCF linearises it at the
walker's static penetration, the OpenSim model fits Hunt-Crossley through the same point
(docs: "Where the contact law lives", user guide, equations).  Each export's numbers are
re-derived here from the law's force function alone: the static penetration by a root
finder on ``F_n(d, 0) = W``, the tangent stiffness and the damping there by differences of
``F_n`` (not from the exporters' closed forms), and the MJCF file read back as written.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import brentq

from walkerlab.config import load_scene
from walkerlab.export.adams_contact import contact_mm
from walkerlab.export.mjcf_scene import MJCF_CONTACT_SHRINK
from walkerlab.export.opensim_contact import hunt_crossley
from walkerlab.models.contact.laws import (
    coulomb_friction_coefficient,
    impact_normal_force_scalar,
)
from walkerlab.models.contact.rigid_limit import contact_si
from walkerlab.stages.export import write
from walkerlab.walker.plant import Plant

CONFIGS = Path(__file__).resolve().parents[2] / "configs"


def _law(c):
    """The scene's IMPACT normal force ``(d [m], v [m/s]) -> N``."""
    return lambda d, v: impact_normal_force_scalar(d, v, c.k, c.e, c.cmax, c.dmax)


def _static_point(c, weight_n):
    """Static penetration ``d_s`` [m] of ``weight_n`` [N] on one foot, the tangent stiffness
    [N/m] and the damping [N s/m] there, from the law's force alone (root finder and central
    differences, relative step 1e-6: truncation ~1e-12, round-off ~1e-10 of the force)."""
    f = _law(c)
    ds = brentq(lambda d: f(d, 0.0) - weight_n, 1e-12, 1.0, xtol=1e-16, rtol=1e-15)
    h = 1e-6 * ds
    stiffness = (f(ds + h, 0.0) - f(ds - h, 0.0)) / (2 * h)
    damping = (f(ds, 1e-3) - f(ds, 0.0)) / 1e-3  # linear in the rate while F_n > 0
    return ds, stiffness, damping


@pytest.mark.parametrize("scene", ["paper", "kneed"])
def test_the_adams_dataset_writes_the_one_law_in_mm(scene):
    """The Adams IMPACT and friction numbers (mm-kg-s) give the law's forces in newtons and
    its friction coefficients at every penetration, rate and slip velocity tried."""
    settings = load_scene(CONFIGS / f"{scene}.yaml").contact
    c, _ = contact_si(settings)
    m = contact_mm(settings)
    for d in (0.2 * c.dmax, c.dmax, 3 * c.dmax):
        for v in (-0.05, 0.0, 0.3):
            si = impact_normal_force_scalar(d, v, c.k, c.e, c.cmax, c.dmax)
            mm = impact_normal_force_scalar(1e3 * d, 1e3 * v, m["STIFFNESS"], m["EXPONENT"],
                                            m["DAMPING"], m["DMAX"])
            assert mm == pytest.approx(si, rel=1e-12)
    v = np.array([-0.3, -0.05, -0.004, 0.0, 0.002, 0.03, 1.0])  # m/s
    mu = coulomb_friction_coefficient(v, c.mu_s, c.mu_d, c.v_s, c.v_d)
    mu_mm = coulomb_friction_coefficient(1e3 * v, m["MU_STATIC"], m["MU_DYNAMIC"],
                                         m["STICTION_TRANSITION_VELOCITY"],
                                         m["FRICTION_TRANSITION_VELOCITY"])
    np.testing.assert_allclose(mu_mm, mu, rtol=1e-12, atol=1e-15)


def test_the_mjcf_contact_is_the_law_linearised_at_the_static_penetration(tmp_path):
    """The MJCF's solref ``(tau, z)``: ``z`` the damping ratio and ``1/(z w)`` the time
    constant of the law's tangent stiffness and damping at the walker's static penetration
    on one foot, shrunk by MJCF_CONTACT_SHRINK; friction the static coefficient."""
    scene = load_scene(CONFIGS / "paper.yaml")
    plant = Plant.from_scene(scene)
    c, _ = contact_si(scene.contact)
    mass = float(plant.data.total_mass_kg)
    g = float(plant.data.gravity_m_per_s2)
    weight = mass * g * math.cos(scene.slope.phi_rad)
    ds, kl, cs = _static_point(c, weight)
    w = math.sqrt(kl / mass)
    z = cs / (2 * math.sqrt(kl * mass))

    out = write(scene, tmp_path, "mjcf")
    root = ET.parse(out.path).getroot()
    solref = [float(s) for s in root.find(".//geom[@solref]").get("solref").split()]
    assert solref[1] == pytest.approx(z, rel=1e-8)
    assert solref[0] == pytest.approx(1 / (z * w) / MJCF_CONTACT_SHRINK, rel=1e-8)
    friction = [float(s) for s in root.find(".//geom[@friction]").get("friction").split()]
    assert friction[0] == c.mu_s


def test_the_opensim_hunt_crossley_force_passes_through_the_laws_static_point():
    """Simbody's Hunt-Crossley force ``K d^1.5 (1 + 1.5 c v)``, ``K = (4/3) s sqrt(R) /
    2^1.5``, with the exported ``s`` and ``c``, carries the walker's weight at the law's
    static penetration with the law's damping there."""
    scene = load_scene(CONFIGS / "paper.yaml")
    c, _ = contact_si(scene.contact)
    weight, radius = 98.1, 0.02
    ds, _kl, cs = _static_point(c, weight)
    s, diss, vt, _ = hunt_crossley(c, weight, radius)
    K = 4 / 3 * s * math.sqrt(radius) / 2 ** 1.5
    assert K * ds ** 1.5 == pytest.approx(weight, rel=1e-9)
    assert 1.5 * diss * K * ds ** 1.5 == pytest.approx(cs, rel=1e-6)
    assert vt == c.v_s
