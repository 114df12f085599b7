"""Issue 96's rough edges a new user met: the paper scene's default report measures the
work-precision study (a scene field, not a name check), ``--quiet`` on every command's
help, a 3D walker's figures (their title, the lateral coordinates on axes of their own),
a 3D export's omissions printed, the two speeds told apart, and Ctrl-C in a pool's worker
ending it silently."""

from __future__ import annotations

import os
import signal
import time
from concurrent.futures.process import BrokenProcessPool
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from walkerlab.cli import COMMANDS, app
from walkerlab.cli.options import load
from walkerlab.io.trajectory import NamedTrajectory
from walkerlab.stages.pipeline import report_plan

ROOT = Path(__file__).resolve().parents[1]


# ------------------------------------------------------------------ 1: the default report
def test_the_paper_scenes_default_report_measures_the_work_precision_study():
    paper = load(None)  # what `walkerlab report` runs with no scene
    assert paper.workprecision.in_default_report
    assert "workprecision" in report_plan(paper)


def test_the_default_report_comes_from_the_scene_field_not_the_scene_name():
    """The same scene with the field off: opt-in again (``--full``)."""
    paper = load(None)
    off = paper.model_copy(update={"workprecision": paper.workprecision.model_copy(
        update={"in_default_report": False})})
    assert "workprecision" not in report_plan(off)
    assert "workprecision" in report_plan(off, full=True)
    assert "in_default_report: true" in (ROOT / "configs" / "paper.yaml").read_text()


def test_other_shipped_scenes_keep_the_work_precision_study_opt_in():
    for name in ("kneed", "paper_3d", "rabbit"):
        assert "workprecision" not in report_plan(load(name)), name


# ------------------------------------------------------------------ 3: --quiet everywhere
@pytest.mark.parametrize("command", [name for name, _ in COMMANDS])
def test_every_commands_help_lists_quiet(command):
    r = CliRunner().invoke(app, [command, "--help"], env={"COLUMNS": "200"})
    assert r.exit_code == 0, r.output
    assert "--quiet" in r.output and "-q" in r.output


def test_quiet_after_the_command_is_accepted_as_before_it(tmp_path):
    runner = CliRunner()
    for args in (["-q", "capabilities"], ["capabilities", "-q"], ["capabilities", "--quiet"]):
        r = runner.invoke(app, args)
        assert r.exit_code == 0, (args, r.output)


# ------------------------------------------------------------------ 4: 3D walker's figures
def test_out_of_plane_coordinates_are_told_by_their_names():
    from walkerlab.walker.planes import out_of_plane

    for name in ("lean_angle", "lean_rate", "leg1_roll_angle", "pelvis_roll_rate",
                 "heading_angle"):
        assert out_of_plane(name), name
    for name in ("leg1_angle", "leg2_rate", "swing_thigh_angle", "leg1_shank_rate",
                 "torso_angle", "stance_ankle_angle"):
        assert not out_of_plane(name), name


def _trajectory(names, points_dim=2):
    t = np.linspace(0.0, 1.0, 20)
    coords = {f"{n}_{k}": np.sin(t + i) * (0.03 if n == "lean" else 0.2)
              for i, n in enumerate(names) for k in ("angle", "rate")}
    units = {k: ("rad" if k.endswith("_angle") else "rad/s") for k in coords}
    z = np.zeros(t.size)
    return NamedTrajectory(time=t, legs=["leg1", "leg2"], coordinates=coords, units=units,
                           stance_leg=z.astype(int), step_index=z.astype(int), kinetic=z,
                           potential=z, points={"hip": np.zeros((points_dim, t.size))})


def _labels(ax):
    return [ln.get_label() for ln in ax.get_lines()]


def test_fig7_draws_a_3d_walkers_lean_on_axes_of_its_own():
    import matplotlib.pyplot as plt

    from walkerlab.plotting.figures import fig7_angles_rates

    fig = fig7_angles_rates({"ideal": _trajectory(("leg1", "leg2", "lean"), 3)})
    axes = fig.axes
    assert len(axes) == 4
    pitches, lateral = axes[0], axes[1]  # row-major: (a), (c)
    assert all("lean" not in lab for lab in _labels(pitches))
    assert _labels(lateral) == ["lean - ideal"]
    assert all("lean" not in lab for lab in _labels(axes[2]))
    assert _labels(axes[3]) == ["lean - ideal"]
    plt.close(fig)


def test_fig7_of_a_planar_walker_keeps_its_two_panels():
    import matplotlib.pyplot as plt

    from walkerlab.plotting.figures import fig7_angles_rates

    fig = fig7_angles_rates({"ideal": _trajectory(("leg1", "leg2"))})
    assert len(fig.axes) == 2
    assert fig.axes[0].get_title() == "(a) angles"
    plt.close(fig)


