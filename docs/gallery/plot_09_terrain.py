"""
Terrain: down stairs in the rigid and the contact model
=======================================================

``configs/stairs.yaml``: the paper's walker down 1 cm stairs (``terrain.kind: stairs``), one
step per stair. The rigid model's heel strike is the swing foot reaching the next tread, so
the stair gait is a fixed point of the Poincaré map like a slope gait; the contact model
walks the same stairs as checkerboard patches at the rigid footholds, each a riser lower.
"""

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import walkerlab as wl

ROOT = Path(wl.__file__).resolve().parents[1]  # configs/ beside the package
walker = wl.Walker.from_scene(ROOT / "configs" / "stairs.yaml")
gait = walker.fixed_point()
print(f"rigid stair gait: step period {gait.step_period:.6f} s, "
      f"max |Floquet multiplier| {np.max(np.abs(gait.multipliers)):.4f}")
walk = walker.contact().simulate(strides=4)
periods = walk.step_periods[np.isfinite(walk.step_periods)]
print(f"contact: {walk.outcome}; step periods {np.round(periods, 4)} s")

print(f"mean contact step after the start's transient {np.mean(periods[2:]):.4f} s "
      f"({100 * (np.mean(periods[2:]) / gait.step_period - 1):+.2f} % of the rigid step)")

# %%
# The hip's height [m] in the contact run: it falls one riser (10 mm) a step on average,
# rising over each stance leg and dropping at each heel strike (grey lines).

fig, ax = plt.subplots(figsize=(8, 3.2), layout="constrained")
ax.plot(walk.t, walk.column("hip_y"), label="contact model")
for t in walk.heel_strikes:
    ax.axvline(t, color="0.7", lw=0.8)
at_strikes = np.interp(walk.heel_strikes, walk.t, walk.column("hip_y"))
print(f"hip height at the heel strikes falls {-1e3 * np.mean(np.diff(at_strikes)):.2f} mm "
      "a step (the riser: 10 mm)")
ax.set(xlabel="time [s]", ylabel="hip height [m]",
       title="contact walker down 1 cm stairs (grey: heel strikes)")
ax.legend()
plt.show()
