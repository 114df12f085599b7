"""``optimize.h5``: a periodic gait by direct collocation, writer and reader side by side.

Layout (netCDF conventions: every array on the ``time`` dimension of the collocation
points)::

    time                          s        collocation points (2N + 1) on [0, step_period]
    states/<state name>           rad, rad/s   the walker's states there (role order)
    torque/<joint>                N m      each actuator's torque there (``hip``: + on the
                                           swing leg; N m/kg: per foot mass on massless legs;
                                           a five-link biped: stance_hip, swing_hip,
                                           stance_knee, swing_knee)
    step_period, step_length      s, m
    speed                         m/s      step length / step period
    push_off                      N s      the push-off impulse
    objective                     its unit  the objective (attribute objective_name; effort:
                                           int u^2 dt + the free push-off's weighted P^2)
    terms/<name>                  its unit every objective at the optimum (effort,
                                           push_off_work, cost_of_transport, peak_torque)
    contact_replay/step_period    s        the contact model driven by the optimised torque
                                           (attribute contact_replay_outcome; NaN: none)
    replay/max_state_error        rad, rad/s  the rigid model's return error (gait if
                                           <= the scene's replay_tolerance)
    replay/multipliers/{real,imag} -       Floquet multipliers of the replayed gait
    replay/start_shift            rad, rad/s  (closed by shooting, a five-link biped) how
                                           far the exactly periodic start is from the
                                           collocated one (the transcription's error)
    replay/step_period            s        (closed by shooting) the closed step's period
    replay/collocated_start_error rad, rad/s  (closed by shooting) the open-loop return
                                           error from the collocated start itself
    ipopt                         attributes: status, iterations, wall_time_s, cpu_time_s,
                                           build_time_s (the programme's build, when known)
    phases/start_index            -        (a step of phases, e.g. a kneed walker's unlocked
                                           and locked swing; attribute phase_names) index in
                                           ``time`` of each phase's first point (a phase's
                                           first time repeats the previous one's last: the
                                           state jumps there, e.g. at a knee strike)
    phases/duration               s        each phase's duration
    ipopt/<series>                -        on the ``iteration`` dimension: objective,
                                           primal_infeasibility, dual_infeasibility, barrier
    energy/kinetic, energy/potential  J    the walker's energies at the collocation points
                                           (their sum rises by the actuators' work)
    replay/phase_<law>/...        (optimize.phase_replay: a five-link biped's by default)
                                  the torques as a function of the phase variable (the
                                  stance leg's angle; a step of phases: one law per
                                  phase), ``<law>``
                                  ``feedback`` (feed-forward + PD on the collocated joint
                                  trajectory: virtual constraints) or ``feedforward`` (no
                                  PD): ``collocated_start_error``, ``start_shift``,
                                  ``max_state_error`` (rad, rad/s: one step from the start
                                  the law closes to, or from the collocated one),
                                  ``step_period`` (s), ``torque_error`` (N m: max |tau(t) -
                                  u*(t)| along it), ``multipliers/{real,imag}``; attribute
                                  ``closed``

    controllers/<i>/...           (optimize.design: virtual_constraints) one designed
                                  controller per target speed: ``bezier`` (rad, k x (M+1),
                                  attribute output_names), delta2, delta2_restricted,
                                  existence_margin, the collocated and the closed loop's
                                  step periods, multipliers/{real,imag} (the full-order
                                  fixed point's), ... (:data:`CONTROLLER_VALUES`);
                                  attribute scene_file (the scene written beside it).
                                  The top-level step is controller 0's; its
                                  replay/max_state_error the full-order fixed point's
                                  distance from the zero dynamics' orbit.

attributes: ``gait`` (the replay closed), ``state_names``; ``steps`` (a stride of
legs that differ: 2; absent for one step): ``time`` then covers the stride, its phases
are the steps' (as many per step), ``step_period`` and ``step_length`` are the mean
step's, and the replay's return error and multipliers are the stride map's;
``phase_replay_outcome`` (when the phase-variable replay was asked for and refused: why,
one line); ``ipopt_violations`` (when IPOPT did not converge: the constraint groups with
the largest violation at its last iterate, one line).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from walkerlab.io.artifacts import artifact_loader

STAGE = "optimize"

__all__ = ["CONTROLLER_VALUES", "ControllerData", "DESIGN_STAGE", "DesignData", "OptimizeData",
           "PHASE_LAWS", "PhaseReplayData", "STAGE", "load", "load_design", "optimize_record",
           "phase_replay_records", "write", "write_design"]

#: the phase-variable replays an artifact may carry (optimize.phase_replay)
PHASE_LAWS = ("feedback", "feedforward")


@dataclass
class PhaseReplayData:
    """One phase-variable law's rigid replay (``replay/phase_<law>/``; units in the module
    docstring)."""

    collocated_start_error: float
    start_shift: float
    return_error: float
    step_period_s: float
    torque_error: float
    multipliers: np.ndarray
    closed: bool


@dataclass
class OptimizeData:
    """The contents of ``optimize.h5`` (units in the module docstring): the one record of
    an optimised gait, as the driver returns it (:func:`walkerlab.optimal.driver.
    optimize_scene`; its ``phase_replays`` the replays themselves until
    :func:`optimize_record` makes them :class:`PhaseReplayData`) and as :func:`load`
    reads it.

    Attributes
    ----------
    time : ndarray (m,)
        Collocation times since the heel strike [s].
    states : dict of str -> ndarray (m,)
        The states by the rigid walker's names [rad, rad/s].
    torque : ndarray (m,) or (m, k)
        The optimised torque(s) [N m; N m/kg on massless legs].
    step_period_s, step_length_m, push_off_n_s, objective : float
        A stride's: its mean step's period and length.
    replay_error : float
        The rigid replay's return error [rad, rad/s].
    multipliers : ndarray (2n,) complex
        The replay map's Floquet multipliers (NaN: none).
    gait : bool
        IPOPT converged and the replay closed within ``optimize.replay_tolerance``.
    status, iterations, wall_time_s, cpu_time_s, build_time_s
        IPOPT's status and iterations, the solve's wall and CPU time and the programme's
        build time [s].
    state_units : dict
    energy : dict
        ``kinetic``, ``potential`` at the points [``energy_unit``] (each step's from its
        own walker).
    phase_replays : dict
        Law name -> :class:`PhaseReplayData` (the driver's: the replays themselves; empty:
        none, ``phase_replay_outcome`` says why).
    The other fields: the module docstring's datasets and attributes.
    """

    time: np.ndarray
    states: dict
    torque: np.ndarray
    step_period_s: float
    step_length_m: float
    push_off_n_s: float
    objective: float
    replay_error: float
    multipliers: np.ndarray
    gait: bool
    status: str
    iterations: int
    wall_time_s: float
    state_units: dict
    objective_name: str = "effort"
    objective_unit: str = "N^2 m^2 s"
    terms: dict = field(default_factory=dict)
    contact_step_period_s: float = float("nan")
    contact_outcome: str = ""
    torque_unit: str = "N m"
    torque_names: tuple = ("hip",)
    start_shift: float = float("nan")
    replay_step_period_s: float = float("nan")
    collocated_start_error: float = float("nan")
    cpu_time_s: float = float("nan")
    # walkerlab.optimal.transcription.ipopt.HISTORY
    ipopt_history: dict = field(default_factory=dict)
    energy: dict = field(default_factory=dict)  # kinetic, potential (time,) [energy_unit]
    energy_unit: str = "J"
    phase_names: tuple = ()
    phase_start: np.ndarray | None = None
    phase_duration_s: np.ndarray | None = None
    build_time_s: float = float("nan")
    phase_replays: dict = field(default_factory=dict)  # law name -> PhaseReplayData
    steps: int = 1  # steps in the optimised period: 2 for a stride of legs that differ
    phase_replay_outcome: str = ""  # why there are no phase replays ("": there are, or off)
    # IPOPT did not converge: the constraint groups with the largest violation ("": none)
    violations: str = ""
    # optimize.design: virtual_constraints: the designed controllers (ControllerData or the
    # driver's walkerlab.optimal.virtual_constraints.ControllerDesign); empty: none
    controllers: tuple = ()


@dataclass
class ControllerData:
    """One designed controller (``controllers/<i>/``, ``optimize.design:
    virtual_constraints``; units in the module docstring; ``note``, attribute ``note``:
    why its closed loop has no fixed point, or why its coefficients make no controller)."""

    target_speed_m_per_s: float
    bezier_rad: np.ndarray
    output_names: tuple
    step_period_s: float
    step_length_m: float
    objective: float
    effort: float
    delta2: float
    delta2_restricted: float
    existence_margin: float
    restricted_step_period_s: float
    full_order_step_period_s: float
    orbit_shift: float
    multipliers: np.ndarray
    delta2_multiplier: complex
    max_torque_n_m: float
    max_output: float
    max_output_rate: float
    status: str
    iterations: int
    wall_time_s: float
    build_time_s: float
    scene_file: str
    friction_ratio: float = float("nan")
    min_clearance_m: float = float("nan")
    mid_stance_window_m: float = float("nan")
    mid_stance_low_m: float = float("nan")
    contact_step_period_s: float = float("nan")
    contact_speed_m_per_s: float = float("nan")
    contact_heel_strikes: float = float("nan")
    contact_steady: float = float("nan")
    full_order_step_length_m: float = float("nan")
    note: str = ""


#: controllers/<i>/ datasets: (field, unit, description)
CONTROLLER_VALUES = (
    ("target_speed_m_per_s", "m/s", "the target speed (NaN: none)"),
    ("step_period_s", "s", "the collocated step's period"),
    ("step_length_m", "m", "the collocated step's length"),
    ("objective", "N^2 m s", "int |u|^2 dt / step length at the optimum"),
    ("effort", "N^2 m^2 s", "int |u|^2 dt at the optimum"),
    ("delta2", "-", "delta^2 at the optimum (the collocation's expression)"),
    ("delta2_restricted", "-", "delta^2 of the written controller's restricted Poincare "
     "map (walkerlab.analysis.gait.zero_dynamics)"),
    ("existence_margin", "(kg m^2/s)^2", "delta^2/(1-delta^2) V(theta-) + V_max (< 0: the "
     "zero dynamics' orbit exists; the phase variable's units)"),
    ("restricted_step_period_s", "s", "the zero dynamics' step period by quadrature"),
    ("full_order_step_period_s", "s", "the rigid closed loop's fixed point's period (NaN: "
     "none)"),
    ("orbit_shift", "-", "max |x* - x+|: the full-order fixed point from the zero dynamics' "
     "post-impact state [rad, rad/s]"),
    ("max_torque_n_m", "N m", "largest |u| of the collocated step"),
    ("max_output", "rad", "max |y| over the collocation points"),
    ("max_output_rate", "rad/s", "max |y'| over the collocation points"),
    ("wall_time_s", "s", "IPOPT's wall time"),
    ("build_time_s", "s", "the programme's build time"),
    ("friction_ratio", "-", "the stance foot's largest |F_t / F_n| over the collocated "
     "step"),
    ("min_clearance_m", "m", "the swing foot's lowest height over the collocated step "
     "outside the straight legs' mid-stance window (every point: legs with knees)"),
    ("mid_stance_window_m", "m", "half-width of the straight legs' mid-stance pass exempted "
     "from optimize.min_clearance_m (the swing foot that near the stance foot; NaN: none)"),
    ("mid_stance_low_m", "m", "the swing foot's lowest height inside that window (< 0: "
     "below the ground line, as straight legs pass it; NaN: no window)"),
    ("contact_step_period_s", "s", "the contact model's mean step period over the last "
     "steps of its replay from the rigid fixed point (NaN: not replayed)"),
    ("contact_speed_m_per_s", "m/s", "the contact model's speed over those steps"),
    ("contact_heel_strikes", "-", "heel strikes of the contact replay"),
    ("contact_steady", "-", "1: the contact replay walks and its steps settle; 0: it does "
     "not (a fall, a trip or steps that drift); NaN: not replayed"),
    ("full_order_step_length_m", "m", "the rigid closed loop's fixed point's step length "
     "(NaN: none; with its period, the speed the controller walks, against the collocated "
     "step's target)"),
)


def phase_replay_records(replays: dict) -> dict:
    """The phase-variable replays ``{law: replay}`` (objects with the attributes of
    :class:`PhaseReplayData`: :class:`walkerlab.optimal.replay.phase.PhaseReplay`) as
    ``optimize.h5``'s records."""
    return {name: PhaseReplayData(r.collocated_start_error, r.start_shift, r.return_error,
                                  r.step_period_s, r.torque_error, r.multipliers, r.closed)
            for name, r in replays.items()}


