"""Run an exported OpenSim walker (``walker.osim``) in OpenSim's forward simulation from its
default state and read its heel strikes and centre of mass.

OpenSim is an optional dependency (the ``osim`` extra), imported only in a child process:
:func:`walk` runs the simulation in ``python -m walkerlab.export.opensim_walk`` and reads its
numbers back.  OpenSim's Moco library links a CasADi of its own, and the ``optimize``
extra's CasADi in the same process leaves it an undefined symbol (or the reverse, in a
session that walks first and optimises after); in its own process OpenSim never meets
another CasADi, so a session (or an environment with both extras) can optimise a gait and
walk its OpenSim export.

OpenSim's ``Manager`` integrates the model in windows of ``window_s`` with Simbody's CPodes
(an implicit BDF integrator, :data:`INTEGRATOR`); after each window the
loop reads each leg's ``HuntCrossleyForce`` (the force on the leg's body).  A heel strike of
leg i is the first window with contact on its foot after the foot has been off the ground for
at least ``min_air_s`` (shorter gaps are bounces of the compliant contact).  A spoked wheel
(:mod:`walkerlab.export.opensim_wheel`: a ``spoke<k>_contact`` per spoke tip, spoke 0
standing at the start) steps as the legs do, each spoke a group of its own: a step is a
spoke other than the standing one touching down after ``min_air_s`` off the ground, which
then stands.  The stepping
rules act between windows (``Force.setAppliesForce`` on the state, then the manager restarts
from it; OpenSim has no contact-switched force):

- the **joint torques** of a powered export (``<coordinate>_motor``): before each window every
  law of ``walker.actuation.torques`` is evaluated at its joint's angle and rate in the
  present roles (leg2 stands in the default state; the roles swap at each heel strike), the
  rigid view's phase variable and the time since the heel strike
  (:class:`walkerlab.models.actuation.TorqueLaws`, the rigid and contact views' own), and
  its generalised forces are held over the window as the motors' override actuation;

- the **knee latch** of a kneed export (``leg<i>_knee_latch``, the knee stop mirrored) is on
  while the leg's foot is less than the release height above the slope line and its knee is
  within the capture flexion of straight, the foot's height its contact point's above the
  ground as the contact model reads it (:func:`contact_height`: above the tread of the
  lane's patch under it, or above the slope line; the contact point the sphere's centre
  less the file's offset, an arc foot's radius,
  :func:`walkerlab.export.opensim_contact.latch_foot_offset`)
  (:func:`walkerlab.export.mujoco_walk.latch_rule`, the MJCF's rule);
- the **push-off** of a powered export (``leg<i>_push_off``, the force ``F = P0 / T`` along
  the leg from foot to hip, ``P0`` the law's ``impulse_n_s``, ``T`` the scene's
  ``contact.push_off_duration_s``): at each heel strike (the end of the window in which
  it is seen) the trailing leg's is switched on for ``P / F`` (``T`` for a constant impulse;
  ``P`` the law's impulse, :func:`walkerlab.models.actuation.push_off_impulse`, at the hip's
  speed), as the MJCF's loop does.  The rigid model pushes off immediately before heel
  strike; a pulse ending at the swing foot's predicted touchdown (the contact model's rule)
  was tried on powered_compass with the paper's friction velocities and made the steps
  shrink (a fall after 9 strikes).

The integrator is implicit because the model is stiff: the stance foot's Hunt-Crossley
contact (its damping, about 8000 N s/m at the resting depth of a 1.6 kg walker, and the
friction's slope ``mu N / v_t``) acts on the foot point of a light shank, which the knee
lets move on its own (a 3D kneed walker's 0.05 kg shank: about 5 g at the foot), a mode of
about 1e6 /s (the stance foot's contact switched off, the same run costs a twentieth).  An
explicit integrator (OpenSim's default Runge-Kutta-Merson) is held to steps
of a few microseconds by that mode's stability whatever its accuracy (1e-5 to 1e-8 cost the
same): about 100 s of CPU per simulated second for configs/kneed_3d_stabilised.yaml, 140 s
for its powered twin (configs/kneed_3d_powered_stabilised.yaml).  CPodes at the same
accuracy steps over it: 5 times less CPU for the walk (each window's restart is most of what
is left), 10 times less for an uninterrupted run; the heel strikes fall in the same windows
(kneed_3d_stabilised's 11 in 6.096 s, mean step period 0.5481 s, +1.60 % of the rigid one,
as with Runge-Kutta-Merson; its powered twin's first two at 0.5405 and 1.0821 s with both).
"""

