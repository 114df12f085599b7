"""One Lagrangian derivation of a walker from its body tree (:mod:`walkerlab.walker.tree`):
forward kinematics, the energies, Lagrange's flow and the heel-strike impact, for planar and
3D trees alike.

Kinematics (Featherstone 2008, *Rigid Body Dynamics Algorithms*, Sec. 4.1-4.2, in its
rotational and positional parts).  Every body's orientation is the chain of elementary
rotations ``Rot(u_k, a_k)`` (Rodrigues, :func:`walkerlab.codegen.frames.rotation`) of the
joints from the root to it; consecutive rotations about the same axis are merged (their
angles summed, zero angles dropped) before the chain is multiplied out, so a pitch undone
by the next joint leaves no ``sin^2 + cos^2`` behind.  With ``R_b = R_<k Rot(u_k, a_k)
R_>k`` the body's angular velocity in its own frame is ``omega_b = sum_k R_>k^T u_k a_k'``
(Featherstone's ``omega_i = R^T omega_parent + S_i q_i'``, unrolled); its origin is its
parent's plus ``R_parent origin``, its centre of mass ``r_c = p_b + R_b c_b``.

Energies (Murray, Li & Sastry 1994, *A Mathematical Introduction to Robotic Manipulation*,
Sec. 4.3): ``T = sum_b [m_b |r_c'|^2 + omega_b^T I_b omega_b] / 2`` with ``I_b`` about the
centre of mass in the body's frame, so ``M = sum_b m_b J_c^T J_c + J_w^T I_b J_w``
(``J_c = dr_c/dq``, ``J_w = d omega_b / dq'``); ``V = sum_b m_b g up . r_c`` with ``up``
the vertical in the slope's frame (:func:`~walkerlab.codegen.frames.slope_up`).  The flow
``M qdd + C dq + G = 0``: ``C`` from the Christoffel symbols
(:func:`walkerlab.codegen.lagrange.christoffel`), ``G = dV/dq``.

Heel strike (:func:`plastic_impact`; Hurmuzlu & Marghitu 1994, "Rigid body collisions of
planar kinematic chains with multiple contact points", IJRR 13(1); Westervelt et al. 2007,
*Feedback Control of Dynamic Bipedal Robot Locomotion*, Sec. 3.4.2).  In extended
coordinates ``[q, p]`` (``p`` the root's origin, the old stance foot, free) the mass matrix
is ``M_e = [[M, A], [A^T, m I]]``, ``A = sum_b m_b J_c^T`` (a translation of the root moves
every centre of mass with it and turns no body), ``m`` the total mass.  The impact is
plastic: the new stance foot ``f(q)`` sticks, the old one leaves the ground (no impulse
there).  The motions about the new foot have the extended rates ``J dq`` with
``J = [I; -F]``, ``F = df/dq`` (the new foot at rest), and the impulse at the new foot does
no work on them, so ``J^T M_e J dq+ = J^T M_e [I; 0] dq-``:

    Mi = M - A F - F^T A^T + m F^T F,        B = M - F^T A^T.

The planar generators' ``Mi, B`` (:mod:`walkerlab.codegen.legged`, ``add_mass_terms``) and
the 3D compass's (:func:`walkerlab.codegen.legged.derive_legged`) are this formula on
their own bodies.
"""

from __future__ import annotations

import builtins
import types
from collections.abc import Callable
from dataclasses import dataclass
from functools import cached_property, lru_cache

import sympy as sp
from sympy.parsing.sympy_parser import auto_number, parse_expr
from sympy.simplify.fu import TR8

from walkerlab.codegen.equations import Flow
from walkerlab.codegen.frames import rotation, slope_to_world, slope_up
from walkerlab.codegen.lagrange import christoffel
from walkerlab.codegen.seeded import seeded
from walkerlab.walker.tree import BodyTree, CoordinateMap

