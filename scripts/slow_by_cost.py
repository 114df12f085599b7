"""Write ``tests/slow_by_cost.txt``: the quick tests whose measured cost moves them to the
slow run (``pytest -m slow``), so that the quick suite (the README's test command) stays
within its CPU budget.

Input: the log of a warm quick-suite run with every duration,
``pytest -p no:cacheprovider --durations=0 > LOG``.  A test's cost is its setup + call +
teardown wall time on its worker.  A test costing more than ``--threshold`` seconds goes
to the list, except the cheapest test of each file (every file keeps a quick test).
``tests/conftest.py`` marks the listed tests ``slow``.

Usage: ``python scripts/slow_by_cost.py LOG [--threshold 0.75] [--keep tests/slow_by_cost.txt]``
(``--keep``: the ids already listed stay listed: a moved test is not timed by the quick run).
"""

from __future__ import annotations

import argparse
import collections
import re
from pathlib import Path

LINE = re.compile(r"\s*([\d.]+)s (call|setup|teardown)\s+(\S+)")


def costs(log: Path) -> dict[str, float]:
    """Test id -> setup + call + teardown seconds, from a ``--durations=0`` log."""
    per: collections.Counter = collections.Counter()
    for line in log.read_text().splitlines():
        m = LINE.match(line)
        if m:
            per[m.group(3).split("@")[0]] += float(m.group(1))
    return dict(per)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("log", type=Path)
    ap.add_argument("--threshold", type=float, default=0.75)
    ap.add_argument("--keep", type=Path, default=None)
    ap.add_argument("--out", type=Path, default=Path("tests/slow_by_cost.txt"))
    a = ap.parse_args()
    per = costs(a.log)
    by_file = collections.defaultdict(list)
    for k, v in per.items():
        by_file[k.split("::")[0]].append((v, k))
    moved = {}
    for tests in by_file.values():
        tests.sort()
        moved.update({k: v for v, k in tests[1:] if v > a.threshold})
    kept = {}
    if a.keep is not None and a.keep.exists():
        for line in a.keep.read_text().splitlines():
            if line and not line.startswith("#"):
                sec, nid = line.split(maxsplit=1)
                kept[nid] = float(sec)
    moved = {**kept, **moved}
    total, left = sum(per.values()), sum(v for k, v in per.items() if k not in moved)
    head = ["# quick tests moved to the slow run by measured cost (scripts/slow_by_cost.py,",
            f"# threshold {a.threshold:g} s, each file's cheapest kept quick): {len(moved)} tests,",
            f"# {total - left:.0f} of {total:.0f} s of the measured quick run; seconds, id"]
    body = [f"{v:.2f} {k}" for k, v in sorted(moved.items(), key=lambda kv: kv[0])]
    a.out.write_text("\n".join(head + body) + "\n")
    print(f"{len(moved)} tests listed; the quick run keeps {left:.0f} of {total:.0f} s")


if __name__ == "__main__":
    main()
