"""The floating view of a walker: the same bodies, links and feet as the rigid hybrid model
(:mod:`walkerlab.codegen.legged`), with no foot pinned (what the compliant-contact model
integrates): its coordinates, contact points and symbolic equations are derived in
:mod:`walkerlab.codegen.floating_equations` (conventions and equations there); here they
are emitted as numba-compiled code, kept in the user cache (:mod:`walkerlab.codestore`) and
read by the contact model (:mod:`walkerlab.models.contact`) and, as plain Python, by
:class:`walkerlab.models.hybrid.floating_view.FloatingView`.

Generated numba functions (``x = [q, dq]``, ``p`` the parameter vector in
:func:`param_names` order, outputs written into preallocated arrays):

=====================================  ========================================================
``dyn(x, p, M, h)``                    ``M`` (nq, nq) [kg, kg m, kg m^2], ``h`` (nq,) [N, N m]
``dyn_jac(x, a, p, Dq, Dv)``           ``d(M a + h)/dq``, ``dh/d dq`` (nq, nq), ``a`` fixed
                                       (the contact model's module only: the view's
                                       readers do not differentiate the dynamics)
``feet(x, p, P, V, J)``                contact points ``P`` (nf, d) [m], material velocities
                                       ``V`` (nf, d) [m/s], Jacobians ``J`` (nf, d, nq)
``feet_jac(x, F, p, dV, dJtF)``        ``dV = d V_i / dq`` (nf, d, nq) and
                                       ``dJtF = d(sum_i J_i^T F_i)/dq`` (nq, nq), ``F`` (nf, d)
``spins(x, p, S, Jn)``                 each contact point's spin rate about the ground's
                                       normal ``S`` (nf,) [rad/s] and its Jacobian ``Jn``
                                       (nf, nq) (zeros for a planar walker)
``hips(x, p, H, HV)``                  the hip ``H[0]`` (a planar walker's floating base,
                                       a 3D walker's pelvis), leg1's and leg2's own hips
                                       ``H[1]``, ``H[2]`` (the hip's where the legs share
                                       it) (3, d) [m] and their velocities ``HV`` [m/s]
``energies(X, p)``                     numpy: kinetic, potential [J] of states (2 nq, k)
``points(X, p)``                       numpy: named points (d, k) [m]
=====================================  ========================================================

``d`` (the module's ``DIM``) is 2 for a planar walker (world axes ``x`` downhill, ``y`` up) and
3 for a walker in 3D (:func:`walkerlab.codegen.floating_equations.derive_floating`; ``z``
lateral).

Massless bodies (the simplest walker's legs) have no floating model: :func:`check_masses`
raises.
"""

from __future__ import annotations

import hashlib

import numpy as np

from walkerlab import codestore
from walkerlab.codegen.floating_equations import (
    FOOT_PARAMS,
    FREE_3D,
    MASSLESS_MESSAGE,
    ROLES_3D,
    WHEEL_COORDINATES,
    FloatingEquations,
    check_masses,
    contact_names,
    coordinate_names,
    derive_floating,
    param_names,
)
from walkerlab.walker import floating_tree
from walkerlab.walker.description import Structure, WalkerData

__all__ = ["FLAT_FOOT_MESSAGE", "FOOT_PARAMS", "FREE_3D", "HUB_INERTIA_MESSAGE",
           "MASSLESS_MESSAGE", "ROLES_3D",
           "WHEEL_COORDINATES", "FloatingEquations",
           "check_masses", "contact_names", "coordinate_names",
           "derive_floating", "floating_module", "floating_params",
           "generated_state", "param_names"]

HUB_INERTIA_MESSAGE = ("contact.hub_inertia_kg_m2: a rimless wheel with a point-mass hub "
                       "(no walker.hub_inertia_kg_m2) needs a small regularising hub inertia "
                       "in the contact model (its angle has no dynamics once no spoke is "
                       "pinned)")
FLAT_FOOT_MESSAGE = ("contact.flat_foot_mass_kg and contact.flat_foot_inertia_kg_m2: a "
                     "flat-footed walker's contact model needs its feet's mass and inertia "
                     "(the rigid view's feet are massless)")