def optimize_record(optimum: OptimizeData, energy_unit: str = "J") -> OptimizeData:
    """``optimize.h5``'s record of an optimised gait: the driver's
    (:func:`walkerlab.optimal.driver.optimize_scene`, whose ``phase_replays`` are the
    replays themselves) with their records (:func:`phase_replay_records`) and the energies
    in ``energy_unit`` (the scene's)."""
    from dataclasses import replace

    return replace(optimum, phase_replays=phase_replay_records(optimum.phase_replays),
                   energy_unit=energy_unit)


def _write_phase(f, law: str, r: PhaseReplayData) -> None:
    """``replay/phase_<law>/``."""
    from walkerlab.io.artifacts import put

    g = f"replay/phase_{law}"
    what = {"feedback": "the optimal torques as feed-forward of the phase variable plus PD "
            "tracking of the collocated joint trajectory", "feedforward": "the optimal "
            "torques as a function of the phase variable alone"}[law]
    for key, v, unit, desc in (
            ("collocated_start_error", r.collocated_start_error, "-", "one step's return "
             "error from the collocated start [rad, rad/s]"),
            ("start_shift", r.start_shift, "-", "max |closed start - collocated start| "
             "[rad, rad/s] (0: not closed)"),
            ("max_state_error", r.return_error, "-", "return error of one step from the "
             "closed start (not closed: the collocated one) [rad, rad/s]"),
            ("step_period", r.step_period_s, "s", "the replayed step's period"),
            ("torque_error", r.torque_error, "N m", "max over the step of |law torque - "
             "optimised torque| at the same time since the heel strike")):
        put(f, f"{g}/{key}", float(v), unit, f"{what}: {desc}")
    mu = np.asarray(r.multipliers, complex)
    put(f, f"{g}/multipliers/real", mu.real, "-", f"{what}: multipliers of the step map")
    put(f, f"{g}/multipliers/imag", mu.imag, "-", f"{what}: multipliers of the step map")
    f[g].attrs["closed"] = bool(r.closed)


