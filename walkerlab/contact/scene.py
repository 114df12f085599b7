"""Build a contact walker from a validated scene and run it (the library side of ``contact-sim``).

The ``contact-sim`` stage, :mod:`walkerlab.contact.adjust`,
:mod:`walkerlab.analysis.contact_periodic` and the sweep points all go through these
functions, so a scene means the same contact run
everywhere.  This module never imports :mod:`walkerlab.stages` (dependencies point down).
"""

from __future__ import annotations

import numpy as np

from walkerlab.config import ContactSolverSettings, Scene

from .config import ContactSimSettings, TerrainSettings
from .model import ContactWalker

__all__ = ["ContactSceneError", "settings", "ideal_step_length", "build", "simulate_from",
           "named_trajectory"]


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


def build(scene: Scene, x_ideal: np.ndarray, n_steps: int):
    """ContactWalker of the scene (any walker with positive leg masses) with checkerboard
    patches from the ideal step length.

    Parameters
    ----------
    scene : Scene
    x_ideal : ndarray (2n,)
        Ideal fixed point (role order of the rigid walker, leg2 = stance) [rad, rad/s].
    n_steps : int
        Steps the run may take (sets how many patches are laid out).

    Returns
    -------
    walker : ContactWalker
    step_length : float
        Ideal step length [m] (patch spacing).

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
    probe = ContactWalker(contact=contact.to_si(), data=data,
                          knee_stop=contact.knee_stop.to_si())
    step_length = ideal_step_length(probe, x_ideal)
    return ContactWalker.from_settings(contact, terrain, step_length=step_length,
                                       n_steps=n_steps + 4, data=data), step_length


def simulate_from(scene: Scene, x_ideal: np.ndarray, period: float, rate_scale=None,
                  solver: ContactSolverSettings | None = None, strides: int | None = None):
    """Run the contact walker of ``scene`` from the ideal fixed point ``x_ideal``.

    Parameters
    ----------
    x_ideal : ndarray (4,)
        Ideal post-impact state (role order, leg2 = stance) [rad, rad/s].
    period : float
        Ideal step period [s] (sets the default simulated time).
    rate_scale : (float, float), optional
        Multipliers on the initial rates (default ``contact_sim.initial_rate_scale``).
    solver : ContactSolverSettings, optional
    strides : int, optional
        Strides to simulate (default ``contact_sim.n_strides``).

    Returns
    -------
    walker, result, x0, step_length
        :class:`ContactWalker`, :class:`~walkerlab.contact.simulate.ContactResult`, the
        initial state (8,), the ideal step length [m].
    """
    from .simulate import initial_state_from_ideal, simulate_contact

    _, _, cs, sv = settings(scene)
    sv = solver or sv
    n_strides = strides or cs.n_strides
    walker, step_length = build(scene, x_ideal, 2 * n_strides)
    scale = cs.initial_rate_scale if rate_scale is None else rate_scale
    x0 = initial_state_from_ideal(walker, *x_ideal, rate_scale=tuple(scale))
    t_final = cs.t_final_s or (2 * n_strides + 0.5) * period
    res = simulate_contact(
        walker, x0, t_final, method=sv.method, rtol=sv.rtol, atol=sv.atol,
        max_step=sv.max_step_s or np.inf, sample_rate_hz=cs.sample_rate_hz,
        pin_stance_until=cs.pin_stance_until, pin_time_s=cs.pin_time_s,
        fall_hip_height_m=cs.fall_hip_height_m, wall_time_limit_s=cs.wall_time_limit_s,
        max_heel_strikes=2 * n_strides + 1 if cs.stop_after_strides else None)
    return walker, res, x0, step_length


def named_trajectory(walker: ContactWalker, res, legs=("leg1", "leg2")):
    """A :class:`~walkerlab.contact.simulate.ContactResult` in the shared named layout of
    :class:`walkerlab.io.trajectory.NamedTrajectory` (stance leg from the heel strikes);
    coordinates ``<leg>_angle``/``<leg>_rate`` (kneed: ``<leg>_thigh_angle``, ...), points
    from the generated floating view (hip, bodies ``<leg>_<body>``, feet, knees)."""
    from walkerlab.io.trajectory import NamedTrajectory

    legs = list(legs)
    t = res.t
    stance = np.full(t.size, legs.index("leg2"))
    step = np.zeros(t.size, dtype=int)
    for k, (ths, leg) in enumerate(zip(res.heel_strike_times, res.heel_strike_legs)):
        m = t >= ths
        stance[m] = legs.index(leg)
        step[m] = k + 1
    X = res.x
    en = walker.energies(X)
    pts = {k: np.asarray(v) for k, v in walker.points(X).items()}
    coords, units = {}, {}
    nq = walker.nq
    for i, name in enumerate(walker.coordinate_names()):
        if not name.startswith(tuple(legs)):
            continue
        base = name.removesuffix("_angle")
        coords[f"{base}_angle"], units[f"{base}_angle"] = X[:, i], "rad"
        coords[f"{base}_rate"], units[f"{base}_rate"] = X[:, nq + i], "rad/s"
    return NamedTrajectory(
        time=t, legs=legs, coordinates=coords, units=units, stance_leg=stance,
        step_index=step, kinetic=en["kinetic"], potential=en["potential"], points=pts)