__all__ = ["TreeEquations", "TreeKinematics", "derive_tree", "heel_strike",
           "impact_of_bodies", "kinematics",
           "mass_and_potential", "plastic_impact", "product_to_sum", "simplifier"]


def product_to_sum(e: sp.Expr) -> sp.Expr:
    """The simplification of a planar tree's entries (:func:`simplifier`): products of sines
    and cosines turned into sums (sympy's ``fu.TR8``, ``cos a cos b = [cos(a - b) + cos(a +
    b)] / 2``, ...; Fu, Zhong & Zeng 2006, "Automated and readable simplification of
    trigonometric expressions", Math. Comput. Modelling 44) between two expansions: the
    ``cos(a + b)`` halves of a chain's terms cancel and ``cos^2 + sin^2`` is 1, leaving a
    planar mass matrix's closed form (sums of ``cos(q_i - q_j)``).  ``TR8`` is applied to
    each term's product of sines and cosines alone, its other factors left aside (the same
    result, 4-5 times faster than on the whole sum: measured on the five-link biped's mass
    matrix, 0.15 s against 0.69 s).  The result is the sum's terms grouped by their sine or
    cosine, each coefficient with its common factors taken out (``sympy.factor_terms``:
    ``-L (l_t m_s + d m_t) cos(q_1 - q_2)``, not four products): about as compact to print
    as the leg-vector sums' closed form."""
    out = []
    for term in sp.Add.make_args(sp.expand(e)):
        trig, rest = _split_trig(term)
        if len(trig) > 1 or any(isinstance(f, sp.Pow) for f in trig):
            out.append(sp.Mul(*rest) * _tr8(sp.Mul(*trig)))
        else:
            out.append(term)
    groups: dict = {}
    for term in sp.Add.make_args(sp.expand(sp.Add(*out))):
        trig, rest = _split_trig(term)
        key = sp.Mul(*trig)
        groups[key] = groups.get(key, 0) + sp.Mul(*rest)
    return sp.Add(*(sp.factor_terms(c) * t for t, c in groups.items()))


def _split_trig(term: sp.Expr) -> tuple[list, list]:
    """A product's factors: its sines and cosines (and their powers), and the rest."""
    trig, rest = [], []
    for f in sp.Mul.make_args(term):
        base = f.base if isinstance(f, sp.Pow) else f
        (trig if isinstance(base, sp.sin | sp.cos) else rest).append(f)
    return trig, rest


@lru_cache(maxsize=4096)
def _tr8(product: sp.Expr) -> sp.Expr:
    """``TR8`` of one product of sines and cosines (many terms of a matrix share one)."""
    return TR8(product)


@dataclass(frozen=True)
class TreeKinematics:
    """Forward kinematics of a tree in a walker's coordinates (sympy; frames in the slope's,
    or in world axes: :func:`kinematics`' ``world``).

    Attributes
    ----------
    q, dq : tuple of Symbol (n,)
        ``q_<name>``, ``dq_<name>`` for the coordinate map's names [rad, rad/s].
    params : tuple of Symbol
        The tree's parameters, in order.
    rotations : dict[str, Matrix (3, 3)]
        Each body's frame to the slope's frame.
    origins, coms : dict[str, Matrix (3, 1)]
        Each body's frame origin and centre of mass from the root's origin [m].
    omegas : dict[str, Matrix (3, 1)]
        Each body's angular velocity in its own frame [rad/s], linear in ``dq``.
    contacts : dict[str, Matrix (3, 1)]
        Each contact point from the root's origin [m].
    masses : dict[str, Expr]; inertias : dict[str, Matrix (3, 3)]
    gamma, g : Expr
        The slope [rad] and gravity [m/s^2].
    """

    q: tuple
    dq: tuple
    params: tuple
    rotations: dict
    origins: dict
    coms: dict
    omegas: dict
    contacts: dict
    masses: dict
    inertias: dict
    gamma: sp.Expr
    g: sp.Expr


