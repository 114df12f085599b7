"""The virtual constraints of configs/rabbit.yaml: reference tables of the four actuated
joints of a five-link biped as functions of the phase variable (the virtual stance leg's
angle ``theta``, hip to stance foot), printed as the scene's ``walker.actuation.torques``.

Design (a hand-made symmetric gait, as hybrid zero dynamics asks: the heel strike's role
swap maps the references' end configuration onto their start, Westervelt, Grizzle &
Koditschek 2003, IEEE TAC 48(1):42-56, Sec. IV-V):

- the torso at a constant angle ``torso_rad`` (negative: leaning forward, which feeds the
  gait's energy on level ground);
- the stance knee at a constant flexion ``-knee_rad`` (knee angle = shank - thigh);
- the virtual stance leg at ``theta`` going from ``+theta0`` to ``-theta0``, the virtual swing
  leg (hip to swing foot) at ``-theta``, its knee flexed by ``clearance_rad`` more in
  mid-swing (``sin^2`` bump), so both virtual legs have the same length at the ends:
  the swing foot reaches the level ground at ``theta = -theta0`` with the legs mirrored;
- outside ``[-theta0, theta0]`` the same formulas continue (the swing foot keeps going
  forward and down: the heel strike comes wherever tracking puts it) up to ``extend_rad``.

A leg with thigh ``lt`` and shank ``ls`` and knee angle ``k`` has its thigh at
``theta - atan2(ls sin k, lt + ls cos k)`` when its virtual leg is at ``theta``.

Usage: ``python scripts/rabbit_references.py`` (the numbers in configs/rabbit.yaml).
"""

from __future__ import annotations

import numpy as np

#: RABBIT's thigh and shank lengths [m] (Westervelt et al. 2003, Table I)
THIGH_M = SHANK_M = 0.4
#: the gait of configs/rabbit.yaml
DESIGN = {"theta0_rad": 0.25, "knee_rad": 0.2, "clearance_rad": 0.6, "torso_rad": -0.1,
          "extend_rad": 0.15, "points": 17}
JOINTS = ("stance_hip", "swing_hip", "stance_knee", "swing_knee")


def thigh_offset(knee_rad):
    """Angle [rad] from the virtual leg to the thigh, ``atan2(ls sin k, lt + ls cos k)``."""
    return np.arctan2(SHANK_M * np.sin(knee_rad), THIGH_M + SHANK_M * np.cos(knee_rad))


def configuration(theta, d=DESIGN) -> np.ndarray:
    """Absolute link angles (stance shank, stance thigh, swing thigh, swing shank, torso)
    [rad] of the designed gait at the phase ``theta`` [rad]."""
    th0 = d["theta0_rad"]
    u = np.clip((th0 - theta) / (2 * th0), 0.0, 1.0)  # 0 at the step's start, 1 at its end
    k_sw = -d["knee_rad"] - d["clearance_rad"] * np.sin(np.pi * u) ** 2
    k_st = -d["knee_rad"]
    st = theta - thigh_offset(k_st)
    wt = -theta - thigh_offset(k_sw)
    return np.array([st + k_st, st, wt, wt + k_sw, d["torso_rad"]])


def joint_references(d=DESIGN) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """The phase table (increasing) [rad] and each joint's reference angles [rad]: hips
    thigh - torso, knees shank - thigh."""
    phase = np.linspace(-d["theta0_rad"] - d["extend_rad"], d["theta0_rad"] + d["extend_rad"],
                        d["points"])
    c = np.array([configuration(p, d) for p in phase]).T
    ss, st, wt, ws, t = c
    return phase, {"stance_hip": st - t, "swing_hip": wt - t, "stance_knee": ss - st,
                   "swing_knee": ws - wt}


def main() -> None:
    phase, refs = joint_references()

    def row(key, v):  # a YAML flow list wrapped under its key
        import textwrap

        head = f"            {key}: ["
        text = ", ".join(f"{x:.6g}" if key == "phase_rad" else f"{x:.6f}" for x in v) + "]"
        return textwrap.fill(text, 96, initial_indent=head,
                             subsequent_indent=" " * len(head))
    for j in JOINTS:
        print(f"      - joint: {j}\n        max_torque_n_m: 150.0\n        law:")
        print("          stiffness_n_m_per_rad: 2000.0")
        print(f"          damping_n_m_s_per_rad: {120.0 if 'hip' in j else 60.0}")
        print("          reference:")
        print(row("phase_rad", phase))
        print(row("angle_rad", refs[j]))


if __name__ == "__main__":
    main()
