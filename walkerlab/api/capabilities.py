"""The capability table's evidence, measured: each supported cell (a kind's feature in a
view, :data:`walkerlab.walker.kinds.CAPABILITIES`) run on its reference case
(:func:`walkerlab.walker.reference_cases.reference_scene`) and checked against a reference
the cell does not compute itself.

By view (the quantity, its reference and tolerance: :data:`QUANTITIES`):

``rigid``
    ``walkerlab simulate`` over 10 heel strikes from the gait of ``walkerlab fixedpoint``:
    each step's period and length against the fixed point's (the Poincaré map's root,
    found by a root finder, against an integration with event location; relative, 1e-6);
    on a profile, where the gait changes from step to step, the footfalls against the
    profile's height under them [m].  The fixed point's friction verdict (the gait's
    ground forces inside the friction cone) where it made one: a cell's quantity names it
    only then, and a cell without one (a walk on a profile) says "not checked"
    (``Measurement.not_checked``), never passed.
``contact``
    ``walkerlab contact-sim`` walks at least 10 heel strikes; its last 4 steps (whole
    periods of the rigid gait), past the transient of its start, against ``walkerlab
    simulate``'s same steps on the same ground: the mean step period and the hip's speed
    (relative, 3 %), and the spread of the step periods' deviations (steady: 3 %).  On a
    profile that is the scene's slope (the profile cells' generated cases) also the contact
    walk on that slope, heel strike by heel strike (the same ground: integration
    tolerance), and the rigid walk the slope's where the rigid view refuses the profile.
    A reference case whose passive gait is unstable with no stabilised counterpart
    (:data:`walkerlab.walker.reference_cases.FIRST_STEPS`: the 3D kneed walker) holds its
    first steps instead, here and in the ``mjcf`` cell (:mod:`walkerlab.api.capability_early`).
``mjcf``, ``osim``
    The exported file walked in its engine (MuJoCo, OpenSim) for 10 heel strikes from the
    rigid gait: the mean step period against the rigid one (relative, 3 %).  The OpenSim
    model is walked by walkerlab's stepping loop (:mod:`walkerlab.export.opensim_walk`:
    the joint torques, the push-off and a kneed walker's knee latch switched between the
    Manager's windows); a kneed walker's cells say so
    (:data:`walkerlab.walker.capability_cells.KNEE_LATCH_OSIM`: the file alone falls).
``urdf``
    ``walkerlab export --format urdf`` (its keyframe's rigid gait searched as the command
    does) loaded by Pinocchio (``pinocchio.buildModelFromUrdf``; Carpentier et al. 2019):
    its total mass against the walker description's (relative, 1e-9), its bodies' masses
    listed in the detail.  URDF has no ground, contact or actuator element (its file says
    what it leaves out), so no walk is measured.
``adams``
    No Adams Solver runs here: the dataset read back (:func:`walkerlab.export.adams_reader.
    read_adm`): every part's mass against the walker description's (relative, 1e-9).
``gym``
    The environment's rigid view (a zero action; the scene's controller as the policy when
    it has one) against ``walkerlab simulate``: heel-strike times over 10 heel strikes,
    each step's period, relative (1e-6; a controller sampled once per control period: 3 %).
``optimize``
    ``walkerlab optimize``: its optimum replayed on the rigid model returns to its start
    (max-norm return error, 1e-6).

Each cell records the kind of check behind its number (:data:`CHECKS`; the words:
:data:`walkerlab.walker.capability_evidence.CHECK_KINDS`): another engine (MuJoCo,
OpenSim), another model (the compliant-contact walker against the rigid one), an
independent reference (a profile's given heights), a mass read back (Pinocchio, the Adams
reader), or self-consistency (the same model by another algorithm: a root finder against
event location, the gym's loop against simulate's, an optimum replayed).

Runs every stage into a runs folder of its own (``runs_root``); nothing else is written.
"""

from __future__ import annotations

import copy
import math
import warnings
from dataclasses import asdict, dataclass, replace
from pathlib import Path

import numpy as np

from walkerlab.api.capability_early import first_steps
from walkerlab.config import scene_from_dict
from walkerlab.walker.kinds import KINDS
from walkerlab.walker.reference_cases import FIRST_STEPS, reference_scene

