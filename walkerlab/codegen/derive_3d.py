"""Symbolic equations of walkers in three dimensions, as the
:class:`~walkerlab.codegen.equations.Equations` every generated walker has: the printers of
:mod:`walkerlab.codegen.source` turn them into the Python module and the compiled (numba)
module like a planar walker's, so fixed points, Floquet multipliers and simulation run on
them unchanged.

Frames and coordinates
----------------------
World axes as the planar walkers': ``x`` horizontal downhill, ``y`` up, and ``z = x × y``
(to the right of a walker facing downhill).  The slope's unit normal is
``n = (sin gamma, cos gamma, 0)``, its fall line ``s = (cos gamma, -sin gamma, 0)``.

The spoked wheel (``walker.space: 3d`` of ``model: rimless_wheel``; Coleman, Chatterjee &
Ruina 1997, "Motions of a rimless spoked wheel: a simple three-dimensional system with
impacts", Dynamics and Stability of Systems 12(3)) is one rigid body: a hub of mass ``M``,
inertia ``I_hub`` about its axle and ``I_diam`` about any diameter (an axisymmetric body),
with ``n`` massless spokes of length ``L`` in the plane normal to the axle, ``2 alpha =
2 pi / n`` apart.  In stance it turns about the stance spoke's foot, free about every axis
(a spherical joint: the foot neither slips nor leaves the ground; Coleman et al. 1997,
Sec. 2).  Its orientation is ``R = Rot(n, psi) Rot(s, phi) Rot(z, theta)``:

- ``heading`` ``psi``: about the slope normal (0: the axle across the fall line);
- ``lean`` ``phi``: about the fall line (0: the wheel's plane normal to the slope);
- ``stance`` ``theta``: the spin about the axle, the stance spoke's angle from the
  downward vertical in the wheel's plane, positive when its foot is ahead of the hub -
  with ``psi = phi = 0`` the planar wheel's coordinate
  (:func:`derive_spoked`, from the planar tree), so that the upright wheel's equations are
  the planar ones.

The wheel is one body of its tree (:func:`walkerlab.walker.trees.spoked_wheel_3d_tree`:
the hub at ``R (0, L, 0)`` from the stance foot, on a spherical joint there), derived by the
one Lagrangian derivation of :mod:`walkerlab.codegen.tree_derive` - the kinetic energy of
its centre of mass and of its rotation, ``omega^T I omega / 2`` with ``I = diag(I_diam,
I_diam, I_hub)`` in the wheel's frame, the potential ``V = M g y_hub``, the flow
``M(q) q'' + C(q, q') q' + G(q) = 0`` from the Christoffel symbols of ``M``.  (The hand
derivation it replaced, by König's theorem about the fixed foot, is kept as an independent
test reference; they agree to round-off.)

Heel strike: the next spoke's foot ``r_next = r_hub + R Rot(z, 2 alpha) (0, -L, 0)``
reaching the slope, ``n . r_next`` decreasing through 0.  The impact is plastic: the new
foot sticks and the old one leaves the ground; the impulse acts at the new foot, so the
angular momentum about it is conserved (Coleman et al. 1997, Eq. 3):

    I_cm omega+ + M d x (omega+ x d) = I_cm omega- + M d x v_hub-,   d = r_hub - r_next,

which is the plastic impact in extended coordinates at the new foot
(:func:`walkerlab.codegen.tree_derive.heel_strike`: the wheel turns freely about it, so the
motions the impulse does no work on are every rotation about it).  The new
stance spoke is the old one turned by a spoke: ``theta -> theta + 2 alpha``, heading and
lean unchanged (``R Rot(z, 2 alpha)``), the rates too (no rate depends on which spoke stands).

Poincaré section: the state just after a heel strike, the previous stance foot (the spoke
behind, ``theta - 2 alpha``) on the slope: ``theta`` is solved from it in closed form, so
the section coordinates are ``(psi, phi, psi', phi', theta')`` (five; the planar wheel's
one).  The steady rolling motions form a one-parameter family by heading at a given slope
(Coleman et al. 1997): one Floquet multiplier of every one is 1, the heading's.
"""

