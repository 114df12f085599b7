"""Flat feet on stairs and footholds of several heights in the rigid view: the heel strike
lands at the next step's height in every stance mode, and the double support keeps the
trailing toe on the tread it stood on (configs/flat_feet_stairs.yaml,
configs/flat_feet_footholds.yaml; walkerlab.models.hybrid.rigid_foot_modes.on_landing_flat).

The references are hand trigonometry of the walker's links (hip-to-ankle legs, the sole
through the ankle, the swing sole at its rest angle to the leg's perpendicular), sharing no
code with the generated kinematics.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from walkerlab.codegen.cache import functions
from walkerlab.config import load_scene
from walkerlab.integrate.rigid import simulate_steps
from walkerlab.integrate.solver import Solver
from walkerlab.models.hybrid.rigid_foot_modes import mode_of
from walkerlab.models.registry import build_walker
from walkerlab.walker.description import walker_data
from walkerlab.walker.kinds import KINDS
from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]
#: the heel strike's event is located to the solver's tolerance (rtol 1e-12 on ~1 m): the
#: landing height agrees to far below a micron
LANDING_M = 1e-9


def _unit(theta):
    return np.array([math.cos(theta), math.sin(theta)])


def _swing_heel_by_hand(x, pin: str, foot, gamma: float, length: float = 1.0):
    """The swing heel [m] in the frame of the stance heel's touchdown point (x downhill
    along the horizontal, y up), from the state ``x = (swing, stance, stance ankle, ...)``:
    the stance foot pinned at its heel (heel contact, foot flat) or at its toe, ``heel +
    toe`` down the slope from the touchdown point (heel off)."""
    sw, st, a = x[:3]
    sole = _unit(st + a)  # the stance sole, toe up for a positive angle
    if pin == "heel":
        ankle = foot.heel_m * sole
    else:
        ankle = (foot.heel_m + foot.toe_m) * np.array([math.cos(gamma), -math.sin(gamma)]) \
            - foot.toe_m * sole
    hip = ankle + length * np.array([-math.sin(st), math.cos(st)])
    swing_ankle = hip + length * np.array([math.sin(sw), -math.cos(sw)])
    return swing_ankle - foot.heel_m * _unit(sw + foot.ankle.rest_angle_rad)


def _run(name: str, steps: int):
    scene = load_scene(ROOT / "configs" / f"{name}.yaml")
    walker = build_walker(Plant.from_scene(scene))
    x0 = scene.fixedpoint.initial_guess.as_array(walker.state_names())
    traj = simulate_steps(walker, x0, steps, Solver.from_settings(scene.solver))
    assert len(traj.segments) == steps
    assert all(sg.termination == "heel_strike" for sg in traj.segments)
    return scene, walker, traj.segments


def _landing_clearance(seg, foot, gamma):
    """The swing heel's height at heel strike above the slope line through the stance
    foot's touchdown point, along its normal [m] (hand geometry)."""
    pin = "toe" if mode_of(seg.phase_log[-1][0]) == "heel_off" else "heel"
    h = _swing_heel_by_hand(seg.x_end, pin, foot, gamma)
    return h[1] * math.cos(gamma) + h[0] * math.sin(gamma), pin


def test_flat_heel_strikes_the_next_tread_7p5mm_down_in_its_stance_mode():
    scene, _walker, segs = _run("flat_feet_stairs", 2)
    foot = scene.walker.leg.foot
    for seg in segs:
        clearance, pin = _landing_clearance(seg, foot, 0.0)
        assert clearance == pytest.approx(-scene.terrain.riser_m, abs=LANDING_M)
    # the gait's stance foot is on its toe when the heel strikes (the heel-off guard's pin)
    assert pin == "toe"


def test_flat_heel_strikes_each_foothold_at_its_own_height():
    scene, _walker, segs = _run("flat_feet_footholds", 3)
    foot, gamma = scene.walker.leg.foot, scene.slope.phi_rad
    heights = scene.terrain.foothold_heights_m
    for k, seg in enumerate(segs):
        clearance, _pin = _landing_clearance(seg, foot, gamma)
        # step k lands h_k below the stance foot's level along the vertical: h_k cos(gamma)
        # along the slope's normal (h_k <= 0 is below)
        assert clearance == pytest.approx(heights[k % 3] * math.cos(gamma), abs=LANDING_M)


