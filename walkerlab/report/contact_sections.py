"""Report sections built from the optional artifacts (work-precision, contact, compare).

Each function returns Markdown, or an empty list when its artifact does not exist, so a
scene gets only the sections it produces.
"""

from __future__ import annotations

import numpy as np

from walkerlab.io.artifacts import open_artifact
from walkerlab.stages.common import artifact_path


def _table(header, rows):
    from walkerlab.stages.report import _table as t

    return t(header, rows)


def workprecision_section(scene, runs_root) -> list[str]:
    p = artifact_path(scene, runs_root, "workprecision")
    if not p.is_file():
        return []
    out = ["## Error against run time (work-precision)", ""]
    with open_artifact(p, "workprecision") as f:
        for model in f:
            g = f[model]
            rows = []
            for m in g:
                d = g[m]
                for rt, t, e, n in zip(d["rtol"][()], d["time"][()], d["error"][()],
                                       d["nfev"][()]):
                    rows.append([model, m, float(rt), float(t * 1e3), float(e), int(n)])
            out.append(f"### {model} model")
            out.append("")
            if "best_method" in g.attrs:
                out.append(f"Pareto-best setting reaching the target error "
                           f"{g.attrs['target_error']:.0e}: **{g.attrs['best_method']} rtol "
                           f"{g.attrs['best_rtol']:.0e}** ({g.attrs['best_time'] * 1e3:.1f} ms, "
                           f"error {g.attrs['best_error']:.1e}). Scene default: "
                           f"{scene.solver.method} rtol {scene.solver.rtol:.0e}.")
            pm = [str(s) for s in g.attrs.get("pareto_methods", [])]
            pr = list(g.attrs.get("pareto_rtol", []))
            out.append("")
            out.append("Pareto front (no setting is both faster and more accurate): "
                       + ", ".join(f"{m} {r:.0e}" for m, r in zip(pm, pr)) + ".")
            out.append("")
            out.append(_table(["model", "method", "rtol", "median wall [ms]",
                               "error vs reference", "RHS evals"], rows))
            out.append("")
    return out


def sections(scene, runs_root) -> list[str]:
    """All optional sections, in report order."""
    out: list[str] = []
    for fn in _SECTION_FUNCS:
        out += fn(scene, runs_root)
    return out


_SECTION_FUNCS = [workprecision_section]