@dataclass(frozen=True)
class TreeEquations(Flow):
    """The flow (:class:`~walkerlab.codegen.equations.Flow`: gravity only in ``G``),
    energies and points of a tree (:func:`derive_tree`; ``n = len(q)``).

    Attributes
    ----------
    kinetic, potential : Expr
        [J]; the potential from the heights above the horizontal through the stance foot.
    A : Matrix (n, 3); total_mass : Expr
        The extended mass matrix's coupling ``sum_b m_b J_c^T`` and total mass (module
        docstring), for :func:`heel_strike`.
    kinematics : TreeKinematics
    """

    kinetic: sp.Expr
    potential: sp.Expr
    A: sp.Matrix
    total_mass: sp.Expr
    kinematics: TreeKinematics

    @cached_property
    def points(self) -> dict:
        """Every contact point, body origin (``<body>_origin``) and centre of mass
        (``<body>_com``) from the stance foot in world axes (``x`` downhill, ``y`` up):
        dict of Matrix (3, 1) [m], turned on first use (the legs' printed points are others)."""
        kin, to_world = self.kinematics, slope_to_world(self.kinematics.gamma)
        points = {k: to_world * v for k, v in kin.contacts.items()}
        for k in kin.coms:
            points[f"{k}_origin"] = to_world * kin.origins[k]
            points[f"{k}_com"] = to_world * kin.coms[k]
        return points


def _merged(chain: list) -> list:
    """Consecutive elementary rotations ``(axis tuple, angle)`` about the same axis merged,
    zero angles dropped (the product is unchanged)."""
    out: list = []
    for axis, angle in chain:
        if out and out[-1][0] == axis:
            angle = out.pop()[1] + angle
        if angle != 0:
            out.append((axis, angle))
    return out


def _product(chain: list) -> sp.Matrix:
    R = sp.eye(3)
    for axis, angle in chain:
        R = R * rotation(sp.Matrix(axis), angle)
    return R


@lru_cache(maxsize=1024)
def _parsed(text: str, params: tuple[str, ...], coordinates: tuple[str, ...]) -> sp.Expr:
    """A tree's entry in its parameters and coordinates (``c`` is ``q_c``), parsed once per
    process by ``parse_expr`` with exact numbers (``auto_number``, as ``sympify``) and no
    other rewriting, in sympy's names gathered once: a quarter of ``sympify``'s time."""
    ns = {**{p: sp.Symbol(p, real=True) for p in params},
          **{c: sp.Symbol(f"q_{c}", real=True) for c in coordinates},
          "sin": sp.sin, "cos": sp.cos, "tan": sp.tan, "sqrt": sp.sqrt, "pi": sp.pi}
    return parse_expr(text, local_dict=ns, global_dict=_sympy_names(),
                      transformations=(auto_number,))


@lru_cache(maxsize=1)
def _sympy_names() -> dict:
    """``parse_expr``'s default names (``from sympy import *``, built-ins, Max/Min)."""
    names: dict = {}
    exec("from sympy import *", names)  # noqa: S102 - sympy's own default namespace
    names.update({k: v for k, v in vars(builtins).items()
                  if isinstance(v, types.BuiltinFunctionType)})
    names.update(max=sp.Max, min=sp.Min)
    return names