def _load_phase(f, law: str) -> PhaseReplayData:
    g = f[f"replay/phase_{law}"]
    return PhaseReplayData(
        float(g["collocated_start_error"][()]), float(g["start_shift"][()]),
        float(g["max_state_error"][()]), float(g["step_period"][()]),
        float(g["torque_error"][()]),
        g["multipliers/real"][()] + 1j * g["multipliers/imag"][()], bool(g.attrs["closed"]))


def write(f, d: OptimizeData) -> None:
    """Fill an open artifact (``write_artifact``'s writer) with ``d``."""
    from walkerlab.io.artifacts import put
    from walkerlab.io.netcdf import coordinate

    coordinate(f, "time", d.time, "s", "collocation point time since the heel strike")
    for name, v in d.states.items():
        put(f, f"states/{name}", v, d.state_units[name], f"{name} at the collocation points",
            dims=("time",))
    tq = np.asarray(d.torque, float).reshape(len(d.time), -1)
    for k, name in enumerate(d.torque_names):
        put(f, f"torque/{name}", tq[:, k], d.torque_unit, "hip torque (+ on the swing leg, - on "
            "the stance leg)" if name == "hip" else f"{name} torque (+ on the joint's second "
            "link, - on its first)", dims=("time",))
    f.attrs["torque_names"] = list(d.torque_names)
    put(f, "step_period", float(d.step_period_s), "s", "step period")
    put(f, "step_length", float(d.step_length_m), "m", "distance between the feet at heel "
        "strike")
    put(f, "speed", float(d.step_length_m / d.step_period_s), "m/s", "step length / period")
    put(f, "push_off", float(d.push_off_n_s), "N s", "push-off impulse")
    put(f, "objective", float(d.objective), d.objective_unit, f"objective {d.objective_name} "
        "at the optimum (effort: int u^2 dt, + the free push-off's weighted P^2)")
    units = {"effort": d.objective_unit if d.objective_name == "effort" else "N^2 m^2 s",
             "push_off_work": "J", "cost_of_transport": "-", "peak_torque": "N m"}
    for name, v in d.terms.items():
        put(f, f"terms/{name}", float(v), units.get(name, "-"), f"{name} at the optimum "
            "(cost_of_transport smoothed; torques per foot mass on massless legs)")
    put(f, "contact_replay/step_period", float(d.contact_step_period_s), "s", "mean step "
        "period of the contact model driven by the optimised torque (NaN: not replayed)")
    f.attrs["contact_replay_outcome"] = d.contact_outcome
    f.attrs["objective_name"] = d.objective_name
    put(f, "replay/max_state_error", float(d.replay_error), "-", "max-norm return error of "
        "the rigid model's replay [rad, rad/s]")
    mu = np.asarray(d.multipliers, complex)
    put(f, "replay/multipliers/real", mu.real, "-", "Floquet multipliers of the replay")
    put(f, "replay/multipliers/imag", mu.imag, "-", "Floquet multipliers of the replay")
    f.attrs["gait"] = bool(d.gait)
    f.attrs["state_names"] = list(d.states)
    f.attrs["ipopt_status"] = d.status
    f.attrs["ipopt_iterations"] = int(d.iterations)
    f.attrs["ipopt_wall_time_s"] = float(d.wall_time_s)
    f.attrs["ipopt_cpu_time_s"] = float(d.cpu_time_s)
    f.attrs["ipopt_build_time_s"] = float(d.build_time_s)
    if d.steps > 1:
        f.attrs["steps"] = int(d.steps)
    if d.phase_names:
        f.attrs["phase_names"] = list(d.phase_names)
        put(f, "phases/start_index", np.asarray(d.phase_start, np.int64), "-", "index in "
            "time of each phase's first point (attribute phase_names)")
        put(f, "phases/duration", np.asarray(d.phase_duration_s, float), "s", "each "
            "phase's duration")
    for key, v, unit, what in (
            ("start_shift", d.start_shift, "-", "max |closed start - collocated start| "
             "[rad, rad/s]: the transcription's error"),
            ("step_period", d.replay_step_period_s, "s", "the closed step's period"),
            ("collocated_start_error", d.collocated_start_error, "-", "open-loop return "
             "error from the collocated start [rad, rad/s]")):
        if np.isfinite(v):
            put(f, f"replay/{key}", float(v), unit, what)
    for law, r in d.phase_replays.items():
        _write_phase(f, law, r)
    if d.phase_replay_outcome:
        f.attrs["phase_replay_outcome"] = d.phase_replay_outcome
    if d.violations:
        f.attrs["ipopt_violations"] = d.violations
    for i, c in enumerate(d.controllers):
        _write_controller(f, i, c)
    _write_history_and_energy(f, d)


