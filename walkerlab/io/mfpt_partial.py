"""The in-progress file of an MFPT study (``mfpt.h5.partial``): finished pieces of work kept so an
interrupted ``mfpt`` run resumes where it stopped (:mod:`walkerlab.studies.mfpt`).

Layout: root attribute ``input_hash``; one group per finished piece, named by the study
(``montecarlo/sigma=0.004/chunk=3``: the heel strikes and falls of one chunk of walks;
``mesh/sigma=0.004``: the step-map images of the mesh nodes evaluated so far), holding numeric
datasets and the attribute ``digest`` (SHA-256 of the input hash, the piece's name and every
dataset's dtype and bytes). When the file is opened every piece is read and checked; the file
is then written afresh with the intact pieces only, so a piece whose digest does not match
(edited), or that cannot be read at all (a damaged group, link or heap), is dropped and
computed again, and no damaged structure is ever written into. A file of another input hash, or
one that is not an HDF5 file at all, is started afresh. The file is edited in memory and saved
as one image after every piece (:class:`walkerlab.io.h5image.H5Image`), so a killed run loses
at most the pieces under way, and a full disk is one line ("disk full") with the last saved
file intact.
"""

from __future__ import annotations

import hashlib
from pathlib import Path

import h5py
import numpy as np

from walkerlab.io.h5image import H5Image
from walkerlab.safefs import refuse_link

__all__ = ["MfptPartial", "piece_digest"]


def piece_digest(key: str, name: str, arrays: dict[str, np.ndarray]) -> str:
    """SHA-256 of the input hash ``key``, the piece's ``name`` and its arrays (names,
    dtypes, shapes and bytes, in name order)."""
    h = hashlib.sha256(f"{key}|{name}".encode())
    for k in sorted(arrays):
        a = np.ascontiguousarray(arrays[k])
        h.update(k.encode() + a.dtype.str.encode() + str(a.shape).encode() + a.tobytes())
    return h.hexdigest()


MEND_ERRORS = (OSError, KeyError, ValueError, RuntimeError, TypeError)


def _intact_pieces(f: h5py.File, key: str) -> tuple[dict[str, dict[str, np.ndarray]], int]:
    """``(pieces, dropped)``: the arrays of every piece of ``f`` whose digest matches, and
    how many pieces (or unreadable groups) did not."""
    pieces: dict[str, dict[str, np.ndarray]] = {}
    dropped = 0

    def walk(g: h5py.Group, prefix: str) -> None:
        nonlocal dropped
        try:
            names = list(g.keys())
        except MEND_ERRORS:
            dropped += 1
            return
        for n in names:
            name = f"{prefix}{n}"
            try:
                obj = g[n]
                if not isinstance(obj, h5py.Group):
                    continue
                digest = obj.attrs.get("digest")
                if digest is None:
                    walk(obj, name + "/")
                    continue
                arrays = {k: obj[k][()] for k in obj if isinstance(obj[k], h5py.Dataset)}
            except MEND_ERRORS:
                dropped += 1
                continue
            if digest == piece_digest(key, name, arrays):
                pieces[name] = arrays
            else:
                dropped += 1

    walk(f, "")
    return pieces, dropped


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

    Attributes
    ----------
    dropped : int
        Pieces of the file that failed their digest or could not be read.

    Raises
    ------
    walkerlab.safefs.RunPathError
        ``path`` is a symbolic link (one line).
    walkerlab.io.artifacts.ArtifactError
        The disk is full ("disk full", one line).
    """

    def __init__(self, path: Path | str, key: str, resume: bool = True):
        self.path = refuse_link(Path(path))
        self.key = key
        self.dropped = 0
        self._pieces: dict[str, dict[str, np.ndarray]] = {}
        self.path.parent.mkdir(parents=True, exist_ok=True)
        if resume and self.path.is_file():
            self._pieces, self.dropped = self._read()
        self._img = H5Image(self.path)
        self._img.f.attrs["input_hash"] = key
        try:
            for name, arrays in self._pieces.items():
                self._write(name, arrays)
            self._img.save()
        except BaseException:
            self._img.close()
            raise

    def _read(self) -> tuple[dict, int]:
        try:
            img = H5Image.load(self.path)
        except (OSError, RuntimeError):  # not an HDF5 file, truncated, ...
            return {}, 0
        try:
            if img.f.attrs.get("input_hash") != self.key:
                return {}, 0
            return _intact_pieces(img.f, self.key)
        except MEND_ERRORS:  # the root itself is damaged
            return {}, 0
        finally:
            try:
                img.close()
            except MEND_ERRORS:
                pass

    def get(self, name: str) -> dict[str, np.ndarray] | None:
        """The arrays of piece ``name``, or None when the file had no intact piece of
        that name (a damaged one is counted in ``dropped`` when the file is opened)."""
        return self._pieces.get(name)

    def _write(self, name: str, arrays: dict[str, np.ndarray]) -> None:
        f = self._img.f
        if name in f:
            del f[name]
        g = f.create_group(name)
        for k, v in arrays.items():
            g.create_dataset(k, data=v)
        g.attrs["digest"] = piece_digest(self.key, name, arrays)

    def put(self, name: str, arrays: dict[str, np.ndarray]) -> None:
        """Store (or replace) piece ``name`` and save the file.

        Raises
        ------
        walkerlab.io.artifacts.ArtifactError
            The disk is full ("disk full", one line; the file saved before is kept).
        """
        arrays = {k: np.asarray(v) for k, v in arrays.items()}
        self._pieces[name] = arrays
        self._write(name, arrays)
        self._img.save()

    def close(self) -> None:
        """Close the file (it stays on disk until :meth:`remove`)."""
        self._img.close()

    def remove(self) -> None:
        """Close and delete the file (the study's artifact is written)."""
        self.close()
        self.path.unlink(missing_ok=True)

    def __enter__(self) -> MfptPartial:
        return self

    def __exit__(self, *exc) -> None:
        self.close()
