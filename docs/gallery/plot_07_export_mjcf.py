"""
Exports: the walker as MJCF, walking in MuJoCo
==============================================

``walkerlab export SCENE --format mjcf`` (here :func:`walkerlab.export_scene`, also
``walkerlab.api.export``) writes the walker as a floating planar multibody model for MuJoCo:
links with their masses and inertias, hinges, the slope, the contact from the scene's IMPACT
law and a ``gait`` keyframe at the rigid fixed point.
:func:`walkerlab.export.mujoco_walk.walk` runs it in MuJoCo from that keyframe; its heel
strikes come at the rigid step period. (``--format urdf`` and ``--format adm`` write the
URDF for Drake and Pinocchio and the MSC Adams dataset.) Walking it needs the ``engines``
extra (MuJoCo).
"""

import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import walkerlab as wl
from walkerlab.export.mujoco_walk import walk

ROOT = Path(wl.__file__).resolve().parents[1]  # configs/ beside the package
runs = Path(tempfile.mkdtemp(prefix="walkerlab-gallery-"))
scene = wl.load_scene(ROOT / "configs" / "paper.yaml")
xml = wl.export_scene(scene, "mjcf", runs_dir=runs)
text = Path(xml).read_text()
print(f"{Path(xml).name}: {len(text.splitlines())} lines")
print("\n".join(line for line in text.splitlines()
                if "<body" in line or "<joint" in line or "<key" in line)[:1500])

# %%
# Ten seconds in MuJoCo from the ``gait`` keyframe: the intervals between heel strikes
# against the rigid model's step period.

run = walk(xml, t_final_s=10.0)
rigid = wl.Walker.from_scene(scene).fixed_point()
intervals = np.diff(run.times_s)
print(f"{len(run.times_s)} heel strikes, legs alternate: {run.alternating}, fell: {run.fell}")
print(f"mean interval {intervals.mean():.5f} s against the rigid {rigid.step_period:.5f} s "
      f"({100 * (intervals.mean() / rigid.step_period - 1):+.3f} %)")

fig, ax = plt.subplots(figsize=(6.5, 3.4), layout="constrained")
ax.plot(np.arange(1, len(intervals) + 1), intervals, "o-", label="MuJoCo (exported MJCF)")
ax.axhline(rigid.step_period, color="C3", ls="--", label="rigid model")
ax.set(xlabel="step", ylabel="step period [s]", title="paper walker in MuJoCo")
ax.legend()
plt.show()
