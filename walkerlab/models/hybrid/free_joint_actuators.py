"""Joint torques on a free-jointed biped (``knee.lock: free``; with a hinged torso the
five-link biped of Westervelt, Grizzle & Koditschek 2003, IEEE TAC 48(1):42-56): its hips
and knees driven by torque laws, e.g. PD tracking of references of the phase variable
(virtual constraints).

Every coordinate is a link's absolute angle (:mod:`walkerlab.codegen.legged`), so a
joint's angle ``delta = q[second] - q[first]`` (:data:`walkerlab.config.actuation.
FIVE_LINK_JOINTS`) and its torque's generalised force is ``tau`` on the second link's row and
``-tau`` on the first's: ``B`` has one column ``e_second - e_first`` per actuator, and the flow
gains ``M^-1 B tau`` (:func:`walkerlab.models.hybrid.actuated.actuate` adds it, as on every
actuated walker).  The phase variable ``s`` is the virtual stance leg's angle (hip to
stance foot, from the generated ``leg_angles``), ``ds`` its rate; it decreases through a
step.  ``joint: hip`` acts between the two thighs.
The push-off impulse (Kuo 2002) acts at the trailing foot along the virtual trailing leg
(foot to hip), through the generated extended impact (``De, E``;
:class:`walkerlab.models.hybrid.push_off.PushOffTransition`), as on every walker.

The actuators are the generic :class:`walkerlab.models.hybrid.actuators.Actuators`;
here only what a free-jointed walker adds (one spline for laws sharing a table).
Everything is complex-safe (the generated ``leg_angles`` and ``matrices`` are), so the flow's
Jacobian is taken by the complex step as on the straight-legged walkers.
"""

from __future__ import annotations

from walkerlab.models.actuation import shared_phase_table as _shared_phase_table
from walkerlab.models.hybrid.actuators import Actuators

__all__ = ["FiveLinkActuators", "five_link_actuators"]


#: a free-jointed walker's actuators are the generic ones (the name kept for its users)
FiveLinkActuators = Actuators


def five_link_actuators(data, spec, roles, push_off: bool = False) -> FiveLinkActuators:
    """The actuators of a free-jointed walker, after checking what it can carry.

    Parameters
    ----------
    data : walkerlab.walker.description.WalkerData
        Of a free-jointed kind, ``free_joints`` or ``hinged_torso``
        (:attr:`walkerlab.walker.description.Structure.kind`).
    spec : walkerlab.config.actuation.Actuation
    roles : tuple of str
        The walker's roles.
    push_off : bool
        The caller carries the push-off (the rigid view:
        :func:`walkerlab.models.hybrid.actuated.actuate`); False (the contact view's
        :class:`walkerlab.models.contact.joint_torques.JointTorqueActuators`, which has no
        pulse for it yet): a push-off is refused in one line rather than dropped.

    Returns
    -------
    FiveLinkActuators

    Raises
    ------
    ValueError
        A joint the walker does not have (naming the joints it has), a torque per foot mass,
        a push-off the caller does not carry (one line, naming the field).
    """
    from walkerlab.codegen.cache import functions

    if spec.ankle_push_off is not None:  # point feet (as leg_masses.massless_limit says)
        raise ValueError("walker.actuation.ankle_push_off: needs flat feet (leg.foot.kind: "
                         "flat); point feet take push_off, the impulse along the leg")
    if spec.push_off is not None and not push_off:
        raise ValueError("walker.actuation.push_off: the free-jointed step's phase-law replay "
                         "(walkerlab optimize) carries the joint torques alone; give the "
                         "push-off to fixedpoint, simulate or contact-sim")
    for i, t in enumerate(spec.torques):
        if t.scaled_by != "none":
            raise ValueError(f"walker.actuation.torques.{i}.scaled_by: foot_mass is for "
                             "walkers whose legs are massless")
    acts = Actuators(spec, functions(data), len(roles), False, float(data.total_mass_kg))
    if spec.push_off is not None:  # every link's swap from the generated reset
        acts.push.swap_from_reset()
    shared = _shared_phase_table(spec.torques)
    if shared is not None:  # one spline for every law's reference: 2 calls, not 2k
        acts.laws.refs = shared
    return acts
