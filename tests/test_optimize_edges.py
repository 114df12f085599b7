"""``walkerlab optimize`` at its edges (issue 51, items 4, 7 and 15): a five-link biped
without a target is refused at once, a failure keeps its origin for the debug trace, the
contact replay's solver failure is the replay's outcome (not the optimisation's end), a
level-ground optimum starts from its targets when the walker has no gait, and a result
that is not a gait is not replayed on the contact model (``--require-gait``)."""

from __future__ import annotations

import traceback
from pathlib import Path

import numpy as np
import pytest

from walkerlab.config import load_scene

pytest.importorskip("casadi")
CONFIGS = Path(__file__).resolve().parents[1] / "configs"


def test_a_five_link_biped_without_a_target_is_refused_at_once(tmp_path):
    """configs/rabbit.yaml has no ``optimize`` section: before, the default section (no
    target) ran ~50 s into a 1 mm shuffle and then stopped on scipy's root finder ("f(a)
    and f(b) must have different signs") in the contact replay; now one line at once, naming
    the targets to give, and nothing written.  The StageError is chained to its origin (the
    debug trace shows where it came from)."""
    from typer.testing import CliRunner

    from walkerlab.cli import app
    from walkerlab.stages import optimize as stage
    from walkerlab.stages.common import StageError

    r = CliRunner().invoke(app, ["optimize", str(CONFIGS / "rabbit.yaml"), "--runs-dir",
                                 str(tmp_path)])
    assert r.exit_code == 1 and r.output.count("error:") == 1, r.output
    assert "has no 'optimize' section" in r.output
    assert "optimize.target_step_length_m" in r.output and "more characters" not in r.output
    assert not list(tmp_path.rglob("optimize.h5"))
    scene = load_scene(CONFIGS / "rabbit.yaml")
    d = scene.model_dump(mode="json", exclude_none=True)
    d["optimize"] = {"intervals": 20}  # a section without a target: refused alike
    with pytest.raises(StageError, match="optimize: a five-link biped's optimal step "
                       "needs a target") as exc:
        stage.run(type(scene).model_validate(d), tmp_path)
    origin = "".join(traceback.format_tb(exc.value.__cause__.__traceback__))
    assert "five_link_scene.py" in origin


def test_a_contact_replay_whose_solver_fails_is_an_outcome(monkeypatch):
    """The contact replay is a report on the optimum: its solver's failure (scipy's event
    location raising "f(a) and f(b) must have different signs", as RABBIT's feed-forward + PD
    law did on the contact model without a target) becomes its outcome, one line saying
    what failed and what to try, and the optimisation stands."""
    from walkerlab.analysis.contact import sim
    from walkerlab.config import SolverSettings
    from walkerlab.optimal import contact_replay

    def fail(*a, **k):
        raise ValueError("f(a) and f(b) must have different signs")

    monkeypatch.setattr(sim, "simulate_from", fail)
    solver = SolverSettings.for_contact(method="LSODA", rtol=1e-8, atol=1e-10)
    period, outcome = contact_replay._run(None, np.zeros(4), 0.7, 1, solver)
    assert np.isnan(period)
    assert outcome.startswith("not replayed: the contact model's solver (LSODA, rtol 1e-08)")
    assert "f(a) and f(b) must have different signs" in outcome and "contact_solver" in outcome
    assert "\n" not in outcome


def test_an_infeasible_target_is_not_replayed_on_contact_and_require_gait_fails(tmp_path):
    """compass_optimal at 0.6 m/s with |u| <= 0.5 N m: IPOPT reports the problem infeasible
    and the rigid replay returns 0.03 away - NOT a gait.  Before, the command exited 0 and
    replayed the contact model on it anyway; now the contact replay is skipped ("not a
    gait"), ``--require-gait`` exits 1 with one line (as ``fixedpoint --require-stable``,
    optimize.h5 stays, and a reused one is judged alike)."""
    import yaml
    from typer.testing import CliRunner

    from walkerlab.cli import app
    from walkerlab.io.schemas.optimize import load

    d = yaml.safe_load((CONFIGS / "compass_optimal.yaml").read_text())
    d["optimize"].update(target_speed_m_per_s=0.6, max_torque_n_m=0.5)
    scene = tmp_path / "tight.yaml"
    scene.write_text(yaml.safe_dump(d))
    args = ["optimize", str(scene), "--runs-dir", str(tmp_path / "runs")]
    r = CliRunner().invoke(app, [*args, "--require-gait"])
    assert r.exit_code == 1 and r.output.count("error:") == 1, r.output
    assert "error: --require-gait: the optimum is NOT a gait: IPOPT did not converge" \
        in r.output
    out = load(tmp_path / "runs" / "tight" / "optimize.h5")
    assert not out.gait and np.isfinite(out.replay_error)  # the old code replayed it
    assert np.isnan(out.contact_step_period_s)
    assert out.contact_outcome.startswith("not replayed: not a gait (IPOPT: ")
    r = CliRunner().invoke(app, [*args, "--require-gait"])  # reused: read back
    assert r.exit_code == 1 and "reused" in r.output and "--require-gait" in r.output
