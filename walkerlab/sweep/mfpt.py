"""The many-walk and many-cell work of the MFPT study, on local processes or Dask.

Monte Carlo walks are dealt out in chunks of walk numbers (each walk's slopes come from its
own random stream, so a chunk's result does not depend on the chunking or the executor);
the mesh's step-map images are dealt out in chunks of (state, slope) rows.  Both go through
:func:`walkerlab.execution.executor.run_each` on :func:`walkerlab.sweep.runner.sweep_executor`
(in this process, a local process pool or a Dask cluster, unchanged).
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass

import numpy as np

from walkerlab.analysis import mfpt as M
from walkerlab.analysis.batch_step import HEEL_STRIKE, BatchStepMap

#: walks per Monte Carlo task, rows per mesh task
WALKS_PER_TASK = 500
ROWS_PER_TASK = 4000

_MAPS: dict[str, BatchStepMap] = {}


def scene_walker_at(scene):
    """``gamma -> HybridWalker``: the scene's rigid walker on another slope."""
    from walkerlab.models.registry import build_walker

    def at(gamma: float):
        return build_walker(scene.model_copy(update={
            "slope": scene.slope.model_copy(update={"angle_rad": float(gamma),
                                                    "angle_deg": None})}))
    return at


def step_map_for(base: dict) -> BatchStepMap:
    """The batched step map of a scene mapping (built once per process; a walker without
    compiled flows, e.g. flat feet, gets the row-by-row
    :class:`~walkerlab.analysis.python_step.PythonStepMap`)."""
    from walkerlab.analysis.python_step import make_step_map
    from walkerlab.config import MfptSettings, scene_from_dict
    from walkerlab.models.registry import build_walker

    key = json.dumps(base, sort_keys=True)
    if key not in _MAPS:
        scene = scene_from_dict(base)
        st = scene.mfpt or MfptSettings()
        _MAPS.clear()
        _MAPS[key] = make_step_map(build_walker(scene), scene_walker_at(scene), st.rtol,
                                   st.atol, st.max_step_time_s)
    return _MAPS[key]


@dataclass(frozen=True)
class WalkTask:
    """Monte Carlo walks ``walks`` at one sigma (picklable)."""

    base: dict
    x0: tuple
    sd: float
    walks: tuple
    max_steps: int
    seed: int
    distribution: str
    index: int


@dataclass(frozen=True)
class ImageTask:
    """Step-map images of ``X`` on slopes ``gamma`` (picklable)."""

    base: dict
    X: np.ndarray
    gamma: np.ndarray
    start: int


def run_walks(task: WalkTask):
    """``(index, steps, fell)`` of a chunk of walks."""
    sm = step_map_for(task.base)
    res = M.monte_carlo(sm, np.asarray(task.x0), task.sd, task.walks, task.max_steps,
                        task.seed, distribution=task.distribution)
    return task.index, res.steps, res.fell


def run_images(task: ImageTask):
    """``(start, x_next, ok)`` of a chunk of mesh rows."""
    sm = step_map_for(task.base)
    r = sm.step(task.X, task.gamma)
    return task.start, r.x_next, r.outcome == HEEL_STRIKE


def monte_carlo(scene, x0: np.ndarray, sd: float, walks: int, max_steps: int, seed: int,
                distribution: str = "normal", workers: int = 1, scheduler=None
                ) -> M.MonteCarloResult:
    """Monte Carlo MFPT walks of a scene at one sigma [rad] (see
    :func:`walkerlab.analysis.mfpt.monte_carlo`), chunked over the executor."""
    from walkerlab.execution.executor import run_each
    from walkerlab.sweep.runner import sweep_executor

    base = scene.model_dump(mode="json")
    tasks = [WalkTask(base, tuple(float(v) for v in x0), float(sd),
                      tuple(range(a, min(a + WALKS_PER_TASK, walks))), max_steps, seed,
                      distribution, i)
             for i, a in enumerate(range(0, walks, WALKS_PER_TASK))]
    steps = np.zeros(walks, dtype=np.int64)
    fell = np.zeros(walks, dtype=bool)
    with sweep_executor(workers, scheduler) as ex:
        for _, (i, s, f) in run_each(ex, run_walks, [(t,) for t in tasks]):
            a = i * WALKS_PER_TASK
            steps[a:a + s.size], fell[a:a + f.size] = s, f
    return M.MonteCarloResult(steps, fell)


def image_evaluator(scene, ex):
    """``(X, gamma) -> (x_next, ok)`` on the open executor ``ex`` (for
    :func:`M.mesh_mfpt`; one worker pool serves every mesh of a refinement)."""
    from walkerlab.execution.executor import run_each

    base = scene.model_dump(mode="json")

    def evaluate(X, gamma):
        n = X.shape[0]
        tasks = [ImageTask(base, X[a:a + ROWS_PER_TASK], gamma[a:a + ROWS_PER_TASK], a)
                 for a in range(0, n, ROWS_PER_TASK)]
        xn = np.full_like(X, np.nan)
        ok = np.zeros(n, dtype=bool)
        for _, (a, x, o) in run_each(ex, run_images, [(t,) for t in tasks]):
            xn[a:a + x.shape[0]], ok[a:a + o.size] = x, o
        return xn, ok
    return evaluate


def mesh(scene, x0: np.ndarray, sd: float, settings, workers: int = 1, scheduler=None):
    """Converged (or capped) mesh MFPT at one sigma: ``(last MeshResult, all meshes)``.

    The nodes are the post-impact states visited by noisy walks from the gait at ``sd`` and
    at ``1.5 sd`` (so the tails, where the falls start, are meshed too; a fallen walk starts
    again on the gait); the images of the nodes are computed over the executor."""
    base = scene.model_dump(mode="json")
    sm = step_map_for(base)
    n = settings.mesh_max_cells
    walks = 100
    steps = max(20, math.ceil(n / walks) + 2)  # a pool of ~2 max_cells
    pool = M.visited_states(sm, x0, (sd, 1.5 * sd), walks, steps, settings.seed)
    if len(pool) < 10 * len(x0):
        raise ValueError(f"mfpt: sigma {sd:g} rad: the walks fall too soon to shape a mesh "
                         "(fewer post-impact states than needed)")
    from walkerlab.sweep.runner import sweep_executor

    with sweep_executor(workers, scheduler) as ex:
        return M.mesh_mfpt_converged(sm, pool, x0, sd, cells=settings.mesh_cells,
                                     refine=settings.mesh_refine,
                                     rel_change=settings.mesh_rel_change, max_cells=n,
                                     quadrature=settings.quadrature_nodes,
                                     evaluate=image_evaluator(scene, ex))


def _finite(v: float) -> float:
    return v if math.isfinite(v) else math.nan
