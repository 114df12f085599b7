"""CasADi functions of a free-jointed (five-link) biped's step, from its own symbolic model
(:func:`walkerlab.codegen.legged.derive_legged`), built once per walker structure and
cached on disk like the generated flows (:mod:`walkerlab.codegen.cache`).

Every function takes the walker's parameter vector ``p`` (``structure.param_names`` order,
``WalkerData.params``) as an input, so one cached file serves every set of masses and
lengths, as one generated module does:

``flow(x, u, p)``      ``[dq, M^-1 (B u - C dq - G)]`` (2n,): Lagrange's equations of the
                       walker (Westervelt, Grizzle & Koditschek 2003, IEEE TAC 48(1), Eq. 3
                       with ``B u``); ``u`` (4,) the joint torques [N m] in :data:`JOINTS`
                       order, each ``+tau`` on its second link's row and ``-tau`` on its
                       first's (:data:`walkerlab.config.actuation.FIVE_LINK_JOINTS`, the
                       signs of :mod:`walkerlab.models.hybrid.free_joint_actuators`)
``feet(x, p)``         ``[clearance, ahead, clearance rate, stance knee, swing knee]``: the
                       swing foot's height above the slope [m] (the heel-strike guard), its
                       distance ahead of the stance foot along the slope [m], the height's
                       rate [m/s], and the knees' angles (shank minus thigh, [rad], 0
                       straight, negative flexed)
``reset(x, p)``        heel strike and role swap (2n,): ``Mi dq+ = B dq-`` (Westervelt et
                       al. 2003, Sec. III-B), ``q+ = relabel_q(q-)``, ``dq+ = R dq+``

Cache: ``<user cache>/models/<cache_key(structure)>-collocation-<hash>.casadi`` (the
walker's structure key, this module's source and CasADi's version in the name; the same
private-folder, sha256-header rules as the generated code: a damaged or untrusted file is
rebuilt).
"""

from __future__ import annotations

import hashlib
from functools import cache
from pathlib import Path

__all__ = ["JOINTS", "five_link_functions"]

#: the actuated joints, the order of ``u`` (hips then knees)
JOINTS = ("stance_hip", "swing_hip", "stance_knee", "swing_knee")


def _build(structure) -> dict:
    """Derive (sympy) and convert (CasADi SX) the step's functions (module docstring)."""
    import casadi as ca
    import numpy as np

    from walkerlab.codegen.casadi_functions import casadi_matrix
    from walkerlab.codegen.legged import derive_legged  # light
    from walkerlab.config.actuation import FIVE_LINK_JOINTS  # light

    eq = derive_legged(structure)
    n, roles = len(eq.q), list(structure.roles)
    syms = [*eq.q, *eq.dq, *eq.params]
    x, u, p = ca.SX.sym("x", 2 * n), ca.SX.sym("u", len(JOINTS)), ca.SX.sym("p", len(eq.params))
    args = [*ca.vertsplit(x), *ca.vertsplit(p)]
    B = np.zeros((n, len(JOINTS)))
    for k, j in enumerate(JOINTS):
        first, second = FIVE_LINK_JOINTS[j]
        B[roles.index(first), k] -= 1.0
        B[roles.index(second), k] += 1.0
    M, C, G = (casadi_matrix(e, syms, args) for e in (eq.M, eq.C, eq.G))
    dq = x[n:]
    qdd = ca.solve(M, ca.DM(B) @ u - C @ dq - G)
    flow = ca.Function("flow", [x, u, p], [ca.vertcat(dq, qdd)], ["x", "u", "p"], ["dx"])
    clear = casadi_matrix([eq.guards["heel_strike"]], syms, args)
    ahead = casadi_matrix([eq.guards["swing_foot_ahead"]], syms, args)
    rate = ca.jtimes(clear, x, ca.vertcat(dq, ca.SX.zeros(n)))
    knees = [x[roles.index(b)] - x[roles.index(a)]
             for a, b in (FIVE_LINK_JOINTS["stance_knee"], FIVE_LINK_JOINTS["swing_knee"])]
    feet = ca.Function("feet", [x, p], [ca.vertcat(clear, ahead, rate, *knees)], ["x", "p"],
                       ["feet"])
    Mi, Bi = casadi_matrix(eq.Mi, syms, args), casadi_matrix(eq.B, syms, args)
    dq_post = ca.solve(Mi, Bi @ dq)
    qn = casadi_matrix(eq.relabel_q, syms, args)
    R = np.array(eq.relabel_rate, float)
    reset = ca.Function("reset", [x, p], [ca.vertcat(qn, ca.DM(R) @ dq_post)], ["x", "p"],
                        ["x_next"])
    return {"flow": flow, "feet": feet, "reset": reset}


@cache
def _source_hash() -> str:
    import casadi as ca

    from walkerlab.codegen import casadi_functions

    h = hashlib.sha256(Path(__file__).read_bytes())
    h.update(Path(casadi_functions.__file__).read_bytes())  # the printer
    h.update(ca.__version__.encode())
    return h.hexdigest()[:12]


def five_link_functions(structure) -> dict:
    """The step's CasADi functions of a free-jointed biped (module docstring), from the
    memo, the disk cache, or derived (sympy) and written there.

    Parameters
    ----------
    structure : walkerlab.walker.description.Structure
        Of the kind ``free_joints`` (:attr:`~walkerlab.walker.description.Structure.kind`:
        the five-link generator's walkers).

    Returns
    -------
    dict
        ``flow``, ``feet``, ``reset`` (:class:`casadi.Function`) and ``n`` (coordinates).

    Raises
    ------
    ValueError
        A walker without free knees or without a hinged torso (the hips act between the
        torso and the thighs), or one the five-link generator does not handle (one line).
    """
    from walkerlab.codegen.cache import cache_key
    from walkerlab.codegen.casadi_functions import cached_functions

    if not (structure.kind.joints_free and structure.kind.has_knees) or not structure.hinged_torso:
        raise ValueError("optimize: the five-link collocation drives the hips between a hinged "
                         "torso and the thighs and the free knees (walker.torso.coupling: "
                         "hinged, walker.leg.knee.lock: free)")

    key = f"{cache_key(structure)}-collocation-{_source_hash()}"
    fns = dict(cached_functions(key, lambda: _build(structure)))
    fns["n"] = len(structure.roles)
    return fns
