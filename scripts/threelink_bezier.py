"""Bezier virtual constraints for the three-link walker (configs/threelink_hzd.yaml) from the
PD gait of configs/threelink.yaml: at its fixed point, one step's swing-leg and torso
absolute angles as functions of the phase ``s = (theta - theta+) / (theta- - theta+)``,
``theta`` the stance leg's angle (``theta+`` / ``theta-`` its values just after / before
the heel strike), fitted by least squares with Bezier polynomials of degree ``M``
(Westervelt, Grizzle & Koditschek 2003, IEEE TAC 48(1):42-56, Eq. 36).  ``c_0``, ``c_1``
are placeholders in a scene with ``invariant: true`` (the impact map sets them).

Usage: ``python scripts/threelink_bezier.py [M]`` (prints the scene's outputs and the fit's
largest residual).
"""

from __future__ import annotations

import sys
from math import comb
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
OUTPUTS = ("swing_leg", "torso")


def fit(M: int = 4, scene=ROOT / "configs" / "threelink.yaml"):
    """Each output's Bezier coefficients (M + 1,) [rad] and the fit's largest residual
    [rad], least squares on the PD gait's samples of one step (2 kHz)."""
    import walkerlab as wl

    walker = wl.Walker.from_scene(scene)
    gait = walker.fixed_point()
    walk = walker.simulate(gait.x, 1, sample_rate_hz=2000)
    names = walker.state_names()
    first = walk.t < walk.heel_strikes[0]
    x = walk.x[first]
    theta = x[:, names.index("stance_angle")]
    th_p = gait.x[names.index("stance_angle")]
    th_m = -gait.x[names.index("stance_angle")]  # the symmetric heel strike: q1- = -q2- = -q1+
    s = (theta - th_p) / (th_m - th_p)
    A = np.array([[comb(M, j) * si ** j * (1 - si) ** (M - j) for j in range(M + 1)]
                  for si in s])
    out, worst = {}, 0.0
    for link in OUTPUTS:
        v = x[:, names.index(f"{link.removesuffix('_leg')}_angle")]
        c = np.linalg.lstsq(A, v, rcond=None)[0]
        out[link] = c
        worst = max(worst, float(np.max(np.abs(A @ c - v))))
    return out, worst


if __name__ == "__main__":
    M = int(sys.argv[1]) if len(sys.argv) > 1 else 4
    coeffs, worst = fit(M)
    for k, c in coeffs.items():
        print(f"        - {{link: {k}, bezier_rad: [{', '.join(f'{v:.6f}' for v in c)}]}}")
    print(f"# largest residual of the fit: {worst:.2e} rad")