from __future__ import annotations

import json
import math
import re
import sys
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

import walkerlab
from walkerlab.config.actuation import Actuation
from walkerlab.export.joint_torques import (
    law_generalized_forces,
    link_angle,
    stance_phase,
    torque_generalized_forces,
)
from walkerlab.export.mujoco_walk import MujocoWalk, latch_rule
from walkerlab.extras import MissingExtra, require, require_installed
from walkerlab.models.actuation import TorqueLaws, push_off_impulse

__all__ = ["OpensimWalk", "contact_height", "walk", "walk_here"]

LEGS = ("leg1", "leg2")

#: the Manager's integrator (``opensim.Manager.IntegratorMethod_<name>``): CPodes, implicit
#: (the module docstring says why); ``RungeKuttaMerson`` is OpenSim's default
INTEGRATOR = "CPodes"


@dataclass
class OpensimWalk(MujocoWalk):
    """Heel strikes and the centre of mass of an OpenSim run: a
    :class:`walkerlab.export.mujoco_walk.MujocoWalk` (``times_s`` the end of the window in
    which the contact began; ``fell``: the hip below half its starting height above the
    slope, a wheel's hub above its stance spoke's tip, as the MJCF's roll reads it) with

    Attributes
    ----------
    com_along_m : ndarray (n,)
        The centre of mass's position along the slope at each strike [m].
    mass_kg : float
        The model's total mass [kg].
    """

    com_along_m: np.ndarray
    mass_kg: float

    def speed_m_per_s(self, skip: int = 2) -> float:
        """The centre of mass's mean speed along the slope from strike ``skip`` to the last
        one (whole steps: the speed within a step varies) [m/s]."""
        return float((self.com_along_m[-1] - self.com_along_m[skip])
                     / (self.times_s[-1] - self.times_s[skip]))


def _foot_geometry(osim, geometry):
    """``(geometry, radius [m])``: a foot's contact geometry as its own type, a point or arc
    foot's ``ContactSphere`` and its radius, or a 3D round foot's ``ContactEllipsoid`` and its
    disc's radius, the first semi-axis (:mod:`walkerlab.export.opensim_3d`)."""
    sphere = osim.ContactSphere.safeDownCast(geometry)
    if sphere is not None:
        return sphere, sphere.getRadius()
    disc = osim.ContactEllipsoid.safeDownCast(geometry)
    return disc, disc.getRadii().get(0)


def _header(text: str) -> dict:
    """Slope, latch and push-off numbers from the file's comments."""
    out: dict = {}
    if m := re.search(r"Ground: slope (\S+) rad", text):
        out["slope"] = float(m.group(1))
    # a unit after a number is the scene's (a nondimensional scene's "l", not "m")
    if m := re.search(r"less than (\S+) \S+ above the ground and its knee within (\S+) rad",
                      text):
        out["latch"] = (float(m.group(1)), float(m.group(2)))
    if m := re.search(r"slope line less (\S+) \S+ \(the sphere's radius", text):
        out["latch_offset"] = float(m.group(1))
    if m := re.search(r"a patch of width (\S+) \S+ is a sphere", text):
        out["patch_width"] = float(m.group(1))
    if m := re.search(r"on for T = (\S+) \S+ from each", text):
        out["pulse"] = float(m.group(1))
    if m := re.search(r"walkerlab_actuation: (\{.*\}) -->", text):
        out["actuation"] = json.loads(m.group(1))
    if m := re.search(r"walkerlab_hip_roll: (\{.*\}) -->", text):
        out["hip_roll"] = json.loads(m.group(1))
    return out


