"""The in-progress file of an MFPT study (``mfpt.h5.partial``): finished pieces of work kept
so an interrupted ``mfpt`` run resumes where it stopped (:mod:`walkerlab.studies.mfpt`).

Layout: root attribute ``input_hash``; one group per finished piece, named by the study
(``montecarlo/sigma=0.004/chunk=3``: the heel strikes and falls of one chunk of walks;
``mesh/sigma=0.004``: the step-map images of the mesh nodes evaluated so far), holding
numeric datasets and the attribute ``digest`` (SHA-256 of the input hash, the piece's name
and every dataset's dtype and bytes).  A piece whose digest does not match (edited, damaged)
is dropped and computed again; a file of another input hash is started afresh.  Pieces are
flushed as they are stored, so a killed run loses at most the pieces under way.
"""

from __future__ import annotations

import hashlib
from pathlib import Path

import h5py
import numpy as np

__all__ = ["MfptPartial", "piece_digest"]


def piece_digest(key: str, name: str, arrays: dict[str, np.ndarray]) -> str:
    """SHA-256 of the input hash ``key``, the piece's ``name`` and its arrays (names,
    dtypes, shapes and bytes, in name order)."""
    h = hashlib.sha256(f"{key}|{name}".encode())
    for k in sorted(arrays):
        a = np.ascontiguousarray(arrays[k])
        h.update(k.encode() + a.dtype.str.encode() + str(a.shape).encode() + a.tobytes())
    return h.hexdigest()


class MfptPartial:
    """Finished pieces of an MFPT study in ``path`` (open while the study runs).

    Parameters
    ----------
    path : Path
        The partial file (``<artifact>.partial``); never written through a symbolic link.
    key : str
        Input hash of the study; a file with another hash (or unreadable) is replaced.
    resume : bool
        False: start afresh even from a matching file.

    Raises
    ------
    walkerlab.safefs.RunPathError
        ``path`` is a symbolic link (one line).
    """

    def __init__(self, path: Path | str, key: str, resume: bool = True):
        from walkerlab.safefs import refuse_link

        self.path = refuse_link(Path(path))
        self.key = key
        self.dropped = 0
        self.path.parent.mkdir(parents=True, exist_ok=True)
        f = None
        if resume and self.path.is_file():
            try:
                f = h5py.File(self.path, "a")
                if f.attrs.get("input_hash") != key:
                    f.close()
                    f = None
            except OSError:
                f = None
        if f is None:
            self.path.unlink(missing_ok=True)
            f = h5py.File(self.path, "x")
            f.attrs["input_hash"] = key
            f.flush()
        self._f = f

    def get(self, name: str) -> dict[str, np.ndarray] | None:
        """The arrays of piece ``name``, or None when it is missing or fails its digest
        (then it is removed, and counted in ``dropped``)."""
        if name not in self._f:
            return None
        g = self._f[name]
        try:
            arrays = {k: g[k][()] for k in g if isinstance(g[k], h5py.Dataset)}
            ok = g.attrs.get("digest") == piece_digest(self.key, name, arrays)
        except (OSError, KeyError, ValueError):
            ok = False
        if not ok:
            del self._f[name]
            self._f.flush()
            self.dropped += 1
            return None
        return arrays

    def put(self, name: str, arrays: dict[str, np.ndarray]) -> None:
        """Store (or replace) piece ``name`` and flush the file."""
        if name in self._f:
            del self._f[name]
        g = self._f.create_group(name)
        arrays = {k: np.asarray(v) for k, v in arrays.items()}
        for k, v in arrays.items():
            g.create_dataset(k, data=v)
        g.attrs["digest"] = piece_digest(self.key, name, arrays)
        self._f.flush()

    def close(self) -> None:
        """Close the file (it stays on disk until :meth:`remove`)."""
        if self._f is not None:
            self._f.close()
            self._f = None

    def remove(self) -> None:
        """Close and delete the file (the study's artifact is written)."""
        self.close()
        self.path.unlink(missing_ok=True)

    def __enter__(self) -> MfptPartial:
        return self

    def __exit__(self, *exc) -> None:
        self.close()
