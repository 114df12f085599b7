"""Compare two runs folders artifact by artifact: every dataset's bytes and every attribute,
apart from run-dependent records (wall and CPU times, content hashes, walkerlab's source
hash, timestamps).  For restructurings that must keep every number bit-identical.

    python scripts/compare_artifacts.py runs_before runs_after

Prints one line per artifact (identical / which datasets or attributes differ; datasets
only the second has are listed apart, as additions) and exits 1 when anything that both
have differs or the first has something the second lacks.
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

import h5py
import numpy as np

#: names of datasets and attributes that record the run, not its result
RUN_RECORDS = re.compile(r"(wall|cpu|elapsed|time_s$|timing|hash|created|generated|version"
                         r"|seconds|_s_per_|duration|host|machine|load)", re.I)


#: netCDF dimension-scale bookkeeping: object references that depend on the open file
REFERENCES = frozenset({"DIMENSION_LIST", "REFERENCE_LIST"})


def _items(f: h5py.File) -> dict:
    out = {}

    def visit(name, obj):
        for k, v in obj.attrs.items():
            if not RUN_RECORDS.search(k) and k not in REFERENCES:
                out[f"{name}@{k}"] = v
        if isinstance(obj, h5py.Dataset) and not RUN_RECORDS.search(name.rsplit("/", 1)[-1]) \
                and "/timing/" not in f"/{name}":  # a group of timings (zero_dynamics/timing)
            out[name] = obj[()]

    for k, v in f.attrs.items():
        if not RUN_RECORDS.search(k):
            out[f"/@{k}"] = v
    f.visititems(visit)
    return out


def _same(a, b) -> bool:
    if isinstance(a, np.ndarray | np.generic) or isinstance(b, np.ndarray | np.generic):
        a, b = np.asarray(a), np.asarray(b)
        if a.shape != b.shape or a.dtype != b.dtype:
            return False
        if a.dtype.kind in "fc":
            return a.tobytes() == b.tobytes()
        return bool(np.all(a == b))
    return a == b


def compare(a: Path, b: Path) -> list[str]:
    """Differences between the artifacts ``a`` and ``b`` (empty: identical)."""
    with h5py.File(a, "r") as fa, h5py.File(b, "r") as fb:
        ia, ib = _items(fa), _items(fb)
    diffs = [f"only before: {k}" for k in sorted(set(ia) - set(ib))]
    diffs += [f"only after: {k}" for k in sorted(set(ib) - set(ia))]
    diffs += [f"differs: {k}" for k in sorted(set(ia) & set(ib)) if not _same(ia[k], ib[k])]
    return diffs


def main(before: str, after: str) -> int:
    A, B = Path(before), Path(after)
    bad = n = added = 0
    for a in sorted(A.rglob("*.h5")):
        b = B / a.relative_to(A)
        n += 1
        if not b.exists():
            print(f"{a.relative_to(A)}: missing after")
            bad += 1
            continue
        d = compare(a, b)
        new = [x for x in d if x.startswith("only after: ")]
        d = [x for x in d if not x.startswith("only after: ")]
        groups = sorted({x.removeprefix("only after: ").split("/")[0].split("@")[0]
                         for x in new})
        print(f"{a.relative_to(A)}: " + ("identical" if not d else f"{len(d)} differ: "
                                           + "; ".join(d[:6]))
              + (f" (+ {len(new)} new datasets/attributes in {', '.join(groups)})"
                 if new else ""))
        bad += bool(d)
        added += bool(new)
    print(f"{n} artifacts, {n - bad} identical in everything they had before ({added} with "
          f"new datasets), {bad} differ")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(*sys.argv[1:3]))
