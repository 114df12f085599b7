"""Where a contact run starts, from the rigid gait: the floating walker's state placed on the
ground (:func:`initial_state_from_ideal`: the stance foot at its static penetration) and,
for a flat-footed walker, the rigid gait's mid-stance (:func:`rigid_mid_stance`).

The run itself is :mod:`walkerlab.analysis.contact.sim` (which re-exports these names); a
state is read by name (``walker.state_names()``), never by row.
"""

from __future__ import annotations

import numpy as np

from walkerlab.integrate.brentq import brentq
from walkerlab.integrate.ends import RunEnd
from walkerlab.integrate.rigid import simulate_steps
from walkerlab.integrate.solver import Solver
from walkerlab.models.contact.scene import ContactSceneError


def initial_state_from_ideal(walker, *x_ideal, rate_scale=(1.0, 1.0)) -> np.ndarray:
    """Floating-walker state from an ideal-model state (leg1 = swing, leg2 = stance).

    The stance foot (leg2) is placed at s = 0 at its static penetration
    ``(M g cos phi / k)^(1/e)`` [m] (along -n) and held at rest there: the hip follows from
    the stance leg's links (``walker.pinned_to_full``).  ``rate_scale`` multiplies leg1's
    and leg2's rates first.

    Parameters
    ----------
    *x_ideal : float
        The rigid model's state in the order of its ``state_names()``, e.g. ``theta1,
        theta2, dtheta1, dtheta2`` (swing / stance leg angles [rad] and rates [rad/s]) for
        the compass gait (``walker.link_state_from_ideal``).
    rate_scale : (float, float)
        Multipliers [-] on leg1's (swing) and leg2's (stance) rates.

    Returns
    -------
    ndarray (N,)
        Named by ``walker.state_names()``.
    """
    foot2 = -walker.static_penetration() * walker.normal
    z = walker.link_state_from_ideal(np.asarray(x_ideal, float).ravel(), rate_scale)
    return walker.pinned_to_full(z, foot2)


def rigid_mid_stance(scene, x_ideal: np.ndarray, plant) -> np.ndarray:
    """The rigid gait's state at its mid-stance, where a flat-footed contact run starts
    (``contact_sim.start: mid_stance``).

    One step of the rigid walker (:func:`walkerlab.models.registry.build_walker`) from
    ``x_ideal``, and the instant within it where the legs are parallel (``theta_swing =
    theta_stance``, the section of the contact step map,
    :mod:`walkerlab.analysis.contact.step_map`), found by ``scipy.optimize.brentq`` on the
    step's dense output.  There the
    stance foot is flat (foot flat: the sole on the ground, no impact under way): placed by
    :func:`initial_state_from_ideal` the contact walker starts as the rigid one is, heel
    and toe at the static penetration, the swing foot at its spring's rest angle.  From the
    post-impact state instead, the contact model starts its stance heel at rest in the
    middle of a heel strike (and its trailing foot off the ground) that the rigid view has
    already resolved by an impulse: on configs/flat_feet.yaml the next step is 8-9 % short
    (the rigid gait's period-2 mode excited), from mid-stance within 1.5 %.

    Parameters
    ----------
    scene : Scene
        A scene of a flat-footed walker (its ``solver`` integrates the step).
    x_ideal : ndarray, shape (2n,)
        The rigid walker's post-impact state (its ``state_names()`` order: swing, stance,
        stance ankle, their rates) [rad, rad/s].
    plant : walkerlab.walker.plant.Plant
        The scene's walker described once (the contact set-up's).

    Returns
    -------
    ndarray, shape (2n,)
        The state at mid-stance, in the same order [rad, rad/s].

    Raises
    ------
    walkerlab.models.contact.scene.ContactSceneError
        The step does not reach mid-stance (it falls first), or reaches it with the stance
        foot not flat (one line naming ``contact_sim.start``).
    """
    from walkerlab.models.registry import build_walker

    walker = build_walker(plant.with_(scene))
    seg = simulate_steps(walker, np.asarray(x_ideal, float), 1,
                         Solver.from_settings(scene.solver)).segments[0]
    if seg.termination != RunEnd.HEEL_STRIKE.value:
        raise ContactSceneError("contact_sim.start: mid_stance: the rigid step from the "
                                f"fixed point ends in {seg.termination} before its heel "
                                "strike")

    lay = walker.layout()
    i_swing, i_stance = lay.index("swing_angle"), lay.index("stance_angle")

    def apart(t):  # theta_swing - theta_stance [rad]
        state = seg.sample(np.array([t]))[:, 0]
        return float(state[i_swing] - state[i_stance])

    t0, t1 = seg.t_start, seg.t_end
    if not apart(t0) < 0.0 < apart(t1):
        raise ContactSceneError("contact_sim.start: mid_stance: the rigid step has no "
                                "mid-stance (its legs are never parallel)")
    tm = brentq(apart, t0, t1, xtol=1e-13, rtol=1e-13)
    mode = next((name for name, ta, tb, _g in seg.phase_log if ta <= tm <= tb), "")
    if not mode.startswith("foot_flat"):
        raise ContactSceneError(f"contact_sim.start: mid_stance: the rigid gait is in "
                                f"{mode or '?'} at its mid-stance, not foot flat: start "
                                "from its fixed point (start: ideal)")
    return seg.sample(np.array([tm]))[:, 0]
