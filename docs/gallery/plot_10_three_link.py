"""
The three-link walker: a torso hinged on straight legs
======================================================

``configs/threelink.yaml`` is the running example of Grizzle, Abba & Plestan (2001) and of
Westervelt, Grizzle, Chevallereau, Choi & Morris (2007): two straight legs (1 m, 5 kg at
mid-leg), a 15 kg hip and a 10 kg torso 0.5 m above the hip, hinged there, with a torque
between the torso and each leg. Passive, the torso falls; the scene's PD laws on the two
hip angles track references of the stance leg's angle (the phase variable), holding the
torso 0.1 rad forward and the swing leg ahead of the stance leg's mirror image, and the
walker finds a stable gait on level ground. Below: its fixed point and multipliers, two
strides of the rigid model, and the same laws on the compliant-contact model.
"""

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import walkerlab as wl

ROOT = Path(wl.__file__).resolve().parents[1]  # configs/ beside the package
scene = ROOT / "configs" / "threelink.yaml"
walker = wl.Walker.from_scene(scene)
gait = walker.fixed_point()
print(f"step period {gait.step_period:.5f} s, step length {gait.step_length:.4f} m, "
      f"speed {gait.speed:.4f} m/s")
print("multipliers", np.round(np.abs(gait.multipliers), 4))

# %%
# Two strides of the rigid model: the stance leg's angle, the phase variable, decreases
# through each step; the swing leg swings through; the torso stays near its 0.1 rad forward
# lean, pushed back at each heel strike and pulled forward again by the hip torques.

walk = walker.simulate(gait.x, 2)
names = walker.state_names()
fig, ax = plt.subplots(figsize=(6.4, 3.6), layout="constrained")
for name in ("stance_angle", "swing_angle", "torso_angle"):
    ax.plot(walk.t, walk.x[:, names.index(name)], label=name.removesuffix("_angle"))
for t in walk.heel_strikes:
    ax.axvline(t, color="0.8", lw=0.8, zorder=0)
ax.set(xlabel="time [s]", ylabel="angle [rad]", title="three-link walker, rigid model")
ax.legend(loc="upper right", fontsize=8)
plt.show()

# %%
# The compliant-contact model (the paper's contact law; checkerboard lanes, so that the
# straight swing foot passes over the gap at mid-stance) under the same laws, from the rigid
# gait: its steps against the rigid step period.

contact = wl.ContactWalker.from_scene(scene)
run = contact.simulate(gait.x, strides=2, period_s=gait.step_period)
print(f"contact: {run.message}")
print("contact steps [s]", np.round(np.diff(run.heel_strikes), 4),
      f"(rigid {gait.step_period:.4f} s)")
