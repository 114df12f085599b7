"""The Adams dataset's knee latch (issue 58 item 3): the contact model's latch written as
statements, SFORCE/3 and 4 with a STEP-weighted IMPACT, not left out.

The dataset's expressions are evaluated at planar states with this test's own reading of the
Adams Solver functions (STEP: the cubic step; IMPACT: ``max(0, k (x1 - x)^e - STEP(x, x1 -
d, cmax, x1, 0) x')`` for ``x < x1``, else 0; Adams Solver function reference) and the
markers placed by :class:`tests.test_export_adams_actuation.AdamsState`; the reference is
walkerlab's contact model itself: its knee torque (stop and latch) on the same state, with
the foot's penetration from its contact table.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yaml

from tests.test_export_adams_actuation import AdamsState, evaluate
from walkerlab.config import scene_from_dict
from walkerlab.export.adams import adm_text
from walkerlab.export.adams_latch import LATCH_SFORCE
from walkerlab.export.adams_reader import read_adm
from walkerlab.export.adams_statements import MM
from walkerlab.walker.description import walker_data
from walkerlab.walker.multibody import multibody
from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]


def _kneed(foot: dict, **terrain):
    d = yaml.safe_load((ROOT / "configs" / "kneed.yaml").read_text())
    d["walker"]["leg"]["foot"] = foot
    d["name"] = "kneed_" + foot["kind"]
    if terrain:
        d["terrain"] = terrain
    return scene_from_dict(d)


def _step(x, x0, h0, x1, h1):
    if x <= x0:
        return h0
    if x >= x1:
        return h1
    s = (x - x0) / (x1 - x0)
    return h0 + (h1 - h0) * s * s * (3 - 2 * s)


def _impact(x, dx, x1, k, e, cmax, d):
    if x >= x1:
        return 0.0
    return max(0.0, k * (x1 - x) ** e - _step(x, x1 - d, cmax, x1, 0.0) * dx)


def _walker(scene):
    from walkerlab.config.contact import ContactSettings
    from walkerlab.models.contact.model import ContactWalker
    from walkerlab.models.contact.rigid_limit import contact_si

    c, knee = contact_si(scene.contact or ContactSettings())
    return ContactWalker(contact=c, data=walker_data(scene.walker, scene.slope.phi_rad),
                         knee_stop=knee)


@pytest.mark.parametrize("foot", [{"kind": "point"}, {"kind": "arc", "radius_m": 0.05}])
def test_adams_knee_latch_equals_the_contact_models(foot):
    """At 60 states (the stance foot from 0.5 mm in the ground to 3 mm above it, around the
    2 mm release height; knees from 0.03 rad flexed to 0.002 rad hyperextended, around the
    0.01 rad capture; knee rates +-1 rad/s) each knee's torque on its shank from the
    dataset's stop and latch SFORCEs equals the contact model's knee torque (N mm against
    N m x 1000) to 1e-9 relative, 1e-6 N mm absolute; the latch acts (> 1 N m) at some
    states and is off (0) above the release height at others."""
    scene = _kneed(foot)
    data = walker_data(scene.walker, scene.slope.phi_rad)
    mb = multibody(data)
    model = read_adm(adm_text(scene, mb, Plant.from_scene(scene), "k", "test"))
    sforces = model.functions("SFORCE")
    variables = model.functions()
    assert set(LATCH_SFORCE.values()) <= set(sforces)
    w = _walker(scene)
    phi = scene.slope.phi_rad
    n = np.array([math.sin(phi), math.cos(phi)])
    L_thigh = next(ln.length_m for ln in mb.links if ln.name == "leg1_thigh")
    L_shank = next(ln.foot_m for ln in mb.links if ln.name == "leg1_shank")
    R = foot.get("radius_m", 0.0)
    rng = np.random.default_rng(58)
    held = free = 0
    for _ in range(60):
        th = {g: rng.uniform(-0.3, 0.3) for g in ("leg1", "leg2")}
        ext = {g: rng.uniform(-0.03, 0.002) for g in ("leg1", "leg2")}
        rate = {g: rng.uniform(-1, 1) for g in ("leg1", "leg2")}
        wt = {g: rng.uniform(-1, 1) for g in ("leg1", "leg2")}
        # the hip placed so that leg2's contact point is h2 above the slope line
        h2 = rng.uniform(-0.0005, 0.003)
        sh2 = th["leg2"] + ext["leg2"]
        centre = (L_thigh * np.array([math.sin(th["leg2"]), -math.cos(th["leg2"])])
                  + L_shank * np.array([math.sin(sh2), -math.cos(sh2)]))
        hip = np.array([rng.uniform(-0.1, 0.1), 0.0])
        hip[1] = (h2 + R - (hip[0] + centre[0]) * n[0]) / n[1] - centre[1]
        vhip = rng.uniform(-0.5, 0.5, 2)
        psi = {f"{g}_thigh": th[g] for g in th} | {f"{g}_shank": th[g] + ext[g] for g in th}
        om = {f"{g}_thigh": wt[g] for g in th} | {f"{g}_shank": wt[g] + rate[g] for g in th}
        st = AdamsState(mb, hip * MM, vhip * MM, psi, om, {})
        ns = st.namespace(variables)
        ns.update(STEP=_step, IMPACT=_impact)
        x = np.zeros(len(w.state_names()))
        x[:6] = (*hip, psi["leg1_thigh"], psi["leg1_shank"], psi["leg2_thigh"],
                 psi["leg2_shank"])
        x[6:] = (*vhip, om["leg1_thigh"], om["leg1_shank"], om["leg2_thigh"],
                 om["leg2_shank"])
        pen = w.foot_quantities(x[None])
        for k, g in enumerate(("leg1", "leg2")):
            delta = float(pen[g]["penetration"][0])
            ref = -w.kernels._knee_torque(ext[g], rate[g], w.contact_params, delta) * MM
            got = (evaluate(sforces[k + 1], ns)
                   + evaluate(sforces[LATCH_SFORCE[g]], ns))
            assert got == pytest.approx(ref, rel=1e-9, abs=1e-6), (g, ext[g], delta)
            if g == "leg2" and ext[g] < -0.001:
                held += ref > 1e3
                free += h2 > 0.002 and ref == 0.0
    assert held and free


@pytest.mark.parametrize("foot", [{"kind": "point"}, {"kind": "arc", "radius_m": 0.05}])
def test_adams_knee_latch_on_footholds_reads_the_tread_under_the_foot(foot):
    """Footholds 5 mm below each other (the dataset's patches at tread heights): each knee's
    stop + latch torque from the dataset equals the contact model's with the same patches
    (the dataset's start: centres and tread heights) to 1e-9 relative, 1e-6 N mm, at the
    start's state with the swing leg lifted and knees flexed, and with the walker moved k =
    1, 2 steps down the footholds, its stance foot about 0.5 mm above leg2's k-th tread (10,
    20 mm below the slope line: read against the slope line, the latch would take a foot
    that is up as 9-19 mm in the ground); nothing left out."""
    from walkerlab.export.adams import adams_omissions, adams_start

    scene = _kneed(foot, kind="footholds", foothold_heights_m=[-0.005])
    data = walker_data(scene.walker, scene.slope.phi_rad)
    mb = multibody(data)
    start = adams_start(scene, mb, Plant.from_scene(scene))
    assert start.lane_heights is not None and adams_omissions(scene, mb) == ()
    model = read_adm(adm_text(scene, mb, Plant.from_scene(scene), "k", "test", start))
    sforces, variables = model.functions("SFORCE"), model.functions()
    from walkerlab.config.contact import ContactSettings
    from walkerlab.models.contact.model import ContactWalker
    from walkerlab.models.contact.rigid_limit import contact_si

    c, knee = contact_si(scene.contact or ContactSettings())
    w = ContactWalker(contact=c, data=data, knee_stop=knee, lane1=np.array(start.lanes[0]),
                      lane2=np.array(start.lanes[1]), heights1=np.array(start.lane_heights[0]),
                      heights2=np.array(start.lane_heights[1]),
                      patch_half_width=start.patch_width_m / 2, continuous=False)
    phi = scene.slope.phi_rad
    t_hat = np.array([math.cos(phi), -math.sin(phi)])
    n_hat = np.array([math.sin(phi), math.cos(phi)])
    held = 0
    for lift, flex, k in ((0.0, -0.004, 0), (0.3, -0.3, 0), (0.0, -0.004, 1),
                          (0.1, -0.2, 2), (0.45, -0.003, 1)):
        psi = dict(start.angles)
        psi["leg1_thigh"] += lift
        psi["leg1_shank"] += lift + flex
        psi["leg2_shank"] += -0.004  # the stance knee flexed within the capture
        hip = np.array(start.hip, float)
        if k:
            lane, hs = start.lanes[1], start.lane_heights[1]
            hip = hip + (lane[k] - lane[0]) * t_hat + (hs[k] - hs[0] + 0.001) * n_hat
        om = dict(start.rates)
        st = AdamsState(mb, hip * MM, np.array(start.hip_velocity) * MM, psi, om, {})
        ns = st.namespace(variables)
        ns.update(STEP=_step, IMPACT=_impact, ABS=abs)
        x = np.zeros(len(w.state_names()))
        x[:6] = (*hip, psi["leg1_thigh"], psi["leg1_shank"], psi["leg2_thigh"],
                 psi["leg2_shank"])
        x[6:] = (*start.hip_velocity, om["leg1_thigh"], om["leg1_shank"], om["leg2_thigh"],
                 om["leg2_shank"])
        pen = w.foot_quantities(x[None])
        for i, g in enumerate(("leg1", "leg2")):
            ext = psi[f"{g}_shank"] - psi[f"{g}_thigh"]
            rate = om[f"{g}_shank"] - om[f"{g}_thigh"]
            delta = float(pen[g]["penetration"][0])
            ref = -w.kernels._knee_torque(ext, rate, w.contact_params, delta) * MM
            got = evaluate(sforces[i + 1], ns) + evaluate(sforces[LATCH_SFORCE[g]], ns)
            assert got == pytest.approx(ref, rel=1e-9, abs=1e-6), (lift, k, g, delta)
            if g == "leg2" and k:
                assert -0.002 < delta < 0.0  # just above its tread (the knee flexed 4 mrad)
                held += ref > 1e3
    assert held
