"""Compass-gait entry points of the generic derivation (kept for callers of the old module).

The equations of every walker are derived by :mod:`walkerlab.models.symbolic` from its
description; the compass gait is the biped with a hip point mass and one point mass per leg.
The printed Appendix A of the paper has a wrong sign in ``C[1, 0]`` (A.5): the derived
``C[1, 0] = -m L b sin(theta2 - theta1) dtheta1`` (Goswami et al. 1996, Eq. 3), the printed
one has ``+``; with the printed sign the total energy drifts during swing.

Run ``python -m walkerlab.models.derivation`` for a printout of the derived matrices.
"""

from __future__ import annotations

from walkerlab.models.description import BodySpec, Structure


def compass_gait_structure() -> Structure:
    """The compass gait (paper A.1-A.3) as a generic biped structure."""
    return Structure("absolute", (BodySpec("mass", "point_mass"),))


def compass_gait_symbolic():
    """Symbolic equations of the compass gait (:class:`walkerlab.models.symbolic.Equations`)."""
    from walkerlab.models.symbolic import derive

    return derive(compass_gait_structure())


def compass_gait_functions() -> dict:
    """Load (or generate and cache) the compass gait's generated module; used to warm workers."""
    from walkerlab.models.cache import generated_module

    return generated_module(compass_gait_structure())


if __name__ == "__main__":  # pragma: no cover - a readable printout of the derivation
    import sympy as sp

    d = compass_gait_symbolic()
    for name in ("M", "C", "G", "Mi", "B", "De", "E"):
        print(f"{name} =")
        sp.pprint(getattr(d, name))
