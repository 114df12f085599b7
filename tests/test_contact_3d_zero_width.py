"""The 3D straight-legged walkers of zero hip width (configs/paper_3d.yaml, point feet;
configs/round_feet_3d.yaml, a disc in each leg's sagittal plane) in the compliant-contact
model, against references the contact view does not compute:

- where the legs pass each other (equal pitches) every mass lies on one line, so without
  the legs' axial inertia (:func:`walkerlab.codegen.floating_equations.legs_axial_inertia`) the
  floating view's mass matrix is singular there; with it, its smallest eigenvalue is the
  two legs' axial inertia, ``2 m (0.01 L)^2 / 2`` (the rod's formula, not the view's);
- the contact walk (slow) against the rigid walk (``walkerlab simulate``, the rigid
  model): ten heel strikes, steps 7-10's mean step period and the hip's speed within 1 %
  (measured: paper_3d +0.17 %, -0.59 %, the planar paper walker's own contact gap;
  round_feet_3d +0.08 %, -0.63 %), a disc foot's patches centred on its roll (the disc's
  reference point ``R (theta + gamma)`` ahead of its touchdown), and the walk upright
  through the steps compared (its roll, seeded at round-off (paper_3d) or by the
  integrator's absolute tolerance (round_feet_3d, contact_solver.atol 1e-13) and growing
  x11 a step, under 0.05 rad by heel strike 10: measured 5e-4 rad, paper_3d, and 1e-8 rad,
  round_feet_3d).
"""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

from walkerlab.codegen.floating import floating_params
from walkerlab.codegen.floating_equations import (
    AXIAL_RADIUS_L,
    derive_floating,
    legs_axial_inertia,
)
from walkerlab.config import load_scene
from walkerlab.walker.description import walker_data


def _data(name: str):
    scene = load_scene(f"configs/{name}.yaml")
    return walker_data(scene.walker, scene.slope.phi_rad)


def _mass_matrix(eq, data, pitch: float) -> np.ndarray:
    """``eq``'s mass matrix (nq, nq) with both legs at ``pitch`` [rad] (the legs passing),
    every other coordinate 0 (upright, no heading)."""
    values = dict(zip(eq.params, np.asarray(floating_params(data), float)))
    values.update({s: (pitch if str(s).endswith("_angle") else 0.0) for s in eq.q})
    return np.array(eq.M.xreplace(values).evalf(), dtype=float)


def test_the_zero_width_walkers_contact_mass_matrix_is_regular_where_the_legs_pass():
    """configs/paper_3d.yaml with its legs passing normal to the slope: without the axial
    inertia the mass matrix has an eigenvalue 0 (to round-off: under 1e-12 of its largest);
    with it the smallest is the two legs' axial inertia ``m (0.01 L)^2`` (5e-4 kg m^2) to
    1e-9 (the spin about the slope's normal there turns the legs about their axes and
    nothing else), and the view of a walker with hip width is returned as it is."""
    data = _data("paper_3d")
    eq = derive_floating(data.structure)
    phi = float(data.slope_rad)
    bare = np.linalg.eigvalsh(_mass_matrix(eq, data, -phi))
    assert abs(bare[0]) < 1e-12 * bare[-1]
    ev = np.linalg.eigvalsh(_mass_matrix(legs_axial_inertia(data.structure, eq), data, -phi))
    p = dict(zip(data.structure.param_names, data.params))
    axial = p["m_leg"] * (AXIAL_RADIUS_L * p["L"]) ** 2
    assert ev[0] == pytest.approx(axial, rel=1e-9)
    view = object()  # a walker with hip width: its view returned untouched, not derived
    assert legs_axial_inertia(_data("hip_width").structure, view) is view
    assert legs_axial_inertia(_data("paper").structure, view) is view  # planar