from __future__ import annotations

from functools import cache

import sympy as sp
from sympy.simplify.fu import TR10i

from walkerlab.codegen.equations import Equations
from walkerlab.codegen.frames import slope_to_world
from walkerlab.codegen.seeded import seeded as _seeded
from walkerlab.codegen.tree_derive import (
    derive_tree,
    heel_strike,
    impact_of_bodies,
    kinematics,
    simplifier,
)
from walkerlab.walker.trees import spoked_wheel_3d_tree
from walkerlab.walker.walker_trees import spoked_wheel_tree


def _planar_spoked(structure) -> Equations:
    """The planar spoked wheel (McGeer 1990, "Passive dynamic walking", IJRR 9(2), the
    rimless wheel) from its tree (:func:`walkerlab.walker.walker_trees.spoked_wheel_tree`):
    one coordinate, the stance spoke's angle ``q`` from the vertical; the heel strike
    ``2 q + 2 alpha + 2 gamma`` (the spokes symmetric about the slope's normal), the impact
    about the next spoke's foot (:func:`~walkerlab.codegen.tree_derive.impact_of_bodies`:
    ``B = m L^2 cos 2 alpha + I``), the new stance spoke the next (``q + 2 alpha``); the
    section just after a heel strike, ``q = alpha - gamma``."""
    tree, coords = spoked_wheel_tree(structure.spokes)
    te = derive_tree(tree, coords)
    kin, (q,), (dq,) = te.kinematics, te.q, te.dq
    P = dict(zip(tree.params, te.params))
    alpha, gamma = P["alpha"], P["gamma"]
    simplify = simplifier(kin)
    V = simplify(te.potential)
    # the impact and the points from the tree's kinematics in world axes (the slope's turn
    # merged with the wheel's: angles q + 2 k alpha, no gamma); the impact's matrices, the
    # frame's invariants, taken upright (q = 0: the same closed forms, far fewer products)
    world = kinematics(tree, coords, world=True)
    Mi, B = impact_of_bodies(world, world.contacts["next_foot"].jacobian(sp.Matrix([q])),
                             simplify, at={q: 0})
    hub, nxt = kin.coms["wheel"], kin.contacts["next_foot"]
    # each point's sums of products gathered into sines of sums (sympy's fu.TR10i, Fu et al.
    # 2006: L sin(q + 2 alpha), ...): the closed forms product-to-sum gives (1.5 s), in 0.07 s
    named = {"hip": world.coms["wheel"], "stance_foot": sp.zeros(3, 1),
             "swing_foot": world.contacts["next_foot"],
             **{k: world.contacts[k] for k in ["trailing_foot"] + [
                 f"spoke{i}_foot" for i in range(2, structure.spokes - 1)]}}
    points = {k: v[:2, :].applyfunc(lambda e: TR10i(sp.expand(e))) for k, v in named.items()}
    return Equations(
        q=(q,), dq=(dq,), params=te.params, M=te.M, C=te.C,
        G=sp.Matrix([sp.expand(sp.diff(V, q))]), Mi=Mi, B=B,
        relabel_q=sp.Matrix([q + 2 * alpha]), relabel_rate=sp.eye(1),
        kinetic=te.kinetic, potential=V,
        guards={"heel_strike": 2 * q + 2 * alpha + 2 * gamma, "rolls_back": dq,
                "hip_height": hub[1], "swing_clearance": nxt[1]},
        points=points, leg_angles={"stance": q, "swing": q + 2 * alpha},
        section_drop=0, drop_solution=alpha - gamma,
        De=sp.zeros(3, 3), E=sp.zeros(2, 3), limit=False, section_tied=None)


