"""Stage ``mfpt``: mean first-passage time on per-step random slopes -> ``mfpt.h5`` (+ figure).

Reads the ``mfpt`` section (defaults when absent), ``terrain.per_step`` and the gait from
``fixedpoint.h5``; the study, resumable from ``mfpt.h5.partial``, is
:func:`walkerlab.studies.mfpt.resumable_mfpt_study`; the layout :mod:`walkerlab.io.schemas.mfpt`.
"""

from __future__ import annotations

from pathlib import Path

from walkerlab import progress
from walkerlab.config import Scene
from walkerlab.config.options import mfpt_options
from walkerlab.io.freshness import input_hash
from walkerlab.io.runpaths import figures_dir, stage_artifact
from walkerlab.io.schemas import mfpt as schema
from walkerlab.io.schemas.fixedpoint import load_fixedpoint
from walkerlab.models.contact.parts import periodic_gait_refusal
from walkerlab.plotting.artifact_figures import save_mfpt_figure
from walkerlab.stages.common import StageError, StageOutcome, require, run_cached
from walkerlab.studies.mfpt import MfptStudyError, mfpt_summary, resumable_mfpt_study
from walkerlab.walker.kinds import KindRefused
from walkerlab.walker.plant import Plant

SECTIONS = ("walker", "slope", "ideal", "terrain", "mfpt")


def figure_path(scene: Scene, runs_root: Path | str) -> Path:
    """``runs/<scene>/report/figures/mfpt.png``."""
    return figures_dir(scene, runs_root) / "mfpt.png"


def draw(scene: Scene, runs_root: Path | str = "runs") -> list[Path]:
    """Draw log MFPT against sigma (PNG + SVG) from ``mfpt.h5``."""
    d = schema.load(stage_artifact(scene, runs_root, "mfpt"))
    return save_mfpt_figure(d, scene.name, figure_path(scene, runs_root).parent)


def check(scene: Scene, sigma_rad: list[float] | None = None, method: str | None = None,
          workers: int = 2, **_options):
    """``(MfptSettings, workers)`` with the command-line overrides, checked before anything
    runs (:func:`walkerlab.config.options.mfpt_options`).  Raises StageError: no
    ``fixedpoint`` section, or ``mfpt.model: contact`` for a walker without a contact view
    or whose contact periodic gait the contact view does not find (a 3D walker, a rimless
    wheel); SceneError: an option out of bounds (one line)."""
    require(scene, "fixedpoint", "mfpt")
    st, workers = mfpt_options(scene, sigma_rad, method, workers)
    if st.model == "contact":  # the contact walker's Monte Carlo: the table's contact cell
        plant = Plant.from_scene(scene)
        kind = plant.kind
        try:
            kind.require("walk", "contact", f"mfpt.model: contact: {kind.field}")
        except KindRefused as exc:
            raise StageError(str(exc)) from None
        # its walks start on the contact model's own periodic gait
        why = periodic_gait_refusal(scene, plant.data)
        if why is not None:
            raise StageError(f"mfpt.model: contact: {why}")
    return st, workers


def run(scene: Scene, runs_root: Path | str = "runs", force: bool = False,
        sigma_rad: list[float] | None = None, method: str | None = None, workers: int = 2,
        scheduler=None) -> StageOutcome:
    """Compute (or reuse) the MFPT at each sigma [rad] (``--sigma-rad``; ``method``: mesh,
    montecarlo or both) on ``workers`` local processes or a Dask ``scheduler``, and draw it.
    Raises StageError (one line): no ``fixedpoint`` section, or a walker the study cannot
    carry (:class:`walkerlab.studies.mfpt.MfptStudyError`)."""
    st, workers = check(scene, sigma_rad, method, workers)
    per = scene.terrain.per_step if scene.terrain is not None else None
    if per is not None and per.slope_sd_rad > 0 and getattr(st, "sigma_m", None) is None:
        progress.note(f"mfpt: terrain.per_step.slope_sd_rad ({per.slope_sd_rad:g} rad) is not "
                      "used: the study sweeps mfpt.sigma_rad (--sigma-rad) "
                      f"{', '.join(f'{v:g}' for v in st.sigma_rad)} rad")
    up, path = (stage_artifact(scene, runs_root, s) for s in ("fixedpoint", "mfpt"))
    done = []  # the resume file, removed once the artifact is written

    def work():

        x_star = load_fixedpoint(up).x
        try:
            data, partial = resumable_mfpt_study(
                scene, x_star, st, path.with_name(path.name + ".partial"),
                input_hash("mfpt", scene, SECTIONS, (up,), extra="resume"), not force,
                workers, scheduler, plant=Plant.from_scene(scene))  # described once, handed down
        except MfptStudyError as exc:
            raise StageError(str(exc)) from None
        done.append(partial)
        return (lambda f: schema.write(f, data)), mfpt_summary(data, st.mesh_rel_change)

    out = run_cached("mfpt", scene, runs_root, SECTIONS, (up,), work, force,
                     {"workers": workers if scheduler is None else 0,
                      "scheduler": str(scheduler or "")},
                     extra_key=f"sigma={st.sigma_rad};method={st.method}")
    for partial in done:
        partial.remove()
    if not out.reused or not figure_path(scene, runs_root).is_file():
        draw(scene, runs_root)
    return out
