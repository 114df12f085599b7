"""The collocation's starting step: one step of the scene's gait (the fixed point), of a
continuation branch's gait at a parameter value, or another optimisation's result
(``optimize.initial_guess``); or, for a walker with no gait of its own (a passive walker on
level ground), a step built from the targets (:func:`target_step`, as Kelly 2017 builds
the five-link biped's)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from walkerlab.config.actuation import Actuation, PushOff
from walkerlab.config.studies import GuessFromArtifact
from walkerlab.integrate.rigid import simulate_steps
from walkerlab.integrate.solver import Solver
from walkerlab.models.hybrid.actuated import actuate

__all__ = ["has_target", "read_guess", "simulated_step", "starting_segment", "starting_step",
           "stairs_targets", "target_numbers", "target_step"]

#: the swing leg's forward swing over the straight-line guess, as a share of the step's
#: half-angle (a bump ``b sin(pi s)``: the swing foot clears level ground mid-step)
SWING_BUMP = 0.5


def has_target(o) -> bool:
    """The ``optimize`` section ``o`` gives a target speed, step length or step period."""
    return any(t is not None for t in (o.target_speed_m_per_s, o.target_step_length_m,
                                       o.target_step_period_s))


def stairs_targets(scene):
    """``scene``'s ``optimize`` section with, on stairs, the tread's depth as the target
    step length when none is given (a gait on stairs advances one tread a step:
    :mod:`walkerlab.optimal.transcription.landing`); else the section itself."""
    o, t = scene.optimize, scene.terrain
    if t is None or t.kind != "stairs" or o.target_step_length_m is not None:
        return o
    return o.model_copy(update={"target_step_length_m": float(t.tread_m)})


def target_numbers(o, leg_length_m: float) -> tuple[float, float]:
    """The step length [m] and period [s] of a step built from the ``optimize`` section
    ``o``'s targets: the two given, or one with the speed; a speed alone: a step of
    ``0.625 leg_length`` (Kelly's 0.5 m on RABBIT's 0.8 m legs) at that speed.

    Raises
    ------
    ValueError
        Only a step length or only a step period given (one line: the other, or the speed).
    """
    v, d, t = o.target_speed_m_per_s, o.target_step_length_m, o.target_step_period_s
    if d is None and t is not None and v is None or d is not None and t is None and v is None:
        raise ValueError("optimize: a step built from the targets needs two of "
                         "target_step_length_m, target_step_period_s, target_speed_m_per_s "
                         "(or the speed alone)")
    if d is None:
        d = v * t if t is not None else 0.625 * leg_length_m
    if t is None:
        t = d / v
    return float(d), float(t)


def target_step(scene, walker, samples: int = 400):
    """A starting step of a straight-legged walker with no gait of its own, from the targets
    (:func:`target_numbers`; on stairs the step is the tread, :func:`stairs_targets`): the
    legs swap at constant rates between the heel-strike
    postures of the target step - stance leg from ``alpha - phi`` to ``-alpha - phi``,
    swing leg the mirror, ``sin alpha = D / (2 l)``, ``phi`` the slope (angles from the
    vertical, positive with the foot ahead; Garcia et al. 1998's post-impact posture) -
    the swing leg swung ahead by ``SWING_BUMP alpha sin(pi s)`` (``s = t / T``) so its
    foot clears level ground, zero hip torque; the free push-off starts at Kuo's (2002)
    ``P = M v tan(alpha)`` (``v = 2 alpha l / T`` the hip's speed), capped at
    ``optimize.push_off_max_n_s``.  Kelly (2017) starts the five-link biped alike.

    Parameters
    ----------
    scene : Scene
        With ``optimize`` targets.
    walker : HybridWalker
        The scene's rigid walker (straight legs, point feet).
    samples : int

    Returns
    -------
    t : ndarray (samples,) [s]; x : ndarray (samples, 2n) in ``walker.state_names()``
    order; u : None; push_off : float [N s] (the free push-off's start) or None (fixed)

    Raises
    ------
    ValueError
        Too few targets (:func:`target_numbers`), a step longer than the legs allow.
    """
    o = stairs_targets(scene)
    length = float(walker.params["leg_length_m"])
    D, T = target_numbers(o, length)
    if D >= 2.0 * length:
        raise ValueError(f"optimize.target_step_length_m: {D:g} m is more than the legs "
                         f"span ({2 * length:g} m)")
    alpha, phi = float(np.arcsin(D / (2.0 * length))), float(walker.slope_rad)
    t = np.linspace(0.0, T, samples)
    s = t / T
    bump, dbump = SWING_BUMP * alpha, SWING_BUMP * alpha * np.pi / T
    stance, dstance = alpha * (1.0 - 2.0 * s) - phi, np.full_like(s, -2.0 * alpha / T)
    swing = -alpha * (1.0 - 2.0 * s) - phi + bump * np.sin(np.pi * s)
    dswing = 2.0 * alpha / T + dbump * np.cos(np.pi * s)
    x = _states_from_legs(walker, stance, swing, dstance, dswing)
    push = None
    if o.push_off == "free":
        m = float(walker.params["total_mass_kg"])
        push = min(m * (2.0 * alpha * length / T) * np.tan(alpha), o.push_off_max_n_s)
    return t, x, None, push


def _states_from_legs(walker, stance, swing, dstance, dswing) -> np.ndarray:
    """States (m, 2n) whose legs have these absolute angles and rates (m,) each: the
    walker's ``leg_coordinates`` are affine in its state for straight legs (absolute,
    slope-relative or relative coordinates), so the map is read off at the zero state and
    the unit states and inverted by least squares (no projection on the heel-strike
    surface: :func:`walkerlab.analysis.gait.starts.state_from_legs` does that for a
    post-impact state)."""
    leg = walker.legs[-1]  # in stance (the post-impact convention)
    keys = [f"{leg}_angle", f"{walker.legs[0]}_angle", f"{leg}_rate", f"{walker.legs[0]}_rate"]
    n2 = walker.layout().zeros().size

    def coords(x):
        d = walker.leg_coordinates(x, leg)
        return np.array([float(d[k]) for k in keys])

    c = coords(np.zeros(n2))
    A = np.stack([coords(e) - c for e in np.eye(n2)], axis=1)
    want = np.stack([stance, swing, dstance, dswing], axis=1) - c
    return np.linalg.lstsq(A, want.T, rcond=None)[0].T



def starting_segment(walker, x0, period_s: float, solver):
    """The one step of ``walker`` from the post-impact state ``x0`` (2n,) that a starting
    guess samples (at most 3 ``period_s`` [s] long).

    Returns
    -------
    walkerlab.integrate.rigid.Segment

    Raises
    ------
    ValueError
        The step does not end in a heel strike (one line).
    """
    seg = simulate_steps(walker, np.asarray(x0, float), 1, solver,
                         max_step_time=3.0 * period_s).segments[0]
    if seg.termination != "heel_strike":
        raise ValueError("optimize: the starting gait does not make a step "
                         f"({seg.termination})")
    return seg


def simulated_step(walker, x0, period_s: float, solver, samples: int = 400):
    """One step of ``walker`` from the post-impact state ``x0`` (2n,) sampled at
    ``samples`` times from its dense output.

    Returns
    -------
    t : ndarray (samples,)
        Times from 0 [s].
    x : ndarray (samples, 2n)

    Raises
    ------
    ValueError
        As :func:`starting_segment` (no heel strike; one line).
    """
    x0 = np.asarray(x0, float)
    seg = starting_segment(walker, x0, period_s, solver)
    t = np.linspace(seg.t_start, seg.t_end, samples)
    x = np.empty((t.size, x0.size))
    for k, (_ph, sol, (a, b)) in enumerate(seg.pieces):  # each phase's dense output
        last = k == len(seg.pieces) - 1
        sel = (t >= a) & ((t <= b) if last else (t < b))
        if sel.any():
            x[sel] = np.asarray(sol(t[sel]), float)[:x0.size].T
    return t - t[0], x


def pushed(walker, data, push_off_n_s: float):
    """The walker that steps a starting guess: ``walker``, with the scene's push-off
    ``push_off_n_s`` [N s] (> 0) before each heel strike (Kuo 2002; the scene's gait, from
    ``fixedpoint``, is the pushed walker's); ``walker`` itself without one."""
    if not push_off_n_s:
        return walker
    return actuate(walker, data, Actuation(push_off=PushOff(impulse_n_s=push_off_n_s)))


def starting_step(scene, walker, x_gait, period_s: float):
    """The starting step of ``scene``'s collocation (module docstring); ``x_gait`` None:
    the walker has no gait, the step is built from the targets (:func:`target_step`).

    Returns
    -------
    t : ndarray (m,) [s]; x : ndarray (m, 2n); u : ndarray (m,) or None [N m];
    push_off : float or None [N s]
        ``u`` and ``push_off`` from another ``optimize.h5`` only (``push_off`` also from
        the targets when it is free).

    Raises
    ------
    ValueError
        The artifact is missing, damaged, of another stage or walker, or ``at`` is off its
        branch (one line naming the field).
    """
    solver = Solver.from_settings(scene.solver)
    if x_gait is None:  # no gait of its own: a step from the targets
        return target_step(scene, walker)
    if scene.optimize.initial_guess is None:
        return (*simulated_step(walker, x_gait, period_s, solver), None, None)
    kind, got = read_guess(scene, list(walker.state_names()))
    if kind == "optimize":
        x = np.stack([got.states[n] for n in walker.state_names()], axis=1)
        return got.time - got.time[0], x, got.torque, got.push_off_n_s
    return (*simulated_step(walker, got, period_s, solver), None, None)


def read_guess(scene, names: list):
    """The artifact named by ``scene.optimize.initial_guess``: another ``optimize.h5``, or
    a continuation artifact's gait at ``at`` on ``branch``.

    Parameters
    ----------
    names : list of str
        The walker's state names (the artifact's must be the same).

    Returns
    -------
    kind : str
        ``"optimize"`` or ``"continuation"``.
    value : walkerlab.io.schemas.optimize.OptimizeData or ndarray (2n,)
        The optimisation, or the branch's post-impact state there.

    Raises
    ------
    ValueError
        The artifact is missing, damaged, of another stage or walker, or ``at`` is off its
        branch (one line naming the field).
    """
    from walkerlab.io.artifacts import ArtifactError, open_artifact  # light

    g = scene.optimize.initial_guess
    path = Path(g.from_)
    try:
        with open_artifact(path) as f:
            kind = str(f.attrs.get("stage"))
        if kind == "optimize":
            from walkerlab.io.schemas.optimize import load  # light

            d = load(path)
            if list(d.states) != names:
                raise ValueError(f"its states {list(d.states)} are not the walker's {names}")
            return "optimize", d
        if kind != "continuation" or g.at is None:
            raise ValueError("give an optimize.h5, or a continuation artifact with 'at'")
        from walkerlab.io.schemas.continuation import load_continuation  # light

        return "continuation", GuessFromArtifact(from_=g.from_, at=g.at, branch=g.branch).pick(
            load_continuation(path), names)
    except (ArtifactError, ValueError, KeyError) as exc:
        raise ValueError(f"optimize.initial_guess: {exc}") from None
