"""Sympy's random choices seeded while a walker is derived, so that a derivation takes the
same time in every process (:func:`seeded`; read by :mod:`walkerlab.codegen.derive_3d` and
:mod:`walkerlab.codegen.tree_derive`).
"""

from __future__ import annotations

from functools import wraps

__all__ = ["SYMPY_SEED", "seeded"]

#: the seed of sympy's random choices while a walker is derived (:func:`seeded`)
SYMPY_SEED = 0


def seeded(derive):
    """``derive`` with sympy's random number generator (``sympy.core.random.rng``) seeded
    with :data:`SYMPY_SEED` while it runs, its state restored after.

    ``trigsimp`` (the 3D walkers' mass and impact matrices', until they were simplified
    product-to-sum; still the exports' axes, :mod:`walkerlab.export.tree_bodies`, and a
    caller's own ``simplify``) calls ``factor``, whose
    multivariate factorisation (Wang's, ``dmp_zz_wang``) draws its evaluation points at
    random.  The factors are the same whatever it draws (measured: the same generated text
    from eight generator states), but its time is not: in a test process whose generator had
    been drawn from before, the Hensel lifting of the round-feet walker's impact matrix ran
    for over 30 minutes, where a fresh process derives the walker in 45 s.  Seeded, a
    derivation takes the same time in every process and on every machine."""
    import sympy.core.random as srand

    @wraps(derive)
    def run(*args, **kwargs):
        state = srand.rng.getstate()
        srand.rng.seed(SYMPY_SEED)
        try:
            return derive(*args, **kwargs)
        finally:
            srand.rng.setstate(state)
    return run
