"""Virtual constraints as feedback in the compliant-contact view: the rigid view's
computed torque
(:class:`walkerlab.models.virtual_constraints.VirtualConstraintController`) evaluated at
the contact walker's role state.

The same controller, evaluated by the same code
-----------------------------------------------
A floating state with leg ``stance`` in stance is a rigid state in role order
(:meth:`walkerlab.models.contact.joint_torques.JointTorqueActuators.role_state`: the link
angles and their rates; the hip's translation left out).  At that role state the torques
are the rigid closed loop's (Westervelt, Grizzle & Koditschek 2003, IEEE TAC 48(1):42-56,
Sec. IV; Isidori 1995)::

    u = (L_g L_f h)^-1 (-L_f^2 h - kp y - kd y'),   saturated at max_torque_n_m,

with the rigid model's ``M, C, G`` at the role state: the outputs ``y = h0(q) - hd(s)`` on
the floating model's link angles, the phase ``theta`` (the virtual stance leg's angle, or the
scene's combination of the coordinates) of the stance foot in contact (the run's discrete
state, switched at each heel strike by :mod:`walkerlab.integrate.contact_powered`).  The
rigid model pins the stance foot; the contact model's foot is held by a stiff spring, so the
computed torque linearises the contact walker's outputs up to the foot's compliance.  The
torques act as :class:`~walkerlab.models.contact.joint_torques.JointTorqueActuators`' (``+tau``
on a joint's second link, ``-tau`` on its first; the same ``B``).

Compiled
--------
On the compiled right-hand side (:mod:`walkerlab.models.contact.powered_source`, CyRK's BDF:
``contact_solver.method: cyrk_bdf``) the law is data too: :meth:`VirtualConstraintLaw.packed`
gives a law block of ``k`` constant torques (plain laws, no gains, no saturation of their
own) followed by the controller's numbers (the *VC tail*: role-state indices per stance
leg, ``B``, the Bezier coefficients, ``theta+``, ``theta- - theta+``, ``kp``, ``kd``, the
torque limit), and a right-hand side generated per pair of (walker kernels, compiled
controller) (:func:`compiled_rhs_module`, cached in the user cache like every generated
module) evaluates, before the powered right-hand side, the controller's compiled ``law``
(:func:`walkerlab.codegen.virtual_constraints.compiled_controller`: the same function the
rigid view and :meth:`VirtualConstraintJointTorques.torques` call) at the role state and
writes its torques into those constant laws.  So the torques, their generalised force
``B u`` and their power ``u . B^T dq`` are the Python route's (the same ``law``, the same
block arithmetic: a test holds them equal).  Where the law is not compiled (no numba, a
Bezier degree of 16 or more) :meth:`VirtualConstraintLaw.packed` is None and the run stays
on :func:`scipy.integrate.solve_ivp` (as with any other ``contact_solver`` method: RABBIT's
scenes ask LSODA).
"""

from __future__ import annotations

import hashlib

import numpy as np

from walkerlab import codestore
from walkerlab.models.contact.joint_torques import JointTorqueActuators
from walkerlab.models.contact.powered_source import CYRK_POWERED_SOURCE
from walkerlab.models.virtual_constraints import VirtualConstraintController

__all__ = ["VirtualConstraintJointTorques", "VirtualConstraintLaw", "compiled_rhs_module",
           "vc_tail"]