__all__ = ["CHECKS", "CONE", "QUANTITIES", "Measurement", "measure"]

#: view -> (quantity, tolerance, unit)
QUANTITIES = {
    "rigid": ("simulate's step periods and lengths over 10 heel strikes against the fixed "
              "point's", 1e-6, "relative"),
    "contact": ("contact-sim walks >= 10 heel strikes; over its last 4 steps (whole gait "
                "periods), the mean step period and the hip's speed against simulate's same "
                "steps on the same ground, and the spread of the step periods' deviations "
                "(steady: no drift)", 0.03, "relative"),
    "mjcf": ("the MJCF walked in MuJoCo: mean step period over 10 heel strikes against the "
             "rigid gait", 0.03, "relative"),
    "osim": ("the OpenSim model walked by OpenSim: mean step period over 10 heel strikes "
             "against the rigid gait", 0.03, "relative"),
    "urdf": ("the URDF loaded by Pinocchio: its total mass against the walker description "
             "(URDF has no ground, contact or actuator element: the walk is not measured)",
             1e-9, "relative"),
    "adams": ("the dataset read back: every part's mass against the walker description "
              "(massless flat feet: with the contact model's foot masses the dataset gives them; "
              "no Adams Solver here: the walk is not measured)", 1e-9, "relative"),
    "gym": ("the rigid view under a zero action (or the scene's controller as its policy) "
            "against walkerlab simulate: each of 10 step periods (relative; a controller "
            "held per control period: 3 %)", 1e-6, "relative"),
    "optimize": ("the optimum replayed on the rigid model: its return error (max norm)",
                 1e-6, "state"),
}
#: the rigid view's second check, named in a cell's quantity only where it ran: the fixed
#: point's friction verdict (:mod:`walkerlab.analysis.gait.friction`; a walk on a profile has
#: none)
CONE = "and the gait's ground forces inside the friction cone (the fixed point's verdict)"
#: the kind of check behind each view's number
#: (:data:`walkerlab.walker.capability_evidence.CHECK_KINDS`); the rigid view on a profile is
#: held to the profile's given heights (``reference``)
CHECKS = {"rigid": "self", "gym": "self", "optimize": "self", "contact": "model",
          "mjcf": "engine", "osim": "engine", "urdf": "mass", "adams": "mass"}
#: the gym's tolerance when the scene's controller is the policy (its torque sampled once
#: per control period and held: a zero-order hold of the continuous feedback)
GYM_POLICY_TOLERANCE = 0.03
#: heel strikes a walk must reach
STRIKES = 10
#: the steps of the contact walk held to the rigid gait: its last ones (an even number, a
#: period-2 gait's two steps in turn), past the transient of its start from the rigid gait
SETTLED = 4


@dataclass(frozen=True)
class Measurement:
    """One cell's measured agreement.

    Attributes
    ----------
    kind, feature, view : str
        The cell.
    case : str
        The reference case (``configs/<name>.yaml`` or ``generated: ...``).
    quantity : str
        What was measured against what.
    value : float
        The measured disagreement (signed where it has a sign: ``+0.012`` is 1.2 % long;
        NaN when nothing could be measured).
    tolerance : float
        The tolerance the cell is held to (same unit as ``value``).
    unit : str
        "relative", "m" or "state".
    ok : bool
        ``|value| <= tolerance`` and the walk reached what it must.
    detail : str
        One line: what was seen (heel strikes, numbers) or why nothing was measured.
    check : str
        The kind of check behind the number (a key of
        :data:`walkerlab.walker.capability_evidence.CHECK_KINDS`: ``engine``, ``model``,
        ``reference``, ``mass``, ``self``).
    not_checked : str
        A check of the view that did not run on this case, and why ("" when none): it is
        not in ``quantity`` and not counted as passed (the rigid view's friction cone of a
        walker in 3D).
    """

    kind: str
    feature: str
    view: str
    case: str
    quantity: str
    value: float
    tolerance: float
    unit: str
    ok: bool
    detail: str
    check: str = ""
    not_checked: str = ""

    def as_dict(self) -> dict:
        """The measurement as a JSON-ready mapping (NaN as None)."""
        d = asdict(self)
        d["value"] = None if not math.isfinite(self.value) else float(self.value)
        return d


