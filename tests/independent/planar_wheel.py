"""An independent reference for the planar spoked wheel's equations (sums of spoke vectors, no
body tree), which printed it before :func:`walkerlab.codegen.derive_3d.derive_spoked` derived
it from its tree; ``tests/test_planar_trees.py`` compares the two.

The original generator's description follows: the planar spoked wheel's equations (McGeer 1990)
as the :class:`~walkerlab.codegen.equations.Equations` every generated walker has: the
printers of :mod:`walkerlab.codegen.source` turn them into the Python module and the
compiled (numba) module like any biped's, so fixed points, simulation, basins and MFPT run
on the wheel unchanged.

The wheel (McGeer 1990, "Passive dynamic walking", IJRR 9(2), Sec. 2; Coleman, Chatterjee &
Ruina 1997, "Motions of a rimless spoked wheel", Dyn. Stab. Syst. 12(3)) is one rigid body:
a hub of mass ``M_hub`` and inertia ``I_hub`` about its centre, with massless spokes of
length ``L`` ``2 alpha = 2 pi / n`` apart.  Its one coordinate ``q_stance`` is the stance
spoke's angle from the downward vertical, positive when its foot is ahead of the hub (the
leg angles of every walker here; the wheel rolls downhill in +x with ``q_stance``
decreasing).  With the hub at ``L (-sin q, cos q)`` from the stance foot:

- flow: ``(M L^2 + I) qdd - M g L sin q = 0`` (an inverted pendulum about the foot);
- heel strike: the next spoke ahead, at ``q + 2 alpha``, reaches the slope:
  ``sigma = 2 q + 2 alpha + 2 gamma`` decreasing through zero (the two feet symmetric about
  the slope normal, as a biped's ``psi_sw + psi_st + 2 gamma``);
- impact: plastic, angular momentum about the new contact point conserved,
  ``(M L^2 + I) dq+ = (M L^2 cos(2 alpha) + I) dq-`` (a point mass: ``dq+ = cos(2 alpha)
  dq-``); the new stance spoke is the old one turned by a spoke, ``q -> q + 2 alpha``;
- fall: ``rolls_back``, the rate ``dq`` rising through zero (the wheel stops before
  vaulting over the stance foot and rolls back uphill);
- ``swing_clearance``: the next spoke's foot above the slope line through the stance foot
  (the step-down studies' guard: the heel strike on ground ``drop`` lower);
- Poincaré section: the state just after heel strike, ``q = alpha - gamma`` (the previous
  stance foot still on the slope behind); the map is one-dimensional, in the rate.

The "legs" of the vocabulary are the two spokes of a step: ``stance`` and ``swing`` (the
next spoke ahead, ``q + 2 alpha``), whose feet are the named points ``stance_foot`` and
``swing_foot``; the spoke behind (``q - 2 alpha``, the previous stance spoke just after a
heel strike) has its foot at ``trailing_foot``, the others (``k`` spokes ahead of the
stance spoke, ``2 <= k <= n - 2``) at ``spoke<k>_foot``; the hub is the point ``hip``.
"""

from __future__ import annotations

from functools import cache

import sympy as sp

from tests.independent.link_sums import e
from walkerlab.codegen.equations import Equations
from walkerlab.codegen.frames import planar_slope_axes
from walkerlab.walker.description import Structure


@cache
def derive(structure: Structure) -> Equations:
    """Flow, impact, guards, energies and points of a spoked wheel (module docstring).

    Parameters
    ----------
    structure : Structure
        With ``spokes`` > 0 (parameters :data:`walkerlab.walker.description.SPOKED_PARAMS`).

    Returns
    -------
    Equations
        ``n = 1``; ``De``, ``E`` are zeros (no printed-equation variant).

    Raises
    ------
    ValueError
        ``structure`` is not a spoked wheel.
    """
    if not structure.spokes:
        raise ValueError("rolling_polygon.derive: the structure is not a spoked wheel")
    q, dq = sp.symbols("q_stance dq_stance", real=True)
    par = sp.symbols(structure.param_names, real=True)
    g, L, gamma, m, inertia, alpha = par
    hub = -L * e(q)                       # from the stance foot
    ahead = q + 2 * alpha                  # the next spoke (the vocabulary's swing leg)
    swing_foot = hub + L * e(ahead)
    about_foot = m * L ** 2 + inertia      # inertia about the stance foot
    kinetic = sp.Rational(1, 2) * about_foot * dq ** 2
    potential = m * g * hub[1]
    normal, _ = planar_slope_axes(gamma)
    return Equations(
        q=(q,), dq=(dq,), params=tuple(par),
        M=sp.Matrix([[about_foot]]), C=sp.zeros(1, 1),
        G=sp.Matrix([sp.diff(potential, q)]),
        Mi=sp.Matrix([[about_foot]]),
        B=sp.Matrix([[m * L ** 2 * sp.cos(2 * alpha) + inertia]]),
        relabel_q=sp.Matrix([ahead]), relabel_rate=sp.eye(1),
        kinetic=kinetic, potential=potential,
        guards={"heel_strike": 2 * q + 2 * alpha + 2 * gamma, "rolls_back": dq,
                "hip_height": (hub.T * normal)[0],
                "swing_clearance": (swing_foot.T * normal)[0]},
        points={"hip": hub, "stance_foot": sp.zeros(2, 1), "swing_foot": swing_foot,
                "trailing_foot": hub + L * e(q - 2 * alpha),
                **{f"spoke{k}_foot": hub + L * e(q + 2 * k * alpha)
                   for k in range(2, structure.spokes - 1)}},
        leg_angles={"stance": q, "swing": ahead},
        section_drop=0, drop_solution=alpha - gamma,
        De=sp.zeros(3, 3), E=sp.zeros(2, 3), limit=False, section_tied=None,
    )