def _write_controller(f, i: int, c) -> None:
    """``controllers/<i>/`` of one designed controller ``c`` (:class:`ControllerData`'s
    attributes)."""
    from walkerlab.io.artifacts import put

    g = f"controllers/{i}"
    put(f, f"{g}/bezier", np.asarray(c.bezier_rad, float), "rad", "the optimised Bezier "
        "coefficients in force (one row per output, attribute output_names; with "
        "invariant: true c_0, c_1 are the impact map's, as the written scene's)")
    for key, unit, desc in CONTROLLER_VALUES:
        put(f, f"{g}/{key}", float(getattr(c, key)), unit, desc)
    mu = np.asarray(c.multipliers, complex)
    put(f, f"{g}/multipliers/real", mu.real, "-", "the full-order fixed point's Floquet "
        "multipliers (variational)")
    put(f, f"{g}/multipliers/imag", mu.imag, "-", "the full-order fixed point's Floquet "
        "multipliers (variational)")
    near = complex(c.delta2_multiplier)
    put(f, f"{g}/delta2_multiplier", np.array([near.real, near.imag]), "-", "the full-order "
        "multiplier nearest delta^2 (real, imaginary)")
    a = f[g].attrs
    a["output_names"] = list(c.output_names)
    a["ipopt_status"] = str(c.status)
    a["ipopt_iterations"] = int(c.iterations)
    a["scene_file"] = str(c.scene_file)
    if getattr(c, "note", ""):
        a["note"] = str(c.note)


