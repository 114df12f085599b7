"""Compiled right-hand sides of a walker's flow: numba ``cfunc``s for CyRK's C++ integrators.

The source comes from :func:`walkerlab.codegen.compiled_source.generate_compiled` (the same symbolic
equations as the Python module of :mod:`walkerlab.codegen.cache`) and is cached next to it as
``<key>_nb.py`` in the per-user cache (same key, same ownership/mode and sha256 checks,
atomic write); the per-row integrator's loops specialised to its flows
(:func:`walkerlab.integrate.rows_dop853.kernels`) in ``<key>_rows_<hash>_nb.py``.  Each is
imported as a real module so that numba's own disk cache (``cache=True``, in ``<user
cache>/numba``, :func:`walkerlab.usercache.use_for_numba`) keeps the machine code: a new
process pays the numba import and a cache load, not a compile.

numba and CyRK are imported only when
:meth:`walkerlab.models.compiled_flows.CompiledFlow.address` is first called (the
``cyrk_compiled`` solver backend); building a walker does not import them.
"""

from __future__ import annotations

from walkerlab import codestore
from walkerlab.codegen import cache


def compiled_module(structure):
    """The imported compiled module of ``structure`` (generated on a cache miss).

    Raises
    ------
    ImportError
        numba is not installed.
    """
    key = cache.cache_key(structure)
    return codestore.import_generated(f"{key}_nb.py", f"walkerlab_compiled_{key}",
                                      lambda: cache.module_source(structure, key, compiled=True))