def kinematics(tree: BodyTree, coords: CoordinateMap | None = None,
               world: bool = False) -> TreeKinematics:
    """Forward kinematics of ``tree`` (module docstring) in the coordinates ``coords``.

    Parameters
    ----------
    tree : walkerlab.walker.tree.BodyTree
    coords : walkerlab.walker.tree.CoordinateMap, optional
        The walker's coordinates and the joints' angles in them; default the joints' own.
    world : bool
        Frames, origins, centres of mass and contacts in world axes (``x`` horizontal
        downhill, ``y`` up): the slope's frame turned by ``-gamma`` about ``z``
        (:func:`~walkerlab.codegen.frames.slope_to_world`) at the root of every chain, so
        that it merges with the joints' pitches (a planar link's absolute angle from the
        vertical comes out with no ``gamma`` in it).

    Returns
    -------
    TreeKinematics

    Raises
    ------
    ValueError
        ``coords`` does not fit ``tree`` (:meth:`~walkerlab.walker.tree.CoordinateMap.check`).
    """
    coords = coords or CoordinateMap.identity(tree)
    coords.check(tree)
    par = tuple(sp.Symbol(p, real=True) for p in tree.params)
    q = tuple(sp.Symbol(f"q_{c}", real=True) for c in coords.names)
    dq = tuple(sp.Symbol(f"dq_{c}", real=True) for c in coords.names)

    def num(v):  # an expression in the names, or a number (whole numbers exact)
        if isinstance(v, str):
            return _parsed(v, tree.params, coords.names)
        return sp.Integer(int(v)) if float(v).is_integer() else sp.Float(v)

    def vec(v):
        return sp.Matrix([num(c) for c in v])

    angle = {c: num(e) for c, e in coords.joint_angles}
    chains, R, origin, com, omega, mass, inertia = {}, {}, {}, {}, {}, {}, {}
    root = tree.root.name
    gamma = num(tree.root.slope_rad)
    chains[root] = [((0, 0, 1), -gamma)] if world else []
    R[root], origin[root] = _product(chains[root]), sp.zeros(3, 1)
    for b in tree.bodies:
        j = b.joint
        slide = j.kind == "prismatic"   # the origin moves along the axis, nothing turns
        steps = [] if slide else [(tuple(num(c) for c in axis), angle[c]) for axis, c in
                                  zip(j.axes, j.coordinates)]
        chain = _merged(chains[j.parent] + steps)
        chains[b.name] = chain
        R[b.name] = _product(chain)
        at = vec(j.origin_m) + (vec(j.axes[0]) * angle[j.coordinates[0]] if slide else
                                sp.zeros(3, 1))
        origin[b.name] = origin[j.parent] + R[j.parent] * at
        com[b.name] = origin[b.name] + R[b.name] * vec(b.com_m)
        w = sp.zeros(3, 1)
        for k, (axis, a) in enumerate(chain):   # omega_b = sum_k R_>k^T u_k a_k'
            rate = sum(sp.diff(a, qi) * dqi for qi, dqi in zip(q, dq))
            w += _product(chain[k + 1:]).T * sp.Matrix(axis) * rate
        omega[b.name] = w
        mass[b.name] = num(b.mass_kg)
        inertia[b.name] = sp.Matrix([[num(v) for v in row] for row in b.inertia_kg_m2])
    contacts = {c.name: origin[c.body] + R[c.body] * vec(c.point_m) for c in tree.contacts}
    return TreeKinematics(q=q, dq=dq, params=par, rotations={k: R[k] for k in com},
                          origins={k: origin[k] for k in com}, coms=com, omegas=omega,
                          contacts=contacts, masses=mass, inertias=inertia,
                          gamma=gamma, g=num(tree.root.gravity_m_per_s2))