def _load_controllers(f) -> tuple:
    if "controllers" not in f:
        return ()
    out = []
    for i in range(len(f["controllers"])):
        g = f[f"controllers/{i}"]
        vals = {key: float(g[key][()]) for key, _u, _d in CONTROLLER_VALUES
                if key in g}  # a file written before a field was added: its default
        near = g["delta2_multiplier"][()]
        out.append(ControllerData(
            bezier_rad=g["bezier"][()], output_names=tuple(str(s) for s in
                                                           g.attrs["output_names"]),
            multipliers=g["multipliers/real"][()] + 1j * g["multipliers/imag"][()],
            delta2_multiplier=complex(near[0], near[1]), status=str(g.attrs["ipopt_status"]),
            iterations=int(g.attrs["ipopt_iterations"]),
            scene_file=str(g.attrs["scene_file"]), note=str(g.attrs.get("note", "")),
            **vals))
    return tuple(out)


def _write_history_and_energy(f, d: OptimizeData) -> None:
    """``ipopt/<series>`` on the ``iteration`` dimension and ``energy/<kind>`` on ``time``."""
    from walkerlab.io.artifacts import put
    from walkerlab.io.netcdf import coordinate

    n = len(d.ipopt_history.get("objective", ()))
    if n:
        coordinate(f, "iteration", np.arange(n), "-", "IPOPT iteration (0: the initial guess)")
        for name, v in d.ipopt_history.items():
            put(f, f"ipopt/{name}", np.asarray(v, float), "-", f"IPOPT's {name} at each "
                "iteration (the NLP's own scaling)", dims=("iteration",))
    for name, v in d.energy.items():
        put(f, f"energy/{name}", np.asarray(v, float), d.energy_unit, f"{name} energy of the "
            "collocated states (gravity's potential relative to the stance foot)",
            dims=("time",))


