"""Validated settings of the compliant-contact model and its runs (pydantic v2).

The scene sections ``contact``, ``terrain``, ``contact_sim`` and ``contact_solver`` (read
through :mod:`walkerlab.config`).  The contact model package imports its settings from here;
this module imports no model (settings lie under the models, not beside them).

Numbers in :class:`ContactSettings` are written in the unit system named by
``unit_system`` (ADAMS's default is mm-kg-s); :meth:`ContactSettings.to_si` converts them
explicitly to SI (NOTES.md: "a wrong unit here changes the answer by 10^6").
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Annotated, Literal

from pydantic import (
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Field,
    model_serializer,
    model_validator,
)

__all__ = ["MAX_CONTACT_STRIDES", "ContactParamsSI", "ContactSettings", "ContactSimSettings",
           "ContactSolverSettings", "KneeStopSI", "KneeStopSettings", "PerStepTerrain",
           "TerrainSettings"]


@dataclass(frozen=True)
class ContactParamsSI:
    """Contact parameters in SI units (what the model kernels use).

    Attributes
    ----------
    k : float
        Stiffness ``[N/m**e]``.
    e : float
        Force exponent ``[-]``.
    cmax : float
        Maximum damping ``[N s/m]``.
    dmax : float
        Penetration at full damping ``[m]``.
    mu_s, mu_d : float
        Static / dynamic friction coefficients ``[-]``.
    v_s, v_d : float
        Stiction / friction transition velocities ``[m/s]``.
    """

    k: float
    e: float
    cmax: float
    dmax: float
    mu_s: float
    mu_d: float
    v_s: float
    v_d: float


@dataclass(frozen=True)
class KneeStopSI:
    """Knee-stop parameters in SI (the IMPACT law on the knee's hyperextension angle).

    Attributes
    ----------
    k : float
        Stiffness ``[N m/rad**e]``.
    e : float
        Exponent ``[-]``.
    cmax : float
        Maximum damping ``[N m s/rad]``.
    dmax : float
        Hyperextension at full damping ``[rad]``.
    latch : bool
        The stop also holds a loaded leg's knee against flexion (knee latch).
    latch_height : float
        Height of the foot above the ground at which the latch has released ``[m]``.
    latch_capture : float
        Flexion beyond which the latch does not hold ``[rad]``.
    """

    k: float
    e: float
    cmax: float
    dmax: float
    latch: bool = False
    latch_height: float = 0.002
    latch_capture: float = 0.01


# Numbers are strict and finite (issue 12, D10): no bool or string as a number, no inf/NaN;
# a YAML int still validates as a float.  Same rules as walkerlab.config.schema._Strict.
_STRICT = ConfigDict(extra="forbid", strict=True, allow_inf_nan=False)

# Longest contact run (D8): 100 strides is ~20x the paper's 5 and keeps the artifact < 100 MB.
MAX_CONTACT_STRIDES = 100


def _list_to_tuple(v):
    return tuple(v) if isinstance(v, list) else v


def _len_factor(unit_system: str) -> float:
    """Metres per length unit of ``unit_system``."""
    return {"mm-kg-s": 1e-3, "SI": 1.0}[unit_system]


class KneeStopSettings(BaseModel):
    """The knee's stop (straight leg) as a one-sided compliant rotational contact: the IMPACT
    law of the feet applied to the hyperextension angle ``shank - thigh`` (> 0 past
    straight), torque ``k ext^e + STEP(ext, 0, 0, dmax, cmax) ext'`` pushing the knee back
    (MSC ADAMS models joint stops this way).  Used by kneed walkers only; SI units.

    Defaults (chosen on the walker of ``configs/kneed.yaml``, Hsu Chen 2007, standing on one
    leg): the stop holds the knee within ~5e-6 rad of straight under ~0.05 N m; full damping
    is reached at 1e-5 rad so the stop is overdamped from the first micro-radians (stiffness
    there ~1.5 k sqrt(delta) ~ 5e2 N m/rad against ~0.3 kg m^2 above the knee: critical
    damping ~25 N m s/rad < 200) and a knee strike is nearly plastic, like the rigid model's.
    A less damped stop rebounds, and a free knee that rebounds into flexion under load buckles.
    """

    model_config = _STRICT

    stiffness_N_m_per_rad: float = Field(
        1e5, gt=0, le=1e12, description="Stop stiffness k [N m/rad^e].",
        json_schema_extra={"unit": "N m/rad^e"})
    exponent: float = Field(1.5, ge=1.0, le=10.0, description="Stop force exponent e [-].",
                            json_schema_extra={"unit": "-"})
    max_damping_N_m_s_per_rad: float = Field(
        200.0, ge=0, description="Stop maximum damping cmax [N m s/rad].",
        json_schema_extra={"unit": "N m s/rad"})
    penetration_at_max_damping_rad: float = Field(
        1e-5, gt=0, description="Hyperextension dmax at which full damping is reached [rad].",
        json_schema_extra={"unit": "rad"})

    latch: bool = Field(
        False, description="Knee latch: while a leg's foot is on the ground the stop also "
        "acts in flexion (the same law mirrored), so the stance knee is held straight both "
        "ways, as the suction cups / magnets of real kneed passive walkers (McGeer 1990; "
        "Cornell) and the rigid model's locked knee do; it holds through the other leg's "
        "heel strike and releases as its foot rises above latch_release_height_m.")
    latch_release_height_m: float = Field(
        0.002, gt=0, le=0.1, description="Height of the foot above the ground at which its "
        "knee's latch has released (engagement STEP(penetration, -h, 0, 0, 1)) [m].",
        json_schema_extra={"unit": "m"})
    latch_capture_rad: float = Field(
        0.01, gt=0, le=0.5, description="Flexion within which the latch captures the knee "
        "(full hold within half of it) [rad]: a knee bent farther when its foot touches down "
        "is not snapped straight.", json_schema_extra={"unit": "rad"})

    def to_si(self) -> KneeStopSI:
        """The same numbers as a :class:`KneeStopSI`."""
        return KneeStopSI(self.stiffness_N_m_per_rad, self.exponent,
                          self.max_damping_N_m_s_per_rad, self.penetration_at_max_damping_rad,
                          self.latch, self.latch_release_height_m,
                          self.latch_capture_rad)


class ContactSettings(BaseModel):
    """IMPACT normal force + Coulomb friction, numbers in ``unit_system``.

    Defaults are the paper's values (k = 1e5, damping 90, mu_s = 0.9, mu_d = 0.7) read in
    ADAMS's default mm-kg-s units, with the ADAMS View defaults for the rest (NOTES.md).
    """

    model_config = _STRICT

    unit_system: Literal["mm-kg-s", "SI"] = Field(
        "mm-kg-s",
        description="Unit system of the numbers below: 'mm-kg-s' (ADAMS default) or 'SI'."
    )
    stiffness: float = Field(
        1e5, gt=0, le=1e12, description="IMPACT stiffness k (at most 1e12).",
        json_schema_extra={"unit": "N/<len>^e"},
    )
    exponent: float = Field(
        2.2, ge=1.0, le=10.0, description="IMPACT force exponent e (ADAMS default 2.2).",
        json_schema_extra={"unit": "-"},
    )
    max_damping: float = Field(
        90.0, ge=0, description="IMPACT maximum damping cmax (paper: 'damping 90').",
        json_schema_extra={"unit": "N s/<len>"},
    )
    penetration_at_max_damping: float = Field(
        0.1, gt=0, description="IMPACT penetration dmax at which full damping is reached.",
        json_schema_extra={"unit": "<len>"},
    )
    mu_static: float = Field(0.9, ge=0, description="Static friction coefficient.",
                             json_schema_extra={"unit": "-"})
    mu_dynamic: float = Field(0.7, ge=0, description="Dynamic friction coefficient.",
                              json_schema_extra={"unit": "-"})
    stiction_velocity: float = Field(
        100.0, gt=0, description="Stiction transition velocity vs.",
        json_schema_extra={"unit": "<len>/s"},
    )
    friction_velocity: float = Field(
        1000.0, gt=0, description="Friction transition velocity vd (> vs).",
        json_schema_extra={"unit": "<len>/s"},
    )

    stiffness_family: Literal["paper", "rigid_limit"] = Field(
        "paper", description="How damping and dmax follow the stiffness: 'paper' keeps "
        "max_damping and penetration_at_max_damping as given (a stiffer contact is then more "
        "elastic); 'rigid_limit' reads them, the transition velocities and the knee latch's "
        "release height as holding at reference_stiffness and follows the one rigid-limit "
        "family (walkerlab.contact.rigid_limit) with kappa = stiffness / reference_stiffness: "
        "cmax * kappa^(1/(e+1)), dmax and latch height * kappa^(-1/(e+1)), vs and vd * "
        "kappa^(-1/2), so a drop impact keeps its (near-plastic) restitution and the periodic "
        "gait converges to the rigid one as k grows.")
    reference_stiffness: float = Field(
        1e5, gt=0, description="Stiffness at which max_damping and penetration_at_max_damping "
        "hold in the 'rigid_limit' family (paper: 1e5 N/mm^2.2).",
        json_schema_extra={"unit": "N/<len>^e"})
    knee_stop: KneeStopSettings = Field(
        default_factory=KneeStopSettings, description="Knee stops of a kneed walker (SI, "
        "unit_system does not apply): stiffness_N_m_per_rad, exponent, "
        "max_damping_N_m_s_per_rad, penetration_at_max_damping_rad.")

    flat_foot_mass_kg: float | None = Field(
        None, gt=0, le=100, description="Flat feet only (SI, unit_system does not apply): "
        "each foot's mass [kg], at its ankle.  The walker description's flat foot is "
        "massless (the rigid view); the floating contact model regularises it with this "
        "small mass, a contact-model setting like the stiffness (with zero mass the foot's "
        "angle would have no dynamics of its own).",
        json_schema_extra={"unit": "kg"})
    flat_foot_inertia_kg_m2: float | None = Field(
        None, gt=0, le=100, description="Flat feet only (SI): each foot's moment of inertia "
        "about its ankle [kg m^2] (regularisation, see flat_foot_mass_kg).",
        json_schema_extra={"unit": "kg m^2"})

    @model_serializer(mode="wrap")
    def _drop_unset_flat_foot(self, handler):
        # a scene without flat feet serialises as before (same content hashes)
        d = handler(self)
        if isinstance(d, dict):
            for k in ("flat_foot_mass_kg", "flat_foot_inertia_kg_m2"):
                if d.get(k) is None:
                    d.pop(k, None)
        return d

    def flat_foot(self) -> tuple[float, float] | None:
        """``(flat_foot_mass_kg, flat_foot_inertia_kg_m2)`` or None if either is unset."""
        if self.flat_foot_mass_kg is None or self.flat_foot_inertia_kg_m2 is None:
            return None
        return float(self.flat_foot_mass_kg), float(self.flat_foot_inertia_kg_m2)

    @model_validator(mode="after")
    def _check_relations(self) -> ContactSettings:
        if self.mu_dynamic > self.mu_static:
            raise ValueError(
                f"mu_dynamic ({self.mu_dynamic}) must be <= mu_static ({self.mu_static})"
            )
        if not self.stiction_velocity < self.friction_velocity:
            raise ValueError(
                f"stiction_velocity ({self.stiction_velocity}) must be < "
                f"friction_velocity ({self.friction_velocity})"
            )
        return self

    def to_si(self) -> ContactParamsSI:
        """Convert to SI: ``k_SI = k * f**-e``, ``c_SI = c / f``, lengths and velocities ``* f``.

        ``f`` = metres per length unit (1e-3 for mm-kg-s).  E.g. ``k = 1e5 N/mm^2.2`` becomes
        ``1e5 * 1000**2.2 N/m^2.2``.  The numbers as written: the ``stiffness_family`` is
        applied by :func:`walkerlab.contact.rigid_limit.contact_si`.

        Returns
        -------
        ContactParamsSI
        """
        f = _len_factor(self.unit_system)
        e = self.exponent
        cmax, dmax = self.max_damping, self.penetration_at_max_damping
        return ContactParamsSI(
            k=self.stiffness * f ** (-e),
            e=e,
            cmax=cmax / f,
            dmax=dmax * f,
            mu_s=self.mu_static,
            mu_d=self.mu_dynamic,
            v_s=self.stiction_velocity * f,
            v_d=self.friction_velocity * f,
        )


class PerStepTerrain(BaseModel):
    """Per-step ground of the rigid model (Byl & Tedrake 2009, "Metastable walking machines").

    Step ``n`` is taken on the straight line through the stance foot at slope ``gamma_n``
    (for a compass walker the heel-strike guard becomes ``theta_swing + theta_stance =
    -2 gamma_n``).  ``gamma_n`` is drawn i.i.d. about the scene's slope (``slope_sd_rad``;
    ``normal`` or ``uniform`` with the same standard deviation), reproducibly from ``seed``.
    """

    model_config = _STRICT

    slope_distribution: Literal["normal", "uniform"] = Field(
        "normal", description="distribution of each step's slope about the scene's slope")
    slope_sd_rad: float = Field(0.0, ge=0, le=0.2,
                                description="standard deviation of each step's slope [rad]")
    seed: int = Field(0, ge=0, description="seed of the per-step draws [-]")


class TerrainSettings(BaseModel):
    """Ground geometry: continuous slope or the paper's 'checkerboard' lanes.

    For ``checkerboard`` each leg has its own lane with ground patches of width
    ``patch_width_m`` centred on that leg's ideal footfalls: leg2 at ``s = 0, 2l, 4l, ...``,
    leg1 at ``s = l, 3l, ...`` (``l`` = ideal step length, given at run time).  Elsewhere in
    the lane there is no ground (a gap), so the swing foot is not scuffed at mid-stance.
    """

    model_config = _STRICT

    kind: Literal["checkerboard", "continuous"] = Field(
        "checkerboard", description="'checkerboard' (per-leg patches at footfalls) or 'continuous'."
    )
    patch_width_m: float = Field(
        0.10, gt=0, description="Width of each checkerboard patch along the slope [m]."
    )
    per_step: PerStepTerrain | None = Field(
        None, description="Ground that changes from step to step (rough terrain, a step-down); "
        "used by the rigid model's metastability and disturbance studies (walkerlab mfpt)")

    @model_serializer(mode="wrap")
    def _drop_unset_per_step(self, handler):
        # a scene without per-step terrain serialises as before (same content hashes)
        d = handler(self)
        if isinstance(d, dict) and d.get("per_step") is None:
            d.pop("per_step", None)
        return d


class ContactSimSettings(BaseModel):
    """Run settings of a contact simulation."""

    model_config = _STRICT

    n_strides: int = Field(5, ge=1, le=MAX_CONTACT_STRIDES,
                           description="Strides (2 steps each) to simulate [-]; at most 100.")
    t_final_s: float | None = Field(
        None, gt=0, le=600, description="Simulated time [s] (at most 600); default "
        "n_strides * 2 * ideal step period."
    )
    pin_stance_until: Literal["none", "first_touchdown", "time"] = Field(
        "none", description="Hold the first stance foot fixed until this moment."
    )
    pin_time_s: float = Field(0.0, ge=0,
                              description="Pin duration when pin_stance_until='time' [s].")
    fall_hip_height_m: float | None = Field(
        None, gt=0, description="Fall when hip height above ground < this [m]; default 0.5*L."
    )
    sample_rate_hz: float = Field(1000.0, gt=0, le=1e5, description="Output sample rate [Hz].")
    periodic_gait: bool = Field(
        False, description="Also find the contact walker's own periodic gait and its Floquet "
        "multipliers (walkerlab.analysis.contact_periodic; about 5-10 s)."
    )
    initial_rate_scale: Annotated[tuple[float, float], BeforeValidator(_list_to_tuple)] = Field(
        (1.0, 1.0), description="Multipliers [-] on dtheta1, dtheta2 of the initial state."
    )
    wall_time_limit_s: float | None = Field(
        120.0, gt=0, description="Wall-time limit of one contact run [s]; when it runs out "
        "the run ends with outcome 'time_limit' (null = none).",
        json_schema_extra={"unit": "s"})
    stop_after_strides: bool = Field(
        True, description="Strides cap: stop once 2 * n_strides + 1 heel strikes have "
        "happened, even if t_final_s is longer.")
    periodic_time_limit_s: float | None = Field(
        120.0, gt=0, description="Wall-time limit of the periodic-gait search [s]; when it "
        "runs out the gait is reported as 'time_limit' (null = none).",
        json_schema_extra={"unit": "s"})
    start: Literal["ideal", "adjusted", "periodic_gait"] = Field(
        "ideal", description="Initial state of the run: 'ideal' (the rigid fixed point, rates "
        "times initial_rate_scale; the default), 'adjusted' (rates searched as `contact-sim "
        "--adjust`), 'periodic_gait' (the contact model's own periodic gait at mid-stance, "
        "on patches spaced by its step length: steady state without start-up transients; "
        "adds the periodic-gait search, about 5-10 s).")

    @model_serializer(mode="wrap")
    def _drop_default_start(self, handler):
        # a scene with the default start serialises as before (same content hashes)
        d = handler(self)
        if isinstance(d, dict) and d.get("start") == "ideal":
            d.pop("start", None)
        return d


class ContactSolverSettings(BaseModel):
    """Integrator of the stiff contact model: ``cyrk_bdf`` (CyRK's BDF from compiled code,
    the default), ``odeint`` (LSODA, low overhead), numbalsoda or solve_ivp.

    The one object that carries the solver to every contact integration
    (:func:`walkerlab.analysis.contact_sim.simulate_contact`), as
    becomes :class:`walkerlab.integrate.solver.Solver`, as the rigid side's settings do."""

    model_config = ConfigDict(extra="forbid", frozen=True, strict=True, allow_inf_nan=False)

    method: Literal["odeint", "cyrk_bdf", "numbalsoda", "LSODA", "Radau", "BDF", "RK45",
                    "DOP853"] = Field(
        "cyrk_bdf", description="cyrk_bdf (CyRK's BDF from compiled code), "
        "scipy.integrate.odeint, numbalsoda (LSODA from compiled code; optional extra "
        "'walkerlab[numbalsoda]') or a solve_ivp method")
    rtol: float = Field(1e-8, ge=1e-13, lt=1,
                        description="relative tolerance [-]; at least 1e-13 (LSODA/odeint "
                        "cannot meet a tighter one in double precision)")
    atol: float = Field(1e-10, gt=0, lt=1, description="absolute tolerance [state units]")
    max_step_s: float | None = Field(None, gt=0, description="largest step [s]; null = unbounded")
