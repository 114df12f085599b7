"""A kernel another process is compiling into numba's on-disk cache, waited for before use.

A cold contact run (:func:`walkerlab.stages.contact_sim.run`, alone or in ``walkerlab
report``) has a side process compile its compiled right-hand side while it compiles the
other kernels; the run's first use of that kernel waits for the side process and then loads
the machine code from the cache instead of compiling it a second time.

The hand-off is an explicit argument: the caller that started the side process makes a
:class:`CompiledElsewhere` and passes it down with the walker
(``ContactSetup.rhs_ready`` -> ``ContactWalker.rhs_ready`` -> the compiled backend), which
calls :meth:`CompiledElsewhere.before_first_use`.  No module-level registry: a wait lives as
long as the objects that carry it.
"""

from __future__ import annotations

from collections.abc import Callable

__all__ = ["CompiledElsewhere"]


class CompiledElsewhere:
    """A wait for ``kernel`` of the generated module ``module_name``, compiled by another
    process; :meth:`before_first_use` runs ``wait()`` once (its errors propagate to that
    use).

    Parameters
    ----------
    module_name : str
        The generated module's name (``ContactWalker.kernels.__name__``).
    kernel : str
        The kernel's name in it (``"build_cyrk"``).
    wait : callable
        ``wait()``: returns when the other process is done (or gone).
    """

    def __init__(self, module_name: str, kernel: str, wait: Callable[[], object]):
        self.module_name, self.kernel = module_name, kernel
        self._wait: Callable[[], object] | None = wait

    @property
    def expected(self) -> bool:
        """The wait has not run yet."""
        return self._wait is not None

    def before_first_use(self, module_name: str, kernel: str) -> None:
        """Run the wait if it is for ``kernel`` of ``module_name`` and has not run yet (then
        forget it)."""
        if self._wait is not None and (module_name, kernel) == (self.module_name,
                                                                 self.kernel):
            wait, self._wait = self._wait, None
            wait()
