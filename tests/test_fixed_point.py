"""Fixed point of the Poincaré map for the paper's scene, and Eq. (11)."""

from pathlib import Path

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from tests.conftest import TIGHT
from walkerlab.analysis.gait.poincare import find_fixed_point, poincare_map
from walkerlab.cli import app
from walkerlab.config import load_scene
from walkerlab.models.hybrid.printed_equations import make_compass_gait
from walkerlab.published import paper
from walkerlab.walker.plant import Plant

EQ11 = np.array(paper.EQ11_STATE)  # role-ordered, as printed


def test_fixed_point_residual_and_stability(paper_fixed_point):
    fp = paper_fixed_point
    assert fp.residual <= 1e-10
    assert fp.stable
    # one multiplier is zero by construction (the map lands on the guard surface)
    assert np.min(np.abs(fp.multipliers_variational)) < 1e-12
    # variational and finite-difference multipliers agree (FD with h = 1e-7: ~1e-8)
    assert fp.multiplier_difference < 1e-6


def test_fixed_point_is_a_fixed_point(paper_walker, paper_fixed_point):
    x1, T, _ = poincare_map(paper_walker, paper_fixed_point.x, TIGHT)
    assert np.max(np.abs(x1 - paper_fixed_point.x)) < 1e-10
    assert pytest.approx(paper_fixed_point.period_s, abs=1e-10) == T


def test_appendix_a_reproduces_eq11():
    """Printed Appendix A at phi = 0.0174 rad gives Eq. (11) to the printed digits: angles
    to 4 decimals, dtheta1 to 2 decimals; dtheta2 = -0.8466 is printed as -0.84, i.e. the
    paper truncated it (rounding gives -0.85)."""
    w = make_compass_gait(1.0, 5.0, 10.0, 9.81, 0.5, 0.0174, "appendix_a")
    fp = find_fixed_point(w, EQ11, TIGHT)
    assert np.round(fp.x[:2], 4) == pytest.approx(EQ11[:2], abs=1e-12)
    assert np.round(fp.x[2], 2) == pytest.approx(EQ11[2], abs=1e-12)
    assert np.trunc(fp.x[3] * 100) / 100 == pytest.approx(EQ11[3], abs=1e-12)


def test_derived_fixed_point_differs_from_eq11(paper_fixed_point):
    """The energy-consistent model's gait differs from Eq. (11) by ~2e-3 rad in the angles
    and ~2e-2 rad/s in the stance rate (the A.5 sign error)."""
    d = np.abs(paper_fixed_point.x - EQ11)
    assert 1e-3 < d[0] < 5e-3
    assert d[3] > 1e-2


def test_flat_ground_has_no_passive_gait():
    from walkerlab.analysis.gait.poincare import FixedPointNotFound

    w = make_compass_gait(1.0, 5.0, 10.0, 9.81, 0.5, 0.0, "derived")
    with pytest.raises(FixedPointNotFound):
        find_fixed_point(w, EQ11, TIGHT)


# -------------------- the no-gait advice, whole
ROOT = Path(__file__).resolve().parents[1]


POWERED = ROOT / "configs" / "powered_compass.yaml"


def _cli(*args):
    r = CliRunner().invoke(app, [str(a) for a in args])
    return r.exit_code, r.stderr.strip(), r.stdout


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
    lines = err.splitlines()  # the advice; what was tried, whole, on a second line
    assert code == 1 and len(lines) in (1, 2) and lines[-1].startswith(("error:", "  ["))
    assert "give fixedpoint.initial_guess" not in err
    assert "the initial guess did not converge" in err
    assert "start from a gait known nearby (walkerlab fixedpoint --from" in err
    assert "trivial standing solution" in err
    assert "more characters" not in err and "WALKERLAB_DEBUG" not in err


# -------------------- no-gait messages whole, the verdict's zero multipliers, --require-stable
def _one_line(*args) -> str:
    """The error of a failing command: one line, or two when its reason is long (the
    search's ``[detail]`` on the second), never cut."""
    code, err, _ = _cli(*args)
    assert code == 1, (code, err)
    lines = err.splitlines()
    assert len(lines) == 1 or (len(lines) == 2 and lines[1].startswith("  ")), err
    assert "WALKERLAB_DEBUG" not in err and "more characters" not in err
    return " ".join(ln.strip() for ln in lines)