def floating_params(data: WalkerData, foot_mass_kg: float | None = None,
                    foot_inertia_kg_m2: float | None = None,
                    hub_inertia_kg_m2: float | None = None) -> np.ndarray:
    """The floating view's parameter vector (:func:`param_names` order) of ``data``.

    ``foot_mass_kg`` [kg], ``foot_inertia_kg_m2`` [kg m^2]: a flat foot's regularising mass
    and inertia about the ankle (``contact.flat_foot_mass_kg``, ``flat_foot_inertia_kg_m2``),
    used only when the walker's feet are massless (``walker.leg.foot.mass_kg`` unset: feet
    with mass carry their own ``m_foot``, ``I_foot`` in ``data.params``).

    ``hub_inertia_kg_m2`` [kg m^2]: a spoked wheel's regularising hub inertia
    (``contact.hub_inertia_kg_m2``), used only when the wheel's own ``I_hub`` is 0 (a
    point-mass hub, whose angle has no dynamics once no spoke is pinned); ignored otherwise.

    Raises
    ------
    ValueError
        A flat-footed walker without a foot mass and inertia (:data:`FLAT_FOOT_MESSAGE`); a
        point-mass hub without a regularising inertia (:data:`HUB_INERTIA_MESSAGE`).
    """
    p = [float(v) for v in data.params]
    if data.structure.spokes:
        i_hub = data.structure.param_names.index("I_hub")
        if p[i_hub] <= 0.0:
            if hub_inertia_kg_m2 is None:
                raise ValueError(HUB_INERTIA_MESSAGE)
            p[i_hub] = float(hub_inertia_kg_m2)
        return np.asarray(p, dtype=float)
    if data.structure.foot == "flat" and not data.structure.foot_mass:  # else the walker's
        if foot_mass_kg is None or foot_inertia_kg_m2 is None:
            raise ValueError(FLAT_FOOT_MESSAGE)
        p += [float(foot_mass_kg), float(foot_inertia_kg_m2)]
    return np.asarray(p, dtype=float)


# ---------------------------------------------------------------------------- code generation
def _fn(name: str, args: str, eq: FloatingEquations, outputs, pr, jit: bool = True) -> list[str]:
    """A straight-line numba function assigning ``outputs`` [(target, expr)] after a cse."""
    import sympy as sp

    exprs = [e for _, e in outputs]
    repl, red = sp.cse(exprs, symbols=sp.numbered_symbols("_c"), order="none")
    nq = len(eq.q)
    lines = (["@njit(cache=True, error_model='numpy')"] if jit else []) + [f"def {name}({args}):"]
    lines.append(f"    {', '.join(str(s) for s in eq.params)}, = p")
    lines += [f"    {s} = x[{i}]" for i, s in enumerate(eq.q)]
    lines += [f"    {s} = x[{nq + i}]" for i, s in enumerate(eq.dq)]
    lines += [f"    {pr.doprint(a)} = {pr.doprint(b)}" for a, b in repl]
    lines += [f"    {t} = {pr.doprint(r)}" for (t, _), r in zip(outputs, red)]
    return lines + [""]


def _numpy_fn(name: str, eq: FloatingEquations, named: dict) -> list[str]:
    """A vectorised numpy function of states ``X`` (2 nq,) or (2 nq, k) returning a dict."""
    import sympy as sp
    from sympy.printing.numpy import NumPyPrinter

    pr = NumPyPrinter({"fully_qualified_modules": True})
    keys, flat, shapes = list(named), [], []
    for k in keys:
        v = named[k]
        if isinstance(v, sp.MatrixBase):
            shapes.append(v.shape[0])
            flat += list(v)
        else:
            shapes.append(None)
            flat.append(v)
    repl, red = sp.cse(flat, symbols=sp.numbered_symbols("_n"), order="none")
    nq = len(eq.q)
    lines = [f"def {name}(X, p):", f"    {', '.join(str(s) for s in eq.params)}, = p",
             "    X = np.asarray(X, dtype=float)"]
    lines += [f"    {s} = X[{i}]" for i, s in enumerate(eq.q)]
    lines += [f"    {s} = X[{nq + i}]" for i, s in enumerate(eq.dq)]
    lines.append(f"    _z = 0.0 * {eq.q[0]}")
    lines += [f"    {pr.doprint(a)} = {pr.doprint(b)}" for a, b in repl]
    out, pos = [], 0
    for k, shp in zip(keys, shapes):
        if shp is None:
            out.append(f"{k!r}: {pr.doprint(red[pos])} + _z")
            pos += 1
        else:
            vals = [f"{pr.doprint(r)} + _z" for r in red[pos:pos + shp]]
            pos += shp
            out.append(f"{k!r}: np.array(({', '.join(vals)},))")
    return lines + [f"    return {{{', '.join(out)}}}", ""]