def contact_height(centre, r_foot: float, offset: float, patches, half_width: float,
                   t_hat, n_hat) -> float:
    """The height [m] of a foot's contact point above the ground, as the contact model's knee
    latch reads it (minus the penetration, :func:`walkerlab.models.contact.generated._point`):
    the contact point's height above the top of the lane's patch whose centre lies within
    ``half_width`` of it along the slope; above the slope line where no patch is under it or
    where the point is above the lane's highest patch top (the contact model skips the
    patches' lookup there: a foot above every patch touches none).  The contact point lies
    ``offset`` below the foot sphere's centre (the file's latch offset,
    :func:`walkerlab.export.opensim_contact.latch_foot_offset`: an arc's radius, a point foot's
    0), a patch's tread ``r_foot - offset`` above its sphere's top (the ground's offset below
    the treads).

    Parameters
    ----------
    centre : array_like (2,)
        The foot sphere's centre in the ground frame [m].
    r_foot, offset : float
        The sphere's radius and the latch offset [m].
    patches : sequence of (float, float)
        The lane's patches: each top's position along the slope and its height along the
        slope normal [m] (the patch sphere's centre plus its radius); empty: no patches.
    half_width : float
        Half the patch width [m].
    t_hat, n_hat : array_like (2,)
        The slope's tangent (downhill) and normal (up).
    """
    c = np.asarray(centre, float)
    h = float(c @ n_hat) - offset  # the contact point above the slope line
    treads = [(s, top + r_foot - offset) for s, top in patches]
    if h < max([0.0, *(t for _, t in treads)]):
        along = float(c @ t_hat)
        for s, tread in treads:
            if abs(along - s) <= half_width:
                return h - tread
    return h


class _Drive:
    """The torque laws of ``walker.actuation.torques`` on the export's ``<coordinate>_motor``
    actuators (module docstring): each law's joint angle and rate, the phase variable (the
    angle of the line from the hip to the stance foot from the downward vertical, the rigid
    view's), the laws (:class:`walkerlab.models.actuation.TorqueLaws`), and the generalised
    forces they make (:func:`walkerlab.export.joint_torques.torque_generalized_forces`) as the
    actuators' override actuation."""

    def __init__(self, model, spec, coords, bodies, foot_loc, hip=("hip_x", "hip_y")):
        import opensim as osim

        self.laws = TorqueLaws(spec.torques)
        self.gf = [[torque_generalized_forces(t.joint, st, coords) for t in spec.torques]
                   for st in (0, 1)]
        cs = model.getCoordinateSet()
        self.coord = {c: cs.get(c) for c in coords}
        fs = model.getForceSet()
        used = {c for per_stance in self.gf for g in per_stance for c in g}
        # the laws' motors only (a 3D walker's roll motors are the hip-roll law's)
        self.motor = {c: osim.CoordinateActuator.safeDownCast(fs.get(f"{c}_motor"))
                      for c in coords if fs.contains(f"{c}_motor") and c in used}
        self.bodies, self.foot_loc = bodies, foot_loc
        self.hip = (cs.get(hip[0]), cs.get(hip[1]))
        # a walker in 3D (its pelvis on pelvis_x, ...): the rigid 3D model's phase, the
        # stance leg's pitch (the MJCF's loop, walkerlab.export.mujoco_walk.PoweredLoop)
        self.pitch = (None if hip[0] == "hip_x" else
                      [link_angle("stance", st, coords) for st in (0, 1)])

    def phase(self, state, stance: int) -> tuple[float, float]:
        """The phase variable [rad] and its rate [rad/s] (class docstring; a walker in 3D:
        its stance leg's pitch)."""
        if self.pitch is not None:
            g = self.pitch[stance]
            return (sum(k * self.coord[c].getValue(state) for c, k in g.items()),
                    sum(k * self.coord[c].getSpeedValue(state) for c, k in g.items()))
        g = LEGS[stance]
        b, loc = self.bodies[g], self.foot_loc[g]
        return stance_phase([c.getValue(state) for c in self.hip],
                            [c.getSpeedValue(state) for c in self.hip],
                            b.findStationLocationInGround(state, loc).to_numpy()[:2],
                            b.findStationVelocityInGround(state, loc).to_numpy()[:2])

    def control(self, state, stance: int, since_s: float) -> None:
        """Set every motor's override actuation for the coming window [N m] (``since_s``:
        the time since the last heel strike [s], for time-referenced laws)."""
        q = {c: k.getValue(state) for c, k in self.coord.items()}
        v = {c: k.getSpeedValue(state) for c, k in self.coord.items()}
        out = law_generalized_forces(self.laws, self.gf[stance], q, v,
                                     self.phase(state, stance), since_s)
        for c, m in self.motor.items():
            m.setOverrideActuation(state, out.get(c, 0.0))
            m.overrideActuation(state, True)


