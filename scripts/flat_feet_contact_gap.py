"""How the flat-footed walker's contact gait compares with its rigid gait
(configs/flat_feet.yaml): the measurement behind the note in that scene's contact section.

Usage::

    PYTHONPATH=$PWD python scripts/flat_feet_contact_gap.py [STEPS]

The contact walker is run step by step from the rigid fixed point (each step a
``simulate_contact`` run to the next heel strike, restarted from the state there), under two
rules at each heel strike:

- ``contact``: the run simply goes on (what ``walkerlab contact-sim`` does: the trailing
  foot, loaded on its toe by its deflected ankle spring, stays on the ground for ~17-20 ms
  and its spring pushes the trailing leg off);
- ``rigid_rule``: the rigid view's heel strike without its double support (walkerlab before
  issue 48; ``make_rigid_walker(..., double_support=False)``): the trailing foot leaves the
  ground at once and snaps to its spring's rest angle (its spring energy lost) - its foot
  angle and rate are set to its leg's and the ground patch under it is removed;

each with a regularising foot mass of 0.1 kg (:data:`FOOT_KG`, the scene's before) and with a
tenth of it (the scene's now), from the rigid
gait of the same rule (with and without the double support).  It prints the step periods
and their ratio to that rigid gait's.  Nothing is asserted:
tests/test_flat_feet_contact_gap.py checks the conclusions.
"""

from __future__ import annotations

import dataclasses
import sys
from pathlib import Path

import numpy as np

from walkerlab.analysis.contact.sim import initial_state_from_ideal, simulate_contact
from walkerlab.analysis.gait.poincare import find_fixed_point
from walkerlab.config import load_scene
from walkerlab.integrate.contact import ContactLimits
from walkerlab.integrate.solver import Solver
from walkerlab.models.contact.scene import contact_setup
from walkerlab.models.hybrid.rigid import make_rigid_walker
from walkerlab.models.registry import build_walker
from walkerlab.walker.description import walker_data
from walkerlab.walker.plant import Plant

SCENE = Path(__file__).resolve().parents[1] / "configs" / "flat_feet.yaml"
#: samples per second of each step's run: the heel strike is read at the first sample at or
#: after it (50 us late at most)
SAMPLE_RATE_HZ = 20000.0
#: The contact gait's step length [m] (mean over its first 7-16 steps from the rigid gait
#: with double support, patches at the rigid 0.6286 m) by foot mass scale: its steps are
#: 3-5 % shorter than the rigid ones, so on patches laid at the rigid step its footfalls
#: drift 15-25 mm a step towards the patches' back edges (their toes then leave the patch).
CONTACT_STEP_M = {1.0: 0.6086, 0.1: 0.600}
#: The regularising foot (mass [kg], inertia about the ankle [kg m^2]) the scales are of:
#: configs/flat_feet.yaml's until it took a tenth of it (0.01 kg, 5e-5 kg m^2)
FOOT_KG, FOOT_KG_M2 = 0.1, 5e-4


def rigid_gait(scene, double_support: bool = True):
    """The rigid view's fixed point (role order) and step period [s]; ``double_support``
    False: the rigid view without its double support (the trailing foot released at heel
    strike, walkerlab before issue 48)."""
    walker = build_walker(Plant.from_scene(scene))
    if not double_support:
        walker = make_rigid_walker(walker_data(scene.walker, scene.slope.phi_rad),
                                   double_support=False)
    guess = scene.fixedpoint.initial_guess.as_array(walker.state_names())
    fp = find_fixed_point(walker, guess, Solver.from_settings(scene.solver), fd_check=False)
    return fp.x, float(fp.period_s)


def _release_trailing_foot(walker, X, leg: str):
    """The rigid heel strike's trailing foot: angle and rate set to its leg's (the spring at
    rest), and its lane's patch under it removed (the foot passes through the slope)."""
    names = list(walker.state_names())
    n = leg[-1]
    X = np.array(X, float)
    X[names.index(f"theta{n}_foot")] = X[names.index(f"theta{n}")]
    X[names.index(f"dtheta{n}_foot")] = X[names.index(f"dtheta{n}")]
    heel = float(np.asarray(walker.points(X)[f"{leg}_heel"], float).ravel() @ walker.tangent)
    lane = getattr(walker, f"lane{n}")
    return dataclasses.replace(walker, **{f"lane{n}": lane[lane > heel + 0.5]}), X


def step_periods(scene, x_ideal, steps: int, rigid_rule: bool,
                 foot_mass_scale: float = 1.0, spacing_m: float | None = None) -> np.ndarray:
    """Step periods [s] of the contact walker from the rigid fixed point ``x_ideal``, one
    run per step (``rigid_rule``: the rigid view's heel strike, see the module docstring);
    ``foot_mass_scale`` scales the flat feet's mass and inertia; ``spacing_m`` [m] lays the
    patches at that step instead of the rigid gait's (:data:`CONTACT_STEP_M`: the contact
    gait's own, so that its footfalls stay on their patches)."""
    setup = contact_setup(scene, plant=Plant.from_scene(scene))
    law = setup.law.model_copy(update={
        "flat_foot_mass_kg": FOOT_KG * foot_mass_scale,
        "flat_foot_inertia_kg_m2": FOOT_KG_M2 * foot_mass_scale})
    setup = dataclasses.replace(setup, law=law)
    walker, _ = setup.build(x_ideal, steps + 2, step_length_m=spacing_m)
    X = initial_state_from_ideal(walker, *x_ideal)
    trailing, out = "leg1", []
    for _ in range(steps):
        w = walker
        if rigid_rule:
            w, X = _release_trailing_foot(walker, X, trailing)
        stance = "leg2" if trailing == "leg1" else "leg1"
        res = simulate_contact(w, X, 3.0, setup.solver,
                               ContactLimits(sample_rate_hz=SAMPLE_RATE_HZ),
                               max_heel_strikes=1, initial_stance=stance)
        if len(res.heel_strike_times) == 0 or res.heel_strike_legs[0] != trailing:
            break
        j = int(np.searchsorted(res.t, res.heel_strike_times[0]))
        out.append(float(res.t[j]))
        X, trailing = res.x[j], stance
    return np.array(out)


def main(steps: int = 8) -> None:
    scene = load_scene(SCENE)
    gaits = {rule: rigid_gait(scene, double_support=not rule) for rule in (False, True)}
    for rule, (_x, period) in gaits.items():
        print(f"rigid step period {period:.4f} s "
              f"({'without' if rule else 'with'} its double support)")
    for rule in (False, True):
        x_ideal, period = gaits[rule]
        for scale in (1.0, 0.1):
            p = step_periods(scene, x_ideal, steps, rule, scale,
                             None if rule else CONTACT_STEP_M[scale])
            name = "rigid_rule" if rule else "contact"
            print(f"{name:10s} foot mass x{scale:<4} periods {np.round(p, 4)}  last 4 / rigid "
                  f"{np.mean(p[-4:]) / period:.4f}")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 8)
