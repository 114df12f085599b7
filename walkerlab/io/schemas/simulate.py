"""``simulate.h5``: N strides of the rigid hybrid walker (writer and loader side by side).

Layout: root attributes ``model``, ``variant``, ``legs``, ``termination``,
``strides_requested``, ``total_mass_kg``, ``gravity_m_per_s2``; ``state`` (dimension scale,
role-ordered state names); ``samples/`` (:mod:`walkerlab.io.trajectory`); ``steps/`` (one
row per step on dimension ``step``: ``t_start``, ``t_end``, ``period`` [s], ``step_length``
[m], ``hip_speed`` [m/s], ``impact_energy_loss`` [J] (the heel-strike collision's loss),
``transition_energy_change`` [J] (the kinetic energy's net change across push-off and heel
strike), ``stance_leg``, ``termination``,
``phases`` (each phase of the step and the guard that ended it) ...;
``steps/states/<i>`` start/end state of each segment as attributes); ``initial_state``
[rad, rad/s]; ``summary/<name>`` (mean step period [s], step length [m], hip speed [m/s],
total energy [J], RHS evaluations, integration wall time [s]; on a height profile, where
the swing foot entered it, ``trip_time_s`` [s], ``trip_x_m``, ``trip_y_m`` [m], and the
deepest ignored mid-stance foot-through of straight legs ``midstance_scuff_depth_m`` [m],
each only when it happened: :func:`walkerlab.analysis.gait.profile_walk.swing_clearance`);
``ledger/<name>`` (the
energy ledger on dimension ``step``: actuator work, push-off work, collision losses, damper
and potential work, closure [J], push-off impulse [N s], ``cost_of_transport`` [-];
:mod:`walkerlab.analysis.gait.energy`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from walkerlab.io.artifacts import READ_ERRORS, artifact_loader, put
from walkerlab.io.netcdf import coordinate
from walkerlab.io.trajectory import NamedTrajectory, read_samples, write_samples
from walkerlab.units import Units, for_artifact

STAGE = "simulate"
#: unit of each ``steps/`` column
STEP_UNITS = {"t_start": "s", "t_end": "s", "period": "s", "step_length": "m",
              "hip_speed": "m/s", "impact_energy_loss": "J", "transition_energy_change": "J",
              "midstance_time": "s"}
#: what each ``steps/`` column is, where its name does not say it all (others: the name)
STEP_DESCRIPTIONS = {
    "hip_speed": "the hip's horizontal displacement over the step divided by its period (on "
                 "a slope phi: cos(phi) times step length / period, the gait's speed along "
                 "the slope)",
    "impact_energy_loss": "kinetic energy lost in the heel-strike collision (after the "
                          "push-off, if any, minus after the heel strike)",
    "transition_energy_change": "net change of the kinetic energy across the step-to-step "
                                "transition (push-off and heel strike)",
}
#: unit of each ``ledger/`` column (the energy ledger, :mod:`walkerlab.analysis.gait.energy`)
LEDGER_UNITS = {**{k: "J" for k in (
    "actuator_work_positive", "actuator_work_negative", "push_off_work", "heel_strike_loss",
    "internal_collision_loss", "damper_work", "potential_work", "energy_change", "closure",
    "slope_energy")}, "push_off_impulse": "N s", "cost_of_transport": "-"}
#: what each ``ledger/`` column is
LEDGER_DESCRIPTIONS = {
    "actuator_work_positive": "positive work of the joint torques over the step",
    "actuator_work_negative": "negative work of the joint torques over the step",
    "push_off_work": "work of the push-off impulse (kinetic energy gained)",
    "push_off_impulse": "push-off impulse along the trailing leg",
    "heel_strike_loss": "kinetic energy lost in the heel-strike collision",
    "internal_collision_loss": "kinetic energy lost in knee strikes and foot slaps",
    "damper_work": "work of the dampers (<= 0)",
    "potential_work": "work of gravity and the springs (minus the potential's change)",
    "energy_change": "change of the total mechanical energy over the step",
    "closure": "energy change minus the sum of the ledger's terms (round-off)",
    "slope_energy": "potential energy the slope releases over the step, M g d sin(slope)",
    "cost_of_transport": "(positive actuator work + push-off work + slope energy if > 0) "
                         "/ (M g d), d the step length along the ground",
}
#: unit of each ``summary/`` entry (others: "-")
SUMMARY_UNITS = {"wall_time_s": "s", "mean_period_s": "s", "mean_step_length_m": "m",
                 "mean_hip_speed_m_per_s": "m/s", "mean_total_energy_J": "J",
                 "trip_time_s": "s", "trip_x_m": "m", "trip_y_m": "m",
                 "midstance_scuff_depth_m": "m"}


@dataclass
class SimulateRun:
    """What the simulate stage computed (the writer's input).

    Attributes
    ----------
    walker : walkerlab.models.hybrid.base.HybridWalker
        The walker simulated (name, variant, legs, state names, parameters).
    trajectory : walkerlab.integrate.rigid.HybridTrajectory
        Segments of the run (termination, start/end states).
    samples : NamedTrajectory
        Sampled trajectory.
    steps : dict[str, ndarray (n_steps,)]
        Per-step table (:func:`walkerlab.analysis.gait.metrics.step_table`).
    initial_state : ndarray (2n,)
        Role-ordered initial state [rad, rad/s].
    strides_requested : int
    total_mass_kg : float
    summary : dict
        Headline numbers (``termination`` plus :data:`SUMMARY_UNITS` keys, ``nfev``,
        ``steps_completed``).
    ledger : dict[str, ndarray (n_steps,)]
        The energy ledger per step (:func:`walkerlab.analysis.gait.energy.trajectory_ledger`;
        units :data:`LEDGER_UNITS`).
    """

    walker: object
    trajectory: object
    samples: NamedTrajectory
    steps: dict
    initial_state: np.ndarray
    strides_requested: int
    total_mass_kg: float
    summary: dict
    ledger: dict = field(default_factory=dict)


def write_simulate(f, run: SimulateRun) -> None:
    """Fill an open (in-memory) artifact with ``run`` (layout in the module docstring)."""
    walker, traj, steps = run.walker, run.trajectory, run.steps
    f.attrs["model"] = walker.name
    f.attrs["variant"] = walker.variant
    f.attrs["legs"] = list(walker.legs)
    f.attrs["termination"] = traj.termination
    f.attrs["strides_requested"] = run.strides_requested
    f.attrs["total_mass_kg"] = run.total_mass_kg
    f.attrs["gravity_m_per_s2"] = float(walker.params["gravity_m_per_s2"])
    names = walker.state_names()
    coordinate(f, "state", names, "-", "state component (role-ordered)")
    write_samples(f, run.samples)
    g = f.create_group("steps")
    coordinate(g, "step", steps["index"], "-", "step number")
    for k, v in steps.items():
        if k == "index":
            continue
        if v.dtype.kind in "US":
            put(g, k, [str(s) for s in v], "-", k, dims=("step",))
        else:
            put(g, k, v, STEP_UNITS.get(k, "-"), STEP_DESCRIPTIONS.get(k, k), dims=("step",))
    for i, seg in enumerate(traj.segments):
        sg = g.create_group(f"states/{i:04d}")
        for nm, a, b in zip(names, seg.x_start, seg.x_end):
            sg.attrs[f"start_{nm}"] = a
            sg.attrs[f"end_{nm}"] = b
    put(f, "initial_state", run.initial_state, "rad, rad/s", "role-ordered initial state",
        dims=("state",), state_names=names)
    for k, v in run.summary.items():
        if k != "termination":
            put(f, f"summary/{k}", v, SUMMARY_UNITS.get(k, "-"), k)
    if run.ledger:
        lg = f.create_group("ledger")
        coordinate(lg, "step", steps["index"], "-", "step number")
        for k, v in run.ledger.items():
            put(lg, k, np.asarray(v, float), LEDGER_UNITS[k], LEDGER_DESCRIPTIONS[k],
                dims=("step",))


@dataclass
class SimulateArtifact:
    """A loaded ``simulate.h5``.

    Attributes
    ----------
    path : Path
    units : Units
        The scene's unit system (labels of times, lengths, energies).
    termination : str
        How the run ended ("heel_strike", "fall", ...).
    strides_requested : int
    total_mass_kg : float
        [kg]
    gravity_m_per_s2 : float
        [m/s^2]
    samples : NamedTrajectory
    steps : dict[str, ndarray (n_steps,)]
        ``step`` (int), ``stance_leg`` and ``termination`` (str), and the numeric columns
        (units in :data:`STEP_UNITS`).
    summary : dict[str, float]
        ``summary/`` entries.
    ledger : dict[str, ndarray (n_steps,)]
        The energy ledger per step (``ledger/``, units :data:`LEDGER_UNITS`); empty for an
        artifact written before it existed.
    scene_json : str
        The resolved scene the artifact was written for.
    """

    path: Path
    units: Units
    termination: str
    strides_requested: int
    total_mass_kg: float
    gravity_m_per_s2: float
    samples: NamedTrajectory
    steps: dict = field(default_factory=dict)
    summary: dict = field(default_factory=dict)
    ledger: dict = field(default_factory=dict)
    scene_json: str = "{}"

    def heel_strike_count(self) -> int:
        """Number of steps that ended by a heel strike."""
        return int(np.sum(self.steps["termination"] == "heel_strike"))

    def first_strides(self, strides: int) -> SimulateArtifact:
        """The run as a scene asking ``strides`` strides sees it: a longer run (an earlier
        ``simulate --strides N`` kept for the scene, :func:`longer_run_note`) cut to its
        first ``2 * strides`` steps.  The steps are the same run's, so the cut has the
        fresh run's verdict (``termination``: "heel_strike" when those steps all ended by
        one, however the longer run ended later) and its means: ``mean_period_s``,
        ``mean_step_length_m``, ``mean_hip_speed_m_per_s`` over the kept heel strikes,
        ``mean_total_energy_J`` over the kept samples (each step is sampled from its own
        start: the same samples).  ``nfev`` and ``wall_time_s`` stay the longer run's (the
        cut's ``summary["cut_from_strides"]`` says from how many strides); a trip after the
        kept steps is dropped.  ``self`` when the run is not longer.

        Parameters
        ----------
        strides : int
            Strides the scene asks for (``simulate.strides``), >= 1.
        """
        k = 2 * int(strides)
        n = len(self.steps.get("termination", ()))
        if self.strides_requested <= strides or n <= k:
            return self  # not longer, or it ended within the scene's steps: its own verdict
        import dataclasses

        cut = {key: v[:k] for key, v in self.steps.items()}
        ok = cut["termination"] == "heel_strike"
        keep = self.samples.step_index < k
        sm = self.samples
        samples = dataclasses.replace(
            sm, time=sm.time[keep], coordinates={c: v[keep] for c, v in sm.coordinates.items()},
            stance_leg=sm.stance_leg[keep], step_index=sm.step_index[keep],
            kinetic=sm.kinetic[keep], potential=sm.potential[keep],
            points={c: v[..., keep] for c, v in sm.points.items()},
            phase=None if sm.phase is None else sm.phase[keep])
        summary = {key: v for key, v in self.summary.items()
                   if not key.startswith("trip_") and key != "ground_steps"}

        def mean(col):
            return float(np.mean(cut[col][ok])) if ok.any() and col in cut else np.nan

        summary.update(steps_completed=int(ok.sum()), mean_period_s=mean("period"),
                       mean_step_length_m=mean("step_length"),
                       mean_hip_speed_m_per_s=mean("hip_speed"),
                       mean_total_energy_J=float(np.mean(samples.total)),
                       cut_from_strides=self.strides_requested)
        term = "heel_strike" if ok.all() else str(cut["termination"][~ok][0])
        return dataclasses.replace(
            self, termination=term, strides_requested=int(strides), samples=samples,
            steps=cut, summary=summary, ledger={key: v[:k] for key, v in self.ledger.items()})


@artifact_loader(STAGE)
def load_simulate(f, path: Path, strides: int | None = None) -> SimulateArtifact:
    """Load ``simulate.h5`` (a hand-built artifact may hold only ``samples/``: what it lacks
    of the rest is empty or NaN); with ``strides`` (the scene's ``simulate.strides``), a
    longer run kept for the scene is seen as the scene's own run
    (:meth:`SimulateArtifact.first_strides`)."""
    steps = {}
    for k in f["steps"] if "steps" in f else ():
        ds = f["steps"][k]
        if not hasattr(ds, "dtype"):
            continue  # the states/ group
        steps[k] = ds.asstr()[()] if ds.dtype.kind == "O" else ds[()]
    a = f.attrs
    sim = SimulateArtifact(
        path=Path(path), units=for_artifact(f), termination=str(a.get("termination", "")),
        strides_requested=int(a.get("strides_requested", 0)),
        total_mass_kg=float(a.get("total_mass_kg", np.nan)),
        gravity_m_per_s2=float(a.get("gravity_m_per_s2", np.nan)),
        samples=read_samples(f), steps=steps,
        summary={k: f["summary"][k][()] for k in f["summary"]} if "summary" in f else {},
        ledger={k: f["ledger"][k][()] for k in f["ledger"] if k != "step"}
        if "ledger" in f else {},
        scene_json=str(a["scene_json"]))
    return sim if strides is None else sim.first_strides(strides)


def strides_of(path: Path) -> int | None:
    """``strides_requested`` of an existing ``simulate.h5``; None when absent or unreadable
    (no version check: the caller verifies the hash)."""
    import h5py

    try:
        with h5py.File(path, "r") as f:
            return int(f.attrs["strides_requested"])
    except (*READ_ERRORS, TypeError):  # absent, truncated or damaged inside
        return None


@artifact_loader(STAGE)
def run_end(f, path: Path, strides: int | None = None) -> str:
    """How the run of ``simulate.h5`` ended (``termination``: "heel_strike" when every step
    completed, "fall", ...; a trip on a height profile with its time and place: "trip (the
    swing foot entered the profile at t = 0.42 s, x = -1.5 m, y = 0.03 m)"); with
    ``strides``, how its first ``strides`` strides ended (a longer run kept for a scene
    that asks fewer: "heel_strike" when they all completed, whatever came after them)."""
    term = str(f.attrs["termination"])
    if strides is not None and int(f.attrs["strides_requested"]) > strides:
        ends = f["steps/termination"].asstr()[()]
        if ends.size > 2 * strides:  # it went past the scene's steps: theirs decide
            first = ends[:2 * strides]
            bad = first[first != "heel_strike"]
            return "heel_strike" if bad.size == 0 else str(bad[0])
    if term == "trip" and "summary/trip_time_s" in f:
        t, x, y = (float(f[f"summary/trip_{k}"][()]) for k in ("time_s", "x_m", "y_m"))
        term += (f" (the swing foot entered the profile at t = {t:.6g} s, "
                 f"x = {x:.6g} m, y = {y:.6g} m)")
    return term


def longer_run_note(path: Path, asked: int, key_of) -> str:
    """Why the existing ``simulate.h5`` at ``path`` is kept for a scene asking ``asked``
    strides, or "" when it is not: it holds *more* strides of the same run (an earlier
    ``simulate --strides N``), so it contains the scene's strides and the result the user
    asked for is kept rather than replaced.

    ``key_of(n)``: the input hash of the same scene with ``n`` strides; the artifact must
    have it (verified against its content).
    """
    from walkerlab.io.artifacts import verified_hash

    n = strides_of(path)
    if n is None or n <= asked:
        return ""
    have = verified_hash(path)
    if have is None or have != key_of(n):
        return ""
    return (f"kept {n} strides of an earlier 'simulate --strides {n}'; the scene asks for "
            f"{asked}, the first {asked} are the same run")
