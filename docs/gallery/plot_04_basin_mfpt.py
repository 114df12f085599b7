"""
Basins and MFPT: the rimless wheel's basin of attraction and mean first-passage time
====================================================================================

The rimless wheel at Drake's ``RimlessWheel`` defaults (``configs/rimless_wheel.yaml``):
its basin of attraction over the stance phase's phase plane (Coleman, Chatterjee & Ruina
1997), on a small grid, and its mean first-passage time - the expected number of heel
strikes before a fall - on per-step random slopes (Byl & Tedrake 2009), by Monte Carlo walks
and by the mesh of the post-impact section. Both run through :mod:`walkerlab.api` into a
temporary runs folder.
"""

import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
from matplotlib.colors import ListedColormap

import walkerlab as wl
from walkerlab.plotting.basin_figures import OUTCOME_COLORS

ROOT = Path(wl.__file__).resolve().parents[1]  # configs/ beside the package
runs = Path(tempfile.mkdtemp(prefix="walkerlab-gallery-"))
scene = wl.load_scene(ROOT / "configs" / "rimless_wheel.yaml")
basin = wl.basin(scene, grid=(30, 30), runs_dir=runs)
outcomes = list(basin.attrs["outcomes"])
print({o: int(basin[f"counts_{o}"]) for o in outcomes if f"counts_{o}" in basin})

# %%
# MFPT at three slope spreads, 200 walks each (a small run; the scene asks for 1000).

noisy = wl.with_changes(scene, {"mfpt.walks": 200, "mfpt.max_steps": 2000})
mfpt = wl.mfpt(noisy, sigma_rad=[0.012, 0.016, 0.02], method="both", runs_dir=runs)
for s, mesh, mc, se in zip(mfpt.sigma_rad.values, mfpt.mfpt_steps_mesh.values,
                           mfpt.mfpt_steps_montecarlo.values,
                           mfpt.mfpt_steps_montecarlo_stderr.values):
    print(f"sigma {s:.3f} rad: mesh {mesh:7.2f} steps, Monte Carlo {mc:7.2f} +- {se:.2f}")

# %%
# The basin (one colour per outcome) and the MFPT against the slopes' spread.

fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4), layout="constrained")
colors = [OUTCOME_COLORS.get(o, "k") for o in outcomes]
ax1.pcolormesh(basin.x, basin.y, basin.outcome, cmap=ListedColormap(colors),
               vmin=-0.5, vmax=len(outcomes) - 0.5, shading="nearest")
seen = [i for i, o in enumerate(outcomes) if (basin.outcome == i).any()]
for i in seen:
    ax1.plot([], [], "s", color=colors[i], label=outcomes[i].replace("_", " "))
ax1.legend(loc="lower right", fontsize=8)
ax1.set(xlabel=f"stance angle [{basin.x.units}]", ylabel=f"stance rate [{basin.y.units}]",
        title="basin of attraction (30 x 30)")
ax2.errorbar(mfpt.sigma_rad, mfpt.mfpt_steps_montecarlo,
             yerr=mfpt.mfpt_steps_montecarlo_stderr, fmt="o", label="Monte Carlo")
ax2.plot(mfpt.sigma_rad, mfpt.mfpt_steps_mesh, "s-", label="mesh")
ax2.set(yscale="log", xlabel="slope spread σ [rad]", ylabel="MFPT [steps]",
        title="mean first-passage time")
ax2.legend()
plt.show()
