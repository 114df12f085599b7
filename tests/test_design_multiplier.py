"""Design optimisation of the largest Floquet multiplier: its gradient through the fixed point
(eigenvalue perturbation) against central differences of the re-solved gait, and the design
loop that follows the scene's own gait instead of jumping to another one."""

from pathlib import Path

import numpy as np
import pytest

import walkerlab as wl
from walkerlab.config.loader import load_scene
from walkerlab.walker.plant import Plant

CONFIGS = Path(__file__).resolve().parents[1] / "configs"


@pytest.fixture(scope="module")
def paper():
    scene = load_scene(CONFIGS / "paper.yaml")
    return scene, wl.Walker.from_scene(scene).fixed_point().x


def _resolved(gaits, p):
    """|λ|max of the gait re-solved at ``p`` from the gaits' last one, state restored."""
    start = gaits.last.copy(), gaits.p_last.copy()
    v = gaits.value([p], "max_abs_multiplier")
    gaits.last, gaits.p_last = start
    return v


@pytest.mark.parametrize("mass", [10.0, 15.0])
def test_largest_multiplier_gradient_equals_central_differences_of_the_resolved_gait(
        paper, mass):
    """d|λ|max/d(hip mass) from one variational-Jacobian difference along (dx*/dp, 1) and
    the left/right eigenvectors equals the central difference (h = 1e-3 kg, truncation
    ~h² |λ'''| ≈ 1e-9 relative here) of |λ|max at re-solved fixed points to 1e-6 relative
    (measured 2.5e-8 at 10 kg and 3.3e-9 at 15 kg)."""
    from walkerlab.optimal.design.gradients import _Gaits, multiplier_gradient

    scene, x = paper
    gaits = _Gaits(scene, ["walker.hip_mass_kg"], x, max_step=[0.75], plant=Plant.from_scene(scene))
    value, grad = multiplier_gradient(gaits, [mass])
    assert value == pytest.approx(np.max(np.abs(np.linalg.eigvals(
        np.asarray(gaits.gait([mass])[1].jacobian_variational)))), rel=1e-12)
    fd = (_resolved(gaits, mass + 1e-3) - _resolved(gaits, mass - 1e-3)) / 2e-3
    assert abs(fd) > 1e-4
    assert grad[0] == pytest.approx(fd, rel=1e-6)


def test_design_solves_follow_the_scenes_gait_not_a_neighbouring_one(paper):
    """From the paper walker's gait at 10 kg straight to 15 kg, MINPACK lands on another,
    unstable gait of the same walker (|λ|max 2.48); walked in sub-steps of 0.75 kg it stays on
    the scene's own stable gait (|λ|max 0.5754, as the SLSQP path through 12.7 and 15.0 kg
    finds it)."""
    from walkerlab.optimal.design.gradients import _Gaits

    scene, x = paper
    gaits = _Gaits(scene, ["walker.hip_mass_kg"], x, max_step=[0.75], plant=Plant.from_scene(scene))
    assert gaits.value([15.0], "max_abs_multiplier") == pytest.approx(0.57545, abs=1e-4)
    assert gaits.count == 7  # ceil(5 / 0.75) sub-steps, each one fixed point


def test_hip_mass_minimising_the_largest_multiplier_is_interior_with_zero_gradient(paper):
    """The paper walker's hip mass within 5-40 kg minimising |λ|max (SLSQP with the exact
    gradient): 20.64 kg, |λ|max 0.57365 (0.58585 at the scene's 10 kg), where the gradient
    vanishes (|d|λ|/dm| ≤ 1e-6 per kg, against -4.1e-3 per kg at 10 kg)."""
    from walkerlab.optimal.design.search import design_optimize

    scene, x = paper
    res = design_optimize(scene, {"walker.hip_mass_kg": (5.0, 40.0)}, "max_abs_multiplier", x,
                          plant=Plant.from_scene(scene))
    assert res.success, res.message
    assert res.values[0] == pytest.approx(20.64, abs=0.05)
    assert res.value == pytest.approx(0.57365, abs=2e-5) and res.value < 0.5858
    assert abs(res.gradient[0]) < 1e-6


def test_design_artifact_loads_back_and_draws_its_figure(paper, tmp_path):
    """``optimize_design.h5`` is read back by its loader beside its writer (values, unit,
    gradient, history) and its figure is drawn from the loaded artifact."""
    import h5py

    from walkerlab.io.schemas.optimize import load_design, write_design
    from walkerlab.optimal.design.search import DesignResult
    from walkerlab.plotting.design_figure import save_design_figure

    r = DesignResult(["walker.hip_mass_kg"], np.array([20.6]), "speed", 0.53,
                     np.array([-1e-3]), True, "ok", 3,
                     [(np.array([10.0]), 0.52), (np.array([20.6]), 0.53)], "m/s")
    from walkerlab.io.artifacts import write_artifact

    scene, _ = paper
    path = write_artifact(tmp_path / "optimize_design.h5", "optimize_design", scene, "x",
                          lambda f: write_design(f, r), 0.0)
    d = load_design(path)
    assert d.fields == ("walker.hip_mass_kg",) and d.objective_unit == "m/s"
    assert d.values[0] == 20.6 and d.gradient[0] == -1e-3 and d.history_values.shape == (2, 1)
    with h5py.File(path) as f:
        assert f.attrs["objective"] == "speed"
    paths = save_design_figure(d, "paper", tmp_path / "fig")
    assert any(p.suffix == ".png" and p.stat().st_size > 1000 for p in paths)
