"""Bezier virtual constraints for RABBIT (configs/rabbit_hzd.yaml) from the hand-made gait of
configs/rabbit.yaml (scripts/rabbit_references.py): its four joint angles (hips: thigh -
torso, knees: shank - thigh) as functions of the phase ``s = (theta - theta+) / (theta- -
theta+)`` over the designed step (the virtual stance leg from ``+theta0`` to ``-theta0``),
fitted by least squares with Bezier polynomials of degree ``M`` (Westervelt, Grizzle &
Koditschek 2003, IEEE TAC 48(1):42-56, Eq. 36).  ``c_0``, ``c_1`` are placeholders in a
scene with ``invariant: true`` (the impact map sets them).

Usage: ``python scripts/rabbit_bezier.py [M]`` (prints the scene's outputs).
"""

from __future__ import annotations

import sys
from math import comb
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from rabbit_references import DESIGN, configuration  # noqa: E402

JOINTS = ("stance_hip", "swing_hip", "stance_knee", "swing_knee")


def fit(M: int = 5, d=DESIGN) -> dict[str, np.ndarray]:
    """Each joint's Bezier coefficients (M + 1,) [rad], least squares on 201 phases."""
    th0 = d["theta0_rad"]
    s = np.linspace(0.0, 1.0, 201)
    c = np.array([configuration(th0 - 2 * th0 * si, d) for si in s]).T
    ss, st, wt, ws, t = c
    angles = {"stance_hip": st - t, "swing_hip": wt - t, "stance_knee": ss - st,
              "swing_knee": ws - wt}
    A = np.array([[comb(M, j) * si ** j * (1 - si) ** (M - j) for j in range(M + 1)]
                  for si in s])
    return {k: np.linalg.lstsq(A, v, rcond=None)[0] for k, v in angles.items()}


if __name__ == "__main__":
    M = int(sys.argv[1]) if len(sys.argv) > 1 else 5
    for k, c in fit(M).items():
        print(f"        - {{joint: {k}, bezier_rad: [{', '.join(f'{v:.6f}' for v in c)}]}}")
