"""Compiled chunks of a powered contact run: the passive loop's chunked path
(:mod:`walkerlab.integrate._cyrk`, CyRK's BDF on a numba ``cfunc``) for the actuation hook
(:class:`walkerlab.integrate.contact_powered.ActuationHook`) between its events.

The hook's discrete state (the stance leg; no push-off pulse running) is a parameter of
the compiled right-hand side: the generated module's ``powered_rhs`` kernel
(:mod:`walkerlab.models.contact.generated`) with the hip torque of a plain law (constant,
spring-damper about a rest angle, saturation: :class:`walkerlab.models.actuation.TorqueLaws`'
formula ``tau = c - K (delta - delta_0) - D ddelta``) evaluated in the same ``cfunc``, and the
work integrals integrated beside the state.  A chunk runs on the run's sample grid; the
hook's events (touchdown, the push-off pulse's start, a fall) are evaluated on its samples,
and the first sample interval where one of them changes sign in its direction (the rule of
:func:`scipy.integrate.solve_ivp`) is handed back to the hook, which locates the event in
it and applies the transition on its ``solve_ivp`` segments as before (the pulse itself runs
there too).

Used when the contact solver's method is a compiled one (``cyrk_bdf``) and the walker's
actuation fits: point or arc feet, straight legs, hip torques only, plain laws, not scaled
by the foot mass (:func:`chunk_rhs` answers None otherwise: the run stays on ``solve_ivp``).
The samples differ from the ``solve_ivp`` run's by the integrators' tolerances.
"""

from __future__ import annotations

import types

import numpy as np

__all__ = ["ChunkRHS", "chunk_rhs"]

#: fields appended to the packed data vector: has_tau, swing coordinate, stance coordinate,
#: push row (-1), push force, hip x, hip y coordinates; then per law c, K, D, rest angle,
#: limit (one law's worth of zeros without laws)
_HEAD, _LAW = 7, 5

_ADDRESSES: dict = {}  # (kernels module name, layout) -> cfunc address


def _plain_laws(acts) -> bool:
    from walkerlab.models.actuation import TorqueLaws

    # the scene's own laws (a replay swaps in its own callables or hip_torque: solve_ivp)
    if (type(acts.laws) is not TorqueLaws or acts.laws.torques != list(acts.spec.torques)
            or "hip_torque" in vars(acts)):
        return False
    for act in acts.spec.torques:
        law = act.law
        if (act.joint != "hip" or law.reference is not None or law.time_reference is not None
                or act.scaled_by != "none"):
            return False
    return True


def _build(kernels, sizes):
    """Address of the ``cfunc`` (CyRK's ``cyjit_sig``) of the powered right-hand side with
    the plain hip law; numba's disk cache keys it on the kernels module and the layout."""
    from CyRK.nb.numba_solver import cyjit_sig
    from numba import carray, cfunc

    kern = kernels.powered_rhs
    nq, npc, npar, n1, n2, nlaw = sizes
    nx, ny = 2 * nq, 2 * nq + 4
    a1 = 2 + npc
    a2 = a1 + npar
    a3 = a2 + n1
    a4 = a3 + n2
    size = a4 + _HEAD + _LAW * max(nlaw, 1) + 1

    @cfunc(cyjit_sig, cache=True)
    def rhs_c(dy, t, y, d):  # pragma: no cover - runs compiled
        dd = carray(d, (size,))
        yy = carray(y, (ny,))
        out = carray(dy, (ny,))
        x = np.empty(nx)
        for i in range(nx):
            x[i] = yy[i]
        sw, st = int(dd[a4 + 1]), int(dd[a4 + 2])
        tau = 0.0
        for j in range(nlaw):  # each law's torque, summed (TorqueLaws, saturate)
            b = a4 + _HEAD + _LAW * j
            tj = dd[b] - dd[b + 1] * (x[sw] - x[st] - dd[b + 3]) \
                - dd[b + 2] * (x[nq + sw] - x[nq + st])
            if tj > dd[b + 4]:
                tj = dd[b + 4]
            elif tj < -dd[b + 4]:
                tj = -dd[b + 4]
            tau += tj
        o = np.empty(ny)
        kern(x, dd[2:a1].copy(), dd[a1:a2].copy(), dd[a2:a3].copy(), dd[a3:a4].copy(),
             dd[a4] > 0.5, sw, st, tau, int(dd[a4 + 3]), dd[a4 + 4], int(dd[a4 + 5]),
             int(dd[a4 + 6]), o)
        for i in range(ny):
            out[i] = o[i]
        dd[size - 1] += 1.0

    return rhs_c.address


class ChunkRHS:
    """The compiled powered right-hand side of one walker (:func:`chunk_rhs`): its data
    vector per stance leg (:meth:`data`) and a kernels stand-in for
    :func:`walkerlab.integrate._cyrk.solve_chunk` (``kernels``)."""

    def __init__(self, walker):
        acts = walker.actuators
        self.walker = walker
        base = walker.pack()
        laws = [(a.law.constant_n_m, a.law.stiffness_n_m_per_rad, a.law.damping_n_m_s_per_rad,
                 a.law.rest_angle_rad, np.inf if a.max_torque_n_m is None else a.max_torque_n_m)
                for a in acts.spec.torques]
        from walkerlab.models.contact.generated import NPC

        sizes = (walker.nq, NPC, len(walker.walker_params), int(base[0]),
                 int(base[1]), len(laws))
        key = (walker.kernels.__name__, sizes)
        if key not in _ADDRESSES:
            _ADDRESSES[key] = _build(walker.kernels, sizes)
        name = f"{walker.kernels.__name__}_powered_{abs(hash(sizes))}"
        self.kernels = types.SimpleNamespace(__name__=name, build_cyrk=lambda: _ADDRESSES[key])
        self.base, self.laws = base[:-1], np.asarray(laws, float).ravel()
        self.has_tau = 1.0 if laws else 0.0
        self.source = acts.laws  # the laws compiled here (a run whose laws change: solve_ivp)

    def data(self, stance: int) -> np.ndarray:
        """The data vector with leg ``stance`` in stance (0: leg1, 1: leg2), no pulse."""
        acts = self.walker.actuators
        hx, hy = acts.hip
        ext = [self.has_tau, acts.leg[1 - stance], acts.leg[stance], -1.0, 0.0, hx, hy]
        if self.laws.size == 0:
            ext += [0.0] * _LAW
        return np.concatenate([self.base, ext, self.laws, [0.0]]).astype(np.float64)


def chunk_rhs(walker, method: str):
    """The compiled chunk right-hand side of a powered walker (:class:`ChunkRHS`), or None
    when the run stays on ``solve_ivp``: ``method`` not a compiled one
    (:data:`walkerlab.integrate._cyrk.CYRK_METHODS`) or an actuation the compiled kernel
    does not carry (knees, flat feet, joints other than the hip, phase or time tables, laws
    scaled by the foot mass)."""
    from ._cyrk import CYRK_METHODS

    acts = walker.actuators
    if method not in CYRK_METHODS:
        return None
    # the compiled kernel's actuation (point or arc feet, straight legs, hip torques only)
    kernel = getattr(acts, "compiled_rhs", lambda w: None)(walker)
    if kernel is None or not _plain_laws(acts):
        return None
    return ChunkRHS(walker)
