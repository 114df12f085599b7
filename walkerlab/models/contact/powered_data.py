"""The data vector of a powered contact walker's compiled right-hand side: its actuators as
numbers (:mod:`walkerlab.models.contact.powered_source`, the block's layout).

One :class:`PoweredData` per run: what does not change (the passive data, each stance's
joint columns, the laws, the ankle and the ledger's map) is packed once; :meth:`PoweredData.
data` fills in the run's discrete state (stance leg, the time the step began, a push-off
pulse, the ankle push-off) between events.
"""

from __future__ import annotations

import numpy as np

from .powered_source import A_HEAD, W_INDEX

__all__ = ["PoweredData", "powered_data"]


def _laws(acts):
    """The walker's joint-torque laws as a law block (:meth:`TorqueLaws.packed`), or None
    when they are not data (a replay's Python callables, a torque function set on the
    instance)."""
    if "hip_torque" in vars(acts):  # a per-stance law swapped in by a replay
        return None
    laws = acts.joints.laws if hasattr(acts, "joints") else acts.laws
    if not laws:
        return np.array([3.0, 0.0, 0.0])
    packed = getattr(laws, "packed", None)
    block = None if packed is None else packed()
    return None if block is None else np.asarray(block, float)


class PoweredData:
    """The compiled right-hand side's data of one powered contact walker.

    Parameters
    ----------
    walker : ContactWalker
        With ``actuators`` (:class:`~walkerlab.models.contact.actuation.ContactActuators` or
        :class:`~walkerlab.models.contact.joint_torques.JointTorqueActuators`).
    laws : ndarray
        The law block (:func:`powered_data` reads it from the actuators).
    held_force : bool
        The run carries a generalised force held from outside (:attr:`held`, per stance
        leg; a Gymnasium action's torques) and its positive and negative work integrals
        after the walker's ``work_names``.
    """

    def __init__(self, walker, laws: np.ndarray, held_force: bool = False):
        acts = walker.actuators
        self.walker, self.laws = walker, laws
        n = walker.nq
        names = tuple(walker.contact_names())
        self.base = walker.pack()[:-1]
        k = int(laws[1])
        free = hasattr(acts, "joints")  # a free-jointed biped: role-ordered joint columns
        self.B, self.phase = [], []
        for stance in (0, 1):
            if free:
                B = np.zeros((n, k))
                B[acts.index[stance]] = acts.joints.B
                self.phase.append((1.0, float(names.index(f"leg{stance + 1}"))))
            else:
                B = np.asarray(acts.B[stance], float).reshape(n, k) if k else np.zeros((n, 0))
                self.phase.append((0.0, float(acts.leg[stance])))
            self.B.append(B.ravel())
        self.push_rows = (acts.push_row(walker, 0), acts.push_row(walker, 1))
        foot = getattr(acts, "foot", None)
        head = np.zeros(A_HEAD)
        head[1], head[2] = n, k
        head[7:9] = acts.hip
        ankle = getattr(acts, "ankle", None)
        if ankle is not None:
            head[12:15] = (ankle.stiffness_n_m_per_rad, ankle.rest_angle_rad, ankle.constant_n_m)
        if foot is not None:  # flat feet: the dampers' term, the pulse's ankle hold
            p = dict(zip(walker.data.structure.param_names, walker.data.params))
            head[18] = float(p.get("c_ankle", 0.0))
            head[19] = sum(float(p[f"c_s{i}"]) for i in range(len(walker.data.structure.springs)))
            head[20:26] = (*foot, *acts.ankle_leg, *acts.leg)
            head[26] = 1.0
        self.foot = foot
        self.work_names = tuple(acts.work_names) + (
            ("action_positive", "action_negative") if held_force else ())
        works = [W_INDEX[w] for w in self.work_names]
        head[34] = 1.0 if held_force else 0.0
        #: the held generalised force (nq,) [N, N m] with leg1, leg2 in stance
        self.held = (np.zeros(n), np.zeros(n))
        head[27] = len(works)
        self.head = np.concatenate([head, works])
        self.ny = 2 * n + len(works)
        #: the generated module of the compiled right-hand side: the walker's contact
        #: kernels, or, for actuators with a compiled law of their own (virtual
        #: constraints: ``powered_module``), a module calling it before them
        self.module = getattr(acts, "powered_module", lambda w: w.kernels)(walker)
        #: ``(t, y, d, dy)``: the compiled right-hand side as a numba function (the cfunc's
        #: body; ``module.build_cyrk_powered()`` gives the cfunc's address)
        self.rhs = self.module.powered_packed
        # the data vector but its discrete state and held force, laid out once (data() fills
        # those in): ``[base, block (head, B leg1, B leg2, held leg1, held leg2, laws),
        # scratch, counter]``
        a, nh = self.base.size, self.head.size
        self._block = a  # where the block starts
        self._held_at = a + nh + self.B[0].size + self.B[1].size
        h = self.head.copy()
        h[3:5] = self.phase[0]
        h[31] = self.phase[1][1]
        h[5], h[6] = -1.0, 0.0
        block = np.concatenate([h, self.B[0], self.B[1], *self.held, self.laws])
        block[0] = block.size
        scratch = np.zeros(n + 14)  # the compiled call's force and powers
        self._template = np.concatenate([self.base, block, scratch, [0.0]]).astype(np.float64)

    def data(self, stance: int, t_origin: float, push: tuple[int, float] | None = None,
             ankle: bool = False, switch_s: float = np.inf, ghost: bool = False
             ) -> np.ndarray:
        """The data vector with leg ``stance`` in stance (0: leg1, 1: leg2), the step begun
        at ``t_origin`` [s], a push-off pulse ``(trailing leg, force [N])`` on (None: off),
        the ankle push-off on or off, and a heel strike at ``switch_s`` [s] (the other leg
        in stance from then, inf: none); ``ghost``: the swing foot carries no contact
        force once it is ``min_step_m`` ahead of the stance foot (the swing leg's after the
        switch, or with none pending: :mod:`walkerlab.models.contact.powered_source`);
        shape (len,), float64, the call counter 0."""
        acts = self.walker.actuators
        out = self._template.copy()
        h = out[self._block:]  # the block's head (a view)
        h[28:31] = (stance, switch_s, t_origin)
        h[35] = float(acts.min_step_m) if ghost else -1.0
        if push is not None:
            trailing = int(push[0])
            h[5], h[6] = self.push_rows[trailing], float(push[1])
            if self.foot is not None:
                h[15:18] = (1.0, self.foot[trailing], acts.ankle_leg[trailing])
            elif self.walker.dim == 3:  # the trailing foot holds its spin (3D)
                h[15] = 2.0
        if ankle:
            h[9:12] = (1.0, self.foot[0], acts.ankle_leg[0])
            h[32:34] = (self.foot[1], acts.ankle_leg[1])
        k, n = self._held_at, self.walker.nq
        out[k:k + n], out[k + n:k + 2 * n] = self.held
        return out


def powered_data(walker, held_force: bool = False) -> PoweredData | None:
    """The compiled data of ``walker``'s actuators (:class:`PoweredData`; ``held_force`` as
    there), or None when its torque laws are not data (a replay's Python callables: the run
    stays on :func:`scipy.integrate.solve_ivp`)."""
    laws = _laws(walker.actuators)
    return None if laws is None else PoweredData(walker, laws, held_force)