class VirtualConstraintLaw:
    """The law block of the virtual constraints (module docstring, "Compiled").

    Parameters
    ----------
    controller : VirtualConstraintController
    index : sequence of ndarray, optional
        Per stance leg (0: leg1, 1: leg2) the floating coordinate of each role coordinate
        (n,) (:attr:`JointTorqueActuators.index`); without it there is no block.
    """

    def __init__(self, controller: VirtualConstraintController, index=None):
        self.controller = controller
        self.index = index

    def __len__(self) -> int:
        return len(self.controller.joints)

    def packed(self):
        """The law block (L,) float64: ``k`` constant torques (:func:`walkerlab.codegen.
        torque_law.pack_laws`, kind plain, zero) and the VC tail (module docstring,
        :func:`vc_tail`); None where the controller's law is not compiled or no role
        index is given (the run stays on solve_ivp,
        :func:`walkerlab.models.contact.powered_data.powered_data`)."""
        from walkerlab.codegen.torque_law import PLAIN, pack_laws

        c = self.controller
        if self.index is None or c.compiled_module() is None:
            return None
        laws = pack_laws([(PLAIN, 0.0, 0.0, 0.0, 0.0, None, None, None)] * len(self))
        return np.concatenate([laws, vc_tail(c, self.index)])

    def each(self, deltas, ddeltas, s, ds, t_step):
        """Not defined on the joints' angles alone.

        Raises
        ------
        TypeError
            Always: the computed torque needs the role state
            (:meth:`VirtualConstraintJointTorques.torques`).
        """
        raise TypeError("the virtual constraints' computed torque needs the whole role "
                        "state (VirtualConstraintJointTorques.torques)")


class VirtualConstraintJointTorques(JointTorqueActuators):
    """The virtual-constraint controller of one free-jointed contact walker (module
    docstring; the interface of :class:`JointTorqueActuators`).

    Parameters
    ----------
    data : WalkerData
        A free-jointed walker (a hinged torso on straight legs or free knees), point feet.
    spec : walkerlab.config.actuation.Actuation
        With ``virtual_constraints`` (no other actuators: the config refuses them).
    coordinates : tuple of str
        The floating coordinates (:func:`walkerlab.codegen.floating.coordinate_names`).
    pulse_s : float
        Unused (no push-off with virtual constraints); :class:`JointTorqueActuators`'.

    Raises
    ------
    ValueError
        As :class:`VirtualConstraintController` (one line naming the key).
    """

    def __init__(self, data, spec, coordinates, pulse_s: float = 0.0):
        from walkerlab.codegen.cache import functions
        from walkerlab.config.actuation import Actuation

        vc = spec.virtual_constraints
        ctrl = VirtualConstraintController(vc, functions(data), data.structure, data.params)
        # the joints' columns and roles as the rigid view's (one zero law per joint: the
        # laws are replaced by the controller below)
        joints = Actuation(torques=[{"joint": j, "law": {}} for j in ctrl.joints])
        super().__init__(data, joints, coordinates, pulse_s)
        self.spec = spec
        #: the rigid view's controller (:class:`VirtualConstraintController`)
        self.controller = ctrl
        self.joints.laws = VirtualConstraintLaw(ctrl, self.index)
        if not np.allclose(self.joints.B, ctrl.B, rtol=0.0, atol=1e-12):
            raise ValueError("walker.actuation.virtual_constraints.joints: the contact view's "
                             "joint columns differ from the controller's B")

    def powered_module(self, walker):
        """The generated module of ``walker``'s compiled right-hand side with this
        controller (:func:`compiled_rhs_module`), or its kernels where the law is not
        compiled (then :meth:`VirtualConstraintLaw.packed` is None and no compiled run is
        made)."""
        law = self.controller.compiled_module()
        return walker.kernels if law is None else compiled_rhs_module(walker.kernels, law)

    def torques(self, x, stance: int, t_step: float = 0.0) -> np.ndarray:
        """The computed torques (k,) [N m] (``controller.joints`` order) at the floating
        state ``x`` (2 nq,) with leg ``stance`` (0: leg1, 1: leg2) in stance: the rigid
        closed loop's at the role state; ``t_step`` unused (the law is of the state)."""
        return np.real(self.controller.torques(self.role_state(np.asarray(x, float), stance)))


