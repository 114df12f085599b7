"""
Optimisation: the compass walker's least-effort gait
====================================================

``walkerlab optimize`` (here :func:`walkerlab.api.optimize`) finds a periodic gait of a
walker with a hip torque by Hermite-Simpson direct collocation (CasADi with IPOPT), least
``∫u² dt`` for ``configs/compass_optimal.yaml``, and replays it on the rigid model before it
calls it a gait. On a slope the optimum is the passive gait: the torque vanishes and the step
period is the fixed point's. On level ground the passive walker has no gait; with a free
push-off and targets of 0.6 m/s and 0.5 m steps the optimiser finds one, starting from the
targets (the legs swapping between the step's heel-strike postures). Needs the ``optimize``
extra (CasADi).
"""

import tempfile
from pathlib import Path

import matplotlib.pyplot as plt

import walkerlab as wl

ROOT = Path(wl.__file__).resolve().parents[1]  # configs/ beside the package
runs = Path(tempfile.mkdtemp(prefix="walkerlab-gallery-"))
scene = wl.load_scene(ROOT / "configs" / "compass_optimal.yaml")
slope = wl.optimize(scene, runs_dir=runs)
print(f"on the slope: least effort {float(slope.objective):.2e} N^2 m^2 s, "
      f"step period {float(slope.step_period):.6f} s (a gait: {slope.attrs['gait']})")
passive = wl.Walker.from_scene(scene).fixed_point()
print(f"the passive fixed point's step period: {passive.step_period:.6f} s")

# %%
# Level ground, a free push-off, 0.6 m/s with 0.5 m steps.

level = wl.with_changes(scene, {"name": "compass_level", "slope.angle_rad": 0.0,
                                "optimize.push_off": "free",
                                "optimize.target_speed_m_per_s": 0.6,
                                "optimize.target_step_length_m": 0.5})
opt = wl.optimize(level, runs_dir=runs)
print(f"level ground: push-off {float(opt.push_off):.3f} N s, effort "
      f"{float(opt.objective):.3f} N^2 m^2 s, step period {float(opt.step_period):.4f} s, "
      f"rigid replay error {float(opt.replay_max_state_error):.1e}, "
      f"contact replay step period {float(opt.contact_replay_step_period):.4f} s")

fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(9, 3.4), layout="constrained")
for name in ("swing_angle", "stance_angle"):
    ax1.plot(opt.time, opt[f"states_{name}"], label=name.replace("_", " "))
ax1.set(xlabel="time [s]", ylabel="angle [rad]", title="optimal step, level ground")
ax1.legend()
ax2.plot(opt.time, opt.torque_hip)
ax2.set(xlabel="time [s]", ylabel="hip torque [N m]", title="least ∫u² dt")
plt.show()
