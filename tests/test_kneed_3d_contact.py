"""The 3D kneed walker (configs/kneed_3d.yaml, the kind ``locking_knees_3d``) in the
compliant-contact model: its floating view, the body tree with both knees set free on the
ground (:func:`walkerlab.codegen.floating_equations.derive_floating`), against references that do
not share it:

- the planar kneed walker's floating view (configs/kneed.yaml,
  :mod:`walkerlab.codegen.floating_equations`: leg-vector sums written by hand): upright
  (no roll, heading or lateral motion) the 3D walker's sagittal motion has its kinetic and
  potential energy (the hips' lateral offset moves no mass in a sagittal motion);
- the rigid 3D kneed model (:func:`walkerlab.codegen.legged.derive_legged`, itself held
  to Pinocchio in tests/test_kneed_3d.py): with the stance foot held and the stance knee
  straight the floating mass matrix and gravity pulled back to the rigid coordinates are
  the rigid model's;
- the knee stop and latch act at each leg's own knee (its shank's less its thigh's
  coordinate in the floating view's order, not the planar view's positions);
- the contact walk's first stride against the rigid gait (slow): its lateral mode grows x6
  a step (a stride multiplier of 39.9), so only the first steps hold the gait
  (:data:`walkerlab.walker.reference_cases.FIRST_STEPS`).
"""

from __future__ import annotations

import numpy as np
import pytest

from walkerlab.codegen.cache import functions
from walkerlab.codegen.floating import floating_params, floating_plain
from walkerlab.config import load_scene
from walkerlab.walker.description import walker_data

#: configs/kneed.yaml's leg [m]: its length and the thigh's
LEG, THIGH = 1.0, 0.5


def _data(name: str):
    scene = load_scene(f"configs/{name}.yaml")
    return walker_data(scene.walker, scene.slope.phi_rad)


def _view(data):
    """(the plain generated floating module's namespace, its parameter vector, nq)."""
    ns = floating_plain(data.structure)
    return ns, floating_params(data), int(ns["NQ"])


def _e(a):
    """A link at angle ``a`` from the vertical (positive: its far end ahead), the planar
    view's ``(sin a, -cos a)`` per unit length."""
    return np.array([np.sin(a), -np.cos(a)])


def _de(a, w):
    return w * np.array([np.cos(a), np.sin(a)])


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_upright_the_3d_kneed_floating_view_has_the_planar_kneed_walkers_energies(seed):
    """At a random upright state (leg2's foot at ``(x, y, 0)``, no heading, roll or lateral
    rates; each link's pitch and rate random, the knees bent) the 3D view's kinetic and
    potential energy equal the planar kneed view's at the same sagittal state (its hip
    placed from leg2's foot up its shank and thigh by hand) to 1e-12 J on energies of
    order 1 J (two generated codes of one sum: rounding)."""
    ns3, p3, n3 = _view(_data("kneed_3d"))
    nsp, pp, npl = _view(_data("kneed"))
    rng = np.random.default_rng(seed)
    th = dict(zip(("leg1_thigh", "leg1_shank", "leg2_thigh", "leg2_shank"),
                  rng.uniform(-0.4, 0.4, 4)))
    w = dict(zip(th, rng.uniform(-2.0, 2.0, 4)))
    foot, v_foot = rng.uniform(-0.5, 0.5, 2), rng.uniform(-1.0, 1.0, 2)
    names3 = ns3["COORDINATES"]
    x3 = np.zeros(2 * n3)
    for k, v in zip(names3, (*foot, 0.0)):
        x3[names3.index(k)] = v
    x3[n3:n3 + 2] = v_foot
    for link in th:
        x3[names3.index(f"{link}_angle")] = th[link]
        x3[n3 + names3.index(f"{link}_angle")] = w[link]
    # the planar hip: leg2's foot up its shank (L - thigh) and thigh
    hip = foot - (LEG - THIGH) * _e(th["leg2_shank"]) - THIGH * _e(th["leg2_thigh"])
    v_hip = (v_foot - (LEG - THIGH) * _de(th["leg2_shank"], w["leg2_shank"])
             - THIGH * _de(th["leg2_thigh"], w["leg2_thigh"]))
    namesp = nsp["COORDINATES"]
    xp = np.zeros(2 * npl)
    xp[[namesp.index("hip_x"), namesp.index("hip_y")]] = hip
    xp[[npl + namesp.index("hip_x"), npl + namesp.index("hip_y")]] = v_hip
    for link in th:
        xp[namesp.index(f"{link}_angle")] = th[link]
        xp[npl + namesp.index(f"{link}_angle")] = w[link]
    T3, V3 = ns3["energies"](x3, p3)
    Tp, Vp = nsp["energies"](xp, pp)
    assert abs(float(T3) - float(Tp)) < 1e-12 and abs(float(V3) - float(Vp)) < 1e-12, (
        T3, Tp, V3, Vp)
    assert float(Tp) > 0.1   # the check sees the rates


