"""``contact_sim.h5``: the compliant-contact walker's run (writer and loader side by side).

Layout: the named ``samples/`` of :mod:`walkerlab.io.trajectory` (as ``simulate.h5``);
root attributes ``model``, ``legs``, ``termination``, ``method``, ``outcome``,
``outcome_message``, ``stiffness_family`` (``fall_time_s`` when it fell), ``walks`` (1/0:
the one verdict from the steps, :func:`walkerlab.analysis.contact.verdict.walk_verdict`) and
``walks_reason`` (why not; "" when it walks); ``outcome/`` (event time [s], patch edge
[m], hip height [m]; attributes ``after``, the end that followed the heel strikes asked
for, "" when none, and ``after_time`` [s]); ``drop_test/`` (restitution, largest
penetration [m] and contact time [s] of both stiffness families on dimension
``stiffness``); ``contact_params_si/`` (the contact law in SI); ``terrain/`` (patch
centres [m] per lane); ``initial_state`` (named by ``contact_state``),
``initial_state_named/``, ``initial_state_ideal`` (the rigid fixed point it started from),
``initial_rate_scale`` (on dimension ``rate``); ``feet/<leg>/`` (normal and friction force
[N], penetration [m], slip velocity [m/s], touchdown/lift-off times [s]; a flat foot's
heel and toe combined); ``contact_points/<point>/`` (flat feet only: the same per contact
point, ``leg1_heel``, ``leg1_toe``, ...: which points are loaded when); ``events/``
(heel-strike times [s] and legs); ``steps/`` (per step: times [s], stance slip and creep
[mm], friction work [J], bounces, scuffs, peak penetration [m]; flat feet: the stance
foot's mode sequence);
``summary/``; optional ``periodic_gait/`` (the contact model's own gait: period [s], step
length [m], Floquet multipliers) and ``adjust/`` (``--adjust``'s search); a powered walker's
``ledger/`` (``time`` [s], the samples' times; ``work/<name>`` [J] the work integrals on it,
``residual`` [J] the closure; ``steps/<name>`` the ledger per step on dimension
``ledger_step``: push-off and torque work [J], contact work [J], distance [m], slope energy
[J], cost of transport [-], :mod:`walkerlab.analysis.contact.ledger`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from walkerlab.io.artifacts import artifact_loader, put
from walkerlab.io.netcdf import coordinate
from walkerlab.io.stage_files import CONTACT_SIM
from walkerlab.io.trajectory import NamedTrajectory, read_samples, write_samples
from walkerlab.units import Units, for_artifact

STAGE = CONTACT_SIM.name
#: unit of each ``summary/`` entry (others: "-")
SUMMARY_UNITS = {"mean_abs_stance_slip_mm": "mm", "peak_penetration_mm": "mm",
                 "max_abs_stance_turn_mrad": "mrad",
                 "max_abs_stance_slip_mm": "mm", "total_double_support_creep_mm": "mm",
                 "mean_stance_slip_path_mm": "mm", "mean_friction_work_j": "J",
                 "wall_time_s": "s"}
#: a walker in 3D's per-step stance-foot quantities (``steps/``): field, unit, meaning
STEP_3D_FIELDS = (
    ("stance_lateral_slip_mm", "mm", "the stance foot's slide across the slope over its "
     "stance (the integral of its lateral slip velocity)"),
    ("stance_turn_mrad", "mrad", "the stance foot's turn about the slope's normal over its "
     "stance (the integral of its spin: what the torsional friction lets through)"))
#: the stance foot's slip path and friction work per step (``steps/``): name, unit, meaning
STEP_SLIP_FIELDS = (
    ("stance_slip_path_mm", "mm", "path of the stance foot's slip over its stance phase(s), "
     "integral of |slip velocity| (the to-and-fro creep the net stance_slip_mm hides)"),
    ("friction_work_j", "J", "work the friction forces of the stance foot's contact points "
     "take over its stance phase(s), -integral of F_t v_t (>= 0: dissipated)"))


@dataclass
class ContactSimRun:
    """What the contact-sim stage computed (the writer's input).

    Attributes
    ----------
    walker : walkerlab.models.contact.generated walker
        The floating contact walker (state names/units, lanes, contact law in SI).
    result : ContactResult
        The run (feet, events, steps, outcome).
    samples : NamedTrajectory
        The run on the shared named layout.
    initial_state : ndarray (n_contact_states,)
        Start state of the floating walker.
    step_length_m : float
        Ideal step length used to place the patches [m].
    fixed_point : ndarray (2n,)
        Rigid fixed point it started from [rad, rad/s].
    fixed_point_names : list of str
        Its role-ordered state names.
    legs : list of str
    rate_names : list of str
        Per leg, the rate states one entry of the initial rate scale multiplies.
    initial_rate_scale : ndarray (2,)
        Multipliers used (the scene's or ``--adjust``'s).
    stiffness_family : str
    drop : dict
        Drop test (:func:`walkerlab.analysis.contact.record.drop_test`; stiffnesses in its
        ``unit``, the unit the scene writes its stiffness in).
    drop_speed_m_per_s : float
    summary : dict
    gait, gait_error : periodic contact gait or its error (or None)
    adjust : dict or None
        ``--adjust``'s result.
    """

    walker: object
    result: object
    samples: NamedTrajectory
    initial_state: np.ndarray
    step_length_m: float
    fixed_point: np.ndarray
    fixed_point_names: list
    legs: list
    rate_names: list
    initial_rate_scale: np.ndarray
    stiffness_family: str
    drop: dict
    drop_speed_m_per_s: float
    summary: dict
    gait: object = None
    gait_error: Exception | None = None
    adjust: dict | None = None
    step_ledger: dict | None = None
    step_ledger_units: dict = field(default_factory=dict)
    step_ledger_descriptions: dict = field(default_factory=dict)


def _write_outcome_and_drop(f, run: ContactSimRun) -> None:
    walker, res, drop = run.walker, run.result, run.drop
    f.attrs["model"] = walker.model_name
    f.attrs["legs"] = run.legs
    f.attrs["termination"] = res.termination
    f.attrs["method"] = res.method
    f.attrs["outcome"] = res.outcome.kind
    f.attrs["outcome_message"] = res.outcome.message
    f.attrs["stiffness_family"] = run.stiffness_family
    if res.fall_time is not None:
        f.attrs["fall_time_s"] = res.fall_time
    walks, why = res.verdict
    f.attrs["walks"] = int(walks)
    f.attrs["walks_reason"] = why
    o = res.outcome
    g = f.create_group("outcome")
    g.attrs["kind"] = o.kind
    g.attrs["after"] = o.after
    g.attrs["after_time"] = o.after_time_s
    g.attrs["foot"] = o.foot
    g.attrs["message"] = o.message
    put(g, "time", o.time_s, "s", "time of the event that set the outcome (NaN: none)")
    put(g, "patch_edge", o.patch_edge_m, "m", "along-slope position of the patch side "
        "hit by a trip (NaN: no trip)")
    put(g, "hip_height", o.hip_height_m, "m", "hip height above the ground line at "
        "the outcome time")
    g = f.create_group("drop_test")
    g.attrs["method"] = (f"point mass {walker.total_mass:.6g} kg (the walker's) meeting "
                         f"flat ground at {run.drop_speed_m_per_s} m/s, no gravity "
                         "(walkerlab.analysis.contact.drop); restitution = v_out / v_in")
    g.attrs["mass_kg"] = float(walker.total_mass)
    coordinate(g, "stiffness", drop["stiffness"], drop["unit"],
               "IMPACT stiffness in the scene's unit system")
    k = ("stiffness",)
    for fam in ("paper", "rigid_limit"):
        put(g, f"{fam}/restitution", drop[fam]["restitution"], "-",
            f"coefficient of restitution, {fam} family", dims=k)
        put(g, f"{fam}/max_penetration", drop[fam]["max_penetration_m"], "m",
            "largest penetration in the drop", dims=k)
        put(g, f"{fam}/contact_time", drop[fam]["contact_time_s"], "s",
            "duration of the contact (NaN: comes to rest)", dims=k)


def _write_setup(f, run: ContactSimRun) -> None:
    walker, c, x0 = run.walker, run.walker.contact, run.initial_state
    for name, val, unit in (("stiffness", c.k, "N/m^e"), ("exponent", c.e, "-"),
                            ("max_damping", c.cmax, "N s/m"),
                            ("penetration_at_max_damping", c.dmax, "m"),
                            ("mu_static", c.mu_s, "-"), ("mu_dynamic", c.mu_d, "-"),
                            ("stiction_velocity", c.v_s, "m/s"),
                            ("friction_velocity", c.v_d, "m/s")):
        put(f, f"contact_params_si/{name}", val, unit, f"{name} in SI")
    put(f, "terrain/step_length", run.step_length_m, "m", "ideal step length used for patches")
    for leg, lane in (("leg1", walker.lane1), ("leg2", walker.lane2)):
        coordinate(f.require_group("terrain"), f"patch_{leg}", np.arange(len(lane)),
                   "-", f"patch number on {leg}'s lane")
        put(f, f"terrain/lane_{leg}", lane, "m", "patch centres, along-slope s",
            dims=(f"patch_{leg}",))
    put(f, "terrain/patch_half_width", walker.patch_half_width, "m", "")
    put(f, "terrain/continuous", bool(walker.continuous), "-", "")
    coordinate(f, "contact_state", list(walker.state_names()), "-",
               "state component of the floating contact walker")
    put(f, "initial_state", x0, ", ".join(walker.state_units()),
        "initial state, named by state_names", names=list(walker.state_names()),
        dims=("contact_state",))
    for name, val, unit in zip(walker.state_names(), x0, walker.state_units()):
        put(f, f"initial_state_named/{name}", float(val), unit, f"initial {name}")
    coordinate(f, "state", list(run.fixed_point_names), "-",
               "state component of the rigid walker (role-ordered)")
    put(f, "initial_state_ideal", run.fixed_point, "rad, rad/s",
        "ideal fixed point (Table 2 MATLAB)", dims=("state",))
    coordinate(f, "rate", run.rate_names, "-", "rates scaled (leg1 swing, leg2 stance)")
    put(f, "initial_rate_scale", np.asarray(run.initial_rate_scale), "-",
        f"multipliers on ({'; '.join(run.rate_names)})", dims=("rate",))


def _write_trace(g, ft, time, what: str) -> None:
    """One foot's (or contact point's) trace and its touchdown / lift-off times."""
    coordinate(g, "time", time, "s", "sample time")
    t = ("time",)
    put(g, "normal_force", ft.normal_force, "N", "IMPACT normal force", dims=t)
    put(g, "friction_force", ft.friction_force, "N", "Coulomb friction, down-slope",
        dims=t)
    put(g, "penetration", ft.penetration, "m", "signed penetration (<0: above)", dims=t)
    put(g, "slip_velocity", ft.slip_velocity, "m/s", "tangential foot velocity", dims=t)
    for ev in ("touchdown", "liftoff"):
        times = getattr(ft, f"{ev}_times")
        coordinate(g, ev, np.arange(len(times)), "-", f"{ev} number")
        put(g, f"{ev}_times", times, "s", f"{ev} times of {what}", dims=(ev,))


def _write_feet_events_steps(f, run: ContactSimRun) -> None:
    res, tr = run.result, run.samples
    for leg, ft in res.feet.items():
        _write_trace(f.create_group(f"feet/{leg}"), ft, tr.time, f"{leg}'s foot")
    points = getattr(res, "points", None) or {}
    if set(points) != set(res.feet):  # several contact points per foot (flat feet)
        for name, ft in points.items():
            _write_trace(f.create_group(f"contact_points/{name}"), ft, tr.time,
                         f"contact point {name}")
    g = f.create_group("events")
    legs = list(res.heel_strike_legs) or [""]
    coordinate(g, "heel_strike", np.arange(len(legs)), "-", "heel strike number")
    put(g, "heel_strike_times", res.heel_strike_times, "s", "heel-strike times",
        dims=("heel_strike",) if len(res.heel_strike_times) == len(legs) else None)
    put(g, "heel_strike_legs", legs, "-", "leg striking", dims=("heel_strike",))
    steps = res.steps
    g = f.create_group("steps")
    coordinate(g, "step", np.arange(len(steps) or 1), "-", "step number")
    s_dim = ("step",)
    for fld, unit in (("t_start", "s"), ("t_end", "s"), ("period", "s"),
                      ("stance_slip_mm", "mm"), ("double_support_creep_mm", "mm"),
                      ("bounce_count", "-"), ("scuff_count", "-"),
                      ("peak_penetration_m", "m"), ("liftoff_time", "s")):
        put(g, fld, np.array([getattr(s, fld) for s in steps], dtype=float), unit, fld,
            dims=s_dim if steps else None)
    for fld, unit, what in STEP_SLIP_FIELDS:
        put(g, fld, np.array([getattr(s, fld) for s in steps], dtype=float), unit, what,
            dims=s_dim if steps else None)
    if any(np.isfinite(s.stance_turn_mrad) for s in steps):  # a walker in 3D
        for fld, unit, what in STEP_3D_FIELDS:
            put(g, fld, np.array([getattr(s, fld) for s in steps], dtype=float), unit,
                what, dims=s_dim)
    put(g, "stance_leg", [s.stance_leg for s in steps] or [""], "-", "stance leg",
        dims=s_dim)
    if any(getattr(s, "foot_modes", "") for s in steps):  # flat feet
        put(g, "stance_foot_modes", [s.foot_modes for s in steps], "-", "the stance foot's "
            "modes over the step (heel_contact, foot_flat, heel_off, off: which of its heel "
            "and toe carry load, from the contact table) with their start times", dims=s_dim)


def _write_periodic_and_adjust(f, run: ContactSimRun) -> None:
    gait, gait_error, adj = run.gait, run.gait_error, run.adjust
    if gait_error is not None:
        g = f.create_group("periodic_gait")
        g.attrs["outcome"] = gait_error.kind
        g.attrs["message"] = str(gait_error)
    if gait is not None:
        g = f.create_group("periodic_gait")
        g.attrs["section"] = "mid-stance (proximal links aligned), stance foot loaded only"
        g.attrs["outcome"] = "ok"
        g.attrs["steps_per_map"] = int(gait.steps_per_map)  # the multipliers' map
        g.attrs["multiplier_modes"] = list(gait.multiplier_modes)
        for k, v in gait.fixed_point.items():
            g.attrs[f"fixed_point_{k}"] = float(v)
        put(g, "step_period", gait.period_s, "s", "period of the contact gait")
        put(g, "step_length", gait.step_length_m, "m", "")
        put(g, "residual", gait.residual, "-", "scaled map residual")
        coordinate(g, "multiplier", np.arange(len(gait.multipliers)), "-",
                   "Floquet multiplier number")
        m = ("multiplier",)
        put(g, "multipliers/real", gait.multipliers.real, "-",
            "Floquet multipliers, real part", dims=m)
        put(g, "multipliers/imag", gait.multipliers.imag, "-",
            "Floquet multipliers, imag part", dims=m)
        put(g, "multiplier_fd_spread", gait.multiplier_fd_spread, "-",
            "change of the multipliers for FD steps x3 and /3")
        put(g, "stable", bool(gait.stable), "-", "all |multipliers| < 1")
        put(g, "converged", bool(gait.converged), "-", "residual below tolerance")
    if adj is not None:
        for k, v in adj.items():
            if isinstance(v, (int, float, np.ndarray, list, tuple)):
                v = np.asarray(v, dtype=float)
                put(f, f"adjust/{k}", v, "-", k,
                    dims=("rate",) if k == "scale" and v.shape == (2,) else None)
        # which start the run is from, and why; a search that gave up, or skipped a part
        for k in ("kept", "kept_reason", "gave_up", "note"):
            if k in adj:
                f.require_group("adjust").attrs[k] = str(adj[k])


def write_contact_sim(f, run: ContactSimRun) -> None:
    """Fill an open (in-memory) artifact with ``run`` (layout in the module docstring)."""
    _write_outcome_and_drop(f, run)
    write_samples(f, run.samples)
    _write_setup(f, run)
    _write_feet_events_steps(f, run)
    for k, v in run.summary.items():
        if k not in ("termination", "outcome"):
            put(f, f"summary/{k}", v, SUMMARY_UNITS.get(k, "-"), k)
    _write_periodic_and_adjust(f, run)
    _write_work(f, run)


def _write_work(f, run: ContactSimRun) -> None:
    """A powered walker's energy ledger: ``ledger/work/<name>`` [J] on ``time`` (the work
    integrals the run carried, ``walker.actuators.work_names``) and
    ``ledger/residual`` [J], ``E(t) - E(0)`` minus their sum (the ledger's closure)."""
    work = getattr(run.result, "work", None)
    if work is None:
        return
    what = {"hip_torque_positive": "positive work of the hip torques",
            "hip_torque_negative": "negative work of the hip torques",
            "push_off": "work of the push-off pulse at the trailing foot",
            "ankle_torque_positive": "positive work of the ankle push-off torque",
            "ankle_torque_negative": "negative work of the ankle push-off torque",
            "damper": "work of the ankle (and hip) dampers",
            "contact": "work of the contact forces (normal + friction, every point): their "
                       "dissipation and the energy their springs hold",
            "knee_stop": "work of the knee stops (a kneed walker): their dissipation and "
                         "the energy their springs hold",
            "hip_roll_positive": "positive work of the hip-roll law (a 3D walker's "
                                 "hip-roll joints: the stance hip holding the pelvis level, "
                                 "the swing hip placing its leg; Kuo 1999)",
            "hip_roll_negative": "negative work of the hip-roll law"}
    # the actuators' own words (a five-link biped's hip-torque terms carry every joint's)
    what.update(run.walker.actuators.work_labels)
    # the samples' times as the ledger's own coordinate (without it the dimension was a
    # bare scale of zeros)
    coordinate(f.require_group("ledger"), "time", np.asarray(run.result.t, float), "s",
               "time of the samples")
    for k, name in enumerate(run.walker.actuators.work_names):
        put(f, f"ledger/work/{name}", work[:, k], "J", what[name] + " since the start",
            dims=("time",))
    E = run.walker.energies(run.result.x)["total"]
    put(f, "ledger/residual", (E - E[0]) - work.sum(axis=1), "J", "kinetic + potential "
        "energy change minus the works: the ledger's closure", dims=("time",))
    if run.step_ledger:
        g = f.require_group("ledger/steps")
        n = len(next(iter(run.step_ledger.values())))
        coordinate(g, "ledger_step", np.arange(n), "-", "step (mid-step to mid-step, "
                   "around each heel strike with one before and after it)")
        for name, v in run.step_ledger.items():
            put(g, name, np.asarray(v, float), run.step_ledger_units.get(name, "-"),
                run.step_ledger_descriptions.get(name, name), dims=("ledger_step",))


@dataclass
class DropTest:
    """The drop test stored with a contact run.

    Attributes
    ----------
    stiffness : ndarray (n,)
        IMPACT stiffnesses in the scene's unit system (``unit``).
    unit : str
    restitution : dict[str, ndarray (n,)]
        Coefficient of restitution per family ("paper", "rigid_limit") [-].
    mass_kg : float
        Mass dropped [kg].
    """

    stiffness: np.ndarray
    unit: str
    restitution: dict
    mass_kg: float


@dataclass
class PeriodicGait:
    """The contact model's own periodic gait (or why it was not found: ``found`` False,
    ``outcome`` and ``message``).  Period [s], step length [m], multipliers complex.

    ``multipliers`` is an ndarray of shape (m,) (the section's dimension: 6 for straight
    legs, 10 kneed, 15 straight legs in 3D; shape (0,) when not found), Floquet
    multipliers [-] by decreasing modulus, of the map of ``steps_per_map`` steps (2: a
    stride); ``multiplier_modes`` names each one's most moved section coordinate (empty in
    older artifacts).
    """

    found: bool
    outcome: str
    message: str = ""
    step_period_s: float = np.nan
    step_length_m: float = np.nan
    multipliers: np.ndarray = field(default_factory=lambda: np.zeros(0, complex))
    stable: bool = False
    steps_per_map: int = 1
    multiplier_modes: tuple = ()


@dataclass
class ContactSimArtifact:
    """A loaded ``contact_sim.h5`` (units in the module docstring).

    ``summary`` maps each ``summary/`` name to ``(value, unit)``; ``initial_rate_scale``
    multiplies the rates named in ``rate_names`` (None in artifacts without them);
    ``stage_wall_time_s``: the whole stage's compute time [s]; ``walks`` the run's verdict
    from its steps and ``walks_reason`` why not (None and "" in artifacts without them: the
    outcome decides); ``outcome_after`` the end that followed the heel strikes asked for
    ("" when none); ``ledger`` (a powered run)
    maps each work integral's name (:data:`walkerlab.models.contact.actuation.WORK_NAMES`)
    and ``residual`` to its samples (n,) [J]; ``ledger_steps`` (a powered run) its ledger per
    step, name -> (steps,) (``ledger/steps/``: push-off work [J], ..., cost of transport).
    """

    path: Path
    units: Units
    termination: str
    outcome: str
    outcome_message: str = ""
    walks: bool | None = None
    walks_reason: str = ""
    outcome_after: str = ""
    stiffness_family: str = "paper"
    samples: NamedTrajectory | None = None
    summary: dict = field(default_factory=dict)
    stage_wall_time_s: float = np.nan
    contact_params_si: dict = field(default_factory=dict)
    initial_rate_scale: np.ndarray = field(default_factory=lambda: np.ones(2))
    rate_names: list | None = None
    heel_strike_times: np.ndarray = field(default_factory=lambda: np.zeros(0))
    steps: dict = field(default_factory=dict)
    drop: DropTest | None = None
    periodic: PeriodicGait | None = None
    adjust: dict | None = None
    ledger: dict | None = None
    ledger_steps: dict | None = None


def _periodic(f) -> PeriodicGait | None:
    if "periodic_gait" not in f:
        return None
    g = f["periodic_gait"]
    if "step_period" not in g:
        return PeriodicGait(False, str(g.attrs.get("outcome", "?")),
                            str(g.attrs.get("message", "")))
    return PeriodicGait(True, "ok", "", float(g["step_period"][()]),
                        float(g["step_length"][()]),
                        g["multipliers/real"][()] + 1j * g["multipliers/imag"][()],
                        bool(g["stable"][()]), int(g.attrs.get("steps_per_map", 1)),
                        tuple(str(m) for m in g.attrs.get("multiplier_modes", ())))


@artifact_loader(STAGE)
def load_contact_sim(f, path: Path) -> ContactSimArtifact:
    """Load ``contact_sim.h5`` (a hand-built artifact may lack the setup records: they are
    then empty)."""
    term = str(f.attrs["termination"])
    drop = None
    if "drop_test" in f:
        g = f["drop_test"]
        drop = DropTest(g["stiffness"][()], str(g["stiffness"].attrs["unit"]),
                        {fam: g[f"{fam}/restitution"][()]
                         for fam in ("paper", "rigid_limit")},
                        float(g.attrs.get("mass_kg", 20.0)))
    steps = {k: f[f"steps/{k}"][()] for k in ("stance_slip_mm", "double_support_creep_mm",
                                               "period", "stance_slip_path_mm",
                                               "friction_work_j") if f"steps/{k}" in f}
    return ContactSimArtifact(
        path=Path(path), units=for_artifact(f), termination=term,
        outcome=str(f.attrs.get("outcome", term)),
        outcome_message=str(f.attrs.get("outcome_message", "")),
        walks=bool(f.attrs["walks"]) if "walks" in f.attrs else None,
        walks_reason=str(f.attrs.get("walks_reason", "")),
        outcome_after=(str(f["outcome"].attrs.get("after", "")) if "outcome" in f
                       else ""),
        stiffness_family=str(f.attrs.get("stiffness_family", "paper")),
        samples=read_samples(f),
        summary={k: (f["summary"][k][()], str(f["summary"][k].attrs.get("unit", "")))
                 for k in f["summary"]} if "summary" in f else {},
        stage_wall_time_s=float(f.attrs.get("wall_time_s", np.nan)),
        contact_params_si={k: (f["contact_params_si"][k][()],
                               str(f["contact_params_si"][k].attrs["unit"]))
                           for k in f["contact_params_si"]}
        if "contact_params_si" in f else {},
        initial_rate_scale=(f["initial_rate_scale"][()] if "initial_rate_scale" in f
                            else np.ones(2)),
        rate_names=([str(v) for v in f["rate"][()].astype(str)] if "rate" in f else None),
        heel_strike_times=(f["events/heel_strike_times"][()]
                           if "events/heel_strike_times" in f else np.zeros(0)),
        steps=steps, drop=drop, periodic=_periodic(f),
        adjust={**{k: f["adjust"][k][()] for k in f["adjust"]},
                **{k: str(v) for k, v in f["adjust"].attrs.items()}}
        if "adjust" in f else None,
        ledger=({**{k: f["ledger/work"][k][()] for k in f["ledger/work"] if k != "time"},
                 "residual": f["ledger/residual"][()]} if "ledger" in f else None),
        ledger_steps=({k: f["ledger/steps"][k][()] for k in f["ledger/steps"]
                       if k != "ledger_step"} if "ledger/steps" in f else None))


@artifact_loader(STAGE)
def run_end(f, path: Path) -> tuple[str, str]:
    """``(outcome, message)`` of a contact run (the outcome's name, e.g. "walked", "trip";
    the message may be "")."""
    return (str(f.attrs.get("outcome", f.attrs["termination"])),
            str(f.attrs.get("outcome_message", "")))


@artifact_loader(STAGE)
def load_step_periods(f, path: Path) -> np.ndarray:
    """The step periods [s] of ``contact_sim.h5`` at ``path`` (``steps/period``; NaN: a
    step the run did not finish)."""
    return np.asarray(f["steps/period"][()], float) if "steps/period" in f else \
        np.zeros(0)
