"""Published numbers of the paper this project reproduces (the ``paper`` scene).

Every value is typed here once, as printed, with the place where it is printed.  Units are
in the names.  State values are keyed by the *physical* coordinate names of walkerlab's
trajectories (``leg1_angle`` ...): at the start of a run ``leg1`` swings (the paper's
theta_1) and ``leg2`` is in stance (theta_2), and role-ordered fixed points list the swing
leg first, so ``EQ11_STATE`` is also the role-ordered state ``[swing_angle, stance_angle,
swing_rate, stance_rate]``.

A scene compares itself with this module when it says ``published: paper``
(:func:`walkerlab.published.for_scene`); other scenes get no published column.
"""

from __future__ import annotations

TITLE = "A Modeling Framework for Rigid Legs Passive Dynamic Biped Walkers in MSC ADAMS"
# The paper's text this module was written from prints the title, abstract, body and
# references but no authors, venue or year; its newest references are from 2024.  Fill
# these in from the published version when known.
AUTHORS: str | None = None
VENUE: str | None = None
YEAR: int | None = None


def _citation() -> str:
    who = AUTHORS or "authors not printed in our copy"
    where = ", ".join(str(v) for v in (VENUE, YEAR) if v) or (
        "venue and year not printed in our copy (it cites work from 2024)")
    return f'{who}, "{TITLE}", {where}'


CITATION = _citation()
SHORT = "paper"

# Table 1 (physical parameters of the compass biped walker); a = b = L/2 is stated in Sec. 2
# ("the mass of the links is concentrated and placed in the middle of the legs").
TABLE1 = {
    "leg_length_m": 1.0,
    "leg_mass_kg": 5.0,
    "hip_mass_kg": 10.0,
    "gravity_m_per_s2": 9.81,
}

# Eq. (11): fixed point of the Poincare map, state just after heel strike, printed digits.
# Order: theta_1 (swing) [rad], theta_2 (stance) [rad], dtheta_1 [rad/s], dtheta_2 [rad/s].
EQ11_STATE = (-0.2022, 0.1674, -0.60, -0.84)
EQ11_NAMES = ("swing_angle", "stance_angle", "swing_rate", "stance_rate")
# The generic names the report looks for (any source's published fixed point).
FIXED_POINT_STATE, FIXED_POINT_NAMES = EQ11_STATE, EQ11_NAMES
FIXED_POINT_LABEL = "Eq. (11) as printed"

# Table 2: initial state in MATLAB (= Eq. 11) and in MSC ADAMS, by physical coordinate at
# t = 0 (leg1 swings first).  Values: (MATLAB, MSC ADAMS); symbol as printed.
TABLE2 = {
    "leg1_angle": ("θ1 [rad]", -0.2022, -0.2021),
    "leg2_angle": ("θ2 [rad]", 0.1674, 0.1670),
    "leg1_rate": ("θ̇1 [rad/s]", -0.60, -1.02),
    "leg2_rate": ("θ̇2 [rad/s]", -0.84, -3.20),
}
# Sec. 4 / Table 2 "difference rate percent" of the initial rates, as printed.
TABLE2_RATE_INCREASE_PERCENT = (41.0, 74.0)

# Table 3: gait characteristics (MATLAB, MSC ADAMS) for the row keys of
# walkerlab.comparison.tables.gait_metrics.
TABLE3 = {
    "t_left_s": (0.60, 0.59),
    "t_right_s": (0.79, 0.77),
    "t_cycle_s": (1.39, 1.38),
    "v_com_m_per_s": (0.0246, 0.0248),
    "E_avg_J": (150.13, 150.14),
}
# Sec. 5: "the length of the robot's step is constant and equal to 0.0342 meters".
STEP_LENGTH_M = 0.0342
# Sec. 5 on Fig. 8: "the maximum error is around 10^-4" (angles and rates, MATLAB vs ADAMS).
FIG8_MAX_ERROR = 1e-4
# Sec. 4 / Fig. 4b: contact stiffness, damping, static and dynamic friction as printed
# (no units printed; read in ADAMS's default mm-kg-s system, the names configs/paper.yaml
# writes them under).
CONTACT = {"stiffness_n_per_mm_pow_e": 1e5, "max_damping_n_s_per_mm": 90.0, "mu_static": 0.9,
           "mu_dynamic": 0.7}