def _h5(path):
    from walkerlab.io.artifacts import open_artifact  # light

    return open_artifact(Path(path))


def _cyclic_deviation(got: np.ndarray, ref: np.ndarray) -> float:
    """Max relative deviation of ``got`` from the period-n ``ref`` repeated."""
    rep = np.resize(ref, got.shape)
    return float(np.max(np.abs(got / rep - 1.0)))


def _strides_for(d: dict, view: str) -> None:
    if view in ("rigid", "gym", "contact"):
        sim = d.get("simulate") or {}
        d["simulate"] = sim
        sim["strides"] = max(int(sim.get("strides", 5)), 5)
    if view == "contact":
        d.setdefault("contact", {})
        cs = d.get("contact_sim") or {}
        cs["n_strides"] = max(int(cs.get("n_strides", 5)), 5)
        cs.pop("t_final_s", None)
        d["contact_sim"] = cs
        d["simulate"]["strides"] = max(d["simulate"]["strides"], cs["n_strides"])


def _rigid(scene, d, runs: Path) -> tuple[float, str, dict]:
    """simulate's steps against the fixed point's, and the fixed point's friction verdict
    where it made one: with the cell's quantity as measured (``quantity``: the friction cone
    named only when its verdict exists; ``not_checked``: why not) and its ``check``."""
    from walkerlab.stages import pipeline

    fp = pipeline.run("fixedpoint", scene, runs).path
    sim = pipeline.run("simulate", scene, runs).path
    with _h5(fp) as f, _h5(sim) as s:
        term = s["steps/termination"][:].astype(str)
        n = int(np.sum(term == "heel_strike"))
        if n < STRIKES:
            return math.nan, f"simulate reached {n} heel strikes of {STRIKES}", {}
        ok = term == "heel_strike"
        if (d.get("terrain") or {}).get("kind") == "profile":
            quantity = ("simulate's footfalls over 10 heel strikes against the profile's "
                        "height under them")
            return (*_profile_footfalls(s, d, ok),
                    {"quantity": quantity, "check": "reference",
                     "not_checked": "ground forces (the friction cone) not checked: on a "
                                    "profile the rigid cell holds the footfalls to the "
                                    "profile only"})
        lengths = s["steps/step_length"][:][ok]
        if "steps" in f:  # a gait of n steps: each step's period and length in turn
            dev_t = _cyclic_deviation(s["steps/period"][:][ok], f["steps/period"][:])
            dev_l = _cyclic_deviation(lengths, f["steps/length"][:])
        else:  # a symmetric period-1 gait: its step period; every step as long as the first
            dev_t = _cyclic_deviation(s["steps/period"][:][ok],
                                      np.array([f["step_period"][()]]))
            dev_l = _cyclic_deviation(lengths, lengths[:1])
        inside, cone = _friction_verdict(f)
    dev = max(dev_t, dev_l)
    detail = (f"{n} heel strikes; step periods {dev_t:.1e}, lengths {dev_l:.1e} from the "
              "fixed point's")
    if inside is None:  # no verdict: the cone is neither claimed nor counted as passed
        return dev, f"{detail}; {cone}", {"not_checked": cone}
    extra = {"quantity": f"{QUANTITIES['rigid'][0]}, {CONE}"}
    if not inside:  # the model's gait, but not one on real ground (the fixed point's verdict)
        return math.nan, f"{detail}; but {cone}", extra
    return dev, f"{detail}; ground forces inside the friction cone", extra