def test_double_support_keeps_the_trailing_toe_on_the_tread_above():
    scene, walker, segs = _run("flat_feet_stairs", 1)
    seg = segs[0]
    assert seg.phase_log[0][0] == "double_support:heel_contact"
    foot, riser = scene.walker.leg.foot, scene.terrain.riser_m
    # the state just after heel strike with the trailing toe pinned (the step's first)
    x = np.ravel(seg.pieces[0][1](seg.t_start))
    f = functions(walker_data(scene.walker, scene.slope.phi_rad))
    b = f["double_support_trailing"](x, riser)[0]
    sw, st, a = x[:3]
    ankle = foot.heel_m * _unit(st + a)  # the new stance heel at the origin
    hip = ankle + np.array([-math.sin(st), math.cos(st)])
    toe = hip + np.array([math.sin(sw), -math.cos(sw)]) + foot.toe_m * _unit(sw + b)
    assert toe[1] == pytest.approx(riser, abs=1e-12)  # on the tread it stood on
    # the same state's toe without the level would be on the lower tread: a test that can
    # fail (the level moves the toe by the riser)
    b0 = f["double_support_trailing"](x)[0]
    toe0 = hip + np.array([math.sin(sw), -math.cos(sw)]) + foot.toe_m * _unit(sw + b0)
    assert toe0[1] == pytest.approx(0.0, abs=1e-12)


def test_flat_feet_walk_stairs_and_footholds_in_the_rigid_view():
    kind = KINDS["flat_feet"]
    assert kind.supports("stairs", "rigid") and kind.supports("footholds", "rigid")


@pytest.mark.slow  # ~8 s: the rigid gait, then 10 heel strikes of the contact model
def test_contact_walker_on_flat_feet_footholds_walks_five_strides_near_the_rigid_period(
        tmp_path):
    """configs/flat_feet_footholds.yaml in contact-sim: 0.6 m patches at the rigid period-3
    gait's footfalls, each at its foothold's height.  The contact steps alternate about the
    rigid ones (the rigid gait's multiplier -0.69, and the contact view's 0.1 kg feet:
    configs/flat_feet.yaml), so the check is on the mean step: within 1.5 % of the rigid
    gait's mean 0.8112 s (measured +0.67 %), over 10 heel strikes without a scuff."""
    import h5py
    from cli_run import run_cli

    rc, err, _ = run_cli("-q", "contact-sim", ROOT / "configs" / "flat_feet_footholds.yaml",
                         "--runs-dir", tmp_path)
    assert rc == 0, err
    with h5py.File(tmp_path / "flat_feet_footholds" / "contact_sim.h5", "r") as f:
        t = f["events/heel_strike_times"][()]
    assert t.size >= 10
    rigid = (0.7975975921 + 0.8206136305 + 0.8154929357) / 3  # walkerlab fixedpoint
    assert t[-1] / t.size == pytest.approx(rigid, rel=0.015)


@pytest.mark.slow  # ~10 s: the rigid gait, the export and 9.2 s of MuJoCo
def test_the_mjcf_of_flat_feet_on_footholds_walks_in_mujoco(tmp_path):
    """configs/flat_feet_footholds.yaml exported to MJCF: 0.6 m boxes at the rigid period-3
    gait's footfalls, each at its foothold's height, walked from the gait's keyframe.
    Measured: 11 alternating heel strikes, mean step 0.8230 s against the rigid 0.8112 s
    (+1.46 %; configs/flat_feet.yaml on its slope: +1.94 %, the 0.1 kg feet the MJCF carries
    and the rigid view does not, tests/test_export_flat_feet.py): within 2.5 %, as there."""
    pytest.importorskip("mujoco")
    from walkerlab.export.mujoco_walk import walk
    from walkerlab.stages import export as export_stage

    scene = load_scene(ROOT / "configs" / "flat_feet_footholds.yaml")
    path = export_stage.run(scene, tmp_path, "mjcf")
    run = walk(path, 9.2)
    assert not run.fell
    assert len(run.times_s) >= 10 and run.alternating
    rigid = (0.7975975921 + 0.8206136305 + 0.8154929357) / 3
    assert run.step_periods_s.mean() == pytest.approx(rigid, rel=0.025)


