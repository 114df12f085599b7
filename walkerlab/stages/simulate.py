"""Stage ``simulate``: N strides of the rigid hybrid walker -> ``simulate.h5``."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from walkerlab.analysis.metrics import sample_trajectory, step_table, total_mass_kg
from walkerlab.config import MAX_SIMULATE_SAMPLES, Scene, SimulateSettings
from walkerlab.integrate.rigid import simulate_steps
from walkerlab.integrate.solver import Solver
from walkerlab.io.artifacts import put
from walkerlab.io.netcdf import coordinate
from walkerlab.io.readers import load_fixed_point
from walkerlab.io.trajectory import write_samples
from walkerlab.models.registry import build_walker
from walkerlab.stages import fixedpoint as fixedpoint_stage
from walkerlab.stages.common import StageError, StageOutcome, artifact_path, run_cached

SECTIONS = ("walker", "slope", "ideal", "solver", "simulate")

STEP_UNITS = {"t_start": "s", "t_end": "s", "period": "s", "step_length": "m",
              "hip_speed": "m/s", "impact_energy_loss": "J", "midstance_time": "s"}


def with_strides(scene: Scene, strides: int | None) -> Scene:
    """Scene with ``simulate.strides`` overridden (section created with defaults if absent)."""
    sim = scene.simulate or SimulateSettings()
    if strides is not None:
        from pydantic import ValidationError

        try:
            sim = SimulateSettings.model_validate({**sim.model_dump(), "strides": strides})
        except ValidationError as err:
            raise StageError(f"--strides {strides}: {err.errors()[0]['msg'].lower()} "
                             "(simulate.strides)") from None
    return scene.model_copy(update={"simulate": sim})


def _longer_run(scene: Scene, runs_root, upstream: tuple[Path, ...]) -> StageOutcome | None:
    """The existing ``simulate.h5`` when it holds *more* strides of the same run (an earlier
    ``simulate --strides N``) than the scene asks for: it contains the scene's strides, and
    the result the user asked for is kept rather than replaced (``StageOutcome.note`` says
    so; the CLI and the report print it)."""
    import h5py

    from walkerlab.io.artifacts import verified_hash
    from walkerlab.stages.common import input_hash

    path = artifact_path(scene, runs_root, "simulate")
    try:
        with h5py.File(path, "r") as f:
            n = int(f.attrs["strides_requested"])
    except (OSError, KeyError, ValueError, TypeError):
        return None
    if n <= scene.simulate.strides:
        return None
    have = verified_hash(path)
    if have is None or have != input_hash("simulate", with_strides(scene, n), SECTIONS, upstream):
        return None
    note = (f"kept {n} strides of an earlier 'simulate --strides {n}'; the scene asks for "
            f"{scene.simulate.strides}, the first {scene.simulate.strides} are the same run")
    return StageOutcome("simulate", path, True, 0.0, {}, note)


def run(scene: Scene, runs_root: Path | str = "runs", force: bool = False,
        strides: int | None = None) -> StageOutcome:
    """Simulate ``simulate.strides`` strides (2 steps each) and write ``simulate.h5``.

    The initial state is the fixed point from ``fixedpoint.h5`` (the fixedpoint stage is run
    first if its artifact is missing or stale) or the scene's explicit state.  Without
    ``strides`` (the scene's number), an existing run of the same walker with *more* strides
    (``simulate --strides 20``) is reused, and said so, rather than replaced.

    Raises
    ------
    StageError
        Upstream failure; a run that falls is *not* an error: it is recorded.
    """
    scene = with_strides(scene, strides)
    sim = scene.simulate
    upstream: tuple[Path, ...] = ()
    if sim.initial_state == "fixed_point":
        fixedpoint_stage.run(scene, runs_root)
        upstream = (artifact_path(scene, runs_root, "fixedpoint"),)
    if strides is None and not force:
        longer = _longer_run(scene, runs_root, upstream)
        if longer is not None:
            return longer

    def compute():
        walker = build_walker(scene)
        if sim.initial_state == "fixed_point":
            x0, meta = load_fixed_point(upstream[0])
            # refuse before integrating what could not be sampled (sample_trajectory checks
            # the exact count afterwards for any initial state)
            n = 2 * sim.strides * meta["step_period_s"] * sim.sample_rate_hz
            if n > MAX_SIMULATE_SAMPLES:
                raise StageError(f"simulate.sample_rate_hz: {sim.sample_rate_hz:g} Hz over "
                                 f"{sim.strides} strides of {2 * meta['step_period_s']:.3g} s "
                                 f"gives {n:.3g} samples; at most {MAX_SIMULATE_SAMPLES:,} "
                                 "are kept (lower simulate.sample_rate_hz or simulate.strides)")
        else:
            try:
                x0 = sim.initial_state.as_array(walker.state_names())
            except ValueError as exc:
                raise StageError(f"simulate.initial_state: {exc}") from None
        traj = simulate_steps(walker, x0, 2 * sim.strides, Solver.from_settings(scene.solver),
                              max_step_time=sim.max_step_time_s)
        samples = sample_trajectory(traj, sim.sample_rate_hz)
        steps = step_table(traj)
        ok = steps["termination"] == "heel_strike"
        summary = {
            "termination": traj.termination,
            "steps_completed": int(ok.sum()),
            "wall_time_s": traj.wall_time_s,
            "nfev": traj.nfev,
            "mean_period_s": float(np.mean(steps["period"][ok])) if ok.any() else np.nan,
            "mean_step_length_m": float(np.mean(steps["step_length"][ok])) if ok.any() else np.nan,
            "mean_hip_speed_m_per_s": (float(np.mean(steps["hip_speed"][ok])) if ok.any()
                                       else np.nan),
            "mean_total_energy_J": float(np.mean(samples.total)),
        }

        def writer(f):
            f.attrs["model"] = walker.name
            f.attrs["variant"] = walker.variant
            f.attrs["legs"] = list(walker.legs)
            f.attrs["termination"] = traj.termination
            f.attrs["strides_requested"] = sim.strides
            f.attrs["total_mass_kg"] = total_mass_kg(walker)
            f.attrs["gravity_m_per_s2"] = float(walker.params["gravity_m_per_s2"])
            names = walker.state_names()
            coordinate(f, "state", names, "-", "state component (role-ordered)")
            write_samples(f, samples)
            g = f.create_group("steps")
            coordinate(g, "step", steps["index"], "-", "step number")
            for k, v in steps.items():
                if k == "index":
                    continue
                if v.dtype.kind in "US":
                    put(g, k, [str(s) for s in v], "-", k, dims=("step",))
                else:
                    put(g, k, v, STEP_UNITS.get(k, "-"), k, dims=("step",))
            for i, seg in enumerate(traj.segments):
                sg = g.create_group(f"states/{i:04d}")
                for nm, a, b in zip(names, seg.x_start, seg.x_end):
                    sg.attrs[f"start_{nm}"] = a
                    sg.attrs[f"end_{nm}"] = b
            put(f, "initial_state", x0, "rad, rad/s", "role-ordered initial state",
                dims=("state",), state_names=names)
            for k, v in summary.items():
                if k != "termination":
                    put(f, f"summary/{k}", v, {"wall_time_s": "s", "mean_period_s": "s",
                                               "mean_step_length_m": "m",
                                               "mean_hip_speed_m_per_s": "m/s",
                                               "mean_total_energy_J": "J"}.get(k, "-"), k)
        return writer, summary

    return run_cached("simulate", scene, runs_root, SECTIONS, upstream, compute, force)