def simplifier(kin: TreeKinematics) -> Callable[[sp.Expr], sp.Expr]:
    """The simplification a tree's equations get: :func:`product_to_sum`, planar or 3D,
    chosen by measurement against ``trigsimp(expand(e))``.

    The cold derivation (flow and heel strike, s; one process on a loaded 2-core machine)
    and, in 3D, the operations the compiled model evaluates (``count_ops(cse(M, C))``):

    ===============================  =================  ==================
    tree                             trigsimp           product-to-sum
    ===============================  =================  ==================
    compass gait (planar)            2.1 s              0.13 s
    kneed (planar)                   19.5 s             0.63 s
    bisecting-hip torso (planar)     11.3 s             0.33 s
    hip width (3D)                   10.4 s, 178 ops    1.3 s, 135 ops
    bisecting-hip torso (3D)         31.8 s, 268 ops    2.1 s, 202 ops
    hip-roll joints (3D)             23.4 s, 282 ops    2.9 s, 306 ops
    ===============================  =================  ==================

    Both are identities (the entries agree to 1e-15 at random states).  The 3D trees took
    ``trigsimp`` until the plant-model step; product-to-sum moved their fixed points by
    round-off only (the largest differences are tabled in the user guide's 3D page), and
    derives ``configs/hip_width_stabilised.yaml``'s walker in 2.1 s instead of 39 s.
    ``kin`` is taken so that a tree could be given another simplification by its form.
    """
    return product_to_sum


def mass_and_potential(kin: TreeKinematics) -> tuple[sp.Matrix, sp.Matrix, sp.Expr, sp.Expr]:
    """The mass matrix, the extended mass matrix's coupling, the total mass and the potential
    of a tree's kinematics (module docstring), unsimplified.

    Returns
    -------
    M : Matrix (n, n)
        ``sum_b m_b J_c^T J_c + J_w^T I_b J_w`` [kg m^2, kg m, kg by coordinate].
    A : Matrix (n, 3)
        ``sum_b m_b J_c^T`` [kg m or kg].
    total_mass : Expr
        [kg].
    V : Expr
        ``sum_b m_b g up . r_c`` [J], from the root's origin.
    """
    qv, dqv = sp.Matrix(kin.q), sp.Matrix(kin.dq)
    n = len(kin.q)
    M, A, total = sp.zeros(n, n), sp.zeros(n, 3), sp.Integer(0)
    V = sp.Integer(0)
    up = slope_up(kin.gamma)
    for name, r in kin.coms.items():
        m, inertia = kin.masses[name], kin.inertias[name]
        if m != 0:
            Jc = r.jacobian(qv)
            M += m * Jc.T * Jc
            A += m * Jc.T
            total += m
            V += m * kin.g * (up.T * r)[0]
        if inertia != sp.zeros(3, 3):
            Jw = kin.omegas[name].jacobian(dqv)
            M += Jw.T * inertia * Jw
    return M, A, total, V


@seeded
def derive_tree(tree: BodyTree, coords: CoordinateMap | None = None,
                simplify: Callable[[sp.Expr], sp.Expr] | None = None) -> TreeEquations:
    """Lagrange's flow, the energies and the points of ``tree`` (module docstring).

    Parameters
    ----------
    tree : walkerlab.walker.tree.BodyTree
    coords : walkerlab.walker.tree.CoordinateMap, optional
        The walker's coordinates; default the joints' own.
    simplify : callable, optional
        Applied to every entry of ``M`` before the Christoffel symbols (sympy's random
        choices seeded meanwhile: :func:`walkerlab.codegen.seeded.seeded`); default the
        tree's :func:`simplifier`.

    Returns
    -------
    TreeEquations

    Raises
    ------
    ValueError
        ``coords`` does not fit ``tree``.
    """
    kin = kinematics(tree, coords)
    q, dq = kin.q, kin.dq
    dqv = sp.Matrix(dq)
    M, A, total, V = mass_and_potential(kin)
    M = M.applyfunc(simplify or simplifier(kin))
    C = christoffel(M, q, dq)
    G = sp.Matrix([sp.expand(sp.diff(V, qi)) for qi in q])
    kinetic = sp.Rational(1, 2) * (dqv.T * M * dqv)[0]
    return TreeEquations(q=q, dq=dq, params=kin.params, M=M, C=C, G=G, kinetic=kinetic,
                         potential=V, A=A, total_mass=total, kinematics=kin)