class _HipRoll:
    """The hip-roll law of a 3D export (comment ``walkerlab_hip_roll``: the scene's
    :class:`walkerlab.config.walker.HipRollLaw`) on its ``leg<i>_roll_motor`` actuators, the
    MJCF loop's law (:class:`walkerlab.export.mujoco_walk.HipRollLoop`) on OpenSim's state:
    each body's (``pelvis``, ``leg1``, ``leg2``) roll about the fall line ``s`` read from its
    pitch axis ``a`` (the body's ``z``): ``phi = atan2(-a . n, a . z)`` (``n`` the slope's
    normal), its rate ``omega . s``; ``tau_st = k_p phi_p + c_p dphi_p`` on the stance
    leg's roll, ``tau_sw = -k_s (phi_w - g_l phi - g_r dphi) - c_s (dphi_w - dphi_p)`` on
    the swing leg's, held over the window."""

    def __init__(self, model, law: dict, phi: float):
        import opensim as osim

        self.osim = osim
        self.k_p = law["pelvis_stiffness_n_m_per_rad"]
        self.c_p = law["pelvis_damping_n_m_s_per_rad"]
        self.k_s = law["swing_stiffness_n_m_per_rad"]
        self.c_s = law["swing_damping_n_m_s_per_rad"]
        self.g_l, self.g_r = law["lean_gain"], law["lean_rate_gain_s"]
        self.s = np.array([math.cos(phi), -math.sin(phi), 0.0])
        self.n = np.array([math.sin(phi), math.cos(phi), 0.0])
        fs, bs = model.getForceSet(), model.getBodySet()
        self.motor = [osim.CoordinateActuator.safeDownCast(fs.get(f"{g}_roll_motor"))
                      for g in LEGS]
        self.bodies = [bs.get(b) for b in ("pelvis", *LEGS)]

    def rolls(self, state) -> tuple[np.ndarray, np.ndarray]:
        """Rolls [rad] and their rates [rad/s] of the pelvis, leg1 and leg2 (3,), (3,)."""
        z = self.osim.Vec3(0.0, 0.0, 1.0)
        a = [b.expressVectorInGround(state, z).to_numpy() for b in self.bodies]
        phi = np.array([math.atan2(-(v @ self.n), v[2]) for v in a])
        dphi = np.array([b.getAngularVelocityInGround(state).to_numpy() @ self.s
                         for b in self.bodies])
        return phi, dphi

    def torques(self, state, stance: int) -> dict:
        """The law's torques on the legs' rolls (0: leg1) [N m] in ``state`` (realised to
        its velocities)."""
        st, sw = stance, 1 - stance
        phi, dphi = self.rolls(state)
        ref = self.g_l * phi[1 + st] + self.g_r * dphi[1 + st]
        return {st: self.k_p * phi[0] + self.c_p * dphi[0],
                sw: -self.k_s * (phi[1 + sw] - ref) - self.c_s * (dphi[1 + sw] - dphi[0])}

    def control(self, state, tau: dict) -> None:
        """Set the roll motors' override actuation ``tau`` (:meth:`torques`) for the coming
        window [N m] (an override drops the state's stage: read it first)."""
        for i, m in enumerate(self.motor):
            m.setOverrideActuation(state, float(tau[i]))
            m.overrideActuation(state, True)

def _contact_groups(forces) -> tuple[list[str], str]:
    """The model's contact groups, each a ``<group>_contact`` force on its sphere
    ``<group>_foot``, and the one standing in the default state: a legged walker's legs
    (leg2 stands), or a spoked wheel's spokes ``spoke<k>`` (spoke 0 stands:
    :mod:`walkerlab.export.opensim_wheel`), whose touchdowns are its steps."""
    if forces.contains("leg1_contact"):
        return list(LEGS), "leg2"
    spokes = []
    while forces.contains(f"spoke{len(spokes)}_contact"):
        spokes.append(f"spoke{len(spokes)}")
    return spokes, "spoke0"


def advance(state, integrated) -> None:
    """Carry a Manager's integrated state over onto the loop's own ``state``: its time and
    continuous variables ``y`` (q, u, z); the discrete ones (the motors' overrides, the
    forces' on/off switches) are the loop's and integration leaves them alone.

    The loop keeps one ``State`` for the whole walk and never copies a Manager's: in a copy
    (``opensim.State(manager.integrate(t))``) the frames' lazily computed kinematics (the
    cache variables behind ``Frame.getTransformInGround``, ``expressVectorInGround``,
    ``findStationLocationInGround``, ``getAngularVelocityInGround``) can read as valid with
    the values of an earlier window (OpenSim 4.6: the copy's stage versions repeat the ones
    they were computed at): the hip-roll law then read the bodies' rolls and roll rates of
    a window, or of several, before (in configs/hip_width_powered.yaml 12 of the first
    40 windows of 5 ms), and the powered walker struck 65 ms early and fell.  ``setY``
    on the loop's realised state invalidates its positions and velocities, so every frame
    is read afresh."""
    state.setTime(integrated.getTime())
    state.setY(integrated.getY())


