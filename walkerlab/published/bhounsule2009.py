"""Compass gait with round feet (McGeer 1990) in the version of Bhounsule's ``passivewalker.m``.

Sources
-------
T. McGeer, "Passive dynamic walking", Int. J. Robotics Research 9(2):62-82, 1990 (round feet
rolling without slip).  Parameters and the printed stable root: P. A. Bhounsule,
``passivewalker.m`` (Cornell, 2009; github.com/pab47/pab47.github.io), case 2 "more general
passive walker with round feet".  Nondimensional: g = 1, hip-to-foot-centre distance 1.

Caveat (measured): that code's heel-strike law writes the old stance leg's spin momentum as
``I (v1 - v2)`` instead of ``I v1`` (``v2`` is the hip-angle rate).  With ``I = 0`` its law
and ours agree to round-off; with the printed ``I = 0.02`` its root differs from the fixed
point of the correct law by 3.4e-5 rad in the angles and 2.2e-3 in the swing rate.
"""

CITATION = ("T. McGeer, Passive dynamic walking, Int. J. Robotics Research 9(2), 1990; "
            "parameters and root: P. A. Bhounsule, passivewalker.m, Cornell 2009 "
            "(github.com/pab47/pab47.github.io)")

SHORT = "bhounsule2009"

GRAVITY = 1.0                 # nondimensional
HIP_TO_FOOT_CENTRE = 1.0      # l
FOOT_RADIUS = 0.2             # r
LEG_LENGTH = HIP_TO_FOOT_CENTRE + FOOT_RADIUS   # hip to sole
HIP_MASS = 1.0                # M
LEG_MASS = 0.5                # m
LEG_COM_FROM_HIP = 0.5        # c (w = 0: on the leg axis)
LEG_INERTIA_ABOUT_COM = 0.02  # I
SLOPE_RAD = 0.01              # gam

#: Printed stable root ``zstar = [q1 u1 q2 u2]`` just after heel strike: ``q1`` stance angle
#: from the slope normal, ``q2`` angle between the legs (swing = q1 - q2), ``u`` the rates.
ROOT_Q1_U1_Q2_U2 = (0.189472782205104, -0.239124222551699, 0.378945564410209,
                    -0.053691703909393)


def root_as_absolute_angles() -> dict:
    """The printed root in walkerlab's absolute angles from the vertical [rad] and rates."""
    q1, u1, q2, u2 = ROOT_Q1_U1_Q2_U2
    return {"swing_angle_rad": q1 - q2 - SLOPE_RAD, "stance_angle_rad": q1 - SLOPE_RAD,
            "swing_rate_rad_per_s": u1 - u2, "stance_rate_rad_per_s": u1}


# The report's published-fixed-point interface (named after the paper's Eq. 11): the printed
# root as the role-ordered state [swing_angle, stance_angle, swing_rate, stance_rate].
EQ11_NAMES = ("swing_angle", "stance_angle", "swing_rate", "stance_rate")
EQ11_STATE = tuple(root_as_absolute_angles()[n + ("_rad" if n.endswith("_angle") else
                                                   "_rad_per_s")] for n in EQ11_NAMES)
FIXED_POINT_LABEL = "passivewalker.m root"
FIXED_POINT_NOTE = (
    "passivewalker.m's heel-strike law writes the old stance leg's spin angular momentum about "
    "the hip as I (v1 - v2) instead of I v1 (v2 is the rate of the angle between the legs). "
    "With I = 0 its law and ours agree to round-off (tests/test_kneed_round_feet.py); with the "
    "printed I = 0.02 its root lies 3.4e-5 rad from our fixed point in the angles and 2.2e-3 "
    "rad/s in the swing rate. Our gait is also the fixed point of the independent prototype "
    "tests/independent/round_feet_reference.py.")
