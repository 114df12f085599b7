"""
Powered walking: a push-off on level ground
===========================================

``configs/powered_compass.yaml`` is the paper's walker on level ground with a push-off
impulse along the trailing leg just before each heel strike (Kuo 2002): the push-off supplies
the energy the heel-strike collision takes. The gait's energy ledger closes per step, and its
cost of transport is (push-off work) / (M g d). Varying the impulse changes the speed, and
the ``target`` solve (Kuo's ``findgait``) finds the impulse whose gait walks at a set speed.
Last, the contact model's gait at the scene's friction transition velocities and at the
paper's (ADAMS's defaults): the stance foot's creep costs the powered walker speed.
"""

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import walkerlab as wl

ROOT = Path(wl.__file__).resolve().parents[1]  # configs/ beside the package
walker = wl.Walker.from_scene(ROOT / "configs" / "powered_compass.yaml")
gait = walker.fixed_point()
print(f"step period {gait.step_period:.5f} s, speed {gait.speed:.4f} m/s, "
      f"cost of transport {gait.cost_of_transport:.5f}")
for term, value in gait.ledger.items():
    if term in ("push_off_impulse", "cost_of_transport"):
        continue
    print(f"  {term:28s} {np.asarray(value).ravel()[0]:+.5f} J")

# %%
# Speed and cost of transport against the push-off impulse.

field = "walker.actuation.push_off.impulse_n_s"
impulses = np.linspace(1.0, 6.0, 6)
speed, cot = [], []
for p in impulses:
    g = walker.with_changes({field: float(p)}).fixed_point()
    speed.append(g.speed)
    cot.append(g.cost_of_transport)
target = wl.target(ROOT / "configs" / "powered_compass.yaml", field, speed_m_per_s=0.45)
print(f"impulse for 0.45 m/s: {target.value:.5f} {target.unit}")

fig, ax = plt.subplots(figsize=(6, 3.6), layout="constrained")
ax.plot(speed, cot, "o-")
for p, v, c in zip(impulses, speed, cot):
    ax.annotate(f"{p:.0f} N s", (v, c), textcoords="offset points", xytext=(4, -10),
                fontsize=8)
ax.set(xlabel="speed [m/s]", ylabel="cost of transport [-]",
       title="powered compass walker: push-off impulse")
plt.show()

# %%
# The friction law's transition velocities and the contact gait's speed. The regularised
# Coulomb friction lets the loaded stance foot creep; with the paper's stiction and friction
# velocities (ADAMS's defaults, 100 and 1000 mm/s) the creep takes energy the push-off alone
# supplies on level ground, and the contact periodic gait is slower than at the scene's
# 10 and 100 mm/s.

contact = wl.ContactWalker.from_scene(ROOT / "configs" / "powered_compass.yaml")
rigid = walker.fixed_point()
print(f"rigid gait: {rigid.speed:.4f} m/s")
for v_s, v_d in ((10.0, 100.0), (100.0, 1000.0)):
    g = contact.with_changes({"contact.stiction_velocity_mm_per_s": v_s,
                              "contact.friction_velocity_mm_per_s": v_d}).periodic_gait()
    speed_c = g.step_length_m / g.period_s
    print(f"contact gait, transition velocities {v_s:g} / {v_d:g} mm/s: "
          f"{speed_c:.4f} m/s ({100 * (speed_c / rigid.speed - 1):+.1f} % of the rigid speed)")
