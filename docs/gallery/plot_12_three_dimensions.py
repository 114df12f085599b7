"""
Walkers in three dimensions: the wheel's critical slope, the walker's lateral mode
==================================================================================

Two walkers of ``walker.space: 3d``. The disc-like rimless wheel
(``configs/rimless_wheel_3d_disc.yaml``; Coleman, Chatterjee & Ruina 1997) rolls stably
straight downhill on steep slopes only: continued over the slope, its largest multiplier -
the neutral one of its heading set aside - crosses 1 at its critical slope, about
0.186 rad. The paper's walker with hip width (``configs/hip_width.yaml``; Kuo 1999) walks
fore-aft as the planar walker but has an unstable lateral mode: continued over the hip
width, that multiplier stays far outside the unit circle. The artifacts go to a temporary
runs folder.
"""

import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import walkerlab as wl
from walkerlab.numerics import without_neutral

ROOT = Path(wl.__file__).resolve().parents[1]  # configs/ beside the package
runs = Path(tempfile.mkdtemp(prefix="walkerlab-gallery-"))


def largest_but_neutral(mult: np.ndarray, neutral: int) -> np.ndarray:
    """Per point, the largest |multiplier| with the ``neutral`` ones nearest 1 left out."""
    return np.array([np.abs(without_neutral(row, neutral)).max()
                     for row in np.atleast_2d(mult)])


wheel = wl.load_scene(ROOT / "configs" / "rimless_wheel_3d_disc.yaml")
cw = wl.continuation(wheel, "slope.angle_rad", 0.2, 0.15, runs_dir=runs)
walker = wl.load_scene(ROOT / "configs" / "hip_width.yaml")
cl = wl.continuation(walker, "walker.hip_width_m", 0.1, 0.2, runs_dir=runs)
for sp in range(len(cw.special["kind"])):
    print(f"wheel: multiplier through +1 at slope {cw.special['param'][sp]:.4f} rad")

# %%
# Left: the wheel's largest non-neutral multiplier against the slope (its heading's 1 set
# aside). Right: the hip-width walker's largest multiplier per stride against its hip width.

fig, (a, b) = plt.subplots(1, 2, figsize=(9, 3.6), layout="constrained")
for branch in cw.branches:
    a.plot(branch["param"], largest_but_neutral(branch["multipliers"], 1))
for p in cw.special["param"]:
    a.axvline(p, color="0.7", lw=0.8, zorder=0)
a.axhline(1.0, color="k", lw=0.6)
a.set(xlabel="slope [rad]", ylabel="largest |multiplier| (heading set aside)",
      title="disc-like rimless wheel")
for branch in cl.branches:
    b.semilogy(branch["param"], np.abs(branch["multipliers"]).max(axis=1))
b.axhline(1.0, color="k", lw=0.6)
b.set(xlabel="hip width [m]", ylabel="largest |multiplier| per stride",
      title="walker with hip width: the lateral mode")
plt.show()