def _friction_verdict(f) -> tuple[bool | None, str]:
    """The fixed point's friction verdict: ``(True, "")`` inside the cone; ``(False,
    why)`` when the gait leaves it (the foot, the ratio needed and the ground's mu);
    ``(None, why)`` when the artifact holds no verdict or one not made (a walker in 3D, a
    map that does not end in heel strikes): not checked, never counted as inside."""
    if "ground_contact/friction" not in f:
        why = (str(f["ground_contact"].attrs.get("not_checked", "")) if "ground_contact" in f
               else "") or "the fixed point made no friction verdict"
        return None, f"ground forces (the friction cone) not checked: {why}"
    g = f["ground_contact/friction"]
    inside = int(g.attrs.get("inside", -1))
    if inside < 0:
        why = str(g.attrs.get("not_checked", "")) or "no friction coefficient"
        return None, f"ground forces (the friction cone) not checked: {why}"
    if inside:
        return True, ""
    need = float(g["max_ratio"][()])
    mu = float(g["friction_coefficient"][()])
    need_s = "an unbounded ratio" if not math.isfinite(need) else f"mu >= {need:.3g}"
    return False, (f"the gait leaves the friction cone: its {g.attrs.get('foot', 'foot')} "
                   f"needs {need_s} against the ground's mu {mu:g}")


def _profile_footfalls(s, d, ok) -> tuple[float, str]:
    """The landing foot's height at each heel strike against the profile's under it."""
    prof = np.asarray(d["terrain"]["profile_m"], float)
    t_end = s["steps/t_end"][:][ok]
    legs = s["steps/swing_leg"][:][ok].astype(str)
    worst = 0.0
    for t, leg in zip(t_end, legs):
        g = f"samples/points/{leg}_foot"
        ts, x, y = s[f"{g}/time"][:], s[f"{g}/x"][:], s[f"{g}/y"][:]
        i = int(np.argmin(np.abs(ts - t)))
        if abs(ts[i] - t) > 1e-9:
            continue
        worst = max(worst, abs(y[i] - np.interp(x[i], prof[:, 0], prof[:, 1])))
    return worst, f"{len(t_end)} heel strikes; footfalls {worst:.1e} m from the profile"


def _rigid_steps_per_period(fp) -> int:
    """Steps in the rigid gait's period (1: a symmetric gait; 2: legs that differ, ...)."""
    return int(fp["steps/period"].shape[0]) if "steps" in fp else 1


def _slope_of_profile(d: dict) -> dict | None:
    """The scene ``d`` on its own slope, when its ground is a profile that is that slope (a
    straight line of the scene's slope to 1e-12 m: the profile reference cases,
    :func:`walkerlab.walker.reference_cases.slope_profile`), on the same lanes; else
    None."""
    t = d.get("terrain") or {}
    if t.get("kind") != "profile" or not t.get("profile_m"):
        return None
    sl = d.get("slope") or {}
    phi = (sl["angle_rad"] if sl.get("angle_rad") is not None
           else math.radians(sl.get("angle_deg", 0.0)))
    P = np.asarray(t["profile_m"], float)
    if np.max(np.abs(P[:, 1] - P[0, 1] + (P[:, 0] - P[0, 0]) * math.tan(phi))) > 1e-12:
        return None
    out = copy.deepcopy(d)
    out["name"] = f"{d['name']}-slope"
    out["terrain"] = {k: v for k, v in t.items() if k in ("lanes", "patch_width_m")}
    return out


def _same_ground(cs_path, slope_scene, runs: Path) -> tuple[float, str, object]:
    """The contact walk on a profile that is the scene's slope against the contact walk on
    that slope (the same ground: equal to integration tolerance): the largest difference of
    their heel-strike times over the walk, relative to the slope walk's mean step period;
    with the slope walk's artifact path."""
    from walkerlab.io.stage_files import CONTACT_SIM  # light: as the pipeline below
    from walkerlab.stages import pipeline

    ref = pipeline.run(CONTACT_SIM.name, slope_scene, runs).path
    with _h5(cs_path) as f, _h5(ref) as g:
        h = np.asarray(f["events/heel_strike_times"][:], float)
        hs = np.asarray(g["events/heel_strike_times"][:], float)
    k = min(h.size, hs.size)  # each run walks the heel strikes its own scene asks for (the
    if k < 10:                # profile's and the slope's counts of a gait period may differ)
        return math.nan, (f"the profile's contact walk made {h.size} heel strikes, the "
                          f"slope's {hs.size}: fewer than 10 to compare"), ref
    dev = float(np.max(np.abs(h[:k] - hs[:k])) / np.mean(np.diff(hs[:k])))
    return dev, (f"heel strikes {dev:.1e} of a step period from the slope's contact walk "
                 f"over the {k} both made ({h.size} and {hs.size} asked for)"), ref


