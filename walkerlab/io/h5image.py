"""An HDF5 file edited in memory and saved as one image (the in-progress ``.partial`` files
of resumable studies).

HDF5 writing straight into a file on a full disk (or past ``ulimit -f``) fails half-way
through its metadata: the file is damaged, and the library's objects that are still open
report the failed flush again as each is freed, as tracebacks, and can crash the
interpreter at exit.  Here HDF5 only ever writes to memory; :meth:`H5Image.save` writes
the file's image with plain file I/O to a temporary file renamed over ``path``
(:func:`walkerlab.safefs.atomic_replace`), so a full disk is one ``OSError``, the last
saved file stays intact and nothing half-written is left behind.
"""

from __future__ import annotations

import io
import os
from pathlib import Path

import h5py

from walkerlab.io.artifacts import disk_full_error, is_disk_full

__all__ = ["H5Image"]


class H5Image:
    """An HDF5 file in memory (``.f``, an open :class:`h5py.File`), saved to ``path``.

    Parameters
    ----------
    path : Path
        Where :meth:`save` writes (never through a symbolic link: refused by the caller).
    image : bytes, optional
        The file's bytes to start from (None: a new, empty file).
    kept : str
        What a "disk full" error says is left (the last saved file, intact).

    Raises
    ------
    OSError
        ``image`` is not an HDF5 file.
    """

    def __init__(self, path: Path | str, image: bytes | None = None,
                 kept: str = "the work saved before is kept for the rerun"):
        self.path = Path(path)
        self.kept = kept
        self._buf = io.BytesIO(image or b"")
        self.f = h5py.File(self._buf, "a" if image else "w")

    @classmethod
    def load(cls, path: Path | str, **kw) -> H5Image:
        """The file at ``path``, read into memory (``kw``: as for the class).  Raises
        OSError: missing, unreadable or not an HDF5 file."""
        with open(path, "rb") as fh:
            return cls(path, fh.read(), **kw)

    def save(self) -> None:
        """Write the file's current image to ``path`` (temporary file, then rename).

        Raises
        ------
        walkerlab.io.artifacts.ArtifactError
            The disk is full ("disk full", one line): the last saved file is kept, the
            temporary file removed; the file stays open in memory.
        OSError
            Another write error (nothing is left behind).
        """
        from walkerlab.safefs import atomic_replace

        self.f.flush()
        image = self._buf.getbuffer()

        def fill(fd, _tmp):
            with os.fdopen(fd, "wb") as fh:
                fh.write(image)

        try:
            atomic_replace(self.path, fill)
        except OSError as exc:
            if is_disk_full(exc):
                raise disk_full_error(self.path, exc, self.kept) from None
            raise
        finally:
            image.release()

    def close(self) -> None:
        """Close the in-memory file (unsaved changes are lost)."""
        if self.f.id.valid:
            self.f.close()
