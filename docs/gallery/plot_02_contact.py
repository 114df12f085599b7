"""
Contact model: the walker on compliant ADAMS-style ground
=========================================================

The same walker with compliant contact (the IMPACT law and Coulomb friction of MSC ADAMS,
the paper's Section 4), started from the rigid gait: :class:`walkerlab.api.walker.ContactWalker`
runs the ``walkerlab contact-sim`` stage's own code in memory. Its heel strikes are the
touchdowns of the swing foot; its steps are compared with the rigid step period.
"""

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import walkerlab as wl

ROOT = Path(wl.__file__).resolve().parents[1]  # configs/ beside the package
walker = wl.Walker.from_scene(ROOT / "configs" / "paper.yaml")
rigid = walker.fixed_point()
contact = walker.contact()
walk = contact.simulate(strides=2)
print(f"outcome: {walk.outcome}; heel strikes at {np.round(walk.heel_strikes, 4)} s")
periods = walk.step_periods[np.isfinite(walk.step_periods)]
print(f"contact step periods {np.round(periods, 4)} s, "
      f"rigid {rigid.step_period:.4f} s")

# %%
# The normal force under each foot [N] during the run.

fig, ax = plt.subplots(figsize=(8, 3.2), layout="constrained")
for name, force in walk.normal_force.items():
    ax.plot(walk.t, force, label=name)
ax.set(xlabel="time [s]", ylabel="normal force [N]", title="compliant contact, paper walker")
ax.legend()
plt.show()
