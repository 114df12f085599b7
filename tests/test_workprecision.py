"""The work-precision study as the report runs it: overlapped lanes, per-case cache, reuse."""

import os
from pathlib import Path

import numpy as np
import pytest
import yaml

from walkerlab.config import load_scene
from walkerlab.io.artifacts import open_artifact

ROOT = Path(__file__).resolve().parents[1]


def _scene(tmp_path, **wp):
    """The paper's walker, ideal model only, with a two-method, two-tolerance study."""
    d = yaml.safe_load((ROOT / "configs" / "paper.yaml").read_text())
    for k in ("contact", "terrain", "contact_sim", "contact_solver"):
        d.pop(k, None)
    d["simulate"]["strides"] = 1
    d["workprecision"] = {"methods": ["RK45", "Radau"], "rtols": [1e-3, 1e-6], "repeats": 2,
                          "strides": 1, "models": ["ideal"], **wp}
    p = tmp_path / "wp_small.yaml"
    p.write_text(yaml.safe_dump(d))
    return load_scene(p)


@pytest.mark.xdist_group("timing")  # times every solver setting (pins the CPUs it uses)
@pytest.mark.slow  # end to end: a whole report
def test_report_study_measures_every_case_once_and_reuses_it(tmp_path):
    from walkerlab.stages import report

    runs = tmp_path / "runs"
    affinity = os.sched_getaffinity(0)
    lines: list[str] = []
    quick: list[str] = []  # the default report does not time solvers (opt-in --full)
    report.run(_scene(tmp_path), tmp_path / "quick", echo=quick.append)
    assert any("workprecision: not measured (opt-in" in s for s in quick)
    assert not (tmp_path / "quick" / "wp_small" / "workprecision.h5").exists()
    html = report.run(_scene(tmp_path), runs, echo=lines.append, full=True)
    assert os.sched_getaffinity(0) == affinity  # the report's own pinning is undone
    assert any(s.strip().startswith("workprecision: computed") for s in lines)
    wp = html.parents[1] / "workprecision.h5"
    with open_artifact(wp, "workprecision") as f:
        g = f["ideal"]
        assert str(g.attrs["reference_method"]).endswith("DOP853")
        for m in ("RK45", "Radau"):
            err, rep = g[f"{m}/error"][()], g[f"{m}/repeats"][()]
            # every tolerance ran; a 1000x tighter rtol is more accurate by > 10x
            assert np.all(np.isfinite(err)) and err[1] < 0.1 * err[0]
            assert set(rep) <= {1, 2}
        methods = [m for m in g if hasattr(g[m], "keys")]  # scipy's, plus CyRK RK45
        assert f.attrs["cases_total"] == 1 + 2 * len(methods)  # + the reference
        assert f.attrs["cases_reused_from_cache"] == 0
    assert (html.parent / "figures" / "work_precision_ideal.png").is_file()
    # a rerun reuses the stage and both figure groups
    lines.clear()
    report.run(_scene(tmp_path), runs, echo=lines.append, full=True)
    assert any("workprecision: reused" in s for s in lines)
    assert sum("figures reused" in s for s in lines) == 2
    # the default report shows the measured study (inputs unchanged) without timing again
    lines.clear()
    report.run(_scene(tmp_path), runs, echo=lines.append)
    assert not any("workprecision" in s and "not measured" in s for s in lines)
    assert "Work-precision" in (html.parent / "report.md").read_text()
    # another target error: the stage reruns, every case comes from the case cache
    report.run(_scene(tmp_path, target_error=1e-6), runs, echo=lambda s: None, full=True)
    with open_artifact(wp, "workprecision") as f:
        assert f.attrs["cases_reused_from_cache"] == f.attrs["cases_total"]


def test_every_case_source_exists():
    """A measured case is kept until the sources it runs change: each folder or file the
    key hashes must exist (a folder renamed away made every study crash)."""
    from pathlib import Path

    import walkerlab
    from walkerlab.bench.workprecision_plan import CASE_SOURCES, sources_hash

    root = Path(walkerlab.__file__).parent
    for model, parts in CASE_SOURCES.items():
        missing = [p for p in parts if not (root / p).exists()]
        assert not missing, (model, missing)
        assert len(sources_hash(parts)) == 64
