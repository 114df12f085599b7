"""The evidence beside the capability table: for each cell the table supports
(:data:`walkerlab.walker.kinds.CAPABILITIES`), the reference case it was measured on, the
quantity checked against a reference the cell does not compute itself, the measured number,
the tolerance, and the commit it was measured at (``capability_evidence.json`` next to this
module, written by ``scripts/measure_capabilities.py`` through
:func:`walkerlab.api.capabilities.measure`).

A supported cell is *verified* (``✓`` with its number, e.g. ``✓ -0.4 %``) when its
measurement is within its tolerance; otherwise the view still runs it, but the table marks it
``~ n`` (runs, not verified) with the measured number or why nothing was measured, listed
under the kind's grid as the refusals are.  Nothing here runs a model.
"""

from __future__ import annotations

import json
import math
from functools import lru_cache
from pathlib import Path

__all__ = ["EVIDENCE_FILE", "UNVERIFIED", "cell_evidence", "evidence", "number", "verified"]

#: the data file
EVIDENCE_FILE = Path(__file__).with_name("capability_evidence.json")
#: the mark of a cell the view runs whose measurement is missing or outside its tolerance
UNVERIFIED = "~"


@lru_cache(maxsize=1)
def evidence() -> dict:
    """The evidence file's content: ``{"commit", "cells": {"kind/feature/view": {...}}}``
    (empty cells when the file is missing)."""
    if not EVIDENCE_FILE.is_file():
        return {"commit": "", "cells": {}}
    return json.loads(EVIDENCE_FILE.read_text())


def cell_evidence(kind: str, feature: str, view: str) -> dict | None:
    """The cell's measurement (``case``, ``quantity``, ``value``, ``tolerance``, ``unit``,
    ``ok``, ``detail``, ``commit``), or None when it was never measured."""
    return evidence()["cells"].get(f"{kind}/{feature}/{view}")


def verified(kind: str, feature: str, view: str) -> bool:
    """Whether the cell's measurement is within its tolerance."""
    e = cell_evidence(kind, feature, view)
    return bool(e and e["ok"] and e["value"] is not None
                and abs(e["value"]) <= e["tolerance"])


def number(e: dict) -> str:
    """A measurement's number as the table prints it: a relative number of a tolerance of
    1 % or more in per cent (``-0.40 %``), others in scientific notation with their unit
    (``1.7e-13``, ``1.9e-16 m``); ``n/a`` when none was measured."""
    v = e.get("value")
    if v is None or not math.isfinite(v):
        return "n/a"
    if e["unit"] == "relative" and e["tolerance"] >= 0.01:
        return f"{100 * v:+.2f} %"
    unit = "" if e["unit"] in ("relative", "state") else f" {e['unit']}"
    return f"{v:.1e}{unit}"


def unverified_reason(kind: str, feature: str, view: str) -> str:
    """Why a supported cell is not verified: its measurement against its tolerance on its
    case, or that it was never measured."""
    e = cell_evidence(kind, feature, view)
    if e is None:
        return "runs; not measured yet (no reference case measured)"
    tol = number({"value": e["tolerance"], "unit": e["unit"], "tolerance": e["tolerance"]})
    return (f"runs, not verified: {e['case']}: {e['detail']} (tolerance {tol.lstrip('+')}; "
            f"measured at {e['commit'] or 'an uncommitted tree'})")
