"""The events of a powered contact run
(:class:`walkerlab.integrate.contact_powered.ActuationHook`), each a function of one state
for :func:`scipy.integrate.solve_ivp` (terminal, direction -1) and, as its ``values``, of
many states at once (the compiled segments' samples and their contact table:
:mod:`walkerlab.integrate.compiled_segments`):

- the heel strike: the swing foot's penetration crosses 0 on ground, ``min_step_m`` ahead
  of the stance foot (:func:`touchdown_event`);
- the push-off pulse's start, ``pulse_s`` before the predicted touchdown
  (:func:`pulse_event`, :func:`pulse_lead`);
- a flat foot's heel off, where the ankle push-off starts (:func:`heel_off_event`);
- a fall, the hip below the fall height (or thrown above a launch height:
  :func:`fall_event`).

Which leg is in stance is the run's discrete state, read through ``stance_of()``.
"""

from __future__ import annotations

import numpy as np

from .compiled_segments import contact_tables

__all__ = ["fall_event", "heel_off_event", "leg_rows", "pulse_event", "pulse_lead",
           "pulse_lead_s", "touchdown_event"]


def touchdown_event(walker, stance_of):
    """Event: the swing foot's penetration crosses 0 on ground, ahead of the stance foot."""
    acts = walker.actuators
    n = 2 * walker.nq

    def touch(t, y):
        stance = stance_of()
        rows = acts.leg_contacts(walker, y[:n])  # (penetration, ..., s, ..., on_ground)
        sw, st = rows[1 - stance], rows[stance]
        if sw[7] < 0.5 or sw[3] - st[3] < acts.min_step_m:
            return 1.0
        return -float(sw[0])

    def values(X, tab=None):  # the same on states X (m, 2 nq) (their contact table)
        sw, st = leg_rows(walker, X, stance_of(), tab)
        away = (sw[:, 7] < 0.5) | (sw[:, 3] - st[:, 3] < acts.min_step_m)
        return np.where(away, 1.0, -sw[:, 0])

    touch.values = values
    touch.terminal = True
    touch.direction = -1
    return touch


def pulse_event(walker, stance_of, lead_s: float):
    """Event: the push-off pulse starts, ``lead_s`` [s] before the swing foot's predicted
    touchdown on ground ahead of the stance foot (as :func:`touchdown_event`): its
    penetration extrapolated ``lead_s`` ahead at its present rate, ``delta + lead_s
    d delta/dt``, crosses 0 upwards (:func:`pulse_lead`)."""
    acts = walker.actuators
    n = 2 * walker.nq

    def pulse(t, y):
        stance = stance_of()
        rows = acts.leg_contacts(walker, y[:n])
        sw, st = rows[1 - stance], rows[stance]
        if sw[7] < 0.5 or sw[3] - st[3] < acts.min_step_m:
            return 1.0
        return -float(pulse_lead(sw[0], sw[1], lead_s))

    def values(X, tab=None):  # the same on states X (m, 2 nq) (their contact table)
        sw, st = leg_rows(walker, X, stance_of(), tab)
        away = (sw[:, 7] < 0.5) | (sw[:, 3] - st[:, 3] < acts.min_step_m)
        return np.where(away, 1.0, -pulse_lead(sw[:, 0], sw[:, 1], lead_s))

    pulse.values = values
    pulse.terminal = True
    pulse.direction = -1
    return pulse


def leg_rows(walker, X, stance: int, tab=None):
    """The swing and stance legs' contact-table rows (m, 8) on states ``X`` (m, 2 nq) (their
    contact table ``tab`` if computed): each leg's deepest point on ground (its only point
    for point feet), as :meth:`~walkerlab.models.contact.actuation.ContactRows.leg_contacts`
    picks it."""
    if tab is None:
        tab = contact_tables(walker, X)
    acts = walker.actuators
    if acts._points is None:  # each leg's rows of the table, once
        names = walker.contact_names()
        acts._points = [[k for k, c in enumerate(names) if walker.contact_leg(c) == leg]
                        for leg in ("leg1", "leg2")]
    out = []
    for idx in acts._points:
        if len(idx) == 1:  # a point foot: its row
            out.append(tab[:, idx[0]])
            continue
        rows = tab[:, idx]  # (m, points, 8)
        pick = np.argmax(np.where(rows[:, :, 7] > 0.5, rows[:, :, 0], rows[:, :, 0] - 1e3),
                         axis=1)
        out.append(rows[np.arange(len(X)), pick])
    return out[1 - stance], out[stance]


def pulse_lead(penetration, rate, pulse_s: float):
    """The push-off pulse's start criterion: the swing foot's penetration [m] extrapolated
    ``pulse_s`` [s] ahead at its rate [m/s], ``penetration + pulse_s * rate`` (a pulse
    started where it crosses 0 upwards ends at the touchdown the extrapolation predicts;
    arrays or floats alike)."""
    return penetration + pulse_s * rate


def pulse_lead_s(acts) -> float:
    """How long [s] before the predicted touchdown the push-off pulse starts: the pulse's
    duration for a walker with a push-off impulse and a pulse, else 0 (no pulse event)."""
    spec = getattr(acts, "spec", None)
    if getattr(spec, "push_off", None) is None:
        return 0.0
    return float(acts.pulse_s)


def heel_off_event(walker, stance_of):
    """Event: the stance heel's penetration crosses 0 downwards (it leaves the ground) with
    the stance toe loaded (penetration > 0); the ankle push-off starts there."""
    n = 2 * walker.nq
    names = walker.contact_names()
    heel = [names.index(f"{leg}_heel") for leg in ("leg1", "leg2")]
    toe = [names.index(f"{leg}_toe") for leg in ("leg1", "leg2")]

    def heel_off(t, y):
        stance = stance_of()
        tab = walker.actuators.contact_rows(walker, y[:n])  # column 0: penetration [m]
        if tab[toe[stance], 0] <= 0.0:
            return 1.0
        return float(tab[heel[stance], 0])

    def values(X, tab=None):  # the same on states X (m, 2 nq) (their contact table)
        stance = stance_of()
        if tab is None:
            tab = contact_tables(walker, X)
        return np.where(tab[:, toe[stance], 0] <= 0.0, 1.0, tab[:, heel[stance], 0])

    heel_off.values = values
    heel_off.terminal = True
    heel_off.direction = -1
    return heel_off


def fall_event(walker, limits, launch_height_m: float | None = None):
    """Event: the hip falls below ``limits.fall_hip_height_m`` (or, with
    ``launch_height_m``, rises above it: a walker thrown off a patch's side)."""
    n = 2 * walker.nq
    top = np.inf if launch_height_m is None else float(launch_height_m)

    def fall(t, y):
        h = float(walker.hip_height(y[:n])[0])
        return min(h - limits.fall_hip_height_m, top - h)

    def values(X, tab=None):  # the same on states X (m, 2 nq)
        h = walker.hip_height(X)
        return np.minimum(h - limits.fall_hip_height_m, top - h)

    fall.values = values
    fall.terminal = True
    fall.direction = -1
    return fall