def _with_torso(name: str):
    """``name``'s walker carrying configs/kneed_torso_powered_3d.yaml's upper body (0.4 kg
    0.2 m above the hips' midpoint, on the bisecting hip)."""
    from walkerlab.config import scene_from_dict

    d = load_scene(f"configs/{name}.yaml").model_dump(mode="json", exclude_none=True)
    d["walker"]["torso"] = {"coupling": "bisecting_hip", "bodies": [
        {"kind": "point_mass", "name": "mass", "mass_kg": 0.4, "from_hip_m": 0.2}]}
    scene = scene_from_dict(d)
    return walker_data(scene.walker, scene.slope.phi_rad)


@pytest.mark.parametrize("torso", [False, True], ids=["legs", "upper_body"])
def test_the_3d_kneed_floating_view_with_its_stance_foot_held_is_the_rigid_model(torso):
    """At a configuration with lean, a bent swing knee and the legs apart, the floating
    view's mass matrix and gravity pulled back through ``J`` (rigid rates ``lean,
    swing_thigh, swing_shank, stance`` -> floating rates: the foot and heading at rest,
    leg2's roll the lean, leg2's thigh and shank the stance leg's pitch) are the rigid
    model's, ``J^T M_f J = M`` and ``J^T G_f = G``, to 1e-12 of their largest entries; a
    map with leg2's shank left out (a straight stance leg's inertia split) misses by far
    more.  With an upper body on the bisecting hip (Wisse, Hobbelen & Schwab 2007) the
    floating view has no coordinate of its own for it (its pitch the thighs' mean, as the
    rigid model's is the swing thigh's and the stance leg's), and the same holds: the rigid
    kneed model with an upper body is Newton's law of its point masses
    (tests/test_kneed_torso_3d.py)."""
    data = _with_torso("kneed_3d") if torso else _data("kneed_3d")
    ns, p, nq = _view(data)
    names = ns["COORDINATES"]
    q = {"lean": 0.07, "swing_thigh": -0.31, "swing_shank": -0.74, "stance": 0.22}
    to = {"leg2_roll": "lean", "leg1_thigh_angle": "swing_thigh",
          "leg1_shank_angle": "swing_shank", "leg2_thigh_angle": "stance",
          "leg2_shank_angle": "stance"}
    roles = list(q)
    J = np.zeros((nq, 4))
    x = np.zeros(2 * nq)
    for c, r in to.items():
        J[names.index(c), roles.index(r)] = 1.0
        x[names.index(c)] = q[r]
    M_f, h_f = np.empty((nq, nq)), np.empty(nq)
    ns["dyn"](x, p, M_f, h_f)
    M_r, _, G_r = (np.asarray(a, float) for a in functions(data)["matrices"](
        np.r_[list(q.values()), np.zeros(4)]))
    scale = np.abs(M_r).max()
    assert np.abs(J.T @ M_f @ J - M_r).max() < 1e-12 * scale
    assert np.abs(J.T @ h_f - G_r).max() < 1e-12 * np.abs(G_r).max()
    wrong = J.copy()
    wrong[names.index("leg2_shank_angle")] = 0.0
    assert np.abs(wrong.T @ M_f @ wrong - M_r).max() > 1e-3 * scale


def test_the_knee_stop_acts_at_each_3d_knees_own_coordinates():
    """The contact walker's knee quantities read each leg's knee as its shank's less its
    thigh's pitch (by name in the 3D view's order, where the planar view's positions hold
    the foot's lateral slide and the heading): a hyperextended knee (0.003 rad) is pushed
    straight (torque > 0), a straight one carries none, whatever the foot's lateral slide
    and the heading."""
    from walkerlab.analysis.gait.scene import initial_guess
    from walkerlab.models.contact.scene import contact_setup
    from walkerlab.models.registry import build_walker
    from walkerlab.walker.plant import Plant

    scene = load_scene("configs/kneed_3d.yaml")
    plant = Plant.from_scene(scene)
    xi = np.asarray(initial_guess(scene, build_walker(plant)), float)
    cw, _ = contact_setup(scene, plant=plant).build(xi, 10)
    names = cw.coordinate_names()
    nq = len(names)
    x = np.zeros(2 * nq)
    x[names.index("leg2_foot_z")], x[names.index("heading")] = 0.3, 0.2
    for leg, (thigh, shank) in {"leg1": (-0.2, -0.197), "leg2": (0.1, 0.1)}.items():
        x[names.index(f"{leg}_thigh_angle")] = thigh
        x[names.index(f"{leg}_shank_angle")] = shank
    k = cw.knee_stop_quantities(x[None, :])
    assert k["leg1"]["extension"][0] == pytest.approx(0.003, abs=1e-15)
    assert k["leg1"]["torque"][0] > 0.0
    assert k["leg2"]["extension"][0] == 0.0 and k["leg2"]["torque"][0] == 0.0


