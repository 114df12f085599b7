"""A scene's robustness study on the executor: the rigid model's gait sensitivity
norms, largest tolerable step and push (:mod:`walkerlab.analysis.robustness.measures`), its Monte
Carlo MFPT (:mod:`walkerlab.studies.mfpt`) and, when asked, the contact model's largest step
(:mod:`walkerlab.studies.contact_rough`).  It lives above ``analysis`` because it schedules walks
on the executor; the measures themselves are in ``analysis``."""

from __future__ import annotations

import math

import numpy as np

from walkerlab.analysis.contact.rough import contact_start
from walkerlab.analysis.contact.search_budget import PeriodicGaitError
from walkerlab.analysis.robustness.measures import (
    LATERAL_DISTURBANCES,
    UNITS,
    disturbances_of,
    gsn_nonlinear,
    largest_by_bisection,
    linearise,
    relative_coordinates,
    stable,
    state_gsn,
    step_walker,
)
from walkerlab.analysis.robustness.push import LATERAL_AXIS, apply_push
from walkerlab.config import RobustnessSettings
from walkerlab.integrate.python_step import ReflectedStepMap, make_step_map
from walkerlab.integrate.solver import Solver
from walkerlab.io.schemas.robustness import RobustnessData
from walkerlab.models.contact.scene import ContactSceneError
from walkerlab.studies import mfpt as work
from walkerlab.studies.contact_rough import contact_largest_step


def scene_robustness(scene, x_star: np.ndarray, workers: int = 1, scheduler=None,
                     *, plant):
    """Everything ``robustness.h5`` holds for a scene with a ``robustness`` section and its
    gait ``x_star`` (2n,): ``|lambda|max`` and the state norms in absolute and relative leg
    angles, the GSN of each disturbance (linearised, and the nonlinear check at an impulse
    of 1e-5), the step-down/up brackets (search cap a quarter leg length), the largest
    forward and backward mid-stance pushes (:func:`walkerlab.analysis.robustness.push.apply_push`)
    and
    the Monte Carlo MFPT at ``robustness.sigma_rad`` (:func:`walkerlab.studies.mfpt.monte_carlo`).
    ``plant``: the scene's :class:`~walkerlab.walker.plant.Plant` (the stage's).

    A walker whose points have a lateral axis (a walker in 3D) also takes the sideways push
    at the section (:data:`~walkerlab.analysis.robustness.measures.LATERAL_DISTURBANCES`,
    beside the scene's ``robustness.disturbances``) and its largest sideways pushes toward
    the swing leg's side (``out``) and the stance leg's (``in``), with the impulse per unit
    hip velocity change at the gait's section (:func:`lateral_scalars`).  A walker whose
    steps alternate sides (hip width) is stepped by its reflected step map
    (:class:`~walkerlab.integrate.python_step.ReflectedStepMap`): every number is per step,
    the map's Jacobian ``S A_step`` (``S`` the reflection).  An unstable gait (a multiplier
    on or outside the unit circle) has infinite sensitivity norms, its nonlinear check NaN
    (the undisturbed gait falls).

    Returns
    -------
    walkerlab.io.schemas.robustness.RobustnessData

    Raises
    ------
    ValueError
        A walker no step map can carry (slope-relative coordinates, legs that differ; one
        line).  A walker without compiled flows (flat feet) runs on the row-by-row
        :class:`~walkerlab.integrate.python_step.PythonStepMap` (a Python right-hand
        side: slower).
    """
    from walkerlab.analysis.gait.poincare import poincare_map  # light
    from walkerlab.models.registry import build_walker

    # the kind's refusal (a 3D walker: walker.space) before the walker is built
    plant.kind.require_stage("robustness")
    st = scene.robustness or RobustnessSettings()
    walker = build_walker(plant.with_(scene))
    if walker.steps_per_map != 1 and (walker.mirror_reflection is None
                                      or walker.cycle is not None):
        raise ValueError("robustness: legs that differ (a stride map) are not supported")
    sm = make_step_map(walker, work.scene_walker_at(scene, plant), 1e-12, 1e-12)
    solver = Solver("DOP853", 1e-12, 1e-12, None, "scipy")
    if isinstance(sm, ReflectedStepMap):  # one step, reflected: Q(y) = S P(y)
        n2 = x_star.size
        A = walker.reflect(np.eye(n2)) @ poincare_map(step_walker(sm), x_star, solver,
                                                      jacobian=True)[2]
    else:
        A = poincare_map(walker, x_star, solver, jacobian=True)[2]
    names = walker.state_names()
    T = relative_coordinates(names)
    lam = {"absolute": float(np.max(np.abs(np.linalg.eigvals(A)))),
           "relative": float(np.max(np.abs(np.linalg.eigvals(T @ A @ np.linalg.inv(T)))))}
    lateral = tuple(d for d in disturbances_of(step_walker(sm)) if d in LATERAL_DISTURBANCES)
    dists = [*st.disturbances, *lateral]
    gsn, gnl, norm = {}, {}, {"absolute": {}, "relative": {}}
    for d in dists:
        lin = linearise(sm, x_star, A, d)
        gsn[d] = lin.gsn()
        gnl[d] = gsn_nonlinear(sm, x_star, d, 1e-5, steps=60) if stable(A) else math.nan
        norm["absolute"][d], norm["relative"][d] = state_gsn(lin), state_gsn(lin, T)
    cap = 0.25 * float(walker.params.get("leg_length_m", 1.0))
    down = largest_by_bisection(sm, x_star, "floor_height", cap, st.resolution_m,
                                st.survival_steps)
    up = largest_by_bisection(sm, x_star, "floor_height", cap, st.resolution_m,
                              st.survival_steps, sign=-1.0)
    fwd = largest_by_bisection(sm, x_star, "push", st.push_cap_m_per_s,
                               st.push_resolution_m_per_s, st.survival_steps)
    back = largest_by_bisection(sm, x_star, "push", st.push_cap_m_per_s,
                                st.push_resolution_m_per_s, st.survival_steps, sign=-1.0)
    mc = work.monte_carlo(scene, x_star, st.sigma_rad, st.montecarlo_walks,
                          st.montecarlo_max_steps, st.seed, "normal", workers, scheduler,
                          plant=plant)
    m, se = mc.mfpt
    sc = {"step_down_m/lo": down[0], "step_down_m/hi": down[1], "step_up_m/lo": up[0],
          "step_up_m/hi": up[1], "push_forward_m_per_s/lo": fwd[0],
          "push_forward_m_per_s/hi": fwd[1], "push_backward_m_per_s/lo": back[0],
          "push_backward_m_per_s/hi": back[1], "sigma_rad": st.sigma_rad, "mfpt_steps": m,
          "mfpt_steps_stderr": se, "montecarlo_walks": mc.steps.size,
          "montecarlo_falls": int(mc.fell.sum())}
    sc.update(contact_steps(scene, x_star, st, 0.2 * cap, workers, scheduler, plant=plant))
    if lateral:
        sc.update(lateral_scalars(sm, x_star, st))
    return RobustnessData(dists, {d: UNITS[d] for d in dists}, lam, gsn, gnl, norm, sc, names)


