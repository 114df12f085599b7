"""Kernels another process is compiling into numba's on-disk cache, waited for before use.

A cold contact run (:func:`walkerlab.stages.contact_sim.run`, alone or in ``walkerlab
report``) has a side process compile one of its generated kernels while it compiles the
others; the run's first use of that
kernel waits for the side process (:func:`before_first_use`) and then loads the machine
code from the cache instead of compiling it a second time.  The registry is per process and
keyed by the generated module's name and the kernel's; a wait runs at most once.
"""

from __future__ import annotations

from collections.abc import Callable

__all__ = ["before_first_use", "compiled_elsewhere", "expected", "forget"]

_WAITS: dict[tuple[str, str], Callable[[], object]] = {}


def compiled_elsewhere(module_name: str, kernel: str, wait: Callable[[], object]) -> None:
    """Have ``wait()`` run once before this process first uses ``kernel`` of the generated
    module ``module_name`` (its errors propagate to that use)."""
    _WAITS[(module_name, kernel)] = wait


def expected(module_name: str, kernel: str) -> bool:
    """Whether ``kernel`` of ``module_name`` is being compiled elsewhere (a wait for it is
    registered and has not run yet)."""
    return (module_name, kernel) in _WAITS


def before_first_use(module_name: str, kernel: str) -> None:
    """Run the wait registered for ``kernel`` of ``module_name``, if any (then forget it)."""
    if _WAITS:
        wait = _WAITS.pop((module_name, kernel), None)
        if wait is not None:
            wait()


def forget(module_name: str) -> None:
    """Drop every wait registered for ``module_name`` (its compiling process is done or
    gone)."""
    for key in [k for k in _WAITS if k[0] == module_name]:
        del _WAITS[key]