def walk(path: Path | str, duration_s: float, window_s: float = 5e-4,
         min_air_s: float = 0.05, accuracy: float = 1e-7,
         integrator: str = INTEGRATOR) -> OpensimWalk:
    """Simulate ``walker.osim`` for ``duration_s`` from its default state (module docstring),
    in a child process that alone imports OpenSim (``python -m
    walkerlab.export.opensim_walk``: the module docstring says why).

    Parameters
    ----------
    path : path
        An OpenSim export (:mod:`walkerlab.export.opensim`).
    duration_s : float
        Simulated time [s].
    window_s : float
        Length of a window between the stepping rules [s].
    min_air_s : float
        Shortest time off the ground before a contact counts as a heel strike [s].
    accuracy : float
        The integrator's accuracy.
    integrator : str
        The Manager's integrator, ``opensim.Manager.IntegratorMethod_<integrator>``
        (:data:`INTEGRATOR`, CPodes; ``"RungeKuttaMerson"``: OpenSim's default).

    Returns
    -------
    OpensimWalk

    Raises
    ------
    walkerlab.extras.MissingExtra
        OpenSim is not installed (one line naming the ``osim`` extra), or its import failed
        in the child process (one line with the reason).
    RuntimeError
        The child process failed otherwise (its last line of error output).
    """
    import os
    import subprocess
    import tempfile

    require_installed("opensim", "osim", "walking an OpenSim export")
    env = dict(os.environ)  # this walkerlab, whatever put it on sys.path here
    here = str(Path(walkerlab.__file__).resolve().parents[1])
    env["PYTHONPATH"] = os.pathsep.join(p for p in (here, env.get("PYTHONPATH")) if p)
    with tempfile.TemporaryDirectory(prefix="walkerlab_osim_") as tmp:
        out = Path(tmp) / "walk.json"
        args = {"path": str(Path(path).resolve()), "duration_s": float(duration_s),
                "window_s": float(window_s), "min_air_s": float(min_air_s),
                "accuracy": float(accuracy), "integrator": str(integrator),
                "out": str(out)}
        proc = subprocess.run([sys.executable, "-m", "walkerlab.export.opensim_walk",
                               json.dumps(args)], env=env, cwd=tmp, capture_output=True,
                              text=True, check=False)
        if proc.returncode != 0 or not out.is_file():
            lines = [ln for ln in proc.stderr.splitlines() if ln.strip()]
            last = lines[-1].strip() if lines else f"exit code {proc.returncode}"
            if proc.returncode == _MISSING_EXIT:
                raise MissingExtra(last)
            raise RuntimeError(f"walking the OpenSim export {path} failed in its process: "
                               f"{last}")
        d = json.loads(out.read_text())
    return OpensimWalk(times_s=np.array(d["times_s"], float), legs=list(d["legs"]),
                       positions_m=np.array(d["positions_m"], float), fell=bool(d["fell"]),
                       t_end_s=float(d["t_end_s"]),
                       com_along_m=np.array(d["com_along_m"], float),
                       mass_kg=float(d["mass_kg"]))


#: exit code of the child process when OpenSim cannot be imported (its one line on stderr)
_MISSING_EXIT = 3


def _main(argv: list[str]) -> int:
    """The child process of :func:`walk`: ``argv[0]`` the JSON of its arguments and the
    output file; writes the walk's numbers there as JSON (floats exactly: ``repr``)."""
    a = json.loads(argv[0])
    try:
        w = walk_here(a["path"], a["duration_s"], a["window_s"], a["min_air_s"],
                      a["accuracy"], a["integrator"])
    except MissingExtra as exc:
        print(str(exc), file=sys.stderr)
        return _MISSING_EXIT
    d = {k: (v.tolist() if isinstance(v, np.ndarray) else v) for k, v in asdict(w).items()}
    Path(a["out"]).write_text(json.dumps(d))
    return 0


