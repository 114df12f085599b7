"""``fixedpoint.h5``: the period-1 gait of the rigid walker (writer and loader side by side).

Layout: root attributes ``model``, ``variant``, ``state_names``, ``gait`` (label of the
selected gait), ``gait_policy``, ``gait_source``, ``gaits``, ``gait_notes``,
``gait_search``; dimension scales ``state``, ``state_in``, ``multiplier``; the selected
gait's result at the root and every gait found under ``gaits/<label>/``, every equation
variant under ``variants/<variant>/`` (or its ``error`` attribute), each with:
``fixed_point/<state>`` [rad, rad/s] just after heel strike, ``initial_guess/<state>``,
``step_period`` [s] (legs that differ: the mean step, with ``stride_period`` [s] and
``steps/{period,length,swing_leg}`` on dimension ``step``), ``residual``,
``floquet/{variational,finite_difference}/{real,imag,jacobian}``,
``floquet/max_difference``, ``floquet/stable``, ``stats/`` (RHS evaluations, map
evaluations, wall time [s]); ``ground_contact/`` (the selected gait: whether the ground only
pushes, :data:`GROUND_FIELDS`; ``ground_contact/friction/``: the friction it needs at
every foot on the ground against the ground's ``mu``, :data:`FRICTION_FIELDS`; for a walker
in 3D ``ground_contact/twist/``: the moment about the normal the stance foot carries,
:data:`TWIST_FIELDS`); on stairs
``footholds/`` (attributes of :class:`walkerlab.analysis.gait.treads.TreadLanding`: step
advance [m], tread drift per step [m], steps until a foot misses a tread, clearances [m]);
under virtual constraints
``zero_dynamics/`` (:data:`ZERO_DYNAMICS_FIELDS`: the restricted Poincare map's delta^2,
V(theta-), V_max, zeta*, the existence margin, the phase rates at impact and the step
period by quadrature, with units; ``virtual_constraints/``: the Bezier coefficients in
force and the invariance residuals).
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from walkerlab.io.artifacts import artifact_loader, put
from walkerlab.io.friction import FrictionVerdict
from walkerlab.io.netcdf import coordinate
from walkerlab.numerics import without_neutral
from walkerlab.units import Units, for_artifact

STAGE = "fixedpoint"


@dataclass
class FixedPointRun:
    """What the fixedpoint stage computed (the writer's input).

    Attributes
    ----------
    walker : HybridWalker
    search : walkerlab.analysis.gait.search.GaitSearch
        Every period-1 gait found and the one selected.
    variants : dict[str, (HybridWalker, FixedPointResult) or Exception]
        The scene's own equation variant first, then the others solved for comparison.
    own_variant : str
    other_guess : ndarray (2n,)
        Starting point of the other variants' root finder.
    ground : walkerlab.analysis.gait.checks.GroundContact or None
        Whether the selected gait's ground contact is unilateral (None: not computed).
    footholds : walkerlab.analysis.gait.treads.TreadLanding or None
        On stairs: the step advance, tread drift, steps until a foot misses a tread and the
        swing foot's clearances (None: a slope).
    """

    walker: object
    search: object
    variants: dict
    own_variant: str
    other_guess: np.ndarray
    ground: object | None = None
    footholds: object | None = None
    hzd: object | None = None


#: ``zero_dynamics/`` datasets: attribute of :class:`walkerlab.analysis.gait.zero_dynamics.
#: ZeroDynamics` -> (name, unit (``{p}``: the phase variable's), meaning)
ZERO_DYNAMICS_FIELDS = {
    "delta2": ("delta2", "-", "restricted Poincare map's multiplier delta^2 (the heel "
               "strike's ratio of sigma^2 on the zero-dynamics surface)"),
    "v_minus": ("v_minus", "kg^2 m^4/s^2", "V(theta-): zeta- = zeta+ - V(theta-), zeta = "
                "sigma^2/2, sigma = b^T M dq (angular momentum about the stance foot)"),
    "v_max": ("v_max", "kg^2 m^4/s^2", "largest V over the step"),
    "zeta_star": ("zeta_star", "kg^2 m^4/s^2", "fixed point of rho(zeta) = delta^2 zeta - "
                  "V(theta-) (pre-impact)"),
    "existence_margin": ("existence_margin", "kg^2 m^4/s^2", "delta^2/(1-delta^2) V(theta-) "
                         "+ V_max (< 0: the fixed point exists)"),
    "theta_plus": ("theta_plus", "{p}", "phase variable at the step's start"),
    "theta_minus": ("theta_minus", "{p}", "phase variable at the step's end"),
    "phase_rate_minus": ("phase_rate_minus", "{p}/s", "phase rate just before heel strike "
                         "at the fixed point"),
    "phase_rate_plus": ("phase_rate_plus", "{p}/s", "phase rate just after heel strike"),
    "step_period_s": ("step_period", "s", "step period by quadrature along the surface"),
    "max_torque_n_m": ("max_torque", "N m", "largest |u| along the periodic orbit"),
    "kinetic_invariance": ("kinetic_invariance", "-", "max |q'^T (dM/db) q'| / max |I| "
                           "(0: the quadrature's premise holds)"),
    "min_clearance_m": ("min_swing_clearance", "m", "lowest swing-foot height inside the "
                        "step on the surface (< 0: the foot strikes before theta-)"),
    "timing_delta2_s": ("timing/delta2", "s", "wall time of delta^2"),
    "timing_total_s": ("timing/total", "s", "wall time of the zero dynamics"),
}


#: ``zero_dynamics/full_order/``: the full-order fixed point's counterparts
#: (:func:`walkerlab.analysis.gait.zero_dynamics.compare_full_order`)
FULL_ORDER_FIELDS = {
    "phase_rate_minus": ("{p}/s", "full order: phase rate just before heel strike"),
    "phase_rate_plus": ("{p}/s", "full order: phase rate just after heel strike"),
    "step_period_s": ("s", "full order: step period"),
    "delta2_multiplier": ("-", "full order: the Floquet multiplier nearest delta^2 "
                          "(variational; real, imaginary part)"),
    "other_multiplier": ("-", "full order: largest |multiplier| of the others (the "
                         "feedback's)"),
    "output_plus": ("rad", "full order: max |y| just after heel strike"),
    "output_rate_plus": ("rad/s", "full order: max |y'| just after heel strike"),
}


def _write_hzd(g, z) -> None:
    """``zero_dynamics/`` (the restricted map's numbers) and ``virtual_constraints/``
    (the coefficients in force and the invariance residuals)."""
    p = z.phase_unit
    for attr, (name, unit, what) in ZERO_DYNAMICS_FIELDS.items():
        put(g, name, float(getattr(z, attr)), unit.format(p=p), what)
    g.attrs["exists"] = int(z.exists)
    g.attrs["stable"] = int(z.stable)
    g.attrs["saturates"] = int(z.saturates)
    put(g, "x_plus", np.asarray(z.x_plus, float), "rad or rad/s", "post-impact state of the "
        "zero dynamics' periodic orbit (state_names order)")
    fo = getattr(z, "full_order", {}) or {}
    for k, (unit, what) in FULL_ORDER_FIELDS.items():
        if k in fo:
            v = fo[k]
            put(g, f"full_order/{k}", float(np.real(v)) if k != "delta2_multiplier"
                else np.array([np.real(v), np.imag(v)]), unit.format(p=p), what)
    d = z.design
    vc = g.create_group("virtual_constraints")
    vc.attrs["outputs"] = list(z.output_names)
    vc.attrs["joints"] = list(z.joints)
    put(vc, "bezier", np.asarray(d.alpha, float), "rad", "Bezier coefficients in force "
        "(rows: outputs, columns c_0..c_M)")
    put(vc, "bezier_given", np.asarray(d.given, float), "rad", "the scene's coefficients")
    put(vc, "invariance_residual_position", d.residual_position, "rad",
        "max |h0(q+) - c_0|")
    put(vc, "invariance_residual_rate", d.residual_rate, "rad/" + p,
        "max |y'+| / |theta'+| after the heel strike")


def _write_result(g, walker, res, guess) -> None:
    names = walker.state_names()
    units = walker.state_units()
    g.attrs["variant"] = walker.variant
    g.attrs["roles"] = list(walker.roles)
    g.attrs["legs_by_role"] = json.dumps(walker.role_to_leg("leg2"))
    g.attrs["steps_per_map"] = int(walker.steps_per_map)  # the multipliers' map: step, stride
    for name, val, u in zip(names, res.x, units):
        put(g, f"fixed_point/{name}", float(val), u, f"{name} just after heel strike")
    for name, val, u in zip(names, guess, units):
        put(g, f"initial_guess/{name}", float(val), u, "root-finder starting point")
    steps = len(getattr(res, "step_periods_s", ()))
    if steps > 1:  # legs or footholds that differ: the map is several steps, each on its own
        put(g, "step_period", res.period_s / steps, "s", "mean step period of the period-1 "
            f"gait (the Poincare map is a stride of {steps} steps)")
        put(g, "stride_period", res.period_s, "s", "stride period (period of the map)")
        coordinate(g, "step", np.arange(steps), "-",
                   f"step of the stride ({walker.legs[0]} swings first)")
        put(g, "steps/period", np.array(res.step_periods_s), "s", "period of each step",
            dims=("step",))
        put(g, "steps/length", np.array(res.step_lengths_m), "m", "length of each step "
            "(stance foot to swing foot at heel strike)", dims=("step",))
        # the legs take turns (walkerlab.analysis.gait.poincare: step k has legs[k % 2]
        # swinging), also over an odd number of steps (footholds of period 3, ...)
        swing = np.array([walker.legs[k % 2].encode() for k in range(steps)])
        put(g, "steps/swing_leg", swing, "-", "swing leg of each step", dims=("step",))
    else:
        put(g, "step_period", res.period_s, "s", "step period of the period-1 gait")
    put(g, "residual", res.residual, "rad or rad/s", "max |P(x*) - x*| over the state")
    for kind, ev, J in (("variational", res.multipliers_variational, res.jacobian_variational),
                        ("finite_difference", res.multipliers_fd, res.jacobian_fd)):
        put(g, f"floquet/{kind}/real", ev.real, "-", f"Floquet multipliers ({kind}), real part",
            dims=("multiplier",))
        put(g, f"floquet/{kind}/imag", ev.imag, "-", f"Floquet multipliers ({kind}), imag part",
            dims=("multiplier",))
        put(g, f"floquet/{kind}/jacobian", J, "-", "DP, rows/cols in state_names order",
            dims=("state", "state_in"), state_names=names)
    put(g, "floquet/max_difference", res.multiplier_difference, "-",
        "max |multiplier(variational) - multiplier(finite difference)|")
    put(g, "floquet/stable", res.stable, "-", "all |multipliers| < 1")
    if res.neutral:  # a family of gaits (a 3D wheel's heading): its multipliers set aside
        g["floquet"].attrs["neutral"] = list(res.neutral)
    put(g, "stats/nfev", res.nfev, "-", "right-hand-side evaluations")
    put(g, "stats/map_evaluations", res.iterations, "-", "Poincare-map calls by the root finder")
    put(g, "stats/wall_time", res.wall_time_s, "s", "fixed-point search + Jacobians")


def write_fixedpoint(f, run: FixedPointRun) -> None:
    """Fill an open (in-memory) artifact with ``run`` (layout in the module docstring)."""
    walker, search = run.walker, run.search
    f.attrs["model"] = walker.name
    f.attrs["variant"] = walker.variant
    f.attrs["section_words"] = walker.section_words  # what the state x is, in words
    f.attrs["state_names"] = walker.state_names()
    names = walker.state_names()
    coordinate(f, "state", names, "-", "state component (role-ordered)")
    coordinate(f, "state_in", names, "-", "state component perturbed (Jacobian column)")
    coordinate(f, "multiplier", np.arange(len(names)), "-",
               "Floquet multiplier number (sorted by modulus)")
    guess = search.gait.start
    _write_result(f, walker, search.result, guess)
    f.attrs["gait"] = search.gait.label
    f.attrs["gait_policy"] = search.policy
    f.attrs["gait_source"] = search.gait.source
    f.attrs["gaits"] = [g.label for g in search.gaits]
    f.attrs["gait_notes"] = json.dumps(search.notes)
    f.attrs["gait_search"] = json.dumps(search.tried)
    for g in search.gaits:
        grp = f.create_group(f"gaits/{g.label}")
        _write_result(grp, walker, g.result, g.start)
        grp.attrs["source"] = g.source
        if getattr(g, "ground", None) is not None:  # every gait found: its ground verdict
            _write_ground(grp.create_group("ground_contact"), g.ground)
    if run.ground is not None:
        _write_ground(f.create_group("ground_contact"), run.ground)
    if run.hzd is not None:  # virtual constraints only: other artifacts unchanged
        _write_hzd(f.create_group("zero_dynamics"), run.hzd)
    if run.footholds is not None:  # stairs only: a slope's artifact is unchanged
        fh = f.create_group("footholds")
        for k, v in run.footholds.as_dict().items():
            fh.attrs[k] = v
    for v, r in run.variants.items():
        if isinstance(r, Exception):
            f.create_group(f"variants/{v}").attrs["error"] = str(r)
        else:
            _write_result(f.create_group(f"variants/{v}"), r[0], r[1],
                          guess if v == run.own_variant else run.other_guess)


#: ``ground_contact/`` datasets: attribute of the check -> (name, unit, meaning)
GROUND_FIELDS = {
    "min_normal_force_n": ("min_normal_force", "N", "smallest normal force on the stance "
                           "foot over the map's continuous phases (< 0: the foot would lift)"),
    "min_normal_time_s": ("min_normal_time", "s", "when it occurs, from the map's start"),
    "max_friction_ratio": ("max_friction_ratio", "-", "largest |tangential| / normal force "
                           "(the friction coefficient the gait needs)"),
    "heel_strike_normal_impulse_n_s": ("heel_strike_normal_impulse", "N s", "smallest normal "
                                       "impulse of a heel strike (< 0: a pull)"),
    "push_off_normal_impulse_n_s": ("push_off_normal_impulse", "N s", "smallest normal "
                                    "impulse of a push-off (< 0: a pull; 0: none)"),
    "trailing_foot_normal_velocity_m_per_s": ("trailing_foot_normal_velocity", "m/s",
                                              "smallest normal velocity of the trailing foot "
                                              "after a transition (< 0: into the ground)"),
}


#: ``ground_contact/twist/`` datasets (a walker in 3D only): attribute of the check -> (name,
#: unit, meaning)
TWIST_FIELDS = {
    "max_twist_n_m": ("max_twist", "N m", "largest moment about the slope's normal on the "
                      "stance foot (the rigid stance joint lets it roll and pitch, never "
                      "turn: a point foot cannot hold it)"),
    "max_twist_time_s": ("max_twist_time", "s", "when it occurs, from the map's start"),
    "twist_patch_radius_m": ("patch_radius", "m", "radius of the smallest round, evenly "
                             "pressed foot patch whose friction holds the twist (3 |M_n| / "
                             "(2 mu F_n), largest over the phase; NaN: no mu)"),
}


#: ``ground_contact/friction/`` datasets: attribute of the verdict -> (name, unit, meaning)
FRICTION_FIELDS = {
    "max_ratio": ("max_ratio", "-", "largest |tangential| / normal force over every foot on "
                  "the ground, single and double support (inf: a foot's normal force falls "
                  "to 0 while it carries a tangential force): the friction coefficient the "
                  "gait needs"),
    "mu": ("friction_coefficient", "-", "the ground's static friction coefficient "
           "(contact.mu_static, or its default)"),
    "single_support_max_ratio": ("single_support_max_ratio", "-", "largest ratio at the "
                                 "stance foot in single support"),
    "double_support_max_ratio": ("double_support_max_ratio", "-", "largest ratio at either "
                                 "foot in double support (NaN: none)"),
    "time_s": ("max_ratio_time", "s", "when the largest ratio occurs, from the map's start"),
    "exit_time_s": ("cone_exit_time", "s", "first time a foot's force leaves the friction "
                    "cone (NaN: never)"),
    "unloaded_tangential_n": ("unloaded_tangential_force", "N", "tangential force of a "
                              "foot whose normal force falls to 0 (NaN: none)"),
}


def _write_ground(g, ground) -> None:
    """``ground_contact/``: the unilateral-contact check of the selected gait (attributes
    ``ok`` 1/0/-1 for yes/no/not checked and ``not_checked``, why not) and, when made, its
    friction verdict (``friction/``: attributes ``inside`` 1/0/-1, ``foot``, ``mu_source``,
    ``not_checked``; datasets :data:`FRICTION_FIELDS`)."""
    ok = ground.ok
    g.attrs["ok"] = -1 if ok is None else int(ok)
    g.attrs["not_checked"] = ground.not_checked
    for attr, (name, unit, what) in GROUND_FIELDS.items():
        put(g, name, float(getattr(ground, attr)), unit, what)
    if not np.isnan(getattr(ground, "max_twist_n_m", np.nan)):  # 3D: planar ones unchanged
        t = g.create_group("twist")
        for attr, (name, unit, what) in TWIST_FIELDS.items():
            put(t, name, float(getattr(ground, attr)), unit, what)
    fr = getattr(ground, "friction", None)
    if fr is not None:  # new beside the datasets above (which stay as they were)
        h = g.create_group("friction")
        inside = fr.inside
        h.attrs["inside"] = -1 if inside is None else int(inside)
        h.attrs["foot"] = fr.foot
        h.attrs["mu_source"] = fr.mu_source
        h.attrs["not_checked"] = fr.not_checked
        for attr, (name, unit, what) in FRICTION_FIELDS.items():
            put(h, name, float(getattr(fr, attr)), unit, what)


@dataclass
class GroundContactRecord:
    """The stored unilateral-contact check (``ground_contact/``): ``ok`` True / False /
    None (not checked, ``not_checked`` says why) and the numbers by their check's attribute
    names (:data:`GROUND_FIELDS`, SI or the scene's units)."""

    ok: bool | None
    not_checked: str
    values: dict
    friction: FrictionVerdict | None = None


def _ground(f) -> GroundContactRecord | None:
    if "ground_contact" not in f:
        return None
    g = f["ground_contact"]
    ok = int(g.attrs["ok"])
    friction = None
    if "friction" in g:  # artifacts written before the friction verdict have none
        h = g["friction"]
        friction = FrictionVerdict(
            **{a: float(h[name][()]) for a, (name, _, _) in FRICTION_FIELDS.items()
               if name in h},
            foot=str(h.attrs["foot"]), mu_source=str(h.attrs["mu_source"]),
            not_checked=str(h.attrs["not_checked"]))
    values = {a: float(g[name][()]) for a, (name, _, _) in GROUND_FIELDS.items() if name in g}
    if "twist" in g:  # a walker in 3D
        values.update({a: float(g["twist"][name][()]) for a, (name, _, _) in
                       TWIST_FIELDS.items()})
    return GroundContactRecord(None if ok < 0 else bool(ok), str(g.attrs["not_checked"]),
                               values, friction)


@dataclass
class GaitResult:
    """One period-1 gait as stored (a group of ``fixedpoint.h5``).

    Attributes
    ----------
    x : ndarray (2n,)
        Fixed point in ``state_names`` order [rad, rad/s], just after heel strike.
    step_period_s : float
    residual : float
        max |P(x*) - x*|.
    multipliers, multipliers_fd : ndarray (2n,) complex
        Floquet multipliers from the variational equations and from finite differences.
    max_difference : float
    stable : bool
    source : str
        How the gait was found ("initial_guess", "seed", "deflation"; "" at the root).
    error : str
        Why no fixed point was found ("" when found; then the other fields are NaN).
    ground_contact : GroundContactRecord or None
        Whether this gait needs only a ground that pushes (``gaits/<label>/ground_contact/``;
        None where not checked: equation variants, older artifacts).
    steps_per_map : int
        Steps of the Poincaré map the multipliers are of (1: a step, 2: a stride;
        attribute ``steps_per_map``, in older artifacts from ``stride_period``).
    """

    x: np.ndarray
    step_period_s: float
    residual: float
    multipliers: np.ndarray
    multipliers_fd: np.ndarray
    max_difference: float
    stable: bool
    source: str = ""
    error: str = ""
    stride_period_s: float | None = None
    step_periods_s: tuple = ()
    step_lengths_m: tuple = ()
    step_swing_legs: tuple = ()
    ground_contact: GroundContactRecord | None = None
    neutral: tuple = ()
    jacobian: np.ndarray | None = None
    steps_per_map: int = 1

    def max_abs_multiplier(self) -> float:
        """Largest |Floquet multiplier| (variational), the neutral ones (:attr:`neutral`:
        one nearest 1 for each) set aside."""
        return float(np.max(np.abs(without_neutral(self.multipliers, len(self.neutral)))))

    @property
    def period_s(self) -> float:
        """Period of the Poincare map [s]: the stride's when legs differ (a map of two
        steps), else the step's (as the search's result holds it)."""
        return self.step_period_s if self.stride_period_s is None else self.stride_period_s


def _gait(g, names: list[str]) -> GaitResult:
    if "error" in g.attrs:
        return GaitResult(np.full(len(names), np.nan), np.nan, np.nan, np.zeros(0, complex),
                          np.zeros(0, complex), np.nan, False, "", str(g.attrs["error"]))
    return GaitResult(
        x=np.array([g[f"fixed_point/{n}"][()] for n in names]),
        step_period_s=float(g["step_period"][()]), residual=float(g["residual"][()]),
        multipliers=g["floquet/variational/real"][()] + 1j * g["floquet/variational/imag"][()],
        multipliers_fd=(g["floquet/finite_difference/real"][()]
                        + 1j * g["floquet/finite_difference/imag"][()]),
        max_difference=float(g["floquet/max_difference"][()]),
        stable=bool(g["floquet/stable"][()]), source=str(g.attrs.get("source", "")),
        ground_contact=_ground(g), **_stride(g),
        neutral=tuple(str(v) for v in g["floquet"].attrs.get("neutral", ())),
        jacobian=g["floquet/variational/jacobian"][()],
        steps_per_map=int(g.attrs.get("steps_per_map", len(g["steps/period"])
                                      if "stride_period" in g else 1)))


def _stride(g) -> dict:
    """A stride map's own fields (legs that differ), empty otherwise."""
    if "stride_period" not in g:
        return {}
    return {"stride_period_s": float(g["stride_period"][()]),
            "step_periods_s": tuple(float(v) for v in g["steps/period"][()]),
            "step_lengths_m": tuple(float(v) for v in g["steps/length"][()]),
            "step_swing_legs": tuple(v.decode() if isinstance(v, bytes) else str(v)
                                     for v in g["steps/swing_leg"][()])}


@dataclass
class FixedPointArtifact(GaitResult):
    """A loaded ``fixedpoint.h5``: the selected gait (the inherited fields) and the rest.

    Attributes
    ----------
    path : Path
    units : Units
        The scene's unit system.
    model, variant : str
        Walker model and the scene's equation variant.
    section_words : str
        What the state ``x`` is (attribute ``section_words``: "state just after heel
        strike"; flat feet: after the heel strike's impulse, before the trailing toe is
        pinned).
    state_names, state_units : list of str
        Role-ordered state names and their units.
    legs_by_role : dict[str, str]
        Physical leg of each role ("swing" -> "leg1" ...).
    gait, gait_policy : str
        Label of the selected gait and the scene's ``fixedpoint.gait``.
    gait_notes : list of str
    gaits : dict[str, GaitResult]
        Every gait found, by label.
    variants : dict[str, GaitResult]
        Every equation variant solved, by name (``error`` set where none was found).
    scene_json : str
        The resolved scene the gait was computed for (JSON).
    ground_contact : GroundContactRecord or None
        Whether the gait needs only a ground that pushes (None in artifacts without it).
    footholds : dict or None
        On stairs: ``footholds/``'s attributes (:class:`walkerlab.analysis.gait.treads.
        TreadLanding` fields by name); None on a slope.
    """

    path: Path = Path()
    units: Units | None = None
    model: str = ""
    variant: str = ""
    section_words: str = "state just after heel strike"
    state_names: list = field(default_factory=list)
    state_units: list = field(default_factory=list)
    legs_by_role: dict = field(default_factory=dict)
    gait: str = ""
    gait_policy: str = ""
    gait_notes: list = field(default_factory=list)
    gaits: dict = field(default_factory=dict)
    variants: dict = field(default_factory=dict)
    scene_json: str = "{}"
    ground_contact: GroundContactRecord | None = None
    footholds: dict | None = None
    zero_dynamics: dict | None = None


def _zero_dynamics(f) -> dict | None:
    """``zero_dynamics/`` by the fields of :data:`ZERO_DYNAMICS_FIELDS` (and ``exists``,
    ``stable``, ``saturates``, ``unit``: the phase variable's), None without it."""
    if "zero_dynamics" not in f:
        return None
    g = f["zero_dynamics"]
    out = {a: float(g[name][()]) for a, (name, _u, _w) in ZERO_DYNAMICS_FIELDS.items()}
    out.update({k: bool(g.attrs[k]) for k in ("exists", "stable", "saturates")})
    out["phase_unit"] = str(g["theta_plus"].attrs["unit"])
    out["invariance_residual_position"] = float(
        g["virtual_constraints/invariance_residual_position"][()])
    out["invariance_residual_rate"] = float(
        g["virtual_constraints/invariance_residual_rate"][()])
    out["full_order"] = {}
    for k in FULL_ORDER_FIELDS:
        if f"full_order/{k}" in g:
            v = g[f"full_order/{k}"][()]
            out["full_order"][k] = complex(v[0], v[1]) if np.ndim(v) else float(v)
    out["bezier"] = g["virtual_constraints/bezier"][()]
    out["outputs"] = [str(o) for o in g["virtual_constraints"].attrs["outputs"]]
    return out


@artifact_loader(STAGE)
def load_fixedpoint(f, path: Path) -> FixedPointArtifact:
    """Load ``fixedpoint.h5``."""
    names = [str(n) for n in f.attrs["state_names"]]
    main = _gait(f, names)
    return FixedPointArtifact(
        **vars(main), path=Path(path), units=for_artifact(f), model=str(f.attrs["model"]),
        variant=str(f.attrs["variant"]), state_names=names,
        section_words=str(f.attrs.get("section_words", "state just after heel strike")),
        state_units=[str(f[f"fixed_point/{n}"].attrs["unit"]) for n in names],
        legs_by_role=(json.loads(f.attrs["legs_by_role"]) if "legs_by_role" in f.attrs
                      else {}),
        gait=str(f.attrs.get("gait", "")), gait_policy=str(f.attrs.get("gait_policy", "")),
        gait_notes=json.loads(f.attrs.get("gait_notes", "[]")),
        gaits={str(lab): _gait(f[f"gaits/{lab}"], names)
               for lab in f.attrs.get("gaits", [])} if "gaits" in f else {},
        variants={v: _gait(f["variants"][v], names) for v in f["variants"]}
        if "variants" in f else {}, scene_json=str(f.attrs.get("scene_json", "{}")),
        footholds={k: (v.item() if hasattr(v, "item") else v)
                   for k, v in f["footholds"].attrs.items()} if "footholds" in f else None,
        zero_dynamics=_zero_dynamics(f))
