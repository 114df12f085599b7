"""Stage ``mfpt``: mean first-passage time on per-step random slopes -> ``mfpt.h5`` (+ figure).

Reads (after the pipeline has run ``fixedpoint``, :mod:`walkerlab.stages.pipeline`) the
scene's ``mfpt`` section (defaults when absent), ``terrain.per_step`` (distribution
and seed) and the gait from ``fixedpoint.h5``; the walks and mesh cells run on local
processes or Dask (:func:`walkerlab.sweep.mfpt.mfpt_study`).  Skipped when the scene
sections, the sigma list, the method, the upstream gait and the code are unchanged.
"""

from __future__ import annotations

from pathlib import Path

from walkerlab.config import CommandOptions, MfptSettings, Scene, validate_option
from walkerlab.io import runpaths
from walkerlab.io.schemas import mfpt as schema
from walkerlab.io.schemas.fixedpoint import load_fixedpoint
from walkerlab.stages.common import StageError, StageOutcome, artifact_path, require, run_cached

SECTIONS = ("walker", "slope", "ideal", "terrain", "mfpt")


def figure_path(scene: Scene, runs_root: Path | str) -> Path:
    """``runs/<scene>/report/figures/mfpt.png``."""
    return runpaths.figures_dir(scene, runs_root) / "mfpt.png"


def draw(scene: Scene, runs_root: Path | str = "runs") -> list[Path]:
    """Draw log MFPT against sigma (PNG + SVG) from ``mfpt.h5``."""
    from walkerlab.plotting.figures import save
    from walkerlab.plotting.mfpt_figures import mfpt_figure

    d = schema.load(artifact_path(scene, runs_root, "mfpt"))
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
    """Compute (or reuse) the MFPT of the scene's rigid walker at each sigma
    (``sigma_rad`` [rad] and ``method`` override the scene's ``mfpt`` section; ``workers``
    local processes, 1 = this one, or a Dask ``scheduler`` address).  Raises StageError (one
    line): no ``fixedpoint`` section, bad settings, a walker per-step slopes cannot carry."""
    from walkerlab.sweep.mfpt import mfpt_study

    st, workers = check(scene, sigma_rad, method, workers)
    up = artifact_path(scene, runs_root, "fixedpoint")

    def compute():
        try:
            data = mfpt_study(scene, load_fixedpoint(up).x, st, workers, scheduler)
        except ValueError as exc:
            raise StageError(str(exc)) from None
        return (lambda f: schema.write(f, data)), {"sigma_rad": list(map(float, data.sigma_rad)),
            **{k: list(map(float, data[k])) for k in ("mfpt_steps_montecarlo", "mfpt_steps_mesh")}}

    out = run_cached("mfpt", scene, runs_root, SECTIONS, (up,), compute, force,
                     {"workers": workers if scheduler is None else 0,
                      "scheduler": str(scheduler or "")},
                     extra_key=f"sigma={st.sigma_rad};method={st.method}")
    if not out.reused or not figure_path(scene, runs_root).is_file():
        draw(scene, runs_root)
    return out
