"""What ``optimize.h5`` records beside the optimum: IPOPT's iteration history and the
walker's energies over the collocated step, checked against physics (the energy change over
the step equals the hip torque's work, computed from the torques and rates alone)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

import walkerlab as wl
from walkerlab.cli import app
from walkerlab.codegen import legged
from walkerlab.config import load_scene
from walkerlab.models.registry import build_walker
from walkerlab.optimal.outcome import history_and_energies
from walkerlab.optimal.transcription.mode_sequence import collocate_step
from walkerlab.optimal.transcription.step import CollocationSpec
from walkerlab.walker.description import walker_data
from walkerlab.walker.plant import Plant

pytest.importorskip("casadi")
CONFIGS = Path(__file__).resolve().parents[1] / "configs"


@pytest.fixture(scope="module")
def powered():
    """powered_compass made to walk at 0.55 m/s by the least hip torque (its own gait:
    0.499 m/s), 40 Hermite-Simpson intervals."""
    scene = load_scene(CONFIGS / "powered_compass.yaml")
    w = wl.Walker.from_scene(scene)
    g = w.fixed_point()
    walk = w.simulate(g.x, strides=1, sample_rate_hz=2000.0)
    first = walk.stance_leg == walk.stance_leg[0]
    data = walker_data(scene.walker, scene.slope.phi_rad)
    res = collocate_step(data, legged.derive_legged(data.structure),
                         CollocationSpec(intervals=40, push_off_n_s=3.0,
                                         target_speed_m_per_s=0.55),
                         walk.t[first], walk.x[first])
    assert res.status == "Solve_Succeeded"
    return scene, res


def test_energy_change_over_the_step_equals_the_hip_torques_work(powered):
    """Between heel strikes only the hip torque changes the mechanical energy: E(T) - E(0)
    = int tau (omega_swing - omega_stance) dt (tau + on the swing leg, - on the stance
    leg).  The energies come from the walker's own energy function, the work from the
    collocated torques and rates by Simpson's rule on the Hermite-Simpson points (both
    O(h^4)): equal to 1e-6 of the work (measured 2.6e-7 at 40 intervals), and the work (0.209
    J) is not small."""
    scene, res = powered
    rec = history_and_energies(scene, build_walker(Plant.from_scene(scene)), res)
    e = rec["energy"]["kinetic"] + rec["energy"]["potential"]
    names = build_walker(Plant.from_scene(scene)).state_names()
    rate = {n: res.x[:, k] for k, n in enumerate(names)}
    power = res.u * (rate["swing_rate"] - rate["stance_rate"])
    h = res.t[2] - res.t[0]
    work = h / 6 * np.sum(power[:-2:2] + 4 * power[1:-1:2] + power[2::2])
    assert abs(work) > 1e-2
    assert e[-1] - e[0] == pytest.approx(work, rel=1e-6)


def test_ipopt_history_is_recorded_and_the_artifact_reads_it_back(powered, tmp_path):
    """IPOPT's history has one entry per iteration and the guess; its last primal
    infeasibility is within IPOPT's tolerance (1e-10 here); writer and loader keep history
    and energies."""
    from walkerlab.io.artifacts import write_artifact
    from walkerlab.io.schemas import optimize as schema

    scene, res = powered
    rec = history_and_energies(scene, build_walker(Plant.from_scene(scene)), res)
    h = rec["ipopt_history"]
    assert len(h["objective"]) == res.iterations + 1
    assert h["primal_infeasibility"][-1] <= 1e-10 < h["dual_infeasibility"].max()
    d = schema.OptimizeData(res.t, {"a": res.x[:, 0]}, res.u, res.step_period_s,
                            res.step_length_m, 3.0, res.objective, 1e-8,
                            np.zeros(4, complex), True, res.status, res.iterations, 1.0,
                            {"a": "rad"}, **rec)
    path = write_artifact(tmp_path / "optimize.h5", schema.STAGE, scene, "x",
                          lambda f: schema.write(f, d), 0.0)
    back = schema.load(path)
    np.testing.assert_array_equal(back.ipopt_history["dual_infeasibility"],
                                  h["dual_infeasibility"])
    np.testing.assert_array_equal(back.energy["kinetic"], rec["energy"]["kinetic"])
    assert back.energy_unit == "J"


def test_legs_that_differ_are_refused_in_one_line_not_optimised_as_one_step():
    """A one-step transcription with its reset as the periodic condition is a gait only for
    mirror-image legs: with legs that differ it closed on itself with the wrong leg in
    stance every other step (and then the contact replay crashed on the scene's ``legs``).
    It is refused in one line naming the reason."""
    from walkerlab.codegen import legged

    scene = load_scene(CONFIGS / "asymmetric_legs.yaml")
    data = walker_data(scene.walker, scene.slope.phi_rad)
    assert data.mirror is not None
    from walkerlab.optimal.transcription.step import step_functions

    with pytest.raises(ValueError, match="legs that differ") as info:
        step_functions(data, legged.derive_legged(data.structure))
    assert "\n" not in str(info.value)


def test_why_a_result_is_not_a_gait_is_said_with_what_helps():
    """The report's and the CLI's clause for a result that is not a gait: IPOPT's status
    when it did not converge; else the replay's return error, and on an open-loop unstable
    gait that more intervals shrink it (the compass walker at a 0.6 m step, effort + 0.1
    peak torque: 1.1e-6 at 40 intervals, |multiplier| 6.9; 6.6e-8 at 80)."""
    from types import SimpleNamespace

    from walkerlab.report.figures_section import not_a_gait_reason

    d = SimpleNamespace(status="Maximum_Iterations_Exceeded", replay_error=1e-3,
                        multipliers=np.array([0.5 + 0j]))
    assert not_a_gait_reason(d) == "IPOPT did not converge (Maximum_Iterations_Exceeded)"
    d = SimpleNamespace(status="Solve_Succeeded", replay_error=1.1e-6,
                        multipliers=np.array([6.924 + 0j, 0.1 + 0j]))
    says = not_a_gait_reason(d)
    assert "1.1e-06" in says and "6.92" in says and "optimize.intervals" in says
    d.multipliers = np.array([0.9 + 0j])
    assert "intervals" not in not_a_gait_reason(d)


# -------------------- a nondimensional optimum in its units
ROOT = Path(__file__).resolve().parents[1]


def _cli(*args):
    r = CliRunner().invoke(app, [str(a) for a in args])
    return r.exit_code, r.stderr.strip(), r.stdout


def _optimum():
    from walkerlab.io.schemas.optimize import OptimizeData

    return OptimizeData(
        time=np.linspace(0, 1.375, 3), states={}, torque=np.array([0.1, 1.679, 0.2]),
        step_period_s=1.375, step_length_m=0.55, push_off_n_s=0.1335, objective=0.009,
        replay_error=9e-8, multipliers=np.array([2.3, 0.1]), gait=True,
        status="Solve_Succeeded", iterations=17, wall_time_s=0.3, state_units={},
        torque_unit="N m/kg", contact_outcome="not replayed")


def test_a_nondimensional_optimum_is_printed_in_its_units(tmp_path, monkeypatch):
    from walkerlab.report.figures_section import optimize_lines
    from walkerlab.stages import pipeline
    from walkerlab.stages.common import StageOutcome
    from walkerlab.units import Units

    text = optimize_lines(_optimum(), Units("nondimensional"))[0]
    assert ("Step period 1.375 √(l/g), step length 0.5500 l, speed 0.4000 √(g l), push-off "
            "0.1335 M √(g l)") in text
    assert " m/s" not in text and " N s" not in text
    monkeypatch.setattr(pipeline, "run", lambda *a, **k: StageOutcome(
        "optimize", tmp_path / "optimize.h5", False, 1.0, {"data": _optimum()}))
    code, err, out = _cli("optimize", ROOT / "configs" / "kuo2002.yaml",
                          "--runs-dir", tmp_path)
    assert ("step period 1.375 √(l/g), step length 0.55 l, speed 0.4 √(g l), push-off 0.1335 "
            "M √(g l), peak |torque| [g l]") in out, out + err
