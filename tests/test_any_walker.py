"""Downstream code works for a walker with 3 coordinates, not only the 2-coordinate compass gait.

The fixture is a *test* model (it plays the role of the model layer, so it may index its own
state): the paper's compass gait plus a massless "torso" coordinate pulled upright by a
damped spring, ``torso'' = -k torso - c torso'``, with its own named point ``torso_top``.
Its fixed point has torso = 0 and six Floquet multipliers; everything downstream (samples,
artifacts, figures, sweep columns, bifurcation arrays, netCDF dimensions) must size itself
from ``state_names()`` and name the torso, without knowing it exists.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from walkerlab.models.hybrid.base import Guard, HybridWalker, Phase
from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]
K, C, TORSO_M = 40.0, 8.0, 0.3  # spring [1/s^2], damping [1/s], drawn torso length [m]


IDX = [0, 1, 3, 4]  # compass-gait rows of the test state [swing, stance, torso, rates...]


def _embed(J4: np.ndarray, torso: np.ndarray) -> np.ndarray:
    """6x6 Jacobian from the compass-gait 4x4 one and the torso's own 2x2 block."""
    J = np.zeros((6, 6))
    J[np.ix_(IDX, IDX)] = J4
    J[np.ix_([2, 5], [2, 5])] = torso
    return J


def torso_walker(cg: HybridWalker) -> HybridWalker:
    """Compass gait ``cg`` with a passive, damped, massless torso coordinate (test model)."""
    def sub(x):  # the compass-gait part of [swing, stance, torso, rates...]
        x = np.asarray(x)
        return x[IDX]

    def flow_of(f4):
        def flow(t, x):
            d = f4(t, sub(x))
            return np.array([d[0], d[1], x[5], d[2], d[3], -K * x[2] - C * x[5]])
        return flow

    def guard(g):
        return Guard(g.name, lambda t, x, _f=g.function: _f(t, sub(x)), g.direction, g.outcome)

    phases = tuple(Phase(p.name, flow_of(p.flow), tuple(guard(g) for g in p.guards))
                   for p in cg.phases)

    def reset(x):
        r = cg.reset(sub(x))
        return np.array([r[0], r[1], x[2], r[2], r[3], x[5]])

    def points(X):
        X = np.asarray(X)
        pts = dict(cg.points(sub(X)))
        pts["torso_top"] = pts["hip"] + TORSO_M * np.array([np.sin(X[2]), np.cos(X[2])])
        return pts

    def section(x):
        return np.concatenate([cg.section(sub(x)), [x[2], x[5]]])

    def from_section(z):
        x4 = cg.from_section(z[:3])
        return np.array([x4[0], x4[1], z[3], x4[2], x4[3], z[4]])

    def variational(t, x):
        return _embed(cg.variational(t, sub(x)), np.array([[0.0, 1.0], [-K, -C]]))

    return HybridWalker(
        name="compass_with_torso", variant="test", roles=("swing", "stance", "torso"),
        legs=cg.legs, phases=phases, reset=reset,
        energies=lambda X: cg.energies(sub(X)), points=points, section=section,
        from_section=from_section, role_to_leg=cg.role_to_leg,
        total_mass_kg=cg.total_mass_kg, slope_rad=cg.slope_rad, params=dict(cg.params),
        variational=variational,
        reset_jacobian=lambda x: _embed(cg.reset_jacobian(sub(x)), np.eye(2)),
        heel_strike_guard=lambda t, x: cg.heel_strike_guard(t, sub(x)))


@pytest.fixture(scope="module")
def scene():
    from walkerlab.config import load_scene

    return load_scene(ROOT / "configs" / "paper.yaml")


@pytest.fixture(scope="module")
def walker(scene):
    from walkerlab.models.registry import build_walker

    return torso_walker(build_walker(Plant.from_scene(scene)))


@pytest.fixture(scope="module")
def fixed_point(walker, scene):
    from walkerlab.analysis.gait.poincare import find_fixed_point
    from walkerlab.integrate.solver import Solver

    g = dict(zip(["swing_angle", "stance_angle", "swing_rate", "stance_rate"],
                 scene.fixedpoint.initial_guess.as_array()))
    guess = [g["swing_angle"], g["stance_angle"], 0.05, g["swing_rate"], g["stance_rate"], 0.0]
    return find_fixed_point(walker, guess, Solver("DOP853", 1e-10, 1e-10), xtol=1e-11)


def test_fixed_point_and_multipliers_sized_by_the_walker(walker, fixed_point):
    names = walker.state_names()
    assert names == ["swing_angle", "stance_angle", "torso_angle", "swing_rate", "stance_rate",
                     "torso_rate"]
    x = dict(zip(names, fixed_point.x))
    assert abs(x["torso_angle"]) < 1e-8 and abs(x["torso_rate"]) < 1e-8  # damped to upright
    assert fixed_point.multipliers_variational.shape == (6,)
    assert fixed_point.residual < 1e-9


