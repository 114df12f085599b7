"""Stage ``animate``: the walker walking, as ``report/figures/animation.gif`` (+ ``.mp4``).

Not an HDF5 artifact (a figure, like ``walkerlab plot``'s); always redrawn (a few seconds).

Drawn from the artifacts only: ``simulate.h5`` (run or reused first, as ``compare`` does) and,
where it exists and is current, ``contact_sim.h5`` beside it (rigid and contact side by side,
same times).  A ``contact_sim.h5`` of another scene (or of an earlier fixed point) or one
changed after it was written is left out, and a one-line note says why.
The slope comes from the resolved scene stored in ``simulate.h5``.  GIF through matplotlib's
Pillow writer (one shared palette, :func:`walkerlab.plotting.animation.gif_writer`); MP4
through its ffmpeg writer only when ffmpeg is installed.  Both written atomically (temporary
name in the same folder, then rename), then a stamp of the artifacts they were drawn from
(:data:`walkerlab.stages.report_inputs.ANIMATION_STAMP`): the report shows the animation
only while they are the run folder's current ones.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

from walkerlab.config import Scene, SlopeSettings, TerrainSettings
from walkerlab.io import runpaths
from walkerlab.io.freshness import drawing_key
from walkerlab.io.runpaths import figures_dir, stage_artifact
from walkerlab.io.schemas.contact_sim import load_contact_sim
from walkerlab.io.schemas.simulate import load_simulate
from walkerlab.io.stage_files import CONTACT_SIM
from walkerlab.io.terrain import load_terrain
from walkerlab.plotting import CONTACT_LABEL, IDEAL_LABEL
from walkerlab.stages.report_inputs import ANIMATION_STAMP, computed_for

#: Frames per second, and the most frames one animation gets (a 5-stride compass gait,
#: 7 s, is 141 frames at 20 fps; longer runs play faster).
FPS = 20.0
MAX_FRAMES = 150


@dataclass
class AnimateOutcome:
    """Files written and a one-line note (e.g. why there is no MP4)."""

    paths: list[Path] = field(default_factory=list)
    note: str = ""


def run(scene: Scene, runs_root: Path | str = "runs", fps: float = FPS,
        max_frames: int = MAX_FRAMES) -> AnimateOutcome:
    """Write ``runs/<scene>/report/figures/animation.gif`` (and ``.mp4`` with ffmpeg) at
    ``fps`` frames per second [1/s], at most ``max_frames``
    (:func:`walkerlab.plotting.animation.frame_times`)."""
    from matplotlib import pyplot as plt
    from matplotlib.animation import FFMpegWriter, writers

    from walkerlab.plotting.animation import gif_writer, save_frames, walker_animation  # light

    sim = load_simulate(stage_artifact(scene, runs_root, "simulate"),
                        scene.simulate.strides if scene.simulate is not None else None)
    trajs, ground, notes = {IDEAL_LABEL: sim.samples}, {}, []
    contact = stage_artifact(scene, runs_root, CONTACT_SIM.name)
    # any of the contact stage's variants: plain, --adjust, --periodic
    why = computed_for(scene, runs_root, CONTACT_SIM.name, ("adjust", "periodic")) \
        if contact.is_file() else ""
    if why:
        notes.append(f"animated the rigid walker only: {why} (rerun 'walkerlab contact-sim' "
                     "to animate the contact walker beside it)")
    elif contact.is_file():  # with the checkerboard it walks on
        trajs[CONTACT_LABEL] = load_contact_sim(contact).samples
        ground[CONTACT_LABEL] = load_terrain(contact)
    resolved = json.loads(sim.scene_json)
    slope = SlopeSettings.model_validate(resolved["slope"]).phi_rad
    if (resolved.get("terrain") or {}).get("kind") == "stairs":  # the rigid walker's stairs
        t = TerrainSettings.model_validate(resolved["terrain"])
        ground[IDEAL_LABEL] = {"stairs": (t.riser_m, t.tread_m, t.direction or "down",
                                          t.tread_m / 2 if t.first_foothold_m is None
                                          else t.first_foothold_m)}
    folder = figures_dir(scene, runs_root, claim=True)
    frames = walker_animation(trajs, slope, fps=fps, max_frames=max_frames,
                              time_unit=sim.units.time, terrain=ground)
    out = AnimateOutcome(note="; ".join(notes))
    stamp = folder / ANIMATION_STAMP
    stamp.unlink(missing_ok=True)  # no stamp while the animation is half written
    try:
        out.paths.append(save_frames(frames, folder / "animation.gif", gif_writer(fps)))
        if writers.is_available("ffmpeg"):
            out.paths.append(save_frames(frames, folder / "animation.mp4", FFMpegWriter(fps=fps)))
        else:
            out.note = "; ".join(notes + ["ffmpeg not found: wrote the GIF only (install "
                                          "ffmpeg for the MP4)"])
    finally:
        plt.close(frames.fig)
    drawn_from = {"simulate": stage_artifact(scene, runs_root, "simulate")}
    if CONTACT_LABEL in trajs:
        drawn_from[CONTACT_SIM.name] = contact
    runpaths.atomic_text(stamp, drawing_key(drawn_from))  # what the report checks it by
    return out