def test_the_axial_inertia_leaves_an_upright_sagittal_motion_alone():
    """The added kinetic energy is the legs' spin about their axes: zero for any upright
    motion (no heading, no roll), whatever the pitches and their rates."""
    data = _data("paper_3d")
    eq = derive_floating(data.structure)
    added = sp.expand(legs_axial_inertia(data.structure, eq).kinetic - eq.kinetic)
    upright = {s: 0 for s in (*eq.q, *eq.dq)
               if not (str(s).endswith("_angle") or str(s).endswith("_foot_x")
                       or str(s).endswith("_foot_y"))}
    assert added != 0
    assert sp.simplify(added.xreplace(upright)) == 0


def _hip_speed(f, times) -> float:
    t, x = f["samples/points/hip/time"][:], f["samples/points/hip/x"][:]
    return float((np.interp(times[-1], t, x) - np.interp(times[0], t, x))
                 / (times[-1] - times[0]))


@pytest.mark.slow  # ~1 min each: a derivation, then ten steps of the contact walk
@pytest.mark.parametrize(("name", "push_n_s"), [("round_feet_3d", None), ("paper_3d", None),
                                               ("round_feet_3d", 0.08)])
def test_the_zero_width_3d_walkers_walk_in_contact_at_the_rigid_gait(name, push_n_s, tmp_path):
    """``walkerlab contact-sim`` against ``walkerlab simulate`` of the same scene: ten heel
    strikes; over steps 6-9 (whole periods, transients settled) the mean step period and
    the hip's speed within 1 % of the rigid walk's (the capability cell's tolerance is 3 %;
    measured on round_feet_3d +0.09 %, -0.62 %); the walk upright (roll under 0.05 rad); a
    disc's patches centred on its roll.  Steps 6-9, not 7-10, for paper_3d's sake: its roll,
    seeded at round-off and growing x11 a step (the rigid lateral multiplier), is 5e-4 rad
    by heel strike 10 (round_feet_3d's, bounded by its atol of 1e-13, under 1e-8 rad; at
    atol 1e-10 it reached 0.1 rad by heel strike 9 and the swing disc scuffed in step 10).
    With a push-off of 0.08 M sqrt(g l) on the discs (``push_n_s``: the rigid impulse and
    the contact pulse at the trailing disc's material contact point, which lengthen the
    rigid step by 0.8 % and speed it up by a fifth) the same, measured +0.08 %, -0.51 %."""
    import h5py

    from walkerlab.stages import pipeline

    scene = load_scene(f"configs/{name}.yaml")
    if push_n_s is not None:
        d = scene.model_dump(mode="json", exclude_none=True)
        d["walker"]["actuation"] = {"push_off": {"impulse_n_s": push_n_s}}
        scene = type(scene).model_validate(d)
    cs = pipeline.run("contact-sim", scene, tmp_path).path
    sim = pipeline.run("simulate", scene, tmp_path).path
    with h5py.File(cs) as f, h5py.File(sim) as s:
        h = np.asarray(f["events/heel_strike_times"][()], float)
        assert h.size >= 10, f.attrs.get("outcome_message", "")
        ok = s["steps/termination"][:].astype(str) == "heel_strike"
        hr = np.asarray(s["steps/t_end"][:][ok], float)
        assert hr.size >= 10
        hc, hr = h[4:9], hr[4:9]  # heel strikes 5-9: steps 6-9
        period = np.diff(hc).sum() / np.diff(hr).sum() - 1.0
        speed = _hip_speed(f, hc) / _hip_speed(s, hr) - 1.0
        assert abs(period) < 0.01 and abs(speed) < 0.01, (period, speed)
        roll = np.asarray(f["samples/coordinates/leg2_roll_angle"][()], float)
        t = np.asarray(f["samples/coordinates/time"][()], float)
        assert np.max(np.abs(roll[t <= h[9]])) < 0.05
        lane2 = np.asarray(f["terrain/lane_leg2"][()], float)
        start = np.asarray(f["initial_state_ideal"][()], float)
    data = _data(name)
    p = dict(zip(data.structure.param_names, data.params))
    # leg2's patch 0 under its touchdown (point feet) or centred on the disc's roll
    shift = p["R_foot"] * (start[2] + float(data.slope_rad)) if "R_foot" in p else 0.0
    assert lane2[0] == pytest.approx(shift, abs=1e-12)