def _contact(scene, d, runs: Path) -> tuple[float, str]:
    """The contact walk's last steps against the rigid walk's same steps on the same ground
    (``walkerlab simulate``: footholds of several heights, a profile): the mean step period
    and the hip's speed over a window of whole gait periods, and the spread of the step
    periods' deviations within it (a steady walk keeps one deviation).  On a profile that is
    the scene's slope (the profile's reference cases) the contact walk is also held to the
    contact walk on that slope, heel strike by heel strike (:func:`_same_ground`), and the
    rigid walk is the slope's where the rigid view does not walk the profile (flat feet, a
    walker driven by torques: the same ground)."""
    from walkerlab.config import scene_from_dict
    from walkerlab.io.stage_files import CONTACT_SIM  # light: as the pipeline below
    from walkerlab.stages import pipeline
    from walkerlab.stages.common import StageError  # light

    cs = pipeline.run(CONTACT_SIM.name, scene, runs).path
    same, note = None, ""
    slope_d = _slope_of_profile(d)
    if slope_d is not None:
        slope_scene = scene_from_dict(slope_d)
        same = _same_ground(cs, slope_scene, runs)
        rigid = scene
        try:
            pipeline.run("simulate", scene, runs)
        except StageError as exc:  # the rigid view refuses the profile: its slope's walk
            rigid = slope_scene
            note = (f"; the rigid walk on the slope itself ({' '.join(str(exc).split())[:90]}"
                    "...)")
        scene = rigid
    fp = pipeline.run("fixedpoint", scene, runs).path
    sim = pipeline.run("simulate", scene, runs).path
    value, detail = _contact_against_rigid(cs, fp, sim)
    if same is None:
        return value, detail
    dev, line, _ = same
    if not math.isfinite(dev):
        return math.nan, f"{detail}; {line}"
    worst = value if not math.isfinite(value) or abs(value) >= dev else dev
    return worst, f"{detail}; {line}{note}"


def _contact_against_rigid(cs, fp, sim) -> tuple[float, str]:
    """:func:`_contact`'s comparison of the contact walk ``cs`` with the rigid walk ``sim``
    (artifact paths; ``fp`` the rigid gait's)."""
    with _h5(cs) as f, _h5(sim) as s, _h5(fp) as g:
        n = _rigid_steps_per_period(g)
        strikes = int(f["summary/heel_strikes"][()])
        why = str(f.attrs.get("outcome_message", ""))
        h = np.asarray(f["events/heel_strike_times"][:], float)
        t, x = f["samples/points/hip/time"][:], f["samples/points/hip/x"][:]
        ok = s["steps/termination"][:].astype(str) == "heel_strike"
        hr = np.asarray(s["steps/t_end"][:][ok], float)
        tr, xr = s["samples/points/hip/time"][:], s["samples/points/hip/x"][:]
    if strikes < STRIKES:
        return math.nan, (f"contact-sim walked {strikes} heel strikes of {STRIKES}"
                          + (f": {' '.join(why.split())}" if why else ""))
    steps = min(h.size, hr.size)
    window = n * math.ceil(SETTLED / n)  # whole periods of the rigid gait
    if steps < window + 1:
        return math.nan, f"{steps} steps walked by both, fewer than {window + 1}"
    hc, hr = h[steps - window - 1:steps], hr[steps - window - 1:steps]
    Tc, Tr = np.diff(hc), np.diff(hr)
    dt = float(Tc.sum() / Tr.sum() - 1.0)
    vc = (np.interp(hc[-1], t, x) - np.interp(hc[0], t, x)) / (hc[-1] - hc[0])
    vr = (np.interp(hr[-1], tr, xr) - np.interp(hr[0], tr, xr)) / (hr[-1] - hr[0])
    dv = float(vc / vr - 1.0)
    dev = Tc / Tr - 1.0
    spread = float(dev.max() - dev.min())
    worst = max((dt, dv), key=abs)
    if spread > abs(worst):
        worst = spread
    return worst, (f"{strikes} heel strikes; steps {steps - window + 1}-{steps} against the "
                   f"rigid walk's: period {100 * dt:+.2f} %, speed {100 * dv:+.2f} %, "
                   f"spread of the step periods' deviations {100 * spread:.2f} %")


