"""A scene's robustness study on the executor: the rigid model's gait sensitivity
norms, largest tolerable step and push (:mod:`walkerlab.analysis.robustness.measures`), its Monte
Carlo MFPT (:mod:`walkerlab.studies.mfpt`) and, when asked, the contact model's largest step
(:mod:`walkerlab.studies.contact_rough`).  It lives above ``analysis`` because it schedules walks
on the executor; the measures themselves are in ``analysis``."""

from __future__ import annotations

import math

import numpy as np

from walkerlab.analysis.contact.rough import contact_start
from walkerlab.analysis.robustness.measures import (
    UNITS,
    gsn_nonlinear,
    largest_by_bisection,
    linearise,
    relative_coordinates,
    state_gsn,
)
from walkerlab.config import RobustnessSettings
from walkerlab.integrate.python_step import make_step_map
from walkerlab.integrate.solver import Solver
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
    from walkerlab.io.schemas.robustness import RobustnessData  # light
    from walkerlab.models.registry import build_walker

    # the kind's refusal (a 3D walker: walker.space) before the walker is built
    plant.kind.require_stage("robustness")
    st = scene.robustness or RobustnessSettings()
    walker = build_walker(scene, plant)
    if walker.steps_per_map != 1:
        raise ValueError("robustness: legs that differ (a stride map) are not supported")
    sm = make_step_map(walker, work.scene_walker_at(scene, plant), 1e-12, 1e-12)
    A = poincare_map(walker, x_star, Solver("DOP853", 1e-12, 1e-12, None, "scipy"),
                     jacobian=True)[2]
    names = walker.state_names()
    T = relative_coordinates(names)
    lam = {"absolute": float(np.max(np.abs(np.linalg.eigvals(A)))),
           "relative": float(np.max(np.abs(np.linalg.eigvals(T @ A @ np.linalg.inv(T)))))}
    gsn, gnl, norm = {}, {}, {"absolute": {}, "relative": {}}
    for d in st.disturbances:
        lin = linearise(sm, x_star, A, d)
        gsn[d], gnl[d] = lin.gsn(), gsn_nonlinear(sm, x_star, d, 1e-5, steps=60)
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
                          st.montecarlo_max_steps, st.seed, "normal", workers, scheduler)
    m, se = mc.mfpt
    sc = {"step_down_m/lo": down[0], "step_down_m/hi": down[1], "step_up_m/lo": up[0],
          "step_up_m/hi": up[1], "push_forward_m_per_s/lo": fwd[0],
          "push_forward_m_per_s/hi": fwd[1], "push_backward_m_per_s/lo": back[0],
          "push_backward_m_per_s/hi": back[1], "sigma_rad": st.sigma_rad, "mfpt_steps": m,
          "mfpt_steps_stderr": se, "montecarlo_walks": mc.steps.size,
          "montecarlo_falls": int(mc.fell.sum())}
    sc.update(contact_steps(scene, x_star, st, 0.2 * cap, workers, scheduler, plant=plant))
    return RobustnessData(list(st.disturbances), {d: UNITS[d] for d in st.disturbances}, lam,
                          gsn, gnl, norm, sc, names)


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
    from walkerlab.analysis.contact.step_map import PeriodicGaitError  # light

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
