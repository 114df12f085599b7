"""Garcia, Chatterjee, Ruina & Coleman (1998): the simplest walking model.

Nondimensional (leg length l = g = hip mass = 1, time in units of sqrt(l/g)); state just after
heel strike: ``theta`` = stance-leg angle from the slope normal [rad], ``theta_dot`` [1/time];
the hip angle is ``phi = 2 theta`` and ``phi_dot = theta_dot (1 - cos 2 theta)`` on the section.

Where each number is printed
----------------------------
- ``STABLE_SLOPE_RANGE_RAD``: the abstract ("The model exhibits two period-one gait cycles,
  one of which is stable when 0 < gamma < 0.015 rad. With increasing gamma, stable cycles of
  higher periods appear, and the walking-like motions apparently become chaotic through a
  sequence of period doublings"), PubMed 10412391.
- ``LONG_*`` / ``SHORT_*`` (gamma = 0.009): the initial conditions of the authors' MATLAB
  simulation (``int_doubpend`` / ``yderivs_doubpend``, "initial conditions gam=0.009 long step
  to 1e-10", with the eigenvalues in the comment), as redistributed in public repositories;
  a public Floquet study (``floquet_Garcia.m``) attributes the same digits to the paper's
  Table 1.  We could not read the journal's table itself; the digits agree with our own
  computation to 1e-10 (fixed point) - see ``tests/models/test_scenes.py``
  (``test_simplest_walker_long_period_gait_matches_garcia``).
  The eigenvalues in that comment (-0.19121 +- 0.55633i) differ from ours (-0.19010 +-
  0.55760i, |lambda| 0.5883 vs 0.5891) by 1e-3; an independent script with Garcia's printed
  equations and a tight-tolerance finite-difference stride map gives ours, so we attribute
  the difference to their finite-difference Jacobian (cf. Bhounsule 2014, who reports only
  moderate accuracy of finite-difference eigenvalues for this model).
"""


CITATION = ("M. Garcia, A. Chatterjee, A. Ruina, M. Coleman, \"The simplest walking model: "
            "stability, complexity, and scaling\", J. Biomech. Eng. 120(2):281-288, 1998, "
            "doi:10.1115/1.2798313")

#: slope of the reference gaits [rad]
SLOPE_RAD = 0.009

#: long-period (stable) period-1 gait at gamma = 0.009: theta*, theta_dot*
LONG_THETA_RAD = 0.20031090049483
LONG_THETA_DOT = -0.19983247291764
#: its Floquet multipliers as given with it (finite differences, see module docstring)
LONG_MULTIPLIERS = (complex(-0.19120868949940, 0.55633363687106),
                    complex(-0.19120868949940, -0.55633363687106))

#: short-period (unstable) period-1 gait at gamma = 0.009
SHORT_THETA_RAD = 0.19393736960624
SHORT_THETA_DOT = -0.20386692731962
SHORT_MULTIPLIERS = (4.000, 0.459)

#: slope range where the long-period gait is stable [rad] (abstract)
STABLE_SLOPE_RANGE_RAD = (0.0, 0.015)

SHORT = "garcia1998"

# The report's published-fixed-point interface: the printed values by walkerlab state name
# (configs/simplest.yaml: state [stance_angle, hip_angle, stance_rate, hip_rate]; the hip angle
# and rate on the section follow from these, phi = 2 theta, phi_dot = theta_dot (1 - cos 2 theta),
# and are not listed because they are not printed).
FIXED_POINT_NAMES = ("stance_angle", "stance_rate")
FIXED_POINT_STATE = (LONG_THETA_RAD, LONG_THETA_DOT)
FIXED_POINT_LABEL = "long-period gait, gamma = 0.009"
FIXED_POINT_NOTE = (
    "Garcia et al.'s multipliers for this gait, -0.19121 +- 0.55633i (finite differences), "
    "differ by 1e-3 from ours (-0.19010 +- 0.55760i, variational equations); an independent "
    "stride map with their printed equations gives ours. The long-period gait is stable for "
    "0 < gamma < 0.015 rad (their abstract); we find the period doubling at gamma = 0.01509 rad.")