def _engine(fmt):
    def run(scene, d, runs: Path) -> tuple[float, str]:
        from walkerlab.stages import export  # light

        ex = export.write(scene, runs, fmt, walk=True, walk_steps=STRIKES)
        # the cell's tolerance in the walk's line (the export command's own is 1 %)
        w = ex.walk if ex.walk is None else replace(ex.walk, tolerance=QUANTITIES[fmt][1])
        if w is None or not w.walked:
            return math.nan, (w.line if w is not None else "not walked")
        if w.fell or w.strikes < STRIKES or not w.alternating:
            return math.nan, w.line
        return w.relative, w.line
    return run


def _adams(scene, d, runs: Path) -> tuple[float, str]:
    from walkerlab.export.adams_reader import read_adm
    from walkerlab.stages import export  # light
    from walkerlab.walker.description import walker_data
    from walkerlab.walker.multibody import multibody
    from walkerlab.walker.walker_trees import walker_tree

    path = export.write(scene, runs, "adm").path
    model = read_adm(Path(path).read_text())
    data = walker_data(scene.walker, scene.slope.phi_rad)
    parts = [p for p in model.by_kind["PART"] if p != 1]
    total = sum(model.part_mass(p) for p in parts)
    tree = walker_tree(data.structure)[0]
    if tree.one_body or not tree.in_plane:  # its tree's bodies (a wheel's one)
        return (abs(total / data.total_mass_kg - 1.0),
                f"{len(parts)} parts, {total:.6g} kg against {data.total_mass_kg:.6g} kg")
    mb = multibody(data)
    want = mb.hip_mass_kg + sum(ln.mass_kg for ln in mb.links)
    if data.structure.kind.feet_have_modes and not data.structure.foot_mass:
        # massless flat feet: the dataset's foot PARTs carry the contact model's
        # regularising mass (contact.flat_foot_mass_kg), as it documents
        from walkerlab.export.scene_feet import flat_foot_bodies

        want += sum(f[5] for f in flat_foot_bodies(scene, data))
    dev = abs(total / want - 1.0)
    return dev, f"{len(parts)} parts, {total:.6g} kg against {want:.6g} kg"


def _urdf(scene, d, runs: Path) -> tuple[float, str]:
    """The exported URDF loaded by Pinocchio: its total mass against the description's."""
    try:
        import pinocchio
    except ImportError:
        return math.nan, "pinocchio is not installed (pip install pin): the URDF not loaded"
    from walkerlab.stages import export  # light
    from walkerlab.walker.description import walker_data

    path = export.write(scene, runs, "urdf").path
    model = pinocchio.buildModelFromUrdf(str(path))
    if model.nv == 0:  # one link and no joint (a 3D wheel): a free body
        model = pinocchio.buildModelFromUrdf(str(path), pinocchio.JointModelFreeFlyer())
    # every body's mass, the root link's too (a free pelvis: a loader's base)
    total = float(sum(i.mass for i in model.inertias))
    want = float(walker_data(scene.walker, scene.slope.phi_rad).total_mass_kg)
    bodies = {n: round(float(i.mass), 6) for n, i in zip(model.names, model.inertias)
              if i.mass > 0}
    dev = abs(total / want - 1.0)
    return dev, (f"loaded by Pinocchio: {model.nv} joints, bodies (by joint) {bodies}; "
                 f"{total:.6g} kg against {want:.6g} kg")


