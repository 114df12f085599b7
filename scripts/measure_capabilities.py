"""Measure the capability table's supported cells on their reference cases and write the
evidence beside the table (``walkerlab/walker/capability_evidence.json``):

    python scripts/measure_capabilities.py                 # every supported cell
    python scripts/measure_capabilities.py --view contact  # one view's cells (merged in)
    python scripts/measure_capabilities.py --cell straight_legs/walk/mjcf --jobs 2

Each cell runs in a process of its own (:func:`walkerlab.api.capabilities.measure`, its
artifacts in a temporary runs folder); the file is rewritten under a temporary name, then
renamed, with each measured cell's commit (``git rev-parse --short HEAD``, ``+`` when the
package's tracked files had uncommitted changes: the cell was measured on that commit plus
those edits; the table says "with uncommitted changes").  Each cell also records the kind of
check behind its number (``check``) and a check of its view that did not run on its case
(``not_checked``: never counted as passed).  The slow test
``tests/test_capability_evidence.py`` re-measures every cell against what this wrote.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _commit() -> str:
    def git(*a):
        return subprocess.run(["git", *a], cwd=ROOT, capture_output=True, text=True).stdout

    head = git("rev-parse", "--short", "HEAD").strip()
    # the evidence file itself is what a run in parts (--view) rewrites: not a code change
    dirty = bool(git("status", "--porcelain", "--untracked-files=no", "walkerlab", ":(exclude)"
                     "walkerlab/walker/capability_evidence.json").strip())
    return head + ("+" if dirty else "")


#: the order a feature's views are measured in (the rigid gait first: the others reuse it)
ORDER = ("rigid", "gym", "contact", "mjcf", "urdf", "adams", "osim", "optimize")
#: a rigid cell's failure that every view started from the rigid gait shares
NO_GAIT = ("no period-1 gait", "no rigid gait", "gave up after")


#: default wall seconds a cell may take (``--limit-s``): a guard for the machine only.  A cell
#: it stops is reported and NOT written: the evidence is what the views computed, bounded by
#: their own work (the contact run's right-hand-side evaluations, the engines' steps, the
#: rigid model's strides), never by how fast this machine was; the cell keeps its last entry
CELL_LIMIT_S = 300
#: ... an OpenSim cell's at least: its Manager integrates the Hunt-Crossley contact in windows of
#: 0.5 ms (a 3D walker's hip-roll law and torques are set between them, each a restart of the
#: integrator), about 25 s of CPU per simulated second for a 3D kneed walker with CPodes
#: (walkerlab.export.opensim_walk; 100-140 s with Runge-Kutta-Merson, which left the 3D
#: kneed walkers' powered cells unmeasured past 3600 s); on a shared machine (load 5-7 on 2
#: cores) configs/kneed_3d_stabilised_footholds.yaml's cell took 4 min, its gait search,
#: export and 11-strike walk (6.2 s), kneed_torso_powered_3d.yaml's 12 min (8.1 s)
CELL_LIMIT_OSIM_S = 900


class _Timeout(BaseException):  # past measure()'s own `except Exception`
    pass


def _timed(measure, kind, feature, view, tmp, limit_s: int) -> dict | None:
    """``measure(...)``'s mapping, or None when ``limit_s`` of wall time ran out first
    (nothing is recorded for the cell: :data:`CELL_LIMIT_S`)."""
    import signal

    def stop(*_):
        raise _Timeout

    old = signal.signal(signal.SIGALRM, stop)
    signal.alarm(max(limit_s, CELL_LIMIT_OSIM_S) if view == "osim" else limit_s)
    try:
        return measure(kind, feature, view, tmp).as_dict()
    except _Timeout:
        return None
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)


def _unmeasured(cell: str, limit_s: int, commit: str) -> dict:
    """The record of a supported cell never measured: its case, quantity and tolerance, no
    value and no verdict (its run did not end within the wall-clock guard)."""
    from walkerlab.api.capabilities import CHECKS, QUANTITIES
    from walkerlab.walker.reference_cases import reference_scene

    kind, feature, view = cell.split("/")
    q, tol, unit = QUANTITIES[view]
    return {"case": reference_scene(kind, feature, view)[0], "quantity": q, "value": None,
            "tolerance": tol, "unit": unit, "ok": False, "check": CHECKS[view],
            "not_checked": "", "commit": commit,
            "detail": (f"not measured: its run did not end within the measuring machine's "
                       f"wall-clock guard ({limit_s} s); no verdict "
                       "(scripts/measure_capabilities.py --limit-s on a quieter machine)")}


def _group(cells: list[str], limit_s: int = CELL_LIMIT_S) -> list[dict]:
    """One feature's cells (``kind/feature/view``), in :data:`ORDER`, in one runs folder;
    when the rigid gait is not found, the views that start from it say so without
    searching again (optimize transcribes its own)."""
    from walkerlab.api.capabilities import measure

    out, no_gait = [], None
    with tempfile.TemporaryDirectory(prefix="walkerlab-cap-") as tmp:
        for cell in sorted(cells, key=lambda c: ORDER.index(c.split("/")[2])):
            kind, feature, view = cell.split("/")
            t0 = time.process_time()
            if no_gait is not None and view not in ("adams", "optimize"):
                d = dict(no_gait, view=view, detail="the rigid gait: " + no_gait["detail"])
                from walkerlab.api.capabilities import QUANTITIES

                d["quantity"], d["tolerance"], d["unit"] = QUANTITIES[view]
            else:
                d = _timed(measure, kind, feature, view, tmp, limit_s)
                if d is None:   # the machine's speed, not the cell's answer: not recorded
                    out.append({"cell": cell, "unmeasured": limit_s})
                    continue
            if view == "rigid" and not d["ok"] and any(s in d["detail"] for s in NO_GAIT):
                no_gait = d
            d["cpu_s"] = round(time.process_time() - t0, 2)
            d["cell"] = cell
            out.append(d)
    return out


def main(argv=None) -> int:
    from walkerlab.api.capabilities import QUANTITIES
    from walkerlab.walker.capability_evidence import EVIDENCE_FILE
    from walkerlab.walker.kinds import table_rows

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--view", action="append", default=[])
    ap.add_argument("--kind", action="append", default=[])
    ap.add_argument("--cell", action="append", default=[], help="kind/feature/view")
    ap.add_argument("--jobs", type=int, default=1)
    ap.add_argument("--limit-s", type=int, default=CELL_LIMIT_S,
                    help="wall seconds a cell may take before it is left unmeasured "
                         "(reported, not written)")
    ap.add_argument("--out", type=Path, default=None,
                    help="write here instead of the package's evidence file (merge later "
                         "with --merge)")
    ap.add_argument("--merge", type=Path, action="append", default=[],
                    help="merge the cells of these files into the evidence file and stop")
    a = ap.parse_args(argv)
    out = a.out or EVIDENCE_FILE
    cells = [f"{r['kind']}/{r['feature']}/{r['view']}" for r in table_rows()
             if r["supported"] and (not a.view or r["view"] in a.view)
             and (not a.kind or r["kind"] in a.kind)]
    if a.cell:
        cells = [c for c in cells if c in a.cell]
    data = json.loads(out.read_text()) if out.is_file() else {"cells": {}}
    data["tolerances"] = {v: f"{t:g} {u}" for v, (_, t, u) in QUANTITIES.items()}
    if a.merge:
        for m in a.merge:
            data["cells"].update(json.loads(m.read_text())["cells"])
        _write(out, data)
        return 0
    commit = _commit()
    done = 0
    groups: dict[str, list[str]] = {}
    for c in cells:
        groups.setdefault(c.rsplit("/", 1)[0], []).append(c)
    with ProcessPoolExecutor(a.jobs) as pool:
        futs = {pool.submit(_group, g, a.limit_s): g for g in groups.values()}
        for fut in as_completed(futs):
            try:
                results = fut.result()
            except Exception as exc:  # noqa: BLE001 - a crashed worker: record it
                results = [{"cell": c, "value": None, "ok": False, "case": "",
                            "detail": f"crashed: {exc}"[:300], "quantity": "",
                            "tolerance": 0.0, "unit": ""} for c in futs[fut]]
            for d in results:
                c = d.pop("cell")
                if "unmeasured" in d:
                    done += 1
                    print(f"[{done}/{len(cells)}] {c}: not measured within {d['unmeasured']} s "
                          "of wall time (this machine's speed): no verdict written, its last "
                          "entry kept (--limit-s)", flush=True)
                    if c not in data["cells"]:   # a supported cell keeps a record: unmeasured
                        data["cells"][c] = _unmeasured(c, d["unmeasured"], commit)
                    continue
                d["commit"] = commit
                for k in ("kind", "feature", "view"):
                    d.pop(k, None)
                data["cells"][c] = d
                done += 1
                print(f"[{done}/{len(cells)}] {c}: {'ok' if d['ok'] else 'NOT'} "
                      f"{d.get('value')} ({d.get('cpu_s', '?')} s) {d['detail'][:140]}",
                      flush=True)
            _write(out, data)
    return 0


def _write(path: Path, data: dict) -> None:
    """``data`` to ``path``: the cells the table supports, sorted; a temporary name, then
    renamed."""
    from walkerlab.walker.kinds import table_rows

    keep = {f"{r['kind']}/{r['feature']}/{r['view']}" for r in table_rows() if r["supported"]}
    data["cells"] = {k: v for k, v in sorted(data["cells"].items()) if k in keep}
    tmp = path.with_suffix(".json.tmp")
    tmp.write_text(json.dumps(data, indent=1, ensure_ascii=False) + "\n")
    os.replace(tmp, path)


if __name__ == "__main__":
    sys.exit(main())