def test_a_3d_walkers_figures_are_titled_in_3d():
    from types import SimpleNamespace

    from walkerlab.plotting.scene_figures import scene_figure_plan

    def title(scene, dim):
        sim = SimpleNamespace(samples=_trajectory(("leg1", "leg2"), dim), ledger={})
        plan = dict(scene_figure_plan(scene, sim, None, None, None))
        return plan["fig7_angles_rates"].args[1]

    assert title(load("paper_3d"), 3) == "compass gait in 3D walking"
    assert title(load("paper"), 2) == "compass gait walking"


# ------------------------------------------------------------------ 5: 3D export's omissions
def test_a_3d_urdf_export_prints_its_ground_and_the_bisecting_hips_coupling(tmp_path):
    r = CliRunner().invoke(app, ["-q", "export", "torso_bhm_3d", "--format", "urdf",
                                 "--walker-only", "--runs-dir", str(tmp_path)])
    assert r.exit_code == 0, r.output
    left = [ln for ln in r.output.splitlines() if ln.startswith("left out of walker.urdf: ")]
    assert any("the ground" in ln for ln in left), r.output
    assert any("coupling torso_pitch_coupling" in ln for ln in left), r.output


@pytest.mark.slow
def test_a_3d_adams_export_prints_the_energy_requests_it_leaves_out(tmp_path):
    r = CliRunner().invoke(app, ["-q", "export", "paper_3d", "--format", "adm",
                                 "--runs-dir", str(tmp_path)])
    assert r.exit_code == 0, r.output
    assert "left out of walker.adm: the energies' requests" in r.output


# ------------------------------------------------------------------ 2: the two speeds
@pytest.mark.slow
def test_a_walk_on_the_fixed_point_has_cos_slope_times_the_gaits_speed():
    """``gait.speed`` is along the slope, ``walk.speed`` the hip's horizontal speed: on the
    paper's slope they differ by 1 - cos(phi) = 1.5e-4, as their descriptions say."""
    from walkerlab.api import Walker

    w = Walker.from_scene("paper")
    gait = w.fixed_point()
    walk = w.simulate(gait.x, 1)
    phi = load("paper").slope.phi_rad
    np.testing.assert_allclose(walk.speed, gait.speed * np.cos(phi), rtol=1e-9)
    assert abs(walk.speed[0] / gait.speed - 1) > 1e-4


# ------------------------------------------------------------------ 6: Ctrl-C in a worker
def test_a_pool_worker_ends_silently_with_130_on_sigint(capfd):
    from walkerlab.execution import workers

    with workers.process_pool(1) as ex:
        assert ex.submit(signal.getsignal, signal.SIGINT).result() is workers._exit_quietly
        pid = ex.submit(os.getpid).result()
        job = ex.submit(time.sleep, 60)
        os.kill(pid, signal.SIGINT)
        with pytest.raises(BrokenProcessPool):
            job.result()
    err = capfd.readouterr().err
    assert "Traceback" not in err and "KeyboardInterrupt" not in err


_CTRL_C = '''
import os, signal, sys, time


def main():
    signal.signal(signal.SIGINT, lambda *a: None)  # the command's handler: records, prints nothing
    from walkerlab.execution.workers import process_pool
    with open(sys.argv[1], "w") as ready:
        ex = process_pool(2)
        ready.write(str(ex.submit(os.getpid).result()))  # a worker started and now idle
    os.killpg(os.getpgid(0), signal.SIGINT)  # Ctrl-C reaches the terminal's whole group
    for _ in range(200):  # until the workers are gone (each ends on its own)
        if not any(p.is_alive() for p in list(ex._processes.values())):
            break
        time.sleep(0.05)
    ex.shutdown(wait=False)


if __name__ == "__main__":
    main()
'''


def test_ctrl_c_to_a_commands_process_group_prints_no_workers_traceback(tmp_path):
    """Issue 96 item 6: Ctrl-C reaches the pool's workers as well as the command; an idle
    worker printed ``Process ForkServerProcess-1: Traceback ... KeyboardInterrupt`` (one
    compiling numba, an llvmlite traceback) under the command's own ``interrupted``."""
    import subprocess
    import sys

    script = tmp_path / "ctrl_c.py"
    script.write_text(_CTRL_C)
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    r = subprocess.run([sys.executable, str(script), str(tmp_path / "ready")],
                       capture_output=True, text=True, start_new_session=True, env=env,
                       timeout=120)
    assert r.returncode == 0, r.stderr
    assert "Traceback" not in r.stderr and "KeyboardInterrupt" not in r.stderr, r.stderr
