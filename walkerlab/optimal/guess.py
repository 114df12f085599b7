"""The collocation's starting step: one step of the scene's gait (the fixed point), of a
continuation branch's gait at a parameter value, or another optimisation's result
(``optimize.initial_guess``)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

__all__ = ["read_guess", "simulated_step", "starting_step"]


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
        The step does not end in a heel strike (one line).
    """
    from walkerlab.integrate.rigid import simulate_steps

    x0 = np.asarray(x0, float)
    seg = simulate_steps(walker, x0, 1, solver, max_step_time=3.0 * period_s).segments[0]
    if seg.termination != "heel_strike":
        raise ValueError("optimize: the starting gait does not make a step "
                         f"({seg.termination})")
    t = np.linspace(seg.t_start, seg.t_end, samples)
    x = np.empty((t.size, x0.size))
    for k, (_ph, sol, (a, b)) in enumerate(seg.pieces):  # each phase's dense output
        last = k == len(seg.pieces) - 1
        sel = (t >= a) & ((t <= b) if last else (t < b))
        if sel.any():
            x[sel] = np.asarray(sol(t[sel]), float)[:x0.size].T
    return t - t[0], x


def starting_step(scene, walker, x_gait, period_s: float):
    """The starting step of ``scene``'s collocation (module docstring).

    Returns
    -------
    t : ndarray (m,) [s]; x : ndarray (m, 2n); u : ndarray (m,) or None [N m];
    push_off : float or None [N s]
        ``u`` and ``push_off`` from another ``optimize.h5`` only.

    Raises
    ------
    ValueError
        The artifact is missing, damaged, of another stage or walker, or ``at`` is off its
        branch (one line naming the field).
    """
    from walkerlab.integrate.solver import Solver

    solver = Solver.from_settings(scene.solver)
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
    from walkerlab.io.artifacts import ArtifactError, open_artifact

    g = scene.optimize.initial_guess
    path = Path(g.from_)
    try:
        with open_artifact(path) as f:
            kind = str(f.attrs.get("stage"))
        if kind == "optimize":
            from walkerlab.io.schemas.optimize import load

            d = load(path)
            if list(d.states) != names:
                raise ValueError(f"its states {list(d.states)} are not the walker's {names}")
            return "optimize", d
        if kind != "continuation" or g.at is None:
            raise ValueError("give an optimize.h5, or a continuation artifact with 'at'")
        from walkerlab.config.studies import GuessFromArtifact
        from walkerlab.io.schemas.continuation import load_continuation

        return "continuation", GuessFromArtifact(from_=g.from_, at=g.at, branch=g.branch).pick(
            load_continuation(path), names)
    except (ArtifactError, ValueError, KeyError) as exc:
        raise ValueError(f"optimize.initial_guess: {exc}") from None