@cache
@_seeded
def derive_spoked(structure) -> Equations:
    """Flow, impact, guards, energies and points of a spoked wheel in three dimensions
    (module docstring), derived from its body tree
    (:func:`walkerlab.walker.trees.spoked_wheel_3d_tree`: one body on a spherical joint at
    the stance spoke's foot) by :func:`walkerlab.codegen.tree_derive.derive_tree`; the
    impact is :func:`~walkerlab.codegen.tree_derive.heel_strike` at the next spoke's foot
    (the extended-coordinates form of the angular momentum about the new foot conserved:
    the wheel turns freely about it), its entries expanded but not put through
    ``trigsimp`` (the derivation 3 s instead of ~38 s; they are evaluated once a step).

    The section's spin solves the trailing spoke's foot on the slope in closed form: that
    foot is ``R (v_x, v_y, 0)`` from the stance foot, ``v`` its place in the wheel's frame
    and ``R = Rot(n, psi) Rot(s, phi) Rot(z, beta)``, ``beta = theta + gamma``, so its height
    is ``cos(phi) (v_x sin(beta) + v_y cos(beta))``: zero at ``beta = atan2(v_y, -v_x)``
    (``= alpha``, whatever the heading and lean).

    Parameters
    ----------
    structure : walkerlab.walker.description.Structure
        With ``spokes`` > 0 and ``in_3d`` (parameters
        :data:`walkerlab.walker.description.SPOKED_3D_PARAMS`).

    Returns
    -------
    Equations
        ``n = 3`` (heading, lean, stance); points (3, 1) in world axes; ``De``, ``E`` zeros
        (no push-off: a wheel has no joint).

    Raises
    ------
    ValueError
        ``structure`` is not a 3D spoked wheel.
    """
    if not structure.spokes:
        raise ValueError("derive_3d.derive_spoked: the structure is not a spoked wheel")
    if not structure.in_3d:
        return _planar_spoked(structure)
    tree, coords = spoked_wheel_3d_tree(structure.spokes)
    te = derive_tree(tree, coords)
    psi, phi, th = te.q
    P = dict(zip(structure.param_names, te.params))
    alpha, gamma = P["alpha"], P["gamma"]
    # the impact's entries expanded, not trigsimp'd: trigsimp takes ~35 s here (the hand
    # derivation's 25-30 s) for matrices evaluated once a heel strike
    Mi, B = heel_strike(te, "next_foot", simplify=sp.expand)
    nrm = slope_to_world(gamma)[:, 1]   # the slope's normal (world)
    pts = te.points
    nxt, hub = pts["next_foot"], pts["wheel_com"]
    axle = slope_to_world(gamma) * te.kinematics.rotations["wheel"] * sp.Matrix([0, 0, 1])
    L = P["L"]
    v = sp.Matrix([-L * sp.sin(2 * alpha), L - L * sp.cos(2 * alpha)])  # trailing foot
    theta_on = sp.atan2(v[1], -v[0]) - gamma
    points = {"hip": hub, "stance_foot": sp.zeros(3, 1), "swing_foot": nxt,
              "trailing_foot": pts["trailing_foot"],
              **{f"spoke{k}_foot": pts[f"spoke{k}_foot"] for k in range(2, structure.spokes - 1)},
              "axle_tip": hub + L * axle / 4}
    n = 3
    dth = te.dq[2]
    return Equations(
        q=te.q, dq=te.dq, params=te.params, M=te.M, C=te.C, G=te.G, Mi=Mi, B=B,
        relabel_q=sp.Matrix([psi, phi, th + 2 * alpha]), relabel_rate=sp.eye(n),
        kinetic=te.kinetic, potential=te.potential,
        guards={"heel_strike": (nxt.T * nrm)[0], "rolls_back": dth,
                "hip_height": (hub.T * nrm)[0], "swing_clearance": (nxt.T * nrm)[0]},
        points=points,
        leg_angles={"stance": th, "swing": th + 2 * alpha, "heading": psi, "lean": phi},
        section_drop=2, drop_solution=theta_on,
        De=sp.zeros(n + 2, n + 2), E=sp.zeros(2, n + 2), limit=False, section_tied=None,
    )