PAPER = ROOT / "configs" / "paper.yaml"


# ------------------------------------------------ 5: an uphill no-gait message, whole
def test_an_uphill_no_gait_message_ends_its_clauses(tmp_path):
    d = yaml.safe_load(PAPER.read_text())
    d["slope"] = {"angle_rad": -0.0174}
    scene = tmp_path / "uphill.yaml"
    scene.write_text(yaml.safe_dump(d))
    err = _one_line("fixedpoint", scene, "--runs-dir", tmp_path / "runs")
    assert "downhill slope" in err and "try a continuation" in err
    # what was tried is printed whole: no sentence or parenthesis left open
    assert "scale-free seeds (45 fell within the first step)" in err
    assert "[tried the initial guess and 0 of 45" in err


def test_a_long_detail_takes_a_second_line_whole():
    from walkerlab.cli.errors import one_line

    advice = "no gait; " + "advice " * 38
    detail = "[tried a and b (3 fell within the first step); last: " + "word " * 40 + "]"
    lines = one_line(advice + detail).splitlines()
    assert lines[0] == advice.rstrip() and lines[1] == "  " + detail


# ------------------------------------ 7: the zero multipliers of this walker, not all
@pytest.mark.parametrize("scene, names, says, not_said", [
    ("kneed.yaml", ["swing_thigh_angle", "swing_shank_angle", "stance_angle"],
     "swing knee is straight and locked", ("flat foot", "no mass")),
    ("flat_feet.yaml", ["swing_angle", "stance_angle", "stance_ankle_angle"],
     "flat foot lands", ("knee", "no mass")),
    ("simplest.yaml", ["stance_angle", "hip_angle"], "swing leg has no mass",
     ("knee", "flat foot")),
])
def test_the_verdict_names_only_the_zero_multipliers_that_apply(scene, names, says, not_said):
    import json

    import numpy as np

    from walkerlab.report.text import zero_multipliers_text

    sc = load_scene(ROOT / "configs" / scene)
    n0 = 1 + (1 if scene == "simplest.yaml" else 2)
    re = np.r_[np.zeros(n0), 0.5, 0.4]
    text = zero_multipliers_text(re, np.zeros_like(re), names,
                                 json.dumps(sc.model_dump(mode="json")))
    assert text.startswith(f"{n0} multipliers are 0 by construction")
    assert says in text and not any(w in text for w in not_said)
    assert "e.g." not in text


# ------------------------------------------- 12: demanding a stable gait (--require-stable)
def test_require_stable_refuses_an_unstable_gait_in_one_line_and_keeps_the_artifact(tmp_path):
    d = yaml.safe_load(PAPER.read_text())
    d["slope"] = {"angle_deg": 12.0}
    scene = tmp_path / "steep.yaml"
    scene.write_text(yaml.safe_dump(d))
    runs = tmp_path / "runs"
    code, err, out = _cli("fixedpoint", scene, "--runs-dir", runs)
    assert code == 0 and "verdict: UNSTABLE" in out  # as before: the gait found, exit 0
    code, err, out = _cli("fixedpoint", scene, "--runs-dir", runs, "--require-stable")
    assert code == 1 and "verdict: UNSTABLE" in out
    assert len(err.splitlines()) == 1, err
    assert err.startswith("error: --require-stable: the gait found is unstable (largest "
                          "|Floquet multiplier| ")
    assert "no stable period-1 gait was found" in err
    assert (runs / "steep" / "fixedpoint.h5").is_file()
    code, err, _ = _cli("fixedpoint", PAPER, "--runs-dir", runs, "--require-stable")
    assert code == 0, err


