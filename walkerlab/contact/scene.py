"""Build the contact walker of a validated scene (its model; running it is
:mod:`walkerlab.analysis.contact_sim`).

The ``contact-sim`` stage, the adjustment, :mod:`walkerlab.analysis.contact_periodic`, the
stability maps and the sweep points all build their walker here, so a scene means the same
contact model everywhere.  This module imports settings only (:mod:`walkerlab.config`).
"""

from __future__ import annotations

import numpy as np

from walkerlab.config import ContactSimSettings, ContactSolverSettings, Scene, TerrainSettings

from .model import ContactWalker

__all__ = ["IDEAL_ROLES", "ContactSceneError", "build", "ideal_step_length", "settings"]

#: Names of the ideal (rigid compass-gait) state the contact walker starts from, in the
#: order of an ideal state vector (the rigid walker's ``state_names()``).
IDEAL_ROLES = ("swing_angle", "stance_angle", "swing_rate", "stance_rate")


class ContactSceneError(ValueError):
    """The scene lacks a section the contact model needs (one-line message)."""


def settings(scene: Scene):
    """Contact sections of ``scene`` with defaults for the optional ones.

    Returns
    -------
    (ContactSettings, TerrainSettings, ContactSimSettings, ContactSolverSettings)

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
            scene.contact_solver or ContactSolverSettings())


def ideal_step_length(leg_length_m: float, x_ideal, names=IDEAL_ROLES) -> float:
    """Step length [m] of the ideal gait from its post-impact state ``x_ideal`` named by
    ``names``: ``2 L sin((th_st - th_sw) / 2)`` (foot-to-foot chord at heel strike)."""
    x = dict(zip(names, np.asarray(x_ideal, float)))
    th_sw, th_st = x["swing_angle"], x["stance_angle"]
    return 2 * leg_length_m * np.sin((th_st - th_sw) / 2)


def build(scene: Scene, x_ideal: np.ndarray, n_steps: int):
    """ContactWalker of the scene with checkerboard patches from the ideal step length.

    Parameters
    ----------
    scene : Scene
    x_ideal : ndarray (4,)
        Ideal fixed point, named by :data:`IDEAL_ROLES` [rad, rad/s].
    n_steps : int
        Steps the run may take (sets how many patches are laid out).

    Returns
    -------
    walker : ContactWalker
    step_length : float
        Ideal step length [m] (patch spacing).
    """
    contact, terrain, _, _ = settings(scene)
    w = scene.walker
    step_length = ideal_step_length(w.leg_length_m, x_ideal)
    return ContactWalker.from_settings(
        contact, terrain, step_length=step_length, n_steps=n_steps + 4, L=w.leg_length_m,
        m=w.leg_mass_kg, MH=w.hip_mass_kg, a=w.leg_mass_from_foot_m, g=w.gravity_m_per_s2,
        phi=scene.slope.phi_rad), step_length
