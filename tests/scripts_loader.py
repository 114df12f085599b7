"""One loader for the project's files that are not modules of the package (``scripts/``,
``docs/_ext/``), which several tests run as they are shipped."""

from __future__ import annotations

import importlib.util
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def load_file(relative: str):
    """The module made by running ``ROOT / relative`` (e.g. ``"scripts/structure_counts.py"``),
    named after its file, not registered in ``sys.modules``."""
    path = ROOT / relative
    spec = importlib.util.spec_from_file_location(path.stem, path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod
