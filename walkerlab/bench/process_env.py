"""The environment of a timed whole process: the command as an installed walkerlab runs.

An installed package has its bytecode: pip compiles every module of a wheel at install time,
and an editable install writes it on the first run.  A shell that sets
``PYTHONDONTWRITEBYTECODE`` (some containers and CI images do) makes every walkerlab process
compile each module it imports from source again (measured on ``walkerlab fixedpoint``:
~0.09 s of CPU in a 0.6 s process, ~0.3 s on the main job), a cost no user of an installed
walkerlab pays and the plain-library yardsticks never pay (numpy's and scipy's bytecode was
written when they were installed).  So a benchmark runs walkerlab's processes, and their
yardsticks, with the variable removed; the first (warming) run of a command writes the
bytecode.
"""

from __future__ import annotations

import os

__all__ = ["installed_env"]


def installed_env(base: dict | None = None, **extra: str) -> dict:
    """A copy of ``base`` (default ``os.environ``) without ``PYTHONDONTWRITEBYTECODE``,
    with ``extra`` variables set (e.g. ``PYTHONPATH``, ``WALKERLAB_CACHE_DIR``)."""
    env = dict(os.environ if base is None else base)
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    env.update(extra)
    return env
