"""A hash of an artifact's result: every dataset and attribute (its scene and input hash
included) but not the records of the run that vary from one run to the next, so two runs
that computed the same result have the same key (:func:`result_key`)."""

from __future__ import annotations

import hashlib
import re
from pathlib import Path

import h5py
import numpy as np

from walkerlab.io.artifacts import READ_ERRORS

__all__ = ["RUN_RECORD", "result_key"]

#: the names (of attributes and datasets, the last path component) that record the run, not
#: its result: wall, CPU and build times, the creation time, the stored content hash
RUN_RECORD = re.compile(r"((^|_)(wall|cpu|build)_time_s|^created_utc|^content_hash)$")
#: HDF5 dimension-scale bookkeeping (object references of the open file)
_REFERENCES = frozenset({"DIMENSION_LIST", "REFERENCE_LIST"})


def result_key(artifact: Path, salt: str = "") -> str | None:
    """SHA-256 (hex) of ``salt`` and the artifact's result (module docstring), or None when
    the artifact cannot be read."""
    h = hashlib.sha256(salt.encode())

    def value(v) -> None:
        a = np.asarray(v)
        h.update(f"{a.dtype.str}{a.shape}".encode())
        h.update(repr(a.tolist()).encode() if a.dtype.kind in "OSUV"
                 else np.ascontiguousarray(a).tobytes())

    def attrs(obj) -> None:
        for k in sorted(obj.attrs):
            if not RUN_RECORD.search(k) and k not in _REFERENCES:
                h.update(f"@{k}".encode())
                value(obj.attrs[k])

    try:
        with h5py.File(artifact, "r") as f:
            attrs(f)
            names: list[str] = []
            f.visit(names.append)
            for name in sorted(names):
                if RUN_RECORD.search(name.rsplit("/", 1)[-1]):
                    continue
                obj = f[name]
                h.update(f"/{name}".encode())
                if isinstance(obj, h5py.Dataset):
                    value(obj[()])
                attrs(obj)
    except READ_ERRORS:
        return None
    return h.hexdigest()
