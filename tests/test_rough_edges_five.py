"""Rough edges, round five (issue 51, items 6, 8, 9 and 15): the export reads the stored gait,
a powered walker's Adams dataset says on the terminal that it holds the passive walker,
messages that keep their advice, units of a nondimensional optimum, the energy ledger in a
section of its own, SIGTERM as Ctrl-C, a full disk while the generated module is written,
bounded reference tables."""

import errno
import signal
import subprocess
import sys
import textwrap
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from walkerlab.cli import app
from walkerlab.config import SceneError, load_scene, scene_from_dict

ROOT = Path(__file__).resolve().parents[1]
POWERED = ROOT / "configs" / "powered_compass.yaml"


def _cli(*args):
    r = CliRunner().invoke(app, [str(a) for a in args])
    return r.exit_code, r.stderr.strip(), r.stdout


# ------------------------------------------------ 8: export reads a fresh fixedpoint.h5
def test_export_reads_the_gait_of_an_up_to_date_fixedpoint_artifact(tmp_path, monkeypatch):
    """With fixedpoint.h5 up to date the export searches no gait (RABBIT: 94 s of search ->
    2 s), and writes the very file the search gives (bit for bit); a stale artifact is not
    read (the search runs)."""
    from walkerlab.analysis.gait import search
    from walkerlab.stages import export, fixedpoint

    scene = load_scene(POWERED)
    searched = export.run(scene, tmp_path / "a", "mjcf").read_text()  # no artifact: search
    fixedpoint.run(scene, tmp_path / "b")
    calls = []
    real = search.find_gaits
    monkeypatch.setattr(search, "find_gaits", lambda *a, **k: calls.append(1) or real(*a, **k))
    assert export.run(scene, tmp_path / "b", "mjcf").read_text() == searched
    assert export.run(scene, tmp_path / "b", "adm").is_file()
    assert calls == []  # read, not searched (the adm export searched twice before)
    other = scene.model_copy(update={"solver": scene.solver.model_copy(update={"rtol": 1e-11})})
    assert fixedpoint.fresh_artifact(other, tmp_path / "b") is None  # stale for this scene
    export.run(other, tmp_path / "b", "mjcf")
    assert calls  # searched again


# --------------------------- 6: a powered walker's Adams dataset carries its actuation
def test_adm_export_of_a_powered_walker_on_level_ground_carries_its_push_off(tmp_path):
    """Issue 48: the push-off is written (GFORCE pulses), so no warning any more."""
    code, err, out = _cli("export", POWERED, "--format", "adm", "--runs-dir", tmp_path)
    assert code == 0 and "walker.adm" in out and err == ""
    adm = (Path(tmp_path) / "powered_compass" / "walker.adm").read_text()
    assert "GFORCE/1," in adm and "GFORCE/2," in adm and "PASSIVE" not in adm


def test_adm_warning_is_empty_and_what_is_not_written_is_refused():
    """Push-off and hip torques are written (no warning line); a time reference is not
    (refused in one line naming the field)."""
    from walkerlab.export.adams import actuation_warning, check_adams_actuation

    d = yaml.safe_load(POWERED.read_text())
    d["slope"] = {"angle_deg": 1.0}
    d["walker"]["actuation"]["torques"] = [{"joint": "hip", "law": {"constant_n_m": 0.1}}]
    assert actuation_warning(scene_from_dict(d)) == ""
    check_adams_actuation(scene_from_dict(d))
    d["walker"]["actuation"]["torques"][0]["law"]["time_reference"] = {
        "time_s": [0.0, 0.4], "hip_angle_rad": [0.1, -0.1]}
    with pytest.raises(ValueError, match="torques.0.law.time_reference"):
        check_adams_actuation(scene_from_dict(d))
    assert actuation_warning(load_scene(ROOT / "configs" / "paper.yaml")) == ""


# ------------------------------------------------------ 15: reference tables bounded
@pytest.mark.parametrize("where", ["angle_rad", "phase_rad"])
def test_a_reference_angle_beyond_two_turns_is_refused_naming_the_entry(where):
    d = yaml.safe_load((ROOT / "configs" / "rabbit.yaml").read_text())
    d["walker"]["actuation"]["torques"][0]["law"]["reference"][where][1] = 1e308
    with pytest.raises(SceneError) as exc:
        scene_from_dict(d, "s.yaml")
    assert str(exc.value) == (f"s.yaml: walker.actuation.torques.0.law.reference.{where}.1: "
                              "Input should be less than or equal to 6.3")


# ------------------------------------------------ 9/15: the no-gait advice, whole
def test_no_gait_with_an_initial_guess_advises_something_else_and_keeps_the_diagnosis(
        tmp_path):
    """Push-off 0 on level ground from the shipped guess: no gait.  The guess is given, so
    the advice is not to give one; the diagnosis (the standing solution) is in the line,
    and nothing of the advice is cut."""
    d = yaml.safe_load(POWERED.read_text())
    d["walker"]["actuation"]["push_off"]["impulse_n_s"] = 0.0
    f = tmp_path / "p0.yaml"
    f.write_text(yaml.safe_dump(d))
    code, err, _ = _cli("fixedpoint", f, "--runs-dir", tmp_path / "runs")
    assert code == 1 and len(err.splitlines()) == 1
    assert "give fixedpoint.initial_guess" not in err
    assert "the initial guess did not converge" in err
    assert "start from a gait known nearby (walkerlab fixedpoint --from" in err
    assert "trivial standing solution" in err
    assert "more characters" not in err and "WALKERLAB_DEBUG" not in err


def test_advice_longer_than_the_limit_is_kept_whole_only_the_detail_is_cut():
    from walkerlab.cli.errors import MAX_ERROR_CHARS, one_line

    advice = "no gait; " + "advice " * 60  # longer than the limit on its own
    assert len(advice) > MAX_ERROR_CHARS
    line = one_line(advice + "[tried a; last: " + "word " * 60 + "]")
    assert line.startswith(advice + "[tried a ... rerun with WALKERLAB_DEBUG=1")
    short = advice + "[tried a and b]"
    assert one_line(short) == short  # nothing cut: nothing to rerun for


# ------------------------------------------------------ 9: a nondimensional optimum
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


# ------------------------------------------ 9: the energy ledger, a section of its own
def _ledger_sim():
    keys = ("push_off_work", "actuator_work_positive", "actuator_work_negative",
            "heel_strike_loss", "internal_collision_loss", "damper_work", "potential_work",
            "closure", "cost_of_transport")
    from walkerlab.units import Units

    return SimpleNamespace(ledger={k: [0.1, 0.1] for k in keys}, units=Units(), samples=None)


def test_the_energy_ledger_is_a_section_beside_the_gait_not_under_figures(tmp_path,
                                                                          monkeypatch):
    from walkerlab.report import build, contact_sections, sections

    for mod, name in ((sections, "summary_section"), (contact_sections, "sections"),
                      (contact_sections, "initial_states_section")):
        monkeypatch.setattr(mod, name, lambda *a, **k: [])
    monkeypatch.setattr(sections, "gait_section",
                        lambda scene, inputs, pub: ["## Gait characteristics", ""])
    for stem in ("energy_ledger", "fig10_energy"):
        (tmp_path / f"{stem}.png").write_bytes(b"")
    scene = load_scene(POWERED)
    build.write_report(scene, build.ReportInputs({"simulate": _ledger_sim()}), tmp_path,
                       tmp_path)
    md = (tmp_path / "report.md").read_text()
    gait, ledger = md.index("## Gait characteristics"), md.index("## Energy ledger and cost")
    figures = md.index("## Figures")
    assert gait < ledger < figures
    assert md.index("energy_ledger.png") < figures  # the figure moved with its table
    assert md.index("Cost of transport") < figures and md.count("energy_ledger.png") == 1


def test_a_spring_written_as_an_actuator_law_is_named_as_motor_work():
    from walkerlab.report.figures_section import spring_law_note

    d = yaml.safe_load(POWERED.read_text())
    d["walker"]["actuation"]["torques"] = [
        {"joint": "hip", "law": {"stiffness_n_m_per_rad": 20.0}}]
    note = spring_law_note(scene_from_dict(d))
    assert "walker.actuation.torques.0 (hip)" in note and "motor work, no regeneration" in note
    assert "walker.springs" in note
    assert spring_law_note(load_scene(POWERED)) == ""  # push-off alone
    # Kuo's spring scaled by the massless foot's mass does no work: not named
    assert spring_law_note(load_scene(ROOT / "configs" / "kuo2002.yaml")) == ""