@artifact_loader(STAGE)
def load(f, path: Path) -> OptimizeData:
    """Read ``optimize.h5``."""
    names = [str(s) for s in f.attrs["state_names"]]
    joints = tuple(str(s) for s in f.attrs.get("torque_names", ["hip"]))
    tq = np.stack([f[f"torque/{j}"][()] for j in joints], axis=1)

    def opt(key):
        return float(f[f"replay/{key}"][()]) if f"replay/{key}" in f else float("nan")

    return OptimizeData(
        f["time"][()], {n: f[f"states/{n}"][()] for n in names},
        tq[:, 0] if joints == ("hip",) else tq,
        float(f["step_period"][()]), float(f["step_length"][()]),
        float(f["push_off"][()]), float(f["objective"][()]),
        float(f["replay/max_state_error"][()]),
        f["replay/multipliers/real"][()] + 1j * f["replay/multipliers/imag"][()],
        bool(f.attrs["gait"]), str(f.attrs["ipopt_status"]),
        int(f.attrs["ipopt_iterations"]), float(f.attrs["ipopt_wall_time_s"]),
        {n: str(f[f"states/{n}"].attrs["unit"]) for n in names},
        str(f.attrs["objective_name"]), str(f["objective"].attrs["unit"]),
        {k: float(v[()]) for k, v in f["terms"].items()} if "terms" in f else {},
        float(f["contact_replay/step_period"][()]),
        str(f.attrs["contact_replay_outcome"]), str(f[f"torque/{joints[0]}"].attrs["unit"]),
        joints, opt("start_shift"), opt("step_period"), opt("collocated_start_error"),
        float(f.attrs.get("ipopt_cpu_time_s", float("nan"))),
        {k: v[()] for k, v in f["ipopt"].items()} if "ipopt" in f else {},
        {k: v[()] for k, v in f["energy"].items()} if "energy" in f else {},
        str(next(iter(f["energy"].values())).attrs["unit"]) if "energy" in f else "J",
        tuple(str(s) for s in f.attrs.get("phase_names", [])),
        f["phases/start_index"][()] if "phases" in f else None,
        f["phases/duration"][()] if "phases" in f else None,
        float(f.attrs.get("ipopt_build_time_s", float("nan"))),
        {law: _load_phase(f, law) for law in PHASE_LAWS if f"replay/phase_{law}" in f},
        int(f.attrs.get("steps", 1)), str(f.attrs.get("phase_replay_outcome", "")),
        str(f.attrs.get("ipopt_violations", "")), _load_controllers(f))