def test_samples_artifact_and_figures_name_the_torso(walker, fixed_point, scene, tmp_path):
    import h5py

    import walkerlab.io.artifacts as A
    from walkerlab.analysis.gait.metrics import sample_trajectory
    from walkerlab.integrate.rigid import simulate_steps
    from walkerlab.integrate.solver import Solver
    from walkerlab.io.trajectory import read_samples, write_samples
    from walkerlab.plotting import figures as F

    x0 = fixed_point.x + np.array([0, 0, 0.05, 0, 0, 0])  # lean the torso: it must settle
    traj = simulate_steps(walker, walker.from_section(walker.section(x0)), 4,
                          Solver("DOP853", 1e-10, 1e-10))
    tr = sample_trajectory(traj, 200)
    assert set(tr.coordinates) == {"leg1_angle", "leg2_angle", "torso_angle", "leg1_rate",
                                   "leg2_rate", "torso_rate"}
    assert ("torso_angle", "torso_rate") in tr.phase_pairs() and len(tr.phase_pairs()) == 3
    assert "torso_top" in tr.points and {"leg1_foot", "leg2_foot"} <= set(tr.points)
    # leg names swap roles at heel strike: leg1's angle is continuous through the impact
    # (the angle does not jump), while the role-ordered swing angle would
    step = tr.step_index
    i = np.flatnonzero(np.diff(step))[0]
    assert abs(tr.coordinates["leg1_angle"][i + 1] - tr.coordinates["leg1_angle"][i]) < 1e-9
    path = tmp_path / "torso" / "simulate.h5"
    A.write_artifact(path, "simulate", scene, "x", lambda f: write_samples(f, tr), 0.0)
    with h5py.File(path, "r") as f:
        assert f["samples/coordinates/torso_rate"].attrs["unit"] == "rad/s"
        back = read_samples(f)
    np.testing.assert_array_equal(back.coordinates["torso_angle"], tr.coordinates["torso_angle"])
    import matplotlib.pyplot as plt

    fig = F.fig9_limit_cycle({"ideal": back})
    # one panel per link: both legs share "leg", the torso has its own
    assert [ax.get_title() for ax in fig.axes if ax.get_visible()] == ["legs: leg1 and leg2",
                                                                        "torso"]
    assert len(fig.axes[0].get_lines()) == 2 and len(fig.axes[1].get_lines()) == 1
    stick = F.stick_diagram(back, "torso test", slope_rad=scene.slope.phi_rad)
    assert len(stick.axes[0].lines) >= 3 * 14  # two legs and the torso per snapshot
    fig7 = F.fig7_angles_rates({"ideal": back})
    assert len(fig7.axes[0].lines) == 3 and len(fig7.axes[1].lines) == 3  # 3 angles, 3 rates
    for f in (fig, stick, fig7):
        plt.close(f)


def test_sweep_columns_and_bifurcation_arrays_follow_the_walker(walker, fixed_point, scene,
                                                                 tmp_path):
    import xarray as xr

    import walkerlab.io.artifacts as A
    from walkerlab.io.schemas.bifurcation import bifurcation_writer
    from walkerlab.studies.bifurcation import BifurcationResult
    from walkerlab.studies.outcomes import columns
    from walkerlab.studies.point_columns import _fp_columns, interleg_angle

    cols = columns("fixedpoint", walker.state_names(), walker.state_units())
    assert "torso_angle_rad" in cols and "torso_rate_rad_per_s" in cols
    assert "multiplier_5_re" in cols and "multiplier_6_re" not in cols
    got = _fp_columns(walker, fixed_point)
    assert set(got) <= set(cols)
    x = dict(zip(walker.state_names(), fixed_point.x))
    # inter-leg angle from the feet equals |stance - swing| for straight legs
    assert interleg_angle(walker, fixed_point.x) == pytest.approx(
        abs(x["stance_angle"] - x["swing_angle"]), rel=1e-12)
    n = 2
    res = BifurcationResult(
        values=np.array([1.0, 1.1]), state_names=walker.state_names(),
        state_units=walker.state_units(), fixed_point=np.tile(fixed_point.x, (n, 1)),
        fixed_point_interleg_deg=np.full(n, 20.0),
        multipliers=np.tile(fixed_point.multipliers_variational, (n, 1)),
        step_period_s=np.full(n, 0.7), fp_outcome=np.array(["ok", "ok"], object),
        interleg_deg=np.zeros((n, 3)), stance_after_deg=np.zeros((n, 3)),
        ss_outcome=np.array(["walks"] * n, object), attractor_period=np.ones(n, int),
        onset={"onset_deg": np.nan, "bracket_deg": np.array([np.nan, np.nan]),
               "multiplier_at_onset": np.nan}, wall_time_s=np.zeros(n), n_transient=5, n_keep=3)
    path = tmp_path / "bifurcation.h5"
    A.write_artifact(path, "bifurcation", scene, "x", bifurcation_writer(res), 0.0)
    with xr.open_dataset(path, engine="h5netcdf", group="floquet") as ds:
        assert ds["real"].dims == ("slope", "multiplier") and ds.sizes["multiplier"] == 6
    with xr.open_dataset(path, engine="h5netcdf", group="fixed_point") as ds:
        assert ds["torso_rate"].attrs["units"] == "rad/s" and ds["torso_rate"].dims == ("slope",)