# ------------------------------------------------------------- 15: SIGTERM as Ctrl-C
def test_sigterm_during_a_write_leaves_no_lock_nor_temporary_file(tmp_path):
    script = textwrap.dedent(f"""
        import sys, time
        from walkerlab.cli.process import terminate_as_interrupt
        terminate_as_interrupt()
        from walkerlab.config import load_scene
        from walkerlab.io.freshness import write_if_stale
        sc = load_scene({str(ROOT / 'configs' / 'paper.yaml')!r})
        def writer(f):
            f.create_dataset('x', data=[1.0])
            print('ready', flush=True)
            time.sleep(60)
        try:
            write_if_stale('fixedpoint', sc, {str(tmp_path)!r}, ('walker',), (),
                           lambda: (writer, dict()))
        except KeyboardInterrupt:
            sys.exit(130)
        """)
    with subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE,
                          text=True) as p:
        try:
            assert p.stdout.readline().strip() == "ready"
            p.send_signal(signal.SIGTERM)
            assert p.wait(timeout=30) == 130
        finally:
            p.kill()
    left = sorted(q.name for q in (tmp_path / "paper").iterdir())
    assert left == [".scene"], left  # no .fixedpoint.h5.lock, no temporary file


# ------------------------------------------ 15: a full disk while the model is written
def test_a_file_size_limit_while_the_generated_module_is_written_says_disk_full(monkeypatch):
    import walkerlab.safefs as safefs
    from walkerlab.cli.errors import _disk_full_line
    from walkerlab.codegen import cache
    from walkerlab.io.artifacts import is_disk_full

    def full(path, fill, **kw):
        raise OSError(errno.EFBIG, "File too large", str(path))

    monkeypatch.setattr(safefs, "atomic_replace", full)
    with pytest.raises(OSError) as exc:
        cache.import_generated("zz_never_written_nb.py", "walkerlab_zz_never", lambda: "X = 1")
    assert is_disk_full(exc.value) and "cannot write the generated module" in str(exc.value)
    line = _disk_full_line(exc.value)
    assert line.startswith("error: disk full: cannot write ") and "zz_never_written" in line


# ------------------------------------- 8: RABBIT's step map runs its compiled flow on LSODA
@pytest.mark.slow  # builds RABBIT and maps twice (the Python map alone ~1 s)
def test_the_five_link_step_map_on_lsoda_calls_no_python_flow_and_agrees_with_it(
        monkeypatch):
    """RABBIT (LSODA: scipy) runs the phase's compiled actuated flow, as its replays do (one
    map 0.72 -> 0.07 s CPU; with the variational equations 7.9 -> 0.14 s): no call of the
    Python flow, and the same map to the integrator's tolerance (rtol = atol = 1e-11:
    measured 2e-11 rad on the state, 1.4e-12 s on the period)."""
    from dataclasses import replace

    import walkerlab.integrate.rigid as rigid
    from walkerlab.analysis.gait.poincare import poincare_map
    from walkerlab.analysis.gait.scene import initial_guess
    from walkerlab.integrate.solver import Solver
    from walkerlab.models.registry import build_walker

    scene = load_scene(ROOT / "configs" / "rabbit.yaml")
    w = build_walker(scene)
    calls = []

    def counted(f):
        return lambda t, x: calls.append(1) or f(t, x)

    w = replace(w, phases=tuple(replace(p, flow=counted(p.flow)) for p in w.phases))
    solver = Solver.from_settings(scene.solver)
    assert solver.resolved_backend() == "scipy"
    x0 = np.asarray(initial_guess(scene, w), float)
    x1, T1, _ = poincare_map(w, x0, solver)
    assert calls == []
    monkeypatch.setattr(rigid, "_runs_compiled_on_scipy", lambda phase: False)
    x2, T2, _ = poincare_map(w, x0, solver)
    assert calls  # the Python flow, as before
    assert np.max(np.abs(x1 - x2)) < 1e-9 and abs(T1 - T2) < 1e-10