#: the design optimisation's artifact (``walkerlab optimize --design``)
DESIGN_STAGE = "optimize_design"


def write_design(f, r) -> None:
    """Fill an open artifact with a design optimisation ``r``
    (:class:`walkerlab.optimal.design.search.DesignResult`): ``fields`` (attribute), ``values`` (k,)
    in the fields' units, ``objective_value``, ``gradient`` (k,) [measure unit per field
    unit; NaN where the measure is not smooth], ``history/values`` (m, k) and
    ``history/objective`` (m,); attributes ``objective``, ``objective_unit``, ``success``,
    ``message``, ``evaluations``."""
    from walkerlab.io.artifacts import put

    unit = str(getattr(r, "unit", "-"))
    put(f, "values", np.asarray(r.values, float), "-", "optimal values of the fields "
        "(attribute 'fields'), each in its field's unit")
    put(f, "objective_value", float(r.value), unit, f"{r.objective} at the optimum")
    put(f, "gradient", np.asarray(r.gradient, float), f"{unit} per field unit",
        f"d {r.objective} / d field at the optimum (through the fixed point)")
    hv = np.array([h[0] for h in r.history], float).reshape(len(r.history), len(r.fields))
    put(f, "history/values", hv, "-", "each evaluation's field values")
    put(f, "history/objective", np.array([h[1] for h in r.history], float), unit,
        f"each evaluation's {r.objective}")
    f.attrs["fields"] = list(r.fields)
    f.attrs["objective"] = r.objective
    f.attrs["objective_unit"] = unit
    f.attrs["success"] = bool(r.success)
    f.attrs["message"] = str(r.message)
    f.attrs["evaluations"] = int(r.evaluations)


@dataclass
class DesignData:
    """The contents of a design artifact ``optimize_design_<fields>_<objective>.h5``
    (:func:`write_design`)."""

    fields: tuple
    values: np.ndarray  # (k,) the fields' units
    objective: str
    objective_unit: str
    objective_value: float
    gradient: np.ndarray  # (k,) objective unit per field unit
    history_values: np.ndarray  # (m, k)
    history_objective: np.ndarray  # (m,)
    success: bool
    message: str
    evaluations: int


@artifact_loader(DESIGN_STAGE)
def load_design(f, path: Path) -> DesignData:
    """Read a design artifact ``optimize_design_<fields>_<objective>.h5``
    (:func:`write_design`)."""
    return DesignData(
        tuple(str(x) for x in f.attrs["fields"]), f["values"][()],
        str(f.attrs["objective"]), str(f.attrs.get("objective_unit", "-")),
        float(f["objective_value"][()]), f["gradient"][()], f["history/values"][()],
        f["history/objective"][()], bool(f.attrs["success"]), str(f.attrs["message"]),
        int(f.attrs["evaluations"]))
