"""
Gait and stability: the paper walker's fixed point and Floquet multipliers
==========================================================================

The compass-gait walker of ``configs/paper.yaml`` (the paper's Table 1) on its slope: the
period-1 gait is a fixed point ``x* = P(x*)`` of the Poincaré map ``P`` from one heel strike
to the next, and its Floquet multipliers (the eigenvalues of ``DP(x*)``, from the
variational equations with saltation matrices) say whether it is stable: all inside the
unit circle. :class:`walkerlab.api.walker.Walker` holds the walker in memory; nothing is
written to disk.
"""

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import walkerlab as wl

ROOT = Path(wl.__file__).resolve().parents[1]  # configs/ beside the package
walker = wl.Walker.from_scene(ROOT / "configs" / "paper.yaml")
gait = walker.fixed_point()
print(f"step period {gait.step_period:.8f} s, step length {gait.step_length:.4f} m, "
      f"speed {gait.speed:.4f} m/s")
for name, value in gait.state.items():
    print(f"  {name:14s} {value:+.6f}")
print("|Floquet multipliers|:", np.round(np.abs(gait.multipliers), 4),
      "-> stable" if gait.stable else "-> unstable")

# %%
# Two strides from the fixed point, and the multipliers in the complex plane.

walk = walker.simulate(gait.x, strides=2)
names = walker.state_names()
fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(9, 3.6), layout="constrained")
for i in (0, 1):
    ax1.plot(walk.t, walk.x[:, i], label=names[i].replace("_", " "))
for t in walk.heel_strikes:
    ax1.axvline(t, color="0.8", lw=0.8, zorder=0)
ax1.set(xlabel="time [s]", ylabel="leg angle [rad]", title="two strides (heel strikes grey)")
ax1.legend()
circle = np.exp(1j * np.linspace(0, 2 * np.pi, 200))
ax2.plot(circle.real, circle.imag, color="0.6", lw=0.8)
ax2.plot(gait.multipliers.real, gait.multipliers.imag, "o", color="C3")
ax2.set(xlabel="Re λ", ylabel="Im λ", title="Floquet multipliers", aspect="equal")
plt.show()
