"""A powered contact run's energy ledger per step and its cost of transport, beside the rigid
view's (:mod:`walkerlab.analysis.gait.energy`).

The powered contact run carries its work integrals with the state
(:mod:`walkerlab.integrate.contact_powered`: ``walker.actuators.work_names``, cumulative [J]).
A step here runs from the middle of one heel-strike interval to the middle of the next, so
it holds one push-off and one heel strike whole (the pulse ends at the touchdown, the
compliant collision lasts a fraction of a millisecond) and both ends lie in smooth single
support, where interpolating the samples is accurate.  Per step:

- ``push_off_work`` [J]: the push-off pulse's work (0 without one);
- ``actuator_work_positive`` / ``actuator_work_negative`` [J]: the joint (or ankle) torques'
  positive and negative work, with a 3D walker's hip-roll law's (as the rigid ledger counts
  it);
- ``contact_work`` [J]: the contact forces' (their dissipation, and the change of the
  energy their springs hold);
- ``distance`` [m]: the hip's displacement along the slope over the step (on a periodic gait
  the step length);
- ``slope_energy`` [J]: ``M g d sin(phi)``, the potential energy the slope releases;
- ``cost_of_transport`` [-]: ``(positive actuator work + push-off work + slope energy if
  > 0) / (M g d)``, the rigid view's definition (Kuo 2002; Collins et al. 2005).
"""

from __future__ import annotations

import numpy as np

__all__ = ["STEP_LEDGER_DESCRIPTIONS", "STEP_LEDGER_UNITS", "contact_step_ledger"]

#: unit of each per-step column
STEP_LEDGER_UNITS = {"push_off_work": "J", "actuator_work_positive": "J",
                     "actuator_work_negative": "J", "contact_work": "J", "distance": "m",
                     "slope_energy": "J", "cost_of_transport": "-"}
#: what each per-step column is
STEP_LEDGER_DESCRIPTIONS = {
    "push_off_work": "work of the push-off pulse over the step",
    "actuator_work_positive": "positive work of the joint (or ankle) torques over the step",
    "actuator_work_negative": "negative work of the joint (or ankle) torques over the step",
    "contact_work": "work of the contact forces over the step",
    "distance": "hip displacement along the slope over the step",
    "slope_energy": "potential energy the slope releases over the step, M g d sin(slope)",
    "cost_of_transport": "(positive actuator work + push-off work + slope energy if > 0) "
                         "/ (M g d), d the hip's displacement along the ground",
}
_POSITIVE = ("hip_torque_positive", "ankle_torque_positive", "hip_roll_positive")
_NEGATIVE = ("hip_torque_negative", "ankle_torque_negative", "hip_roll_negative")


def contact_step_ledger(walker, t, X, work, heel_strike_times) -> dict[str, np.ndarray]:
    """The energy ledger of a powered contact run per step (module docstring).

    Parameters
    ----------
    walker : ContactWalker
        With ``actuators`` (its ``work_names`` name the columns of ``work``).
    t : ndarray, shape (n,)
        Sample times [s].
    X : ndarray, shape (n, 2 nq)
        Samples of the state [m, rad, m/s, rad/s].
    work : ndarray, shape (n, len(work_names))
        The work integrals at the samples [J].
    heel_strike_times : array_like, shape (k,)
        [s], increasing.

    Returns
    -------
    dict[str, ndarray]
        :data:`STEP_LEDGER_UNITS` columns, each (max(k - 2, 0),): one row per heel strike
        with a heel strike on either side.
    """
    names = tuple(walker.actuators.work_names)
    hs = np.asarray(heel_strike_times, float)
    t = np.asarray(t, float)
    if hs.size < 3:
        return {k: np.zeros(0) for k in STEP_LEDGER_UNITS}
    b = 0.5 * (hs[:-1] + hs[1:])  # mid-step boundaries: single support

    def delta(col):
        v = np.interp(b, t, col)
        return np.diff(v)

    def term(keys):
        cols = [work[:, names.index(k)] for k in keys if k in names]
        return sum(delta(c) for c in cols) if cols else np.zeros(b.size - 1)

    # the hip's position along the ground (a planar walker's floating base; a 3D
    # walker's pelvis: its base is a foot)
    hip = walker.hip_positions(X)
    hip = np.column_stack([np.interp(b, t, hip[:, k]) for k in range(hip.shape[1])])
    d = np.diff(hip @ np.asarray(walker.tangent, float))
    m, g, phi = float(walker.total_mass), float(walker.g), float(walker.phi)
    slope = m * g * d * np.sin(phi)
    push, pos = term(("push_off",)), term(_POSITIVE)
    return {"push_off_work": push, "actuator_work_positive": pos,
            "actuator_work_negative": term(_NEGATIVE), "contact_work": term(("contact",)),
            "distance": d, "slope_energy": slope,
            "cost_of_transport": (pos + push + np.maximum(slope, 0.0)) / (m * g * d)}
