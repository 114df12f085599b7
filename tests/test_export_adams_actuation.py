"""The Adams dataset of a powered walker: hip torques as an SFORCE whose FUNCTION is built
from VARIABLEs of Adams runtime functions, the push-off as a GFORCE pulse.

The file is read back with walkerlab's reader and its expressions evaluated by a small
evaluator of the functions the writer uses (``AZ``, ``WZ``, ``DX``, ``DY``, ``DM``, ``VX``,
``VY``, ``VM``, ``CONTACT``, ``VARVAL``, ``IF``, ``MIN``, ``MAX``) at sample states, against
walkerlab's own laws at the same states (:class:`walkerlab.models.actuation.TorqueLaws`, the
rigid and contact views' evaluation; the contact view's pulse criterion
:func:`walkerlab.integrate.powered_events.pulse_lead`).  Tolerances: the dataset writes
every number as its shortest repr and the reference tables in truncated-power form (the same
piecewise polynomial, summed in another order), so the torques agree to rounding: 1e-9
relative to the largest torque term (2e6 N mm/rad x 1 rad).
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from walkerlab.cli import app
from walkerlab.config import load_scene, scene_from_dict
from walkerlab.export.adams import adams_start, adm_text
from walkerlab.export.adams_actuation import (
    ACT_VARIABLES,
    HIP_SFORCE,
    HIP_TORQUE_SUM,
    PUSH_GFORCE,
    check_adams_actuation,
    hip_torque_ids,
)
from walkerlab.export.adams_feet import part_ids
from walkerlab.export.adams_reader import read_adm
from walkerlab.export.adams_statements import LINE_WIDTH, marker_id
from walkerlab.integrate.powered_events import pulse_lead
from walkerlab.models.actuation import TorqueLaws, push_off_impulse
from walkerlab.walker.description import walker_data
from walkerlab.walker.multibody import multibody
from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]
MM = 1000.0

#: Hip torques on the paper's walker: a saturated spring-damper with an offset and a
#: constant, a cubic (not-a-knot) and a piecewise-linear phase reference.
TORQUES = [
    {"joint": "hip", "max_torque_n_m": 12.5,
     "law": {"constant_n_m": 0.75, "stiffness_n_m_per_rad": 40.0,
             "damping_n_m_s_per_rad": 2.5, "rest_angle_rad": 0.1}},
    {"joint": "hip",
     "law": {"stiffness_n_m_per_rad": 300.0, "damping_n_m_s_per_rad": 7.0,
             "reference": {"phase_rad": [-0.3, -0.2, -0.1, 0.0, 0.1, 0.25, 0.3],
                           "hip_angle_rad": [0.5, 0.35, 0.3, 0.1, -0.1, -0.35, -0.6],
                           "interpolation": "cubic"}}},
    {"joint": "hip", "max_torque_n_m": 30.0,
     "law": {"stiffness_n_m_per_rad": 150.0, "damping_n_m_s_per_rad": 4.0,
             "reference": {"phase_rad": [-0.25, 0.0, 0.1, 0.2],
                           "hip_angle_rad": [0.4, 0.0, -0.3, -0.35],
                           "interpolation": "linear"}}},
]


def _scene(tmp_path, name, **changes):
    raw = yaml.safe_load((ROOT / "configs" / "powered_compass.yaml").read_text())
    for path, value in changes.items():
        node = raw
        *head, last = path.split(".")
        for k in head:
            node = node[k]
        node[last] = value
    path = tmp_path / f"{name}.yaml"
    path.write_text(yaml.safe_dump(raw))
    return load_scene(path)


@pytest.fixture(scope="module")
def compass_start():
    """The powered compass gait's start (shared: the powered scenes below have its
    walker; the gait only places the parts, the laws do not depend on it)."""
    scene = load_scene(ROOT / "configs" / "powered_compass.yaml")
    data = walker_data(scene.walker, scene.slope.phi_rad)
    mb = multibody(data)
    return scene, mb, data, adams_start(scene, mb, Plant.from_scene(scene))


@pytest.fixture(scope="module")
def powered(tmp_path_factory, compass_start):
    """The three hip torques, a speed-dependent push-off, a 5 ms pulse, a 0.02 rad slope."""
    _, mb0, _, start = compass_start
    tmp = tmp_path_factory.mktemp("adm_powered")
    scene = _scene(tmp, "powered_hip", **{
        "walker.actuation.torques": TORQUES,
        "walker.actuation.push_off": {"impulse_n_s": 3.0, "speed_gain_n_s2_per_m": 2.0,
                                      "reference_speed_m_per_s": 0.6},
        "slope.angle_rad": 0.02, "contact.push_off_duration_s": 0.005})
    data = walker_data(scene.walker, scene.slope.phi_rad)
    mb = multibody(data)
    return scene, mb, adm_text(scene, mb, Plant.from_scene(scene), "powered_hip", "test", start)


class AdamsState:
    """A planar state of the walker as the dataset's markers see it (mm, rad): the hip
    point and its velocity, each link's absolute angle and rate (``psi``, ``w`` by link
    name), each CONTACT's normal force; the markers placed along the links as the writer
    places them (joint, knee, foot)."""

    def __init__(self, mb, hip, vhip, psi, w, forces):
        ids = part_ids(mb)
        self.part = {1: (0.0, 0.0)}
        self.pos, self.vel = {101: np.zeros(2)}, {101: np.zeros(2)}
        frames = {}
        for ln in mb.links:  # parents first (Multibody order)
            if ln.parent == "hip":
                p, v = np.asarray(hip, float), np.asarray(vhip, float)
            else:
                pp, pv = frames[ln.parent]
                e, de = self._axis(psi[ln.parent], w[ln.parent])
                p, v = pp + ln.joint_from_parent_m * MM * e, pv + ln.joint_from_parent_m * MM * de
                self.pos[marker_id(ids[ln.parent], "knee")] = p
                self.vel[marker_id(ids[ln.parent], "knee")] = v
            frames[ln.name] = (p, v)
            pid = ids[ln.name]
            self.part[pid] = (psi[ln.name], w[ln.name])
            self.pos[marker_id(pid, "joint")], self.vel[marker_id(pid, "joint")] = p, v
            if ln.foot_m is not None:
                e, de = self._axis(psi[ln.name], w[ln.name])
                self.pos[marker_id(pid, "foot")] = p + ln.foot_m * MM * e
                self.vel[marker_id(pid, "foot")] = v + ln.foot_m * MM * de
        self.forces = forces

    @staticmethod
    def _axis(psi, w):
        """The link's axis (joint -> foot) and its rate of change."""
        return (np.array([math.sin(psi), -math.cos(psi)]),
                w * np.array([math.cos(psi), math.sin(psi)]))

    def namespace(self, variables):
        def az(i, j):
            a = self.part[i // 100][0] - self.part[j // 100][0]
            return math.remainder(a, 2 * math.pi)

        memo = {}

        def varval(v):
            if v not in memo:
                memo[v] = evaluate(variables[v], ns)
            return memo[v]

        def vrel(i, j=None):
            return self.vel[i] - (0.0 if j is None else self.vel[j])

        ns = {"AZ": az, "ATAN2": math.atan2,
              "WZ": lambda i, j, k: self.part[i // 100][1] - self.part[j // 100][1],
              "DX": lambda i, j: self.pos[i][0] - self.pos[j][0],
              "DY": lambda i, j: self.pos[i][1] - self.pos[j][1],
              "DM": lambda i, j: float(np.hypot(*(self.pos[i] - self.pos[j]))),
              "VX": lambda i, j=None: vrel(i, j)[0], "VY": lambda i, j=None: vrel(i, j)[1],
              "VM": lambda i: float(np.hypot(*self.vel[i])),
              "CONTACT": lambda c, jflag, comp, rm: self.forces.get(c, 0.0),
              "VARVAL": varval, "MIN": min, "MAX": max,
              "_IF": lambda a, neg, zero, pos: neg if a < 0 else (zero if a == 0 else pos)}
        return ns


def evaluate(expr: str, ns) -> float:
    """An Adams function expression of the subset above, evaluated (``IF(e: a, b, c)``
    read as ``a`` for ``e < 0``, ``b`` for ``e = 0``, ``c`` for ``e > 0``)."""
    assert re.fullmatch(r"[A-Z0-9_().,:*/+\-E ]+", expr), expr  # no names beyond these
    py = re.sub(r"\bIF\(", "_IF(", expr).replace(":", ",")
    return float(eval(py, {"__builtins__": {}}, ns))  # noqa: S307 - the subset checked above


def _states(mb, rng, n=40):
    """States with either foot loaded (or neither: the start's tie), phase variables inside
    and outside the tables."""
    out = []
    leg1_contacts = range(1, 9)
    for k in range(n):
        psi = {"leg1": rng.uniform(-0.45, 0.45), "leg2": rng.uniform(-0.45, 0.45)}
        w = {"leg1": rng.uniform(-2, 2), "leg2": rng.uniform(-2, 2)}
        loaded = ("leg1", "leg2", None)[k % 3]
        forces = {}
        if loaded == "leg1":
            forces = {3: 120.0, 11: rng.uniform(0, 100)}
        elif loaded == "leg2":
            forces = {14: 150.0, 2: rng.uniform(0, 100)}
        stance = "leg1" if sum(forces.get(c, 0) for c in leg1_contacts) > \
            sum(v for c, v in forces.items() if c not in leg1_contacts) else "leg2"
        out.append((AdamsState(mb, (10.0, 950.0), (600.0, -30.0), psi, w, forces), stance,
                    psi, w))
    return out


def test_hip_torque_function_equals_walkerlab_law(powered):
    """SFORCE/10's FUNCTION, evaluated at 40 states (each foot loaded, and the tie), equals
    the swing leg's torque of walkerlab's laws (sum of three: saturated PD with offset and
    constant, cubic and linear phase references) on leg1 with the role's sign: +tau while
    leg1 swings, -tau while it stands.  Each actuator's VARIABLE equals its own law."""
    scene, mb, adm = powered
    model = read_adm(adm)
    variables = model.functions()
    sforce = model.get("SFORCE", HIP_SFORCE)
    ids = part_ids(mb)
    assert "ROTATION" in sforce.flags
    assert (sforce.integer("I"), sforce.integer("J")) == (marker_id(ids["leg1"], "joint"),
                                                          marker_id(ids["leg2"], "joint"))
    laws = TorqueLaws(scene.walker.actuation.torques)
    rng = np.random.default_rng(48)
    seen = set()
    for st, stance, psi, w in _states(mb, rng):
        swing = "leg2" if stance == "leg1" else "leg1"
        delta, ddelta = psi[swing] - psi[stance], w[swing] - w[stance]
        each = laws(delta, ddelta, psi[stance], w[stance]) * MM
        ns = st.namespace(variables)
        for k, tau in enumerate(each):
            got = ns["VARVAL"](hip_torque_ids(k)["tau"])
            assert math.isclose(got, tau, rel_tol=1e-9, abs_tol=2e-3), (k, got, tau)
        want = float(np.sum(each)) * (1.0 if swing == "leg1" else -1.0)
        got = evaluate(sforce.args["FUNCTION"][0], ns)
        assert math.isclose(got, want, rel_tol=1e-9, abs_tol=5e-3), (got, want)
        assert ns["VARVAL"](HIP_TORQUE_SUM) == pytest.approx(np.sum(each), abs=5e-3)
        seen.add((stance, abs(psi[stance]) > 0.3))
    assert {("leg1", False), ("leg2", False), ("leg2", True)} <= seen  # outside a table too


def test_hip_torque_numbers_read_back(powered):
    """The law's numbers as statements: gains, constant and limit in N mm (x 1000), the
    rest angle in the error's VARIABLE, the role sign from the feet's contact forces."""
    scene, mb, adm = powered
    assert all(len(ln) <= LINE_WIDTH for ln in adm.splitlines())
    model = read_adm(adm)
    v = model.functions()
    ids0 = hip_torque_ids(0)
    base = ids0["tau"] - 109
    law = scene.walker.actuation.torques[0].law
    assert float(v[base + 102]) == law.constant_n_m * MM == 750.0
    assert v[base + 103] == f"{law.stiffness_n_m_per_rad * MM!r}*VARVAL({ids0['error']})"
    assert v[base + 104].startswith(f"{law.damping_n_m_s_per_rad * MM!r}*")
    assert float(v[base + 106]) == 12.5 * MM
    assert v[ids0["error"]] == f"VARVAL({ACT_VARIABLES['delta']})+(-0.1)"
    assert v[ACT_VARIABLES["sign"]] == "IF(VARVAL(301)-VARVAL(302):1,1,-1)"
    # each foot's force sums its own lane's CONTACTs: the CONTACT's IGEOM is that foot
    ids = part_ids(mb)
    for g, vid in (("leg1", 301), ("leg2", 302)):
        foot = marker_id(ids[g], "foot")
        cids = set()
        todo = [vid]
        while todo:
            expr = v[todo.pop()]
            cids |= {int(c) for c in re.findall(r"CONTACT\((\d+),0,1,0\)", expr)}
            todo += [int(x) for x in re.findall(r"VARVAL\((\d+)\)", expr)]
        assert cids and all(model.get("CONTACT", c).integer("IGEOM") == foot for c in cids)
        assert cids == {c for c, s in model.by_kind["CONTACT"].items()
                        if s.integer("IGEOM") == foot}


def _foot_state(mb, phi, stance, swing_height_mm, swing_rate_mm_s, ahead_mm):
    """The stance foot at rest at the origin, the swing foot ``ahead_mm`` down the slope and
    ``swing_height_mm`` above the ground line, approaching it at ``swing_rate_mm_s`` (the
    push-off reads the feet and the hip only: the legs' angles are left generic)."""
    t, n = np.array([math.cos(phi), -math.sin(phi)]), np.array([math.sin(phi), math.cos(phi)])
    hip, vhip = 0.5 * ahead_mm * t + 900.0 * n, np.array([700.0, -20.0])
    st = AdamsState(mb, hip, vhip, {"leg1": 0.1, "leg2": -0.1}, {"leg1": 0.0, "leg2": 0.0},
                    {})
    ids = part_ids(mb)
    swing = "leg2" if stance == "leg1" else "leg1"
    st.pos[marker_id(ids[stance], "foot")] = np.zeros(2)
    st.vel[marker_id(ids[stance], "foot")] = np.zeros(2)
    st.pos[marker_id(ids[swing], "foot")] = ahead_mm * t + swing_height_mm * n
    st.vel[marker_id(ids[swing], "foot")] = -swing_rate_mm_s * n + 900.0 * t
    return st, hip, vhip


def test_push_off_pulse_as_contact_view(powered):
    """GFORCE/1, 2: while a leg stands and the swing foot's touchdown (ahead on the slope)
    is predicted within T by the contact view's criterion (``pulse_lead`` > 0, the swing
    foot above ground), a force P / T at the stance foot towards the hip, P the speed law
    at the hip's speed; zero otherwise (the other foot's GFORCE always)."""
    scene, mb, adm = powered
    model = read_adm(adm)
    v = model.functions()
    T = scene.contact.push_off_pulse_s()
    phi = scene.slope.phi_rad
    ids = part_ids(mb)
    on_count = 0
    for stance in ("leg1", "leg2"):
        for height, rate, ahead in ((0.5, 200.0, 350.0), (1.5, 200.0, 350.0),
                                    (0.5, 50.0, 350.0), (0.5, 200.0, 20.0),
                                    (-0.1, 200.0, 350.0), (0.9, 200.0, 350.0)):
            st, hip, vhip = _foot_state(mb, phi, stance, height, rate, ahead)
            st.forces = {3: 200.0} if stance == "leg1" else {12: 200.0}
            ns = st.namespace(v)
            lead = pulse_lead(-height / MM, rate / MM, T)  # the contact view's, SI
            on = lead > 0 and height > 0 and ahead / MM >= 0.05
            on_count += on
            P = float(push_off_impulse(scene.walker.actuation.push_off,
                                       float(np.hypot(*vhip)) / MM))
            for g in ("leg1", "leg2"):
                gf = model.gforce(PUSH_GFORCE[g])
                foot = marker_id(ids[g], "foot")
                assert int(gf["I"]) == foot and int(gf["RM"]) == 101
                F = np.array([evaluate(gf["FX"], ns), evaluate(gf["FY"], ns)])
                assert all(evaluate(gf[k], ns) == 0.0 for k in ("FZ", "TX", "TY", "TZ"))
                if g == stance and on:
                    e = (hip - st.pos[foot]) / np.hypot(*(hip - st.pos[foot]))
                    assert np.allclose(F, P / T * e, rtol=1e-12), (F, P / T * e)
                else:
                    assert np.all(F == 0.0), (g, stance, height, rate, ahead, F)
    assert on_count == 4  # 0.5 and 0.9 mm above at 200 mm/s (T rate = 1 mm), 350 mm ahead


def test_powered_compass_carries_its_push_off(compass_start):
    """configs/powered_compass.yaml: the 3 N s push-off as a 30 kN pulse for 0.1 ms
    (contact.push_off_duration_s), no hip torque SFORCE (it has none), no "NOT exported"
    line; the passive statements before it as they were."""
    scene, mb, data, start = compass_start
    adm = adm_text(scene, mb, Plant.from_scene(scene), "powered_compass", "test", start)
    assert "NOT exported" not in adm
    model = read_adm(adm)
    v = model.functions()
    assert float(v[ACT_VARIABLES["impulse"]]) == 3.0
    assert float(v[ACT_VARIABLES["pulse_s"]]) == 1e-4
    assert set(model.by_kind["GFORCE"]) == {1, 2}
    assert HIP_SFORCE not in model.by_kind.get("SFORCE", {})
    assert "FLOATING" in model.get("MARKER", 104).flags


@pytest.mark.parametrize("change,word", [
    ({"walker.actuation.torques": [{"joint": "hip", "law": {
        "stiffness_n_m_per_rad": 1.0, "time_reference": {
            "time_s": [0.0, 0.5], "hip_angle_rad": [0.1, -0.1]}}}]}, "time_reference"),
    ({"contact.push_off_duration_s": 0.0}, "push_off_duration_s"),
])
def test_refused_actuation_in_one_line(tmp_path, change, word):
    """What the dataset cannot carry is refused before any file or gait search: one line
    naming the field."""
    from walkerlab.stages import export as export_stage

    scene = _scene(tmp_path, "refused", **change)
    with pytest.raises(ValueError, match=word) as err:
        check_adams_actuation(scene)
    assert "\n" not in str(err.value)
    with pytest.raises(ValueError, match=word):
        export_stage.run(scene, tmp_path / "runs", "adm")
    assert not list((tmp_path / "runs").rglob("walker.a*"))


def test_five_link_joint_torques_equal_walkerlab_laws():
    """configs/rabbit.yaml (five links: free knees, a torso; four PD laws on phase tables
    of the virtual stance leg's angle, saturated at 150 N m): SFORCE/11-14 on the physical
    joints (each leg's hip against the torso, each knee) evaluated at 30 states equal
    walkerlab's laws (:meth:`TorqueLaws.each` on the joints of
    :data:`walkerlab.config.actuation.FIVE_LINK_JOINTS` in the role the contact forces
    give), the phase variable ``atan2(dx, -dy)`` of the hip -> stance foot line.  Was
    refused ("free knees ... need a user subroutine")."""
    from walkerlab.config.actuation import FIVE_LINK_JOINTS
    from walkerlab.export.adams_actuation import JOINT_SFORCE
    from walkerlab.export.adams_statements import AdamsStart

    scene = load_scene(ROOT / "configs" / "rabbit.yaml")
    data = walker_data(scene.walker, scene.slope.phi_rad)
    mb = multibody(data)
    names = [ln.name for ln in mb.links]
    # a stand-in start (the laws do not read it): the gait search is not this test's
    start = AdamsStart((0.1, 0.75), (0.7, 0.0), dict.fromkeys(names, 0.1),
                       dict.fromkeys(names, 0.0), None, 0.1, 0.37, (1.0, 1.0))
    adm = adm_text(scene, mb, Plant.from_scene(scene), "rabbit", "test", start)
    assert all(len(ln) <= LINE_WIDTH for ln in adm.splitlines())
    model = read_adm(adm)
    v = model.functions()
    ids = part_ids(mb)
    laws = TorqueLaws(scene.walker.actuation.torques)
    rng = np.random.default_rng(5)
    roles_seen = set()
    for n in range(30):
        psi = {"leg1_thigh": rng.uniform(-0.6, 0.6), "leg2_thigh": rng.uniform(-0.6, 0.6),
               "torso": rng.uniform(-0.3, 0.3)}
        psi["leg1_shank"] = psi["leg1_thigh"] - rng.uniform(0, 0.8)
        psi["leg2_shank"] = psi["leg2_thigh"] - rng.uniform(0, 0.8)
        w = {k: rng.uniform(-3, 3) for k in psi}
        stance = "leg1" if n % 2 else "leg2"
        forces = {1: 300.0} if stance == "leg1" else {2: 300.0}
        st = AdamsState(mb, (0.0, 800.0), (700.0, 10.0), psi, w, forces)
        ns = st.namespace(v)
        role = {"stance": stance, "swing": "leg2" if stance == "leg1" else "leg1"}
        deltas, rates = [], []
        for t in scene.walker.actuation.torques:
            r, kind = t.joint.split("_")
            first, second = (f"{role[r]}_{x.split('_')[1]}" if x != "torso" else x
                             for x in FIVE_LINK_JOINTS[t.joint])
            deltas.append(psi[second] - psi[first])
            rates.append(w[second] - w[first])
        foot = st.pos[marker_id(ids[f"{stance}_shank"], "foot")]
        dfoot = st.vel[marker_id(ids[f"{stance}_shank"], "foot")] - np.array([700.0, 10.0])
        dx, dy = foot - np.array([0.0, 800.0])
        s = math.atan2(dx, -dy)
        ds = (dx * dfoot[1] - dfoot[0] * dy) / (dx * dx + dy * dy)
        assert ns["VARVAL"](ACT_VARIABLES["phase"]) == pytest.approx(s, abs=1e-14)
        taus = laws.each(deltas, rates, s, ds) * MM
        joints = [t.joint for t in scene.walker.actuation.torques]
        for (kind, g), sid in JOINT_SFORCE.items():
            sf = model.get("SFORCE", sid)
            r = "stance" if g == stance else "swing"
            want = float(sum(tau for tau, j in zip(taus, joints) if j == f"{r}_{kind}"))
            got = evaluate(sf.args["FUNCTION"][0], ns)
            assert math.isclose(got, want, rel_tol=1e-9, abs_tol=5e-3), (kind, g, got, want)
            first = "torso" if kind == "hip" else f"{g}_thigh"
            second = f"{g}_thigh" if kind == "hip" else f"{g}_shank"
            assert sf.integer("I") == marker_id(ids[second], "joint")
            assert sf.integer("J") == marker_id(ids[first], "joint" if kind == "hip"
                                                else "knee")
            roles_seen.add((r, abs(want) == 150.0 * MM))
    assert {("stance", False), ("swing", False)} <= roles_seen


# -------------------- a powered walker's Adams dataset carries its actuation
POWERED = ROOT / "configs" / "powered_compass.yaml"


def _cli(*args):
    r = CliRunner().invoke(app, [str(a) for a in args])
    return r.exit_code, r.stderr.strip(), r.stdout


# --------------------------- 6: a powered walker's Adams dataset carries its actuation
def test_adm_export_of_a_powered_walker_on_level_ground_carries_its_push_off(tmp_path):
    """Issue 48: the push-off is written (GFORCE pulses), so no warning any more."""
    code, err, out = _cli("export", POWERED, "--format", "adm", "--runs-dir", tmp_path)
    assert code == 0 and "walker.adm" in out and err == ""
    adm = (Path(tmp_path) / "powered_compass" / "walker.adm").read_text()
    assert "GFORCE/1," in adm and "GFORCE/2," in adm and "PASSIVE" not in adm


def test_adm_warning_is_empty_and_what_is_not_written_is_refused():
    """Push-off and hip torques are written (no warning line); a time reference is not
    (refused in one line naming the field)."""
    from walkerlab.export.adams import actuation_warning
    from walkerlab.export.adams_actuation import check_adams_actuation

    d = yaml.safe_load(POWERED.read_text())
    d["slope"] = {"angle_deg": 1.0}
    d["walker"]["actuation"]["torques"] = [{"joint": "hip", "law": {"constant_n_m": 0.1}}]
    assert actuation_warning(scene_from_dict(d)) == ""
    check_adams_actuation(scene_from_dict(d))
    d["walker"]["actuation"]["torques"][0]["law"]["time_reference"] = {
        "time_s": [0.0, 0.4], "hip_angle_rad": [0.1, -0.1]}
    with pytest.raises(ValueError, match="torques.0.law.time_reference"):
        check_adams_actuation(scene_from_dict(d))
    assert actuation_warning(load_scene(ROOT / "configs" / "paper.yaml")) == ""


@pytest.mark.parametrize("joint, share", [("stance_hip", -0.5), ("swing_hip", 0.5)])
def test_a_torso_torque_is_its_hip_torque_on_the_bisecting_hip(joint, share):
    """configs/torso_bhm.yaml (an upper body on the bisecting hip) driven at ``joint``: at
    states of the legs (leg2 standing: the feet's tie) the law's angle in the file is leg
    minus upper body, ``-+ delta / 2`` with the upper body's angle the legs' mean, and the
    hip torque SFORCE/10 carries is ``-+ tau / 2`` of the law at it [N mm] (the same virtual
    work: the rigid flows' equality is tests/test_torso_3d.py's)."""
    from walkerlab.export.adams_actuation import TORSO_HIP_VARIABLES

    law = {"constant_n_m": 0.3, "stiffness_n_m_per_rad": 5.0, "damping_n_m_s_per_rad": 0.7,
           "rest_angle_rad": 0.05}
    passive = load_scene(ROOT / "configs" / "torso_bhm.yaml")
    raw = yaml.safe_load((ROOT / "configs" / "torso_bhm.yaml").read_text())
    raw["walker"]["actuation"] = {"torques": [{"joint": joint, "law": law}]}
    scene = scene_from_dict(raw)
    plant = Plant.from_scene(scene)
    mb = multibody(plant.data)
    start = adams_start(passive, mb, Plant.from_scene(passive))  # places the same parts
    model = read_adm(adm_text(scene, mb, plant, "torso", "test", start))
    variables = model.functions()
    a_id, r_id = TORSO_HIP_VARIABLES[joint]
    rng = np.random.default_rng(5)
    for _ in range(10):
        psi = {"leg1": rng.uniform(-0.4, 0.4), "leg2": rng.uniform(-0.4, 0.4)}
        w = {"leg1": rng.uniform(-2, 2), "leg2": rng.uniform(-2, 2)}
        psi["torso"], w["torso"] = (psi["leg1"] + psi["leg2"]) / 2, (w["leg1"] + w["leg2"]) / 2
        ns = AdamsState(mb, (10.0, 950.0), (600.0, -30.0), psi, w, {}).namespace(variables)
        leg = "leg2" if joint == "stance_hip" else "leg1"   # leg1 swings at the tie
        alpha, dalpha = psi[leg] - psi["torso"], w[leg] - w["torso"]
        assert ns["VARVAL"](a_id) == pytest.approx(alpha, rel=1e-12, abs=1e-15)
        assert ns["VARVAL"](r_id) == pytest.approx(dalpha, rel=1e-12, abs=1e-15)
        tau = (law["constant_n_m"] - law["stiffness_n_m_per_rad"] * (alpha - law["rest_angle_rad"])
               - law["damping_n_m_s_per_rad"] * dalpha)
        assert ns["VARVAL"](HIP_TORQUE_SUM) / MM == pytest.approx(share * tau, rel=1e-9)
        sforce = model.get("SFORCE", HIP_SFORCE).args["FUNCTION"][0]
        assert evaluate(sforce, ns) / MM == pytest.approx(share * tau, rel=1e-9)  # sign +1