def lateral_scalars(sm, x_star: np.ndarray, st) -> dict:
    """The largest sideways pushes at the section (the disturbance ``lateral_push``) a
    walker with a lateral axis survives: bisection brackets [m/s] of the hip's lateral
    velocity change toward the swing leg's side (``push_lateral_out``) and the stance leg's
    (``push_lateral_in``), search cap ``robustness.push_cap_m_per_s``, bracket
    ``robustness.push_resolution_m_per_s``, survival ``robustness.survival_steps`` steps
    (:func:`~walkerlab.analysis.robustness.measures.largest_by_bisection`: a count of
    rounds and steps); and ``push_lateral_kg``, the impulse per unit of that velocity change
    at the gait's section [N s per m/s = kg] (the pushes in N s are the brackets times it).

    Parameters
    ----------
    sm : step map
        The walker's step map (``make_step_map``; a reflected one for hip width).
    x_star : ndarray, shape (2n,)
        The gait's post-impact fixed point [rad, rad/s].
    st : walkerlab.config.RobustnessSettings

    Returns
    -------
    dict
        ``push_lateral_{out,in}_m_per_s/{lo,hi}`` [m/s] and ``push_lateral_kg`` [kg].
    """
    out = {"push_lateral_kg": apply_push(step_walker(sm), x_star, 1.0, axis=LATERAL_AXIS)[1]}
    for sign, side in ((1.0, "out"), (-1.0, "in")):
        lo, hi = largest_by_bisection(sm, x_star, "lateral_push", st.push_cap_m_per_s,
                                      st.push_resolution_m_per_s, st.survival_steps, sign)
        out[f"push_lateral_{side}_m_per_s/lo"], out[f"push_lateral_{side}_m_per_s/hi"] = lo, hi
    return out


def contact_steps(scene, x_star: np.ndarray, st, cap_m: float, workers: int = 1,
                  scheduler=None, *, plant) -> dict:
    """The contact model's largest single step-down and step-up (``robustness.contact``):
    bisection brackets [m] (search cap ``cap_m``; the stage uses a twentieth of the leg
    length) of the step at the first heel strike, from the contact model's
    periodic gait, surviving ``robustness.contact_survival_steps`` heel strikes
    (:func:`walkerlab.studies.contact_rough.contact_largest_step`, walks on the executor);
    NaN when not asked for.  ``plant``: the scene's :class:`~walkerlab.walker.plant.Plant`
    (the study's).

    Raises
    ------
    ValueError
        Asked for without a ``contact`` section, patches or periodic gait (one line).
    """
    keys = ("contact_step_down_m/lo", "contact_step_down_m/hi", "contact_step_up_m/lo",
            "contact_step_up_m/hi")
    if not getattr(st, "contact", False):
        return dict.fromkeys(keys, math.nan)

    try:
        start = contact_start(scene, x_star, plant=plant)
    except (ContactSceneError, PeriodicGaitError) as exc:
        raise ValueError(f"robustness.contact: {exc}") from None
    out = {}
    for sign, name in ((1.0, "down"), (-1.0, "up")):
        lo, hi = contact_largest_step(start, sign, cap_m, st.resolution_m,
                                      st.contact_survival_steps, workers, scheduler)
        out[f"contact_step_{name}_m/lo"], out[f"contact_step_{name}_m/hi"] = lo, hi
    return out
