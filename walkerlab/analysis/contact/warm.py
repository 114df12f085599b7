"""Compile a contact run's kernels before the run: numba's on-disk cache, filled untimed.

A cold contact run spends most of its time compiling the walker's numba kernels (the
floating view's ``pinned_to_full`` and ``feet``, the compiled right-hand side of the
solver, the contact table its gait events read).  :func:`compile_run_kernels` makes the
same calls on a short run of the same walker, so another process (``walkerlab report``
starts it beside its rigid stages, :mod:`walkerlab.execution.side`) compiles them into the
private user cache (:mod:`walkerlab.usercache`) while the run's own process does other
work; the run then only loads them.  The kernels' argument types, not their values, decide
what numba compiles: the short run starts from the rigid walker's zero state (legs
straight down, at rest), which needs no fixed point.
"""

from __future__ import annotations

import importlib.util

import numpy as np

from walkerlab.analysis.contact.sim import scene_start, simulate_contact
from walkerlab.integrate.contact_grid import compile_rhs
from walkerlab.models.contact.scene import ContactSetup
from walkerlab.walker.layout import StateLayout

__all__ = ["WARM_UP_TIME_S", "WARM_UP_STEP_M", "compile_rhs_kernels", "compile_run_kernels"]

#: simulated time of the warm-up run [s] (a few solver steps and samples)
WARM_UP_TIME_S = 0.005
#: patch spacing of the warm-up run [m] (its zero state has no step length of its own)
WARM_UP_STEP_M = 0.25


def compile_run_kernels(setup: ContactSetup) -> bool:
    """Run the contact walker of ``setup`` for :data:`WARM_UP_TIME_S` from rest, through
    :func:`walkerlab.analysis.contact.sim.simulate_contact` with the scene's solver and run
    limits: every numba kernel a contact run of the scene compiles is then in numba's
    on-disk cache (compiled, or loaded if it was there).

    A run pinned to a time longer than the warm-up compiles only the pinned kernels; the
    run compiles the rest itself.

    Returns
    -------
    bool
        False when numba is not installed (nothing is compiled), else True.

    Raises
    ------
    ValueError, walkerlab.models.contact.scene.ContactSceneError
        As a contact run of the scene would.
    """
    if importlib.util.find_spec("numba") is None:
        return False

    x = np.zeros(len(StateLayout.rigid(setup.walker.structure.roles).names))
    walker, x0, limits, _ = scene_start(setup, x, setup.sim.n_strides,
                                        step_length_m=WARM_UP_STEP_M)
    simulate_contact(walker, x0, WARM_UP_TIME_S, setup.solver, limits)
    return True


def compile_rhs_kernels(setup: ContactSetup) -> bool:
    """Compile the compiled solvers' right-hand side of ``setup``'s walker (the generated
    module's CyRK cfunc: ``rhs_packed``, ``rhs`` and the contact law's kernels they call)
    into numba's on-disk cache, without a run: no fixed point, none of the run's other
    kernels (``pinned_to_full``, the contact table).  A cold contact run
    (:func:`walkerlab.stages.contact_sim.run`) has this done in a side process while it
    compiles those others itself; its walk then only loads it. Returns and raises as
    :func:`compile_run_kernels` (its ``ValueError`` here only for massless bodies).
    """
    if importlib.util.find_spec("numba") is None:
        return False
    from walkerlab.models.contact.generated import contact_module  # light

    compile_rhs(contact_module(setup.walker.structure, setup.law.hold_heading))
    return True

