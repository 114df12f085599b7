"""The in-progress file of a basin map (``basin.h5.partial``): the grid's cell arrays, the
input hash they belong to and one SHA-256 per finished grid row, rewritten after every chunk
so an interrupted ``basin`` run resumes (:func:`walkerlab.studies.basin.compute_basin`).

Layout: root attribute ``input_hash``; datasets ``outcome``, ``steps``, ``period``
(shape (ny, nx)) and ``row_hash`` (ny strings, ``""``: row not finished or not checked).
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

import h5py
import numpy as np

from walkerlab.io.artifacts import READ_ERRORS
from walkerlab.io.h5image import H5Image

__all__ = ["read_basin_partial", "basin_partial_writer"]

#: the cell arrays of a basin map, in the order they are stored
CELL_ARRAYS = ("outcome", "steps", "period")


def read_basin_partial(part: Path, key: str, shape: tuple[int, int]
                       ) -> tuple[dict[str, np.ndarray] | None, list[str] | None]:
    """Cell arrays and stored row hashes of a partial basin file.

    Parameters
    ----------
    part : Path
        The partial file.
    key : str
        Input hash the file must carry.
    shape : (ny, nx)
        Grid shape the file must have.

    Returns
    -------
    arrays : dict or None
        ``outcome``, ``steps``, ``period`` (ndarray (ny, nx)); None when the file is missing,
        unreadable, of another input hash or of another grid.
    row_hash : list of str or None
        Stored hash of each grid row (``""`` for every row in a file without them).
    """
    if not part.is_file():
        return None, None
    try:
        with h5py.File(part, "r") as f:
            if f.attrs.get("input_hash") != key or f["outcome"].shape != tuple(shape):
                return None, None
            arrays = {k: f[k][()] for k in CELL_ARRAYS}
            stored = [x.decode() if isinstance(x, bytes) else str(x)
                      for x in f["row_hash"][()]] if "row_hash" in f else [""] * shape[0]
    except READ_ERRORS:  # absent, truncated or damaged inside: computed again
        return None, None
    return arrays, stored


@contextmanager
def basin_partial_writer(part: Path, key: str, arrays: dict[str, np.ndarray],
                         row_hash: np.ndarray
                         ) -> Iterator[Callable[[dict[str, np.ndarray], np.ndarray], None]]:
    """Create the partial file (it must not exist) with ``arrays`` and ``row_hash``; yield
    ``write(arrays, row_hash)``, which stores their current values and saves the file.

    The file is edited in memory and saved as one image (:class:`walkerlab.io.h5image.H5Image`):
    a full disk is one line and the file saved before stays intact.

    Raises
    ------
    FileExistsError
        ``part`` exists.
    walkerlab.io.artifacts.ArtifactError
        The disk is full ("disk full", one line).
    """
    if part.exists() or part.is_symlink():
        raise FileExistsError(part)
    img = H5Image(part)
    try:
        f = img.f
        f.attrs["input_hash"] = key
        dsets = {k: f.create_dataset(k, data=v) for k, v in arrays.items()}
        hashes = f.create_dataset("row_hash", data=row_hash, dtype=h5py.string_dtype())
        img.save()

        def write(arrays: dict[str, np.ndarray], row_hash: np.ndarray) -> None:
            for k, d in dsets.items():
                d[...] = arrays[k]
            hashes[...] = row_hash
            img.save()

        yield write
    finally:
        img.close()
