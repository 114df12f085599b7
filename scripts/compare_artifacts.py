"""Compare two runs folders artifact by artifact: every dataset's bytes and every attribute,
apart from run-dependent records (wall and CPU times, content hashes, walkerlab's source
hash, timestamps).  For restructurings that must keep every number bit-identical.

    python scripts/compare_artifacts.py runs_before runs_after [--rtol 1e-12] [--present]

Prints one line per artifact (identical / which datasets or attributes differ, with the
largest relative difference of a floating dataset, ``max |a - b| / max |a|``; datasets
only the second has are listed apart, as additions) and exits 1 when anything that both
have differs or the first has something the second lacks.  ``--rtol``: a round-off change
(a floating dataset of the same shape within ``rtol`` relative) is reported, not failed;
``--present``: only the artifacts the second folder has (a subset of the scenes rerun).
"""

from __future__ import annotations

import argparse
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


def relative(a, b) -> float | None:
    """``max |a - b| / max |a|`` of two floating arrays of one shape (0 where ``a`` is all
    zero and ``b`` equals it; NaNs where both have them agree); None for anything else."""
    a, b = np.asarray(a), np.asarray(b)
    if a.shape != b.shape or a.dtype.kind not in "fc" or b.dtype.kind not in "fc":
        return None
    if not np.array_equal(np.isnan(a), np.isnan(b)):
        return np.inf
    ok = ~np.isnan(a)
    d, scale = np.max(np.abs(a - b)[ok], initial=0.0), np.max(np.abs(a)[ok], initial=0.0)
    return 0.0 if d == 0 else (d / scale if scale > 0 else np.inf)


def compare(a: Path, b: Path) -> tuple[list[str], dict]:
    """Differences between the artifacts ``a`` and ``b`` (empty: identical) and the relative
    size of each differing floating dataset's (:func:`relative`; ``{name: size}``)."""
    with h5py.File(a, "r") as fa, h5py.File(b, "r") as fb:
        ia, ib = _items(fa), _items(fb)
    diffs = [f"only before: {k}" for k in sorted(set(ia) - set(ib))]
    diffs += [f"only after: {k}" for k in sorted(set(ib) - set(ia))]
    differ = [k for k in sorted(set(ia) & set(ib)) if not _same(ia[k], ib[k])]
    diffs += [f"differs: {k}" for k in differ]
    return diffs, {k: relative(ia[k], ib[k]) for k in differ}


def main(argv: list[str]) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("before")
    ap.add_argument("after")
    ap.add_argument("--rtol", type=float, default=None,
                    help="report, not fail, floating datasets within this relative size")
    ap.add_argument("--present", action="store_true",
                    help="only the artifacts the second folder has")
    args = ap.parse_args(argv)
    A, B = Path(args.before), Path(args.after)
    bad = n = added = within = 0
    for a in sorted(A.rglob("*.h5")):
        b = B / a.relative_to(A)
        if not b.exists() and args.present:
            continue
        n += 1
        if not b.exists():
            print(f"{a.relative_to(A)}: missing after")
            bad += 1
            continue
        d, sizes = compare(a, b)
        new = [x for x in d if x.startswith("only after: ")]
        d = [x for x in d if not x.startswith("only after: ")]
        groups = sorted({x.removeprefix("only after: ").split("/")[0].split("@")[0]
                         for x in new})
        worst = max(sizes.items(), key=lambda kv: -1.0 if kv[1] is None else kv[1],
                    default=None)
        small = (args.rtol is not None and len(sizes) == len(d)
                 and all(v is not None and v <= args.rtol for v in sizes.values()))
        size = "" if worst is None or worst[1] is None else \
            f" (largest relative {worst[1]:.1e}: {worst[0]})"
        if not d:
            state = "identical"
        elif small:
            state = f"{len(d)} within rtol{size}"
        else:
            state = f"{len(d)} differ{size}: " + "; ".join(d[:6])
        print(f"{a.relative_to(A)}: {state}"
              + (f" (+ {len(new)} new datasets/attributes in {', '.join(groups)})"
                 if new else ""))
        bad += bool(d) and not small
        within += bool(d) and small
        added += bool(new)
    print(f"{n} artifacts, {n - bad - within} identical in everything they had before "
          f"({added} with new datasets), {within} within rtol {args.rtol}, {bad} differ")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
