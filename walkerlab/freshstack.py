"""Import a heavy library on a fresh Python call stack (CPython's frame data stack churn).

CPython 3.11+ keeps the frames of running Python functions on a per-thread data stack made
of 16 KiB chunks: a call that does not fit in the current chunk maps a new one, and the
chunk is unmapped again as soon as the frame at its base returns.  A loop that calls a
function whose frame lands exactly on a chunk boundary therefore maps and unmaps 16 KiB on
every call.  ``scipy.optimize``'s first import runs ``scipy.special``'s module-level loops
about 60 frames below the importer (nested imports), so whether it churns depends on how
deep the first importer sits: from ``walkerlab fixedpoint``'s root finder it did,
~8,000 ``mmap``/``munmap`` pairs per process, and the count moved
with every frame added or removed anywhere between the CLI and the solver.

:func:`import_on_fresh_stack` imports the module in a short-lived thread, whose data stack
starts empty, so the cost of the import no longer depends on the caller's depth (for the
cost of a thread start).  Python's import lock makes this an ordinary import: the module lands in
``sys.modules`` for every thread, and an error raised by the import (ImportError or any
error of the module's own code) is raised again in the caller.  The thread body calls
``__import__`` directly: the frames between the thread's start and the import are fixed
here (``scipy.optimize``: ~500 16 KiB ``munmap`` calls per process against ~1,900 from
the pre-renovation code's depth and ~10,000 from the root finder's).
"""

from __future__ import annotations

import sys
import threading
from types import ModuleType

__all__ = ["import_on_fresh_stack"]


def import_on_fresh_stack(name: str) -> ModuleType:
    """The module ``name``, imported (if not imported yet) on a fresh thread's call stack.

    Parameters
    ----------
    name : str
        Absolute module name, e.g. ``"scipy.optimize"``.

    Returns
    -------
    module
        ``sys.modules[name]``.

    Raises
    ------
    ImportError
        As ``importlib.import_module(name)`` would (raised in the calling thread).
    Exception
        Whatever the module's own code raises while it is imported.
    """
    if name not in sys.modules:
        errors: list[BaseException] = []
        worker = threading.Thread(target=_load, args=(name, errors), daemon=True)
        worker.start()
        worker.join()
        if errors:
            raise errors[0]
    return sys.modules[name]


def _load(name: str, errors: list) -> None:
    """Thread body: ``__import__`` (no Python frame of importlib's own in between)."""
    try:
        __import__(name)
    except BaseException as exc:  # noqa: BLE001 - raised again in the caller
        errors.append(exc)