@seeded
def plastic_impact(M: sp.Matrix, A: sp.Matrix, total_mass, F: sp.Matrix,
                   simplify: Callable[[sp.Expr], sp.Expr] = product_to_sum
                   ) -> tuple[sp.Matrix, sp.Matrix]:
    """The plastic impact at a new stance foot, the old one leaving the ground, in extended
    coordinates (module docstring; Hurmuzlu & Marghitu 1994; Westervelt et al. 2007,
    Sec. 3.4.2).

    Parameters
    ----------
    M : Matrix (n, n)
        Mass matrix about the old stance foot.
    A : Matrix (n, 3); total_mass : Expr
        The extended mass matrix's coupling and total mass [kg m, kg].
    F : Matrix (3, n)
        The new stance foot's velocity Jacobian (its material contact point's) [m].
    simplify : callable
        Applied to every entry of the results.

    Returns
    -------
    Mi, B : Matrix (n, n)
        ``Mi dq+ = B dq-`` in the pre-impact coordinates.
    """
    Mi = (M - A * F - F.T * A.T + total_mass * F.T * F).applyfunc(simplify)
    B = (M - F.T * A.T).applyfunc(simplify)
    return Mi, B


def impact_of_bodies(kin: TreeKinematics, F: sp.Matrix,
                     simplify: Callable[[sp.Expr], sp.Expr],
                     at: dict | None = None) -> tuple[sp.Matrix, sp.Matrix]:
    """:func:`plastic_impact`'s ``Mi, B`` summed body by body: with ``J_n = J_c - F`` a
    body's centre-of-mass velocity Jacobian about the new stance foot, ``Mi = sum_b m_b
    J_n^T J_n + J_w^T I_b J_w`` and ``B = sum_b m_b J_n^T J_c + J_w^T I_b J_w`` (the same
    matrices: ``sum m J_c^T = A``, ``sum m = m``), whose terms in the old stance leg's
    angle cancel in ``J_n`` before any product is expanded (a planar tree's impact in a
    third of the time).

    Parameters
    ----------
    kin : TreeKinematics
    F : Matrix (3, n)
        The new stance foot's material contact point's velocity Jacobian [m].
    simplify : callable
        Applied to every entry of the results.
    at : dict, optional
        Coordinates the Jacobians (``F`` too) are taken at, where Mi, B do not depend on them.

    Returns
    -------
    Mi, B : Matrix (n, n)
    """
    qv, dqv = sp.Matrix(kin.q), sp.Matrix(kin.dq)

    def there(a):
        return a.subs(at) if at else a

    F = there(F)
    n = len(kin.q)
    Mi, B = sp.zeros(n, n), sp.zeros(n, n)
    for name, r in kin.coms.items():
        m, inertia = kin.masses[name], kin.inertias[name]
        if m != 0:
            Jc = there(r.jacobian(qv))
            Jn = Jc - F
            Mi += m * Jn.T * Jn
            B += m * Jn.T * Jc
        if inertia != sp.zeros(3, 3):
            Jw, inertia = there(kin.omegas[name].jacobian(dqv)), there(inertia)
            Mi += Jw.T * inertia * Jw
            B += Jw.T * inertia * Jw
    return Mi.applyfunc(simplify), B.applyfunc(simplify)


def heel_strike(eqs: TreeEquations, contact: str,
                simplify: Callable[[sp.Expr], sp.Expr] | None = None
                ) -> tuple[sp.Matrix, sp.Matrix]:
    """:func:`plastic_impact` at the tree's contact point ``contact`` (a point foot: its
    material point is the contact point), its entries simplified by ``simplify`` (default
    the tree's :func:`simplifier`).

    Returns
    -------
    Mi, B : Matrix (n, n)

    Raises
    ------
    KeyError
        ``contact`` is not a contact point of the tree.
    """
    F = eqs.kinematics.contacts[contact].jacobian(sp.Matrix(eqs.q))
    return plastic_impact(eqs.M, eqs.A, eqs.total_mass, F,
                          simplify or simplifier(eqs.kinematics))
