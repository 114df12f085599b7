"""The push-off of a flat-footed walker: the extended impact system of each pinned point
(an impulse at the stance toe, then the heel strike after it), derived with sympy as part of
:func:`walkerlab.codegen.foot_modes.derive_flat` (Wisse et al. 2006, "Ankle springs instead
of arc-shaped feet for passive dynamic walkers").
"""

from __future__ import annotations

import sympy as sp

from walkerlab.codegen.link_sums import velocity_terms


def _translation_rows(lin: dict, qs) -> sp.Matrix:
    """``d position / d q`` (len(qs), 2) of a ``{angle: length}`` leg-vector sum, row ``i``
    the position's rate for ``dq = e_i`` (``e'(a) = (cos a, sin a)``)."""
    rows = [[sum((c * sp.cos(a) for a, c in t), sp.Integer(0)),
             sum((c * sp.sin(a) for a, c in t), sp.Integer(0))]
            for t in velocity_terms(lin, qs)]
    return sp.Matrix(rows)


def push_off_systems(q, anchors, bodies_from, kin, flows, resets, post_q, post) -> dict:
    """The extended impact system of each pinned point (``heel``, ``toe``): the push-off at
    the stance toe and the heel strike after it.

    Extended coordinates ``qe = (q, x_f, y_f)``: the walker translated by ``(x_f, y_f)``
    with its pinned point.  Per pin: ``De`` (5, 5), the Hessian of the kinetic energy in
    ``dqe`` (``[M, Mt; Mt^T, m I]``, ``Mt = sum m dr/dq``; singular along the massless
    foot's turn about the ankle, which the push-off holds); ``Jt`` (2, 5), the stance toe's
    Jacobian; ``Jh`` (2, 3), the hip's (its speed for a push-off law); ``Mi`` (3, 3) and
    ``Be`` (3, 5), the heel strike's ``Mi dq+ = Be dqe-`` (momenta of the pre-impact
    velocities, the trailing foot free and moving, projected on the post-impact coordinates
    with the swing heel pinned: ``Be = [B | sum J+^T m]``, ``B`` the passive heel strike's,
    so ``Be [dq; 0] = B dq`` to round-off); ``push`` (2,) the vector toe -> hip;
    ``relabel_q`` (3,) and ``relabel_rate`` (3, 3) the role swap."""
    qv = sp.Matrix(q)
    out = {}
    mode = {"heel": "heel_contact", "toe": "heel_off"}
    for pin, (ankle_lin, _off) in anchors.items():
        pre_bodies, _h, _a = bodies_from(ankle_lin)
        Mt, trans, mass = sp.zeros(3, 2), sp.zeros(3, 2), sp.Integer(0)
        for m_, lin, _i, _psi, name in pre_bodies:
            mass += m_
            Mt += m_ * _translation_rows(lin, q)
            trans += m_ * _translation_rows(post[name][1], post_q)
        hs = resets[f"heel_strike_{pin}"]
        b_new = post_q[2]
        trans = trans.subs(b_new, hs.relabel_q[2]).applyfunc(sp.factor_terms)
        De = flows[mode[pin]].M.row_join(Mt).col_join(Mt.T.row_join(mass * sp.eye(2)))
        pts = kin[pin]["points"]
        toe = pts["stance_toe"]
        out[pin] = {"De": De, "Jt": toe.jacobian(qv).row_join(sp.eye(2)),
                    "Jh": pts["hip"].jacobian(qv), "Mi": hs.Mi, "Be": hs.B.row_join(trans),
                    "push": pts["hip"] - toe, "relabel_q": hs.relabel_q,
                    "relabel_rate": hs.relabel_rate}
    return out