def vc_tail(controller: VirtualConstraintController, index) -> np.ndarray:
    """The controller's numbers after the law block's constant torques (module docstring):
    ``[n, k, M + 1, theta+, theta- - theta+, kp, kd, limit (-1: none), index[0] (n),
    index[1] (n), B (n k, row-major), alpha (k (M + 1), row-major)]``, float64.

    Parameters
    ----------
    controller : VirtualConstraintController
    index : sequence of ndarray
        Per stance leg the floating coordinate of each of the ``n`` role coordinates.
    """
    d = controller.design
    B = np.asarray(controller.B, float)
    alpha = np.asarray(d.alpha, float)
    n, k = B.shape
    limit = -1.0 if controller.limit is None else float(controller.limit)
    head = [n, k, alpha.shape[1], d.theta_plus, d.theta_minus - d.theta_plus,
            controller.kp, controller.kd, limit]
    return np.concatenate([np.asarray(head, float), np.asarray(index[0], float),
                           np.asarray(index[1], float), B.ravel(), alpha.ravel()])


#: The right-hand side of :func:`compiled_rhs_module` (``{kernels}``, ``{law}``: the module
#: names of the walker's generated contact kernels and of the compiled controller).
_RHS_SOURCE = '''# walkerlab: a contact walker's compiled right-hand side under virtual constraints
# (walkerlab.models.contact.virtual_constraints.compiled_rhs_module)
import numpy as np
from numba import carray, njit

from {kernels} import A_HEAD, D_N1, D_N2, D_P, HEAD, NP, NQ, powered_ny, powered_size
from {kernels} import powered_packed as _kernels_powered_packed
from {law} import law as _vc_law


@njit(cache=True, error_model="numpy")
def vc_torques(t, y, d):
    """The controller's torques at the role state of ``y`` (the stance leg of the data's
    actuation block at ``t``) into the law block's constant torques."""
    a3 = D_P + NP + int(d[D_N1]) + int(d[D_N2])
    A = d[a3:a3 + int(d[a3])]
    k = int(A[2])
    st = int(A[28])
    if t >= A[29]:
        st = 1 - st
    b = A_HEAD + int(A[27]) + 2 * NQ * (k + 1)
    v = b + int(A[b])  # the VC tail
    n = int(A[v])
    m1 = int(A[v + 2])
    xr = np.empty(2 * n)
    o = v + 8 + st * n
    for i in range(n):
        c = int(A[o + i])
        xr[i] = y[c]
        xr[n + i] = y[NQ + c]
    o = v + 8 + 2 * n
    B = A[o:o + n * k].copy().reshape((n, k))
    alpha = A[o + n * k:o + n * k + k * m1].copy().reshape((k, m1))
    u, _acc = _vc_law(xr, alpha, A[v + 3], A[v + 4], B, A[v + 5], A[v + 6], A[v + 7])
    for j in range(k):
        A[b + 3 + HEAD * j + 1] = u[j]


@njit(cache=True, error_model="numpy")
def powered_packed(t, y, d, dy):
    """The kernels' powered_packed with the virtual constraints' torques in its law block
    (``d`` as that function's)."""
    vc_torques(t, y, d)
    _kernels_powered_packed(t, y, d, dy)


''' + CYRK_POWERED_SOURCE


def compiled_rhs_module(kernels, law_module):
    """The generated module of a contact walker's compiled right-hand side under virtual
    constraints (module docstring, "Compiled"), with the kernels' interface:
    ``powered_packed(t, y, d, dy)`` (the walker's, after the controller's torques) and
    ``build_cyrk_powered()`` (its CyRK cfunc's address), for the walker's generated
    contact module ``kernels`` and the controller's compiled module ``law_module``
    (:meth:`VirtualConstraintController.compiled_module`); file
    ``<hash>_vcrhs.py`` in the user cache, its hash of both modules' names (each a hash of
    its own source) and this module's source; numba's machine code cached there too."""
    source = _RHS_SOURCE.format(kernels=kernels.__name__, law=law_module.__name__)
    h = hashlib.sha256(source.encode())
    h.update(codestore.source_hash(__file__).encode())
    tag = h.hexdigest()[:24]
    return codestore.import_generated(f"{tag}_vcrhs.py", f"walkerlab_vcrhs_{tag}",
                                      lambda: source)