def test_require_stable_names_a_stable_gait_the_policy_passed_over():
    from types import SimpleNamespace

    import numpy as np

    from walkerlab.report.text import unstable_gait_line

    fp = SimpleNamespace(multipliers=np.array([2.4, 0.1]), step_period_s=0.61,
                         units=SimpleNamespace(time="s"), gait_policy="short_period",
                         gaits={"long_period": SimpleNamespace(stable=True),
                                "short_period": SimpleNamespace(stable=False)})
    line = unstable_gait_line(fp)
    assert "the long-period gait is stable: set fixedpoint.gait: stable" in line


# -------------------- a bounded gait search
# ------------------------------------------------------------------ 8: a bounded gait search
@pytest.mark.parametrize("search", ["find_fixed_point", "find_gaits"])
def test_gait_search_gives_up_when_its_work_budget_is_spent_and_says_why(
        paper_walker, monkeypatch, search):
    """A spring and damper at their caps (1e6) make one step map crawl, and the search
    went on for 12+ maps (459 s, silent) before "no gait found".  Here every step costs
    250,000 more right-hand-side evaluations and the budget is 1,000,000: the search stops
    after exactly 4 maps (MINPACK alone needs ~20) whatever the machine, says why from the
    counts (each map a quarter of the budget: a crawl), and a costly map is said in one
    notice."""
    from walkerlab import progress
    from walkerlab.analysis.gait import budget, poincare
    from walkerlab.analysis.gait import search as gait_search
    from walkerlab.integrate import work_limit
    from walkerlab.integrate.solver import Solver
    from walkerlab.published import paper

    monkeypatch.setattr(budget, "ROOT_BUDGET_EVALUATIONS", 1_000_000, raising=False)
    monkeypatch.setattr(budget, "SLOW_MAP_EVALUATIONS", 100_000, raising=False)
    steps, notes = [], []
    real = poincare.integrate_step

    def costly_step(*a, **k):
        steps.append(1)
        out = real(*a, **k)
        work_limit.count(250_000)  # the budget counts evaluations: spend them
        return out

    monkeypatch.setattr(poincare, "integrate_step", costly_step)
    monkeypatch.setattr(progress, "note", notes.append)
    solver, guess = Solver("DOP853", 1e-12, 1e-12), np.array(paper.EQ11_STATE)
    with pytest.raises(poincare.FixedPointNotFound, match="gave up after 4 step map") as e:
        if search == "find_fixed_point":
            poincare.find_fixed_point(paper_walker, guess, solver)
        else:
            gait_search.find_gaits(paper_walker, solver, guess)
    assert len(steps) == 4, len(steps)
    assert "1,000,000 right-hand-side evaluations" in str(e.value)
    assert "the step's rates grow" in str(e.value) and "root finder" not in str(e.value)
    assert len(notes) == 1 and "step map took 250,4" in notes[0], notes


def test_a_search_of_ordinary_maps_that_spends_its_budget_says_the_root_finder_went_on(
        paper_walker, monkeypatch):
    """A budget spent by many maps of ordinary cost is no crawl: the line says the root
    finder did not converge, and blames no spring or rate."""
    from walkerlab.analysis.gait import budget, poincare
    from walkerlab.integrate.solver import Solver

    monkeypatch.setattr(budget, "ROOT_BUDGET_EVALUATIONS", 3000, raising=False)
    with pytest.raises(poincare.FixedPointNotFound) as e:
        find_fixed_point(paper_walker, np.array(paper.EQ11_STATE) * 1.3,
                         Solver("DOP853", 1e-12, 1e-12))
    text = str(e.value)
    assert "gave up after" in text and "3,000 right-hand-side evaluations" in text
    assert "root finder did not converge" in text and "integrator crawls" not in text
    assert "spring" not in text


