"""The evidence beside the capability table: for each cell the table supports
(:data:`walkerlab.walker.kinds.CAPABILITIES`), the reference case it was measured on, the
quantity checked against a reference the cell does not compute itself, the measured number,
the tolerance, and the commit it was measured at (``capability_evidence.json`` next to this
module, written by ``scripts/measure_capabilities.py`` through
:func:`walkerlab.api.capabilities.measure`).

A supported cell is *verified* (``✓`` with its number and the kind of check behind it,
e.g. ``✓ -0.40 % engine``: :data:`CHECK_KINDS`) when its measurement is within its
tolerance; otherwise the view still runs it, but the table marks it ``~ n`` (runs, not
verified) with the measured number or why nothing was measured, listed under the kind's
grid as the refusals are.  A check of the view that did not run on the cell's case (the
rigid view's friction cone of a walker in 3D: ``not_checked``) is not in its quantity and
never counted as passed: the ``✓`` carries a note saying so.  Nothing here runs a model.

A cell's ``commit`` is ``git rev-parse --short HEAD`` when it was measured, with ``+`` when
the package's tracked files had uncommitted changes then (the measurement is of that commit
plus those edits; ``scripts/measure_capabilities.py``).
"""

from __future__ import annotations

import json
import math
from functools import lru_cache
from pathlib import Path

__all__ = ["CHECK_KINDS", "EVIDENCE_FILE", "UNVERIFIED", "cell_evidence", "check_of",
           "commit_words", "evidence", "not_checked", "number", "stage_evidence",
           "stage_verified", "verified"]

#: the data file
EVIDENCE_FILE = Path(__file__).with_name("capability_evidence.json")
#: the mark of a cell the view runs whose measurement is missing or outside its tolerance
UNVERIFIED = "~"
#: the kinds of check behind a cell's number: the word the table prints -> what it means
CHECK_KINDS = {
    "engine": "another engine walks the exported file (MuJoCo, OpenSim)",
    "model": "another model: the compliant-contact walker against the rigid one",
    "reference": "an independent reference the cell does not compute (a profile's heights)",
    "mass": "a mass read back from the exported file (Pinocchio, the Adams reader): no walk",
    "self": "self-consistency: the same model by another algorithm (a root finder against "
            "event location, the gym's loop against simulate's, an optimum replayed)",
}


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


def stage_evidence(kind: str, stage: str) -> dict | None:
    """The measurement of a study (a pipeline stage beyond the grid's cells, e.g.
    ``robustness``) on a kind that takes it (the file's ``stages``, keyed ``kind/stage``;
    the same fields as a cell's), or None when it was never measured."""
    return evidence().get("stages", {}).get(f"{kind}/{stage}")


def stage_verified(kind: str, stage: str) -> bool:
    """Whether the study's measurement on the kind is within its tolerance
    (:func:`stage_evidence`)."""
    e = stage_evidence(kind, stage)
    return bool(e and e["ok"] and e["value"] is not None
                and abs(e["value"]) <= e["tolerance"])


def verified(kind: str, feature: str, view: str) -> bool:
    """Whether the cell's measurement is within its tolerance (what its quantity names; a
    check that did not run, :func:`not_checked`, is not part of it)."""
    e = cell_evidence(kind, feature, view)
    return bool(e and e["ok"] and e["value"] is not None
                and abs(e["value"]) <= e["tolerance"])


def check_of(e: dict) -> str:
    """The kind of check behind a measurement (a key of :data:`CHECK_KINDS`; "" when the
    evidence does not say)."""
    return e.get("check", "") if e.get("check", "") in CHECK_KINDS else ""


def not_checked(e: dict | None) -> str:
    """The view's check that did not run on the cell's case, and why ("" when none): never
    counted as passed."""
    return str((e or {}).get("not_checked", ""))


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
            f"measured at {commit_words(e['commit'])})")


def commit_words(commit: str) -> str:
    """A measurement's commit as the table says it: ``4f1505ba+`` (``+``: the package had
    uncommitted changes when it was measured) as "4f1505ba with uncommitted changes"."""
    if not commit:
        return "an uncommitted tree"
    return (f"{commit[:-1]} with uncommitted changes" if commit.endswith("+") else commit)
