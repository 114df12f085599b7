"""
Continuation: the gait over the slope, to the first period doubling
===================================================================

``walkerlab continuation`` (here :func:`walkerlab.api.continuation`) follows the paper
walker's gait over the slope by pseudo-arclength continuation, with exact Jacobians of the
Poincaré map, and locates the special points on the way: the first period doubling, where a
Floquet multiplier crosses -1, lies near 4.39°; with ``switch=True`` the period-2 branch
born there is followed too, to its own period doubling near 4.91°. The artifact goes to a
temporary runs folder.
"""

import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import walkerlab as wl

ROOT = Path(wl.__file__).resolve().parents[1]  # configs/ beside the package
runs = Path(tempfile.mkdtemp(prefix="walkerlab-gallery-"))
scene = wl.load_scene(ROOT / "configs" / "paper.yaml")
cont = wl.continuation(scene, "slope.angle_deg", 1.0, 4.95, switch=True, runs_dir=runs)
for sp in range(len(cont.special["kind"])):
    print(f"{cont.special['kind'][sp]} at {cont.special['param'][sp]:.5f} deg "
          f"(period-{cont.special['period'][sp]} branch)")

# %%
# The largest modulus of the multipliers along each branch: it reaches 1 at each period doubling.

fig, ax = plt.subplots(figsize=(7, 3.6), layout="constrained")
for branch in cont.branches:
    largest = np.abs(branch["multipliers"]).max(axis=1)
    ax.plot(branch["param"], largest, label=f"period {branch['period']}")
for p in cont.special["param"]:
    ax.axvline(p, color="0.7", lw=0.8, zorder=0)
ax.axhline(1.0, color="k", lw=0.6)
ax.set(xlabel="slope [deg]", ylabel="largest |Floquet multiplier|",
       title="paper walker: continuation over the slope")
ax.legend()
plt.show()