def _gym(scene, d, runs: Path) -> tuple[float, str]:
    from walkerlab.gym.env import WalkerEnv  # light
    from walkerlab.stages import pipeline

    sim = pipeline.run("simulate", scene, runs).path
    with _h5(sim) as s:
        ok = s["steps/termination"][:].astype(str) == "heel_strike"
        ref = s["steps/t_end"][:][ok][:STRIKES]
        period = float(np.mean(s["steps/period"][:][ok]))
    act = scene.walker.actuation if hasattr(scene.walker, "actuation") else None
    policy = "scene" if getattr(act, "virtual_constraints", None) is not None else None
    steps = int(math.ceil((ref[-1] + 2 * period) / 0.01)) + 10 if ref.size else 1000
    env = WalkerEnv(d, max_episode_steps=steps, policy=policy)
    try:
        env.reset(seed=0)
        strikes: list[float] = []
        for _ in range(steps):
            _, _, term, trunc, info = env.step(np.zeros(env.action_space.shape, np.float32))
            strikes += info["heel_strike_times_s"]
            if term or trunc or len(strikes) >= ref.size:
                break
    finally:
        env.close()
    got = np.asarray(strikes[:ref.size])
    if ref.size < STRIKES or got.size < ref.size:
        return math.nan, f"the gym walked {got.size} heel strikes, simulate {ref.size}"
    gap = np.abs(np.diff(got, prepend=0.0) - np.diff(ref, prepend=0.0))
    dev = float(np.max(gap) / period)
    return dev, (f"{got.size} heel strikes; step periods {np.max(gap):.2g} s apart at most"
                 + (" (the controller held per control period)" if policy else ""))


def _optimize(scene, d, runs: Path) -> tuple[float, str]:
    from walkerlab.stages import pipeline

    path = pipeline.run("optimize", scene, runs).path
    with _h5(path) as f:
        if "replay/max_state_error" in f:
            err = float(f["replay/max_state_error"][()])
            return err, f"replay returns {err:.2g} from its start"
        errs = [float(f[f"controllers/{c}/replay/max_state_error"][()])
                for c in f.get("controllers", {}) if
                f"controllers/{c}/replay/max_state_error" in f]
        if errs:
            return max(errs), f"{len(errs)} controllers, replays return {max(errs):.2g}"
        status = {k: v for k, v in f.attrs.items() if "status" in k or "verdict" in k}
    return math.nan, f"no replay error stored ({status})"


_VIEWS = {"rigid": _rigid, "contact": _contact, "mjcf": _engine("mjcf"), "urdf": _urdf,
          "osim": _engine("osim"), "adams": _adams, "gym": _gym, "optimize": _optimize}


def measure(kind: str, feature: str, view: str, runs_root: Path | str) -> Measurement:
    """Measure one cell on its reference case.

    Parameters
    ----------
    kind, feature, view : str
        The cell (:data:`walkerlab.walker.kinds.KINDS`, ``FEATURES``, ``VIEWS``).
    runs_root : path
        A runs folder for the stages' artifacts (the case's scene name under it).

    Returns
    -------
    Measurement
        ``ok`` False with the reason in ``detail`` when the case does not run, falls or
        misses its tolerance; a refusal or an error is reported there, not raised.
    """
    quantity, tol, unit = QUANTITIES[view]
    case, d = reference_scene(kind, feature, view)
    d = copy.deepcopy(d)
    # one name for a feature's views: they share its rigid gait in one runs folder (its
    # artifacts are reused where up to date, as the commands reuse them)
    d["name"] = f"{kind}-{feature}" + ("-optimize" if view == "optimize" else "")
    _strides_for(d, view)
    if view == "gym" and feature == "virtual_constraints":
        tol = GYM_POLICY_TOLERANCE
    try:
        scene = scene_from_dict(d)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            early = FIRST_STEPS.get((kind, feature))  # an unstable gait's first steps
            run = (first_steps(view, early) if early and view in ("contact", "mjcf", "osim")
                   else _VIEWS[view])
            value, detail, *extra = run(scene, d, Path(runs_root))
    except Exception as exc:  # noqa: BLE001 - a cell that fails is evidence, not a crash
        value, detail, extra = (math.nan, f"{type(exc).__name__}: "
                                f"{' '.join(str(exc).split())}"[:300], [])
    extra = extra[0] if extra else {}  # what the view says it measured, where it varies
    ok = bool(math.isfinite(value) and abs(value) <= tol)
    note = KINDS[kind].note(view, feature)
    if note:  # what the cell rests on beyond the number (a kneed walker's OpenSim loop)
        detail = f"{detail}; {note}"
    return Measurement(kind, feature, view, case, extra.get("quantity", quantity),
                       float(value), tol, unit, ok, detail,
                       extra.get("check", CHECKS[view]), extra.get("not_checked", ""))
