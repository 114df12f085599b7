"""Kneed passive walker of Hsu Chen (2007), as simulated by Tedrake's ``kneedCompassGait.m``.

Sources
-------
V. F. Hsu Chen, "Passive dynamic walking with knees: a point foot model", M.Eng. thesis,
MIT, 2007.  The parameters and the initial condition below are printed in R. Tedrake's MATLAB
simulation of that walker, ``kneedCompassGait.m`` ("simulates the passive 5-link compass gait
model described in Hsu07"; MIT Underactuated Robotics course code).

The thesis' own fixed point and Floquet multipliers are not available to us; the only printed
state is Tedrake's initial condition, computed with an explicit Euler integration (step
1 ms), so it is a *guess*, not a fixed point.  What we compare against is the independent
prototype in ``tests/independent/kneed_reference.py``.
"""

import math

CITATION = ("V. F. Hsu Chen, Passive dynamic walking with knees: a point foot model, "
            "M.Eng. thesis, MIT, 2007; parameters and initial condition as printed in "
            "R. Tedrake, kneedCompassGait.m (MIT Underactuated Robotics)")

GRAVITY_M_PER_S2 = 9.8
THIGH_LENGTH_M = 0.5                   # lt
SHANK_LENGTH_M = 0.5                   # ls
THIGH_MASS_KG = 0.5                    # mt
HIP_MASS_KG = 2 * 0.5 * THIGH_MASS_KG  # mh = 2 massR(1) mt, massR(1) = 0.5
SHANK_MASS_KG = THIGH_MASS_KG / 10     # ms = mt / massR(2), massR(2) = 10
THIGH_MASS_ABOVE_KNEE_M = 0.4 * THIGH_LENGTH_M   # a2 = linkR(1) lt
SHANK_MASS_ABOVE_FOOT_M = 0.7 * SHANK_LENGTH_M   # a1 = linkR(2) ls
SLOPE_RAD = math.asin(7.25 / 144)      # gamma, a 7.25-in rise over 144 in

#: Initial condition printed in kneedCompassGait.m, just after heel strike, knee straight:
#: stance, swing thigh, swing shank angles [rad] (absolute, from the vertical; same sign
#: convention as walkerlab) and their rates [rad/s].
INITIAL_CONDITION = {
    "stance_angle_rad": 0.187700106303669,
    "swing_thigh_angle_rad": -0.288437140111164,
    "swing_shank_angle_rad": -0.288437140111164,
    "stance_rate_rad_per_s": -1.101439041094875,
    "swing_thigh_rate_rad_per_s": -0.039885255927632,
    "swing_shank_rate_rad_per_s": -0.039885255927632,
}