def test_the_search_outcome_does_not_depend_on_cpu_time(paper_walker, monkeypatch):
    """The same search on a machine where every step map is 0.05 s of CPU slower (a busy
    machine, a first run compiling): the same fixed point, bit for bit, the same number of
    maps; the budget counts right-hand-side evaluations, not seconds."""
    import time as _time

    from walkerlab.analysis.gait import budget, poincare
    from walkerlab.integrate.solver import Solver

    solver, guess = Solver("DOP853", 1e-12, 1e-12), np.array(paper.EQ11_STATE)
    monkeypatch.setattr(budget, "ROOT_BUDGET_EVALUATIONS", 40_000, raising=False)
    quick = find_fixed_point(paper_walker, guess, solver, fd_check=False)
    real = poincare.integrate_step

    def slow_step(*a, **k):
        t = _time.thread_time()
        while _time.thread_time() - t < 0.05:
            pass
        return real(*a, **k)

    monkeypatch.setattr(poincare, "integrate_step", slow_step)
    slow = find_fixed_point(paper_walker, guess, solver, fd_check=False)
    assert np.array_equal(quick.x, slow.x) and quick.period_s == slow.period_s
    assert quick.nfev == slow.nfev and quick.iterations == slow.iterations


def test_a_step_map_under_way_is_stopped_at_the_search_budget(paper_walker, monkeypatch):
    """One step map with no end (a controller or spring driving the rates to 1e9 rad/s, the
    integrator crawling) used to run past the budget, which was looked at between maps
    only: its integration counts its evaluations (``solve_on`` wraps the right-hand side)
    and the search ends inside the map, in one line saying where the map was and why it
    crawls - for a walker with no spring, not a spring."""
    from walkerlab import progress
    from walkerlab.analysis.gait import budget, poincare
    from walkerlab.integrate.solver import Solver
    from walkerlab.integrate.work_limit import counted

    monkeypatch.setattr(budget, "ROOT_BUDGET_EVALUATIONS", 1000, raising=False)
    notes = []
    monkeypatch.setattr(progress, "note", notes.append)

    def crawling_step(walker, x, *a, **k):  # the flow, wrapped as the integrator wraps it
        rhs, y = counted(lambda t, y: y), np.full(np.size(x), 1e9)
        while True:
            rhs(0.25, y)
    monkeypatch.setattr(poincare, "integrate_step", crawling_step)
    with pytest.raises(poincare.FixedPointNotFound) as e:
        find_fixed_point(paper_walker, np.array(paper.EQ11_STATE), Solver("DOP853", 1e-12,
                                                                           1e-12))
    text = str(e.value)
    assert len(text.splitlines()) == 1 and "gave up after 1 step map" in text
    assert "stopped after 1,001 evaluations at t = 0.25 s, rates 1e+09 rad/s" in text
    assert "spring" not in text and "the step's rates grow" in text
    assert "nan" not in text
    assert not notes  # the line says it all: no notice beside it


def test_the_slow_map_reason_names_what_the_walker_has():
    """The notice of a slow map names the walker's spring (a torque law with a stiffness),
    its virtual-constraint controller, or neither."""
    from walkerlab.analysis.gait.budget import slow_step_reason
    from walkerlab.models.registry import build_walker

    root = Path(__file__).resolve().parents[1] / "configs"
    sc = load_scene(root / "hip_spring.yaml")
    sprung = slow_step_reason(build_walker(Plant.from_scene(sc)))
    sc1 = load_scene(root / "threelink_hzd.yaml")
    hzd = slow_step_reason(build_walker(Plant.from_scene(sc1)))
    sc2 = load_scene(root / "paper.yaml")
    bare = slow_step_reason(build_walker(Plant.from_scene(sc2)))
    assert "spring" in sprung and "walker.springs" in sprung
    assert "virtual-constraint controller" in hzd and "spring" not in hzd
    assert "spring" not in bare and "controller" not in bare


def test_search_budgets_nest_and_end_with_their_search():
    """A fixed point inside a gait search keeps the search's earlier deadline and adds its
    maps to the search's count; after the search no map is bounded (per thread)."""
    import threading

    from walkerlab.analysis.gait import budget as B

    with B.search_budget(1000):
        outer = B.deadline()
        with B.search_budget(2000):
            assert B.deadline() == outer
            B.map_started()
        with B.search_budget(0):
            with pytest.raises(B.SearchGaveUp, match="gave up after 1 step map"):
                B.map_started()
        assert B.deadline() == outer
        seen = []
        t = threading.Thread(target=lambda: seen.append(B.deadline()))
        t.start()
        t.join()
        assert seen == [float("inf")]  # another thread's search has its own budget
    assert B.deadline() == float("inf")