def generate_floating(eq: FloatingEquations, key: str, dynamics_jacobian: bool = True) -> str:
    """Source of the numba module of the floating view (module docstring's table); without
    ``dynamics_jacobian``, no ``dyn_jac`` (its two symbolic Jacobians are most of the
    generation: 20 s of 24 s for ``configs/hip_width_stabilised.yaml``'s walker, which
    the rigid gait's ground-reaction check, :func:`floating_plain`, does not need)."""
    import sympy as sp

    from walkerlab.codegen.printers import PRINTER as pr
    nq = len(eq.q)
    qv, dqv = sp.Matrix(eq.q), sp.Matrix(eq.dq)
    a = sp.Matrix(sp.symbols(f"a0:{nq}", real=True))
    body = []
    # M and h
    outs = [(f"M[{i}, {j}]", eq.M[i, j]) for i in range(nq) for j in range(nq)]
    outs += [(f"h[{i}]", eq.h[i]) for i in range(nq)]
    body += _fn("dyn", "x, p, M, h", eq, outs, pr)
    if dynamics_jacobian:  # d(M a + h)/dq, dh/d dq
        E = eq.M * a + eq.h
        Dq, Dv = E.jacobian(qv), eq.h.jacobian(dqv)
        outs = [(f"Dq[{i}, {j}]", Dq[i, j]) for i in range(nq) for j in range(nq)]
        outs += [(f"Dv[{i}, {j}]", Dv[i, j]) for i in range(nq) for j in range(nq)]
        lines = _fn("dyn_jac", "x, a, p, Dq, Dv", eq, outs, pr)
        lines.insert(2, f"    {', '.join(str(s) for s in a)}, = a[0], "
                     + ", ".join(f"a[{i}]" for i in range(1, nq)))
        body += lines
    # feet (2 or 3 components: a planar or a 3D walker's)
    d = eq.feet[0][0].shape[0]
    outs = []
    for i, (pos, J) in enumerate(eq.feet):
        v = J * dqv
        outs += [(f"P[{i}, {r}]", pos[r]) for r in range(d)]
        outs += [(f"V[{i}, {r}]", v[r]) for r in range(d)]
        outs += [(f"J[{i}, {r}, {k}]", J[r, k]) for r in range(d) for k in range(nq)]
    body += _fn("feet", "x, p, P, V, J", eq, outs, pr)
    nf = len(eq.feet)
    F = sp.Matrix(nf, d, sp.symbols(f"F0:{d * nf}", real=True))
    outs = []
    JtF = sp.zeros(nq, 1)
    for i, (_, J) in enumerate(eq.feet):
        dV = (J * dqv).jacobian(qv)
        outs += [(f"dV[{i}, {r}, {k}]", dV[r, k]) for r in range(d) for k in range(nq)]
        JtF += J.T * F[i, :].T
    dJ = JtF.jacobian(qv)
    outs += [(f"dJtF[{i}, {k}]", dJ[i, k]) for i in range(nq) for k in range(nq)]
    lines = _fn("feet_jac", "x, F, p, dV, dJtF", eq, outs, pr)
    lines.insert(2, f"    {', '.join(str(f) for f in F)} = "
                 + ", ".join(f"F[{i}, {r}]" for i in range(nf) for r in range(d)))
    body += lines
    # each point's spin about the ground's normal and its Jacobian (zeros in the plane)
    outs = []
    for i in range(nf):
        Jn = eq.spins[i] if eq.spins else sp.zeros(1, nq)
        outs += [(f"S[{i}]", (Jn * dqv)[0])]
        outs += [(f"Jn[{i}, {k}]", Jn[0, k]) for k in range(nq)]
    body += _fn("spins", "x, p, S, Jn", eq, outs, pr)
    # the hip (the floating base of a planar walker; a 3D walker's pelvis) and each leg's
    # own hip (a walker with hip width: its end of the hip axis), with their velocities
    hip = eq.points.get("hip", sp.zeros(d, 1))
    outs = []
    for i, name in enumerate(("hip", "leg1_hip", "leg2_hip")):
        pos = eq.points.get(name, hip)
        v = pos.jacobian(qv) * dqv
        outs += [(f"H[{i}, {r}]", pos[r]) for r in range(d)]
        outs += [(f"HV[{i}, {r}]", v[r]) for r in range(d)]
    body += _fn("hips", "x, p, H, HV", eq, outs, pr)
    body += _numpy_fn("_energies", eq, {"kinetic": eq.kinetic, "potential": eq.potential})
    body += ["def energies(X, p):", "    d = _energies(X, p)",
             "    return d['kinetic'], d['potential']", ""]
    body += _numpy_fn("points", eq, eq.points)
    head = [f"# walkerlab generated floating model code (walkerlab.codegen.floating); key {key}",
            "# Do not edit: regenerated when the walker description or the generator changes.",
            "from math import sin, cos, tan, sqrt  # noqa: F401",
            "import numpy  # noqa: F401", "import numpy as np", "from numba import njit", "",
            f"NQ = {nq}", f"DIM = {d}", f"COORDINATES = {tuple(str(s) for s in eq.q)!r}", ""]
    return "\n".join(head + body) + "\n"