def walk_here(path: Path | str, duration_s: float, window_s: float = 5e-4,
              min_air_s: float = 0.05, accuracy: float = 1e-7,
              integrator: str = INTEGRATOR) -> OpensimWalk:
    """Simulate ``walker.osim`` for ``duration_s`` from its default state in this process
    (imports OpenSim here: :func:`walk` runs it in a process of its own).

    Parameters
    ----------
    path, duration_s, window_s, min_air_s, accuracy, integrator
        As :func:`walk`, which also gives what it returns (:class:`OpensimWalk`) and raises
        (:class:`walkerlab.extras.MissingExtra` without OpenSim).
    """
    osim = require("opensim", "osim", "walking an OpenSim export")
    osim.Logger.removeFileSink()  # OpenSim logs to ./opensim.log: nothing outside runs/
    osim.Logger.setLevelString("warn")  # not a report per window
    text = Path(path).read_text()
    info = _header(text)
    phi = info.get("slope", 0.0)
    t_hat = np.array([math.cos(phi), -math.sin(phi)])
    n_hat = np.array([math.sin(phi), math.cos(phi)])
    model = osim.Model(str(path))
    state = model.initSystem()
    fs = model.getForceSet()
    groups, stance = _contact_groups(fs)
    contact = {g: fs.get(f"{g}_contact") for g in groups}
    geometries = {g: _foot_geometry(osim, model.getContactGeometrySet().get(f"{g}_foot"))
                  for g in groups}
    feet = {g: geometry for g, (geometry, _r) in geometries.items()}
    radius = {g: r for g, (_geometry, r) in geometries.items()}
    # the body that carries the foot sphere (a leg, a shank; a 3D kneed leg's leg<i>_shank)
    bodies = {g: model.getBodySet().get(feet[g].getFrame().getName()) for g in groups}
    foot_loc = {g: osim.Vec3(feet[g].get_location()) for g in groups}
    for g in LEGS:  # a flat foot: the foot point is the ankle, its sole's frame origin
        if model.getBodySet().contains(f"{g}_sole"):
            bodies[g], foot_loc[g] = model.getBodySet().get(f"{g}_sole"), osim.Vec3(0, 0, 0)
    kneed = fs.contains("leg1_knee_latch")
    latch = {g: fs.get(f"{g}_knee_latch") for g in LEGS} if kneed else {}
    knee = {g: model.getCoordinateSet().get(f"{g}_knee") for g in LEGS} if kneed else {}
    push = ({g: osim.PrescribedForce.safeDownCast(fs.get(f"{g}_push_off")) for g in LEGS}
            if fs.contains("leg1_push_off") else {})
    push_law = None
    spec = None
    if "actuation" in info:

        spec = Actuation.model_validate(info["actuation"])
        push_law = spec.push_off
    coords = [model.getCoordinateSet().get(i).getName()
              for i in range(model.getCoordinateSet().getSize())]
    # the hip: a planar walker's hip_x, hip_y; a 3D walker's pelvis (y up, as the plane's)
    hip = ("hip_x", "hip_y") if "hip_x" in coords else ("pelvis_x", "pelvis_y")
    drive = (_Drive(model, spec, coords, bodies, foot_loc, hip) if spec and spec.torques
             else None)
    roll = _HipRoll(model, info["hip_roll"], phi) if "hip_roll" in info else None
    hip_x = model.getCoordinateSet().get(hip[0])
    hip_y = model.getCoordinateSet().get(hip[1])
    mass = model.getTotalMass(state)

    def along(g, s):  # the foot point's position along the slope [m]
        p = bodies[g].findStationLocationInGround(s, foot_loc[g]).to_numpy()[:2]
        return float(p @ t_hat)

    cg = model.getContactGeometrySet()
    patches = {g: [] for g in groups}  # each lane's patch tops: (along, height) [m]
    for g in groups:
        while cg.contains(f"{g}_patch{len(patches[g])}"):
            sph = osim.ContactSphere.safeDownCast(cg.get(f"{g}_patch{len(patches[g])}"))
            loc = osim.Vec3(sph.get_location()).to_numpy()[:2]
            patches[g].append((float(loc @ t_hat), float(loc @ n_hat) + sph.getRadius()))
    half = info.get("patch_width", 0.0) / 2
    off = info.get("latch_offset", 0.0)  # the contact point below the sphere's centre

    def height(g, s):  # the foot's contact point above the ground under it [m]
        p = bodies[g].findStationLocationInGround(s, foot_loc[g]).to_numpy()[:2]
        return contact_height(p, radius[g], off, patches[g], half, t_hat, n_hat)

    def loaded(g, s):
        v = contact[g].getRecordValues(s)
        return abs(v.get(0)) + abs(v.get(1)) > 0.0

    def com_along(s):
        return float(model.calcMassCenterPosition(s).to_numpy()[:2] @ t_hat)

    def hub_height(s):  # the hip above the slope line; a wheel's hub above its stance tip
        h = hip_x.getValue(s) * n_hat[0] + hip_y.getValue(s) * n_hat[1]  # (stairs: a riser
        if stance.startswith("spoke"):  # a step, the ground under the hub is the tip's)
            h -= bodies[stance].findStationLocationInGround(s, foot_loc[stance]).to_numpy(
            )[:2] @ n_hat
        return float(h)

    h0 = hub_height(state)
    method = getattr(osim.Manager, f"IntegratorMethod_{integrator}")

    def new_manager():
        m = osim.Manager(model)
        m.setIntegratorMethod(method)
        m.setIntegratorAccuracy(accuracy)
        m.initialize(state)
        return m

    state.setTime(0.0)
    model.realizeDynamics(state)
    # both feet start on the ground (the trailing one just left it, or stays on its toe in
    # a flat foot's double support): a heel strike needs min_air_s off it first
    air = {g: 0.0 for g in groups}
    on = {g: loaded(g, state) for g in groups}
    latched = {g: False for g in LEGS}
    times, legs, com, feet_at = [], [], [], []
    fell, t = False, 0.0
    pulse_until, pushing, t_step = -1.0, None, 0.0
    restart = True
    while t < duration_s - 1e-12:
        changed = False
        if kneed:
            want = {g: latch_rule(height(g, state), knee[g].getValue(state), *info["latch"])
                    for g in LEGS}  # both before either switch (a switch drops the stage)
            for g in LEGS:
                if want[g] != latched[g]:
                    latch[g].setAppliesForce(state, want[g])
                    latched[g], changed = want[g], True
        if pushing is not None and t >= pulse_until - 1e-12:
            push[pushing].setAppliesForce(state, False)
            pushing, changed = None, True
        if drive is not None or roll is not None:  # the laws' torques, held over the window
            model.realizeVelocity(state)
            # read before any override is set (an override drops the state's stage)
            tau = None if roll is None else roll.torques(state, LEGS.index(stance))
        if drive is not None:
            drive.control(state, LEGS.index(stance), t - t_step)
        if roll is not None:  # after the drive: the roll motors are the law's
            roll.control(state, tau)
        if changed or restart or drive is not None or roll is not None:
            manager = new_manager()
            restart = False
        step = window_s if pushing is None else pulse_until - t
        t = min(t + step, duration_s)
        advance(state, manager.integrate(t))
        model.realizeDynamics(state)
        now_on = {g: loaded(g, state) for g in groups}  # before a switch drops the stage
        for g in groups:
            now = now_on[g]
            if now and not on[g] and air[g] >= min_air_s and g != stance:
                times.append(t)
                legs.append(g)
                com.append(com_along(state))
                feet_at.append(along(g, state))
                trailing, stance, t_step = stance, g, t
                if push:  # the trailing leg pushes off from the heel strike (the MJCF's loop)
                    v = np.array([hip_x.getSpeedValue(state), hip_y.getSpeedValue(state)])
                    P = float(push_off_impulse(push_law, float(v @ t_hat)))
                    if P > 0:  # the file's force F = impulse_n_s / T: the pulse lasts P / F
                        T = info["pulse"] * P / push_law.impulse_n_s
                        push[trailing].setAppliesForce(state, True)
                        pushing, pulse_until, restart = trailing, t + T, True
            air[g] = 0.0 if now else air[g] + step
            on[g] = now
        model.realizeDynamics(state)  # after a switch
        if hub_height(state) < 0.5 * h0:
            fell = True
            break
    return OpensimWalk(times_s=np.array(times), legs=legs, positions_m=np.array(feet_at),
                       fell=fell, t_end_s=t, com_along_m=np.array(com), mass_kg=mass)


if __name__ == "__main__":
    sys.exit(_main(sys.argv[1:]))
