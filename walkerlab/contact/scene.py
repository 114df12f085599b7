"""Build the contact walker of a validated scene (its model; running it is
:mod:`walkerlab.analysis.contact_sim`).

The ``contact-sim`` stage, the adjustment, :mod:`walkerlab.analysis.contact_periodic`, the
stability maps and the sweep points all build their walker here, so a scene means the same
contact model everywhere.  This module imports settings only (:mod:`walkerlab.config`).
"""

from __future__ import annotations

import numpy as np

from walkerlab.config import ContactSimSettings, Scene, SolverSettings, TerrainSettings

from .model import ContactWalker
from .rigid_limit import contact_si

__all__ = ["ContactSceneError", "build", "ideal_step_length", "settings"]


class ContactSceneError(ValueError):
    """The scene lacks a section the contact model needs (one-line message)."""


def settings(scene: Scene):
    """Contact sections of ``scene`` with defaults for the optional ones.

    Returns
    -------
    (ContactSettings, TerrainSettings, ContactSimSettings, SolverSettings)

    Raises
    ------
    ContactSceneError
        The scene has no ``contact`` section.
    """
    if scene.contact is None:
        raise ContactSceneError(f"scene '{scene.name}' has no 'contact' section, which the "
                                "contact model needs")
    return (scene.contact, scene.terrain or TerrainSettings(),
            scene.contact_sim or ContactSimSettings(),
            scene.contact_solver or SolverSettings.for_contact())


def ideal_step_length(walker: ContactWalker, x_ideal) -> float:
    """Advance [m] of the ideal gait per step, from its post-impact state ``x_ideal`` (role
    order of the rigid model): the distance between the two feet's contact points with the
    stance leg placed by :meth:`ContactWalker.link_state_from_ideal` (the foot-to-foot chord
    at heel strike; compass gait ``2 L sin((th_st - th_sw) / 2)``), plus, for arc feet of
    radius R, the roll ``R (th_st - th_sw)`` of the stance arc over the step (on the periodic
    gait the stance leg turns from the post-impact stance angle to the post-impact swing
    angle).  The checkerboard patches are spaced by it."""
    z = walker.link_state_from_ideal(x_ideal)
    x = walker.pinned_to_full(z, np.zeros(2))
    feet = walker.foot_positions(x)
    chord = float(np.hypot(*(feet[1] - feet[0])))
    if walker.structure.foot != "arc":
        return chord
    R = dict(zip(walker.structure.param_names, walker.walker_params))["R_foot"]
    m = walker.nq - 2  # link angles: leg1's, then leg2's; the foot is on each leg's last link
    return chord + R * (z[m - 1] - z[m // 2 - 1])


def build(scene: Scene, x_ideal: np.ndarray, n_steps: int, step_length_m: float | None = None):
    """ContactWalker of the scene (any walker with positive leg masses) with checkerboard
    patches from the ideal step length.

    Parameters
    ----------
    scene : Scene
    x_ideal : ndarray (2n,)
        Ideal fixed point (role order of the rigid walker, leg2 = stance) [rad, rad/s].
    n_steps : int
        Steps the run may take (sets how many patches are laid out).
    step_length_m : float, optional
        Patch spacing [m] instead of the ideal step length (a run started on the contact
        model's own periodic gait lays its patches at that gait's footfalls).

    Returns
    -------
    walker : ContactWalker
    step_length : float
        Ideal step length [m] (the patch spacing unless ``step_length_m`` is given).

    Raises
    ------
    ContactSceneError
        No ``contact`` section, or a walker with a massless body (one line).
    """
    from walkerlab.models.description import walker_data
    from walkerlab.models.floating import check_masses

    contact, terrain, _, _ = settings(scene)
    data = walker_data(scene.walker, scene.slope.phi_rad)
    try:
        check_masses(data.structure)
    except ValueError as err:
        raise ContactSceneError(f"scene '{scene.name}': {err}") from None
    si, knee = contact_si(contact)  # the contact law in SI: once per run
    probe = ContactWalker(contact=si, data=data, knee_stop=knee)
    step_length = ideal_step_length(probe, x_ideal)
    return probe.on_terrain(terrain, step_length=step_length_m or step_length,
                            n_steps=n_steps + 4), step_length

