"""Stage ``mfpt``: mean first-passage time on per-step random slopes -> ``mfpt.h5`` (+ figure).

Reads (after the pipeline has run ``fixedpoint``, :mod:`walkerlab.stages.pipeline`) the
scene's ``mfpt`` section (defaults when absent), ``terrain.per_step`` (distribution
and seed) and the gait from ``fixedpoint.h5``; the walks and mesh cells run on local
processes or Dask (:mod:`walkerlab.sweep.mfpt`).  Skipped when the scene sections, the sigma
list, the method, the upstream gait and the code are unchanged.  An interrupted run resumes
where it stopped: its finished Monte Carlo chunks and mesh images are kept in
``mfpt.h5.partial`` (:mod:`walkerlab.io.mfpt_partial`) while the scene sections and the
gait are the same (pieces are named by sigma: a rerun with other ``--sigma-rad`` or
``--method`` keeps those it shares; ``--force`` starts afresh); the file is removed once
``mfpt.h5`` is written.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from walkerlab.config import CommandOptions, MfptSettings, Scene, validate_option
from walkerlab.io.schemas.fixedpoint import load_fixedpoint
from walkerlab.stages.common import (
    StageError,
    StageOutcome,
    artifact_path,
    input_hash,
    require,
    run_cached,
)

SECTIONS = ("walker", "slope", "ideal", "terrain", "mfpt")


def figure_path(scene: Scene, runs_root: Path | str) -> Path:
    """``runs/<scene>/report/figures/mfpt.png``."""
    from walkerlab.io.runpaths import figures_dir

    return figures_dir(scene, runs_root) / "mfpt.png"


def draw(scene: Scene, runs_root: Path | str = "runs") -> list[Path]:
    """Draw log MFPT against sigma (PNG + SVG) from ``mfpt.h5``."""
    from walkerlab.io.schemas.mfpt import load
    from walkerlab.plotting.figures import save
    from walkerlab.plotting.mfpt_figures import mfpt_figure

    d = load(artifact_path(scene, runs_root, "mfpt"))
    fig = mfpt_figure(d, f"Mean first-passage time - scene '{scene.name}'")
    return save(fig, figure_path(scene, runs_root).parent, "mfpt")


def check(scene: Scene, sigma_rad: list[float] | None = None, method: str | None = None,
          workers: int = 2, **_options) -> tuple[MfptSettings, int]:
    """The settings (``mfpt`` section with the command-line overrides) and worker count,
    checked before anything runs.

    Raises
    ------
    StageError
        No ``fixedpoint`` section, or an option out of bounds (one line).
    """
    require(scene, "fixedpoint", "mfpt")
    st = scene.mfpt or MfptSettings()
    if sigma_rad is not None:
        sigma_rad = validate_option(MfptSettings, "sigma_rad", list(sigma_rad), "--sigma-rad",
                                    "mfpt.sigma_rad")
    if method is not None:
        method = validate_option(MfptSettings, "method", method, "--method", "mfpt.method")
    workers = validate_option(CommandOptions, "workers", workers, "--workers")
    st = st.model_copy(update={k: v for k, v in (("sigma_rad", sigma_rad), ("method", method))
                               if v is not None})
    return st, workers


def run(scene: Scene, runs_root: Path | str = "runs", force: bool = False,
        sigma_rad: list[float] | None = None, method: str | None = None, workers: int = 2,
        scheduler=None) -> StageOutcome:
    """Compute (or reuse) the MFPT of the scene's rigid walker at each sigma.

    Parameters
    ----------
    sigma_rad : list of float, optional
        Per-step slope standard deviations [rad]; overrides ``mfpt.sigma_rad``.
    method : {"mesh", "montecarlo", "both"}, optional
        Overrides ``mfpt.method``.
    workers : int
        Local worker processes (1 = in this process).
    scheduler : str, optional
        Dask scheduler address.

    Raises
    ------
    StageError
        No ``fixedpoint`` section, bad settings, or a walker the per-step terrain cannot
        carry (one line).
    """
    st, workers = check(scene, sigma_rad, method, workers)
    up = artifact_path(scene, runs_root, "fixedpoint")
    path = artifact_path(scene, runs_root, "mfpt")
    done = []  # the resume file, removed once the artifact is written

    def work():
        from walkerlab.io.mfpt_partial import MfptPartial
        from walkerlab.io.schemas import mfpt as schema

        x_star = load_fixedpoint(up).x
        # finished pieces of an interrupted run with the same scene sections and gait are
        # kept (--force: none); pieces are named by sigma, so another --sigma-rad list or
        # --method reuses the pieces it shares
        partial = MfptPartial(path.with_name(path.name + ".partial"),
                              input_hash("mfpt", scene, SECTIONS, (up,), extra="resume"),
                              resume=not force)
        try:
            data = compute(scene, x_star, st, workers, scheduler, partial)
        except ValueError as exc:  # bad input: nothing to resume
            partial.remove()
            raise StageError(str(exc)) from None
        finally:
            partial.close()
        done.append(partial)
        summary = {"sigma_rad": list(map(float, data.sigma_rad)),
                   "mfpt_steps_montecarlo": list(map(float, data["mfpt_steps_montecarlo"])),
                   "mfpt_steps_mesh": list(map(float, data["mfpt_steps_mesh"]))}
        return (lambda f: schema.write(f, data)), summary

    out = run_cached("mfpt", scene, runs_root, SECTIONS, (up,), work, force,
                     {"workers": workers if scheduler is None else 0,
                      "scheduler": str(scheduler or "")},
                     extra_key=f"sigma={st.sigma_rad};method={st.method}")
    for partial in done:
        partial.remove()
    if not out.reused or not figure_path(scene, runs_root).is_file():
        draw(scene, runs_root)
    return out


def compute(scene: Scene, x_star: np.ndarray, st: MfptSettings, workers: int = 1,
            scheduler=None, partial=None):
    """Monte Carlo and/or mesh MFPT at every ``st.sigma_rad`` -> ``MfptData``
    (:func:`walkerlab.sweep.mfpt.mfpt_study`; ``partial``: the resume file)."""
    from walkerlab.sweep.mfpt import mfpt_study

    return mfpt_study(scene, x_star, st, workers, scheduler, partial)