def test_double_support_on_stairs_loses_energy_with_the_trailing_spring_counted():
    """In the double support on stairs (89 ms) the walker's own energy rises (+0.63 J: the
    trailing ankle spring, holding 1.61 J at heel strike, pushes the trailing leg off), and
    its energy plus that spring's only falls (the two ankle dampers; the pinned toe and
    heel do no work): the ledger of a passive walker, at every sample."""
    _scene, walker, segs = _run("flat_feet_stairs", 1)
    seg = segs[0]
    phase, sol = seg.pieces[0][0], seg.pieces[0][1]
    assert phase.name == "double_support:heel_contact"
    t0, t1 = seg.phase_log[0][1], seg.phase_log[0][2]
    assert t1 - t0 > 0.05
    total, own = [], []
    for t in np.linspace(t0, t1, 40):
        x = np.ravel(sol(t))
        ke, pe = walker.energies(x)
        own.append(float(ke + pe))
        total.append(own[-1] + float(phase.held_energy(x)[0]))
    assert own[-1] - own[0] > 0.3  # the spring's release shows in the walker's energy
    assert np.all(np.diff(total) < 1e-9 * abs(total[0]))


def test_an_actuated_flat_walker_keeps_its_landing_on_stairs():
    """The actuators rebuild a flat-footed walker's modes (configs/flat_feet_push_off.yaml's
    ankle push-off): on stairs each mode's heel-strike guard still lands a riser down."""
    from walkerlab.config import scene_from_dict

    d = load_scene(ROOT / "configs" / "flat_feet_push_off.yaml").model_dump(
        mode="json", exclude_none=True)
    sc = scene_from_dict(d)
    level = build_walker(Plant.from_scene(sc))
    d["terrain"] = {"kind": "stairs", "riser_m": 0.0075, "tread_m": 0.405}
    sc1 = scene_from_dict(d)
    stairs = build_walker(Plant.from_scene(sc1))
    assert stairs.actuators is not None and stairs.params["landing_drop_m"] == 0.0075
    x = np.array([-0.2, 0.2, 0.0, -0.7, -0.7, -3.0])

    def strikes(w):
        return [g.function(0.0, x) for ph in w.phases for g in ph.guards
                if g.name == "heel_strike"]
    assert len(strikes(stairs)) == 3  # one per stance mode
    assert np.allclose(np.subtract(strikes(stairs), strikes(level)), 0.0075, atol=1e-15)


def _flat_feet_without_terrain() -> dict:
    import yaml

    d = yaml.safe_load((ROOT / "configs" / "flat_feet.yaml").read_text())
    del d["terrain"]
    return d


def test_a_flat_footed_scene_without_terrain_gets_patches_that_hold_its_sole():
    """Without a ``terrain`` section the contact model's checkerboard patches were 0.10 m
    wide, shorter than the 0.15 m sole that lands on its heel at the patch's centre and
    rolls its load to the toe: the walker tripped at its first step.  The default ground of
    a flat-footed walker is now four soles wide (0.6 m here, configs/flat_feet.yaml's own
    width): the sole's length ahead of the heel's footfall with a sole to spare at either
    end.  A point-footed scene keeps 0.10 m (its artifacts unchanged), and a scene's own
    terrain section is never replaced."""
    from walkerlab.config import scene_from_dict
    from walkerlab.models.contact.scene import contact_setup

    bare = scene_from_dict(_flat_feet_without_terrain(), "flat_bare.yaml")
    assert bare.terrain is None
    ground = bare.terrain_or_default()
    assert ground.lanes == "checkerboard" and ground.is_slope
    assert ground.patch_width_m == pytest.approx(4 * (0.05 + 0.10))
    assert ground.patch_width_m / 2 > 0.05 + 0.10  # the sole rolled to its toe fits
    assert contact_setup(bare,
                         plant=Plant.from_scene(bare)).terrain.patch_width_m == pytest.approx(0.6)
    paper = load_scene(ROOT / "configs" / "paper.yaml")
    assert paper.terrain_or_default().patch_width_m == 0.10
    own = load_scene(ROOT / "configs" / "flat_feet_stairs.yaml")
    assert own.terrain_or_default() is own.terrain


@pytest.mark.slow  # ~5 s: the rigid gait, then 11 heel strikes of the contact model
def test_a_flat_footed_scene_without_terrain_walks_in_contact_sim(tmp_path):
    """configs/flat_feet.yaml without its terrain section: contact-sim --strides 5 walks
    the 11 heel strikes asked for on the default ground (before: a trip at the first step
    on 0.10 m patches)."""
    import h5py
    import yaml
    from cli_run import run_cli

    path = tmp_path / "flat_bare.yaml"
    path.write_text(yaml.safe_dump(_flat_feet_without_terrain()))
    rc, err, _ = run_cli("-q", "contact-sim", path, "--strides", "5", "--runs-dir", tmp_path)
    assert rc == 0, err
    with h5py.File(tmp_path / "flat_bare" / "contact_sim.h5", "r") as f:
        assert f["events/heel_strike_times"].size >= 11
