"""Where many-point work runs: one executor protocol (in this process, a local process pool,
Dask) and the worker processes behind it.

- :mod:`walkerlab.execution.executor`  :class:`Executor` (inline, pool, Dask),
  :func:`make_executor`, :func:`run_chains` / :func:`run_each` (used by sweeps, basin maps,
  bifurcation diagrams, stability maps)
- :mod:`walkerlab.execution.dask`      Dask client helpers (connect, never wait for ever)
- :mod:`walkerlab.execution.lanes`     pinned single-process lanes of the work-precision
  study (one worker per core, gates)
- :mod:`walkerlab.execution.background` a timed study in a thread beside untimed work
  (``walkerlab report``)
- :mod:`walkerlab.execution.workers`   worker processes that end with their parent
  (forkserver/spawn, parent watch)
- :mod:`walkerlab.execution.pending`   a kernel another process is compiling, waited for
  before its first use

Importing this package loads nothing heavy.
"""