# ---------------------------------------------------------------------------- cache


def module_key(structure: Structure, tag: str, sources=()) -> str:
    """Cache key: the rigid generator's key of ``structure`` (structure + generator + sympy),
    this file, the derivations' (:mod:`walkerlab.codegen.floating_equations`,
    :mod:`walkerlab.codegen.floating_names`, the
    planar floating tree :mod:`walkerlab.walker.floating_tree`) and ``sources`` (files whose
    text is part of the module), and ``tag``."""
    from walkerlab.codegen import cache, floating_equations, floating_names

    h = hashlib.sha256(cache.cache_key(structure).encode())
    h.update(tag.encode())
    h.update(codestore.source_hash(__file__, floating_equations.__file__,
                                   floating_names.__file__, floating_tree.__file__,
                                   *sources).encode())
    return h.hexdigest()[:24]


def load_generated(structure: Structure, tag: str, build, sources=()):
    """Import the generated module ``<key>_<tag>.py`` of the cache folder, writing it with
    ``build(key) -> str`` on a miss (or a damaged or untrusted file): one mechanism with the
    rigid compiled flows, :func:`walkerlab.codestore.import_generated`."""
    key, filename, module_name = _generated_names(structure, tag, sources)
    return codestore.import_generated(filename, module_name, lambda: build(key))


def _generated_names(structure: Structure, tag: str, sources=()) -> tuple[str, str, str]:
    """The cache key, file name and module name of the generated module ``tag`` of
    ``structure`` (:func:`load_generated`)."""
    key = module_key(structure, tag, sources)
    return key, f"{key}_{tag}.py", f"walkerlab_{tag}_{key}"


def generated_state(structure: Structure, tag: str, sources=()) -> tuple[str, bool | None]:
    """The module name :func:`load_generated` gives the generated module ``tag`` of
    ``structure``, and whether its source is in the user cache already (False: not yet,
    so the first process to load it generates it and numba compiles its kernels; None: no
    user cache folder, nothing shared between processes), without generating or importing
    it."""
    _key, filename, module_name = _generated_names(structure, tag, sources)
    folder = codestore.cache_dir()
    return module_name, None if folder is None else (folder / filename).is_file()


def floating_source(structure: Structure, key: str) -> str:
    """Generated source of the floating view of ``structure`` (numba functions, no imports of
    other walkerlab packages; no ``dyn_jac``, which the contact model's own module has:
    :func:`walkerlab.models.contact.generated.contact_source`)."""
    return generate_floating(derive_floating(structure), key, dynamics_jacobian=False)


def floating_module(structure: Structure):
    """The imported (compiled on first call, cached) floating module of ``structure``.

    Raises
    ------
    ValueError
        Massless bodies (:data:`MASSLESS_MESSAGE`).
    """
    check_masses(structure)
    return load_generated(structure, "floating", lambda key: floating_source(structure, key))


_plain: dict[str, dict] = {}


def floating_plain(structure: Structure) -> dict:
    """The floating module's functions of ``structure`` as the plain Python they are
    generated from (``njit`` the identity): the generated text
    (:func:`walkerlab.codestore.generated_source`, as :func:`load_generated` reads and
    writes it), executed without
    numba, for a check of a few hundred states that should load no compiler (the rigid
    gait's ground reaction, :mod:`walkerlab.models.hybrid.ground_reaction`).  Memoised per
    process.

    Returns
    -------
    dict
        The module's namespace (``NQ``, ``COORDINATES``, ``dyn``, ``feet``, ``feet_jac``, ...).

    Raises
    ------
    ValueError
        Massless bodies (:data:`MASSLESS_MESSAGE`).
    """
    check_masses(structure)
    key, filename, _ = _generated_names(structure, "floating")
    if key in _plain:
        return _plain[key]
    body, _ = codestore.generated_source(filename, lambda: floating_source(structure, key))
    body = body.replace("from numba import njit\n", "", 1)

    def njit(*_args, **_kwargs):
        return lambda f: f

    ns = {"njit": njit, "__name__": f"walkerlab_floating_plain_{key}"}
    exec(compile(body, f"<walkerlab floating model {key}>", "exec"), ns)  # codegen's text
    _plain[key] = ns
    return ns
