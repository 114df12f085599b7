"""Whether a figure on disk was drawn from an artifact as it is now, without matplotlib.

A command that draws its figure after its stage (``walkerlab optimize``) redraws it on every
run, also when the stage was skipped (its artifact fresh) or recomputed to the same result
(``--force``): about half of such a run, with matplotlib's import.  The PNG carries a key
(a PNG text chunk, :data:`KEY_CHUNK`) of what it was drawn from: the artifact's result
(:func:`walkerlab.io.result_key.result_key`: every dataset and attribute, its scene and
input hash included, not the run's timings), walkerlab's code hash (the drawing code) and
matplotlib's version.  A figure whose key is the current one is the figure drawing would
make: it is kept.  ``walkerlab plot`` and ``walkerlab report`` always draw.
"""

from __future__ import annotations

import struct
from pathlib import Path

__all__ = ["KEY_CHUNK", "drawn_from", "figure_key"]

#: the PNG text chunk's keyword holding the key
KEY_CHUNK = "walkerlab figure key"
_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def figure_key(artifact: Path, figure: str) -> str | None:
    """The key of the figure ``figure`` drawn from ``artifact`` (module docstring:
    :func:`walkerlab.io.result_key.result_key` salted with the figure's name, walkerlab's
    code hash and matplotlib's version), or None when the artifact cannot be read or
    matplotlib's version is unknown (the figure is then drawn)."""
    from importlib.metadata import PackageNotFoundError, version

    from walkerlab.io.artifacts import code_hash  # light
    from walkerlab.io.result_key import result_key  # light

    try:
        mpl = version("matplotlib")
    except PackageNotFoundError:
        return None
    return result_key(artifact, "\n".join((figure, code_hash(), mpl)))


def drawn_from(png: Path, key: str | None) -> bool:
    """Whether the PNG file ``png`` exists and carries the key ``key`` (False for a None
    key, a missing, unreadable or malformed file)."""
    if key is None:
        return False
    try:
        with open(png, "rb") as fh:
            if fh.read(8) != _SIGNATURE:
                return False
            while True:
                head = fh.read(8)
                if len(head) < 8:
                    return False
                length, kind = struct.unpack(">I4s", head)
                if kind in (b"IDAT", b"IEND"):  # text chunks come before the image data
                    return False
                if kind != b"tEXt":
                    fh.seek(length + 4, 1)  # the data and its CRC
                    continue
                word, _, text = fh.read(length).partition(b"\0")
                fh.seek(4, 1)
                if word.decode("latin-1") == KEY_CHUNK:
                    return text.decode("latin-1") == key
    except OSError:
        return False