@pytest.mark.slow
def test_the_3d_kneed_walker_walks_its_first_stride_in_contact_at_the_rigid_step_period(
        tmp_path):
    """``walkerlab contact-sim configs/kneed_3d.yaml``: the first stride's mean step period
    (from the rigid gait's heel strike at t = 0) within 1 % of the rigid gait's (measured
    +0.67 %: +0.10 % and +1.25 %; the planar kneed walker's contact steps run 0.6-2 %
    long), then the lateral mode (x6 a step) capsizes it sideways within 6 heel strikes
    (measured 4), as the run's failure says."""
    import h5py

    from walkerlab.stages import pipeline

    out = pipeline.run("contact-sim", load_scene("configs/kneed_3d.yaml"), tmp_path)
    with h5py.File(out.path) as f:
        times = np.asarray(f["events/heel_strike_times"][()], float)
    with h5py.File(tmp_path / "kneed_3d" / "fixedpoint.h5") as f:
        rigid = float(f["step_period"][()])
    assert times.size >= 2
    assert abs(times[1] / 2 / rigid - 1.0) < 0.01
    assert out.failure and "capsized sideways" in out.failure and times.size <= 6


@pytest.mark.slow  # ~3 min cold (the floating tree's kernels with an upper body), 10 s warm
def test_the_3d_kneed_walker_with_an_upper_body_walks_in_contact_at_the_rigid_gait(tmp_path):
    """configs/kneed_torso_powered_3d.yaml (the stabilised kneed walker in 3D with a 0.4 kg
    upper body on the bisecting hip, driven by a torque between it and the stance leg) in
    the contact model: 6 strides on the rigid footfalls' 0.2 m patches make >= 12 heel
    strikes without a fall, and over steps 9-12 the mean step period and the hip's speed
    are within 3 % of the rigid walk's same steps (measured +0.12 %, -1.64 %)."""
    from walkerlab.api.capabilities import _contact  # the capability cell's measurement
    from walkerlab.config import scene_from_dict

    d = load_scene("configs/kneed_torso_powered_3d.yaml").model_dump(mode="json")
    d["simulate"]["strides"] = 7  # the rigid walk as long as the contact walk
    value, line = _contact(scene_from_dict(d), d, tmp_path)
    assert "heel strikes" in line and int(line.split()[0]) >= 12, line
    assert abs(value) < 0.03, line


def _period_and_speed(line: str) -> tuple[float, float]:
    """The step period's and the hip speed's deviations [%] in a contact cell's line."""
    import re

    period = re.search(r"period ([+-]\d+\.\d+) %", line)
    speed = re.search(r"speed ([+-]\d+\.\d+) %", line)
    assert period and speed, line
    return float(period.group(1)), float(speed.group(1))


@pytest.mark.slow  # ~1 min warm (two contact walks of 12 heel strikes); minutes cold
def test_the_stabilised_3d_kneed_contact_walk_tends_to_the_rigid_walk_on_its_assumptions(
        tmp_path):
    """configs/kneed_3d_stabilised.yaml in contact with the rigid model's two idealisations
    taken: the stance foot spins freely about the ground's normal with the heading held
    (``contact.hold_heading``, no torsional friction: the rigid universal ankle drills), and
    the trailing knee's latch lets go as its foot leaves the ground (release height 0.05 mm,
    where the rigid model unlocks that knee at heel strike). Steps 9-12 against the rigid
    walk's: the period within 0.3 % and the speed within 0.7 % at the scene's stiffness
    (measured +0.21 %, -0.58 %), and the speed gap shrinking as the ground and knee stops
    stiffen 100 times along the rigid-limit family (measured -0.33 % at 10x, -0.20 % at
    100x): the compliance's share, which shrinks toward the rigid limit. With the scene's own
    settings (heading free, 0.05 m torsional friction, 2 mm release) the walk measures
    +0.78 % and -1.68 %; the knee latch's 2 mm accounts for about 1 % of that speed."""
    from walkerlab.api.capabilities import _contact, _strides_for  # the cell's measurement
    from walkerlab.config import scene_from_dict

    base = load_scene("configs/kneed_3d_stabilised.yaml").model_dump(mode="json")
    base["contact"].update(hold_heading=True, torsional_friction_m=0.0)
    base["contact"]["knee_stop"]["latch_release_height_m"] = 5e-5
    _strides_for(base, "contact")  # the rigid walk as long as the contact walk
    out = {}
    for kappa in (1, 100):
        d = {**base, "contact": dict(base["contact"])}
        if kappa > 1:
            d["contact"].update(stiffness_family="rigid_limit",
                                reference_stiffness_n_per_mm_pow_e=1e5,
                                stiffness_n_per_mm_pow_e=1e5 * kappa)
        _, line = _contact(scene_from_dict(d), d, tmp_path / f"k{kappa}")
        assert int(line.split()[0]) >= 12, line
        out[kappa] = _period_and_speed(line)
    (p1, v1), (p100, v100) = out[1], out[100]
    assert abs(p1) < 0.3 and abs(v1) < 0.7, out
    assert abs(p100) < 0.3 and abs(v100) < 0.5 * abs(v1), out
