"""Independent round-foot compass gait with Kuo's push-off (Kuo 2002's pre-emptive impulse
before the plastic heel strike), on the prototype of ``round_feet_reference.py`` (its own
sympy Lagrangian, root finder and integrator; no walkerlab code).

Transition, in the prototype's extended coordinates ``qe = (th_sw, th_st, xf, yf)`` (the whole
walker translated by ``(xf, yf)``, mass matrix ``Me``):

1. push-off: an impulse ``P`` [N s] on the stance arc's *material* point at the contact (its
   velocity ``v_centre + w_st x (-R n)``, Jacobian ``Js`` derived here symbolically), along
   ``e`` from that contact point to the hip: ``Me (dqe' - dqe-) = Js^T P e``;
2. heel strike: plastic, about the swing arc's material contact point (the prototype's
   ``E``), the trailing foot free: ``[Me -E^T; E 0] [dqe+; F] = [Me dqe'; 0]``;
3. the roles swap.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache

import numpy as np
import sympy as sp

from ._lagrange import lam
from .round_feet_reference import RoundFeetReference, _symbolic


@cache
def _stance_material_jacobian():
    """``Js`` (2, 4): the stance arc's material contact point's velocity Jacobian in the
    extended coordinates, and the direction vector contact -> hip (2,) (both lambdified in
    ``(q, par)``)."""
    q, dq, par, *_rest, pts = _symbolic()
    g, L, R, M, m, c, Ileg, gm = par
    xf, yf = sp.symbols("xf yf", real=True)
    qe = sp.Matrix([*q, xf, yf])
    n = sp.Matrix([sp.sin(gm), sp.cos(gm)])
    off = sp.Matrix([xf, yf])
    Jc = (pts["stance_centre"] + off).jacobian(qe)  # the arc's centre
    w = sp.Matrix([q[1]]).jacobian(qe)               # the stance arc turns with its leg
    r = -R * n                                       # centre -> material contact point
    Js = Jc + sp.Matrix([[-r[1]], [r[0]]]) * w       # v = v_c + w x r
    d = pts["hip"] - pts["stance_contact"]
    return lam((q, par), Js), lam((q, par), d)


@dataclass
class PushedRoundFeet(RoundFeetReference):
    """The round-foot prototype with a push-off of ``P`` [N s] before every heel strike."""

    P: float = 0.0

    def impact(self, x, return_extra=False):
        q, dq = np.asarray(x[:2], float), np.asarray(x[2:], float)
        Me = self._f["Me"](q, self._par())
        E = self._f["E"](q, self._par())
        Jsf, df = _stance_material_jacobian()
        Js, d = Jsf(q, self._par()), df(q, self._par()).ravel()
        e = d / np.linalg.norm(d)
        dqe = np.concatenate([dq, [0.0, 0.0]])
        dqe_po = dqe + np.linalg.solve(Me, Js.T @ (self.P * e))
        A = np.zeros((6, 6))
        A[:4, :4], A[:4, 4:], A[4:, :4] = Me, -E.T, E
        sol = np.linalg.solve(A, np.concatenate([Me @ dqe_po, [0.0, 0.0]]))
        x_plus = np.array([q[1], q[0], sol[1], sol[0]])
        if return_extra:
            return x_plus, {"impulse": sol[4:], "dqe_po": dqe_po, "dqe_plus": sol[:4],
                            "Me": Me, "Js": Js, "e": e}
        return x_plus
