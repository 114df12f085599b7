"""The study sections of a scene: what each analysis of the walker asks for (``fixedpoint``,
``simulate``, ``workprecision``, ``basin``, ``mfpt``, ``robustness``) and a walker state
given by name (:class:`StateSpec`) or read from a continuation artifact
(:class:`GuessFromArtifact`).

Every numeric field carries its unit in its name and a description; the caps come from
:mod:`walkerlab.config.limits`.
"""

from __future__ import annotations

import math
from typing import Annotated, Literal

from pydantic import (
    ConfigDict,
    Field,
    ValidationError,
    field_validator,
    model_serializer,
    model_validator,
)

from walkerlab.config.base import AsTuple, Strict, drop_unset
from walkerlab.config.limits import (
    MAX_BASIN_CELLS_PER_AXIS,
    MAX_SIMULATE_STRIDES,
    MAX_STEP_TIME_S,
)


class GuessFromArtifact(Strict):
    """A starting state read from a continuation artifact: the state of a branch
    at a parameter value, instead of digits copied by hand."""

    model_config = ConfigDict(populate_by_name=True)

    from_: str = Field(alias="from", min_length=1, description="continuation artifact "
                       "(runs/<scene>/continuation_<field>.h5), relative to the current "
                       "folder")
    at: float = Field(description="value of the artifact's parameter on the branch [the "
                      "artifact's field unit]")
    branch: int = Field(0, ge=0, le=1000, description="branch index in the artifact (0: the "
                        "period-1 branch through the scene's own gait)")

    def pick(self, data, state_names: list[str] | None = None):
        """State (2n,) of the loaded continuation ``data`` (a
        :class:`walkerlab.io.schemas.continuation.ContinuationData`) on branch
        :attr:`branch` at ``at`` (linear interpolation between its two nearest points), in
        the order of ``state_names``.  Reading the file is the caller's
        (:func:`walkerlab.io.schemas.continuation.initial_state`): config opens no artifact.

        Raises
        ------
        ValueError
            ``at`` off the branch, no such branch, or other state names.
        """
        import numpy as np

        if self.branch >= len(data.branches):
            raise ValueError(f"branch {self.branch}: {self.from_} has "
                             f"{len(data.branches)} branches")
        x = data.state_at(self.at, self.branch)
        names = state_names or data.state_names
        if sorted(names) != sorted(data.state_names):
            raise ValueError(f"{self.from_} holds states {data.state_names}, the walker has "
                             f"{list(names)}")
        return np.array([x[data.state_names.index(n)] for n in names])


class StateSpec(Strict):
    """A walker state right after heel strike, by state name with its unit:
    ``<role>_angle_rad`` and ``<role>_rate_rad_per_s`` for each role of the walker (compass
    gait, Eq. 1: ``swing_angle_rad, stance_angle_rad, swing_rate_rad_per_s,
    stance_rate_rad_per_s``; simplest walker: ``stance_...`` and ``hip_...``), or a state
    read from a continuation artifact, ``{from: <artifact>, at: <parameter value>, branch:
    0}`` (:class:`GuessFromArtifact`)."""

    model_config = ConfigDict(extra="allow", frozen=True)

    @model_validator(mode="after")
    def _named_finite(self) -> StateSpec:
        import re

        extra = self.model_extra or {}
        if "from" in extra:  # a state read from a continuation artifact
            try:
                GuessFromArtifact.model_validate(extra)
            except ValidationError as exc:
                err = exc.errors()[0]
                where = ".".join(str(x) for x in err["loc"])
                raise ValueError(f"{where}: {err['msg']}" if where else err["msg"]) from None
            return self
        for k, v in extra.items():
            if not re.fullmatch(r"[a-z][a-z0-9_]*_(angle_rad|rate_rad_per_s)", k):
                raise ValueError(f"{k}: not a state name (<role>_angle_rad or "
                                 "<role>_rate_rad_per_s)")
            if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v):
                raise ValueError(f"{k}: must be a finite number")  # as Strict fields
        if not self.model_extra:
            raise ValueError("give the state by name (<role>_angle_rad, <role>_rate_rad_per_s)")
        return self

    @property
    def artifact(self) -> GuessFromArtifact | None:
        """The continuation artifact this state is read from, or None (a state by name)."""
        extra = self.model_extra or {}
        return GuessFromArtifact.model_validate(extra) if "from" in extra else None

    def as_array(self, state_names: list[str] | None = None):
        """State (2n,) in the order of ``state_names`` (a walker's ``state_names()``; default:
        the compass gait's ``swing_angle, stance_angle, swing_rate, stance_rate``).

        Raises
        ------
        ValueError
            A state of the walker is missing, or a given name is not one of its states.
        """
        import numpy as np

        if self.artifact is not None:
            raise ValueError(f"the state is read from {self.artifact.from_}: use "
                             "walkerlab.io.schemas.continuation.initial_state")
        names = state_names or ["swing_angle", "stance_angle", "swing_rate", "stance_rate"]
        keys = [n + ("_rad" if n.endswith("_angle") else "_rad_per_s") for n in names]
        given = dict(self.model_extra or {})
        missing = [k for k in keys if k not in given]
        extra = [k for k in given if k not in keys]
        if missing or extra:
            raise ValueError(f"state must give exactly {keys}" +
                             (f"; missing {missing}" if missing else "") +
                             (f"; unknown {extra}" if extra else ""))
        return np.array([float(given[k]) for k in keys])


class StateOffset(StateSpec):
    """A change to a walker state by state name with its unit (as :class:`StateSpec`'s
    names: ``<role>_angle_rad``, ``<role>_rate_rad_per_s``); the states it does not name
    are unchanged."""

    def as_array(self, state_names: list[str] | None = None):
        """The change (2n,) in the order of ``state_names`` (a walker's ``state_names()``),
        0 where a state is not named.

        Raises
        ------
        ValueError
            A name that is not one of the walker's states (one line listing them), or a
            state read from an artifact (an offset is given by name).
        """
        import numpy as np

        if self.artifact is not None:
            raise ValueError("give the change by state name (<role>_angle_rad, "
                             "<role>_rate_rad_per_s), not from an artifact")
        names = state_names or ["swing_angle", "stance_angle", "swing_rate", "stance_rate"]
        keys = [n + ("_rad" if n.endswith("_angle") else "_rad_per_s") for n in names]
        given = dict(self.model_extra or {})
        extra = [k for k in given if k not in keys]
        if extra:
            raise ValueError(f"{extra[0]}: not a state of the walker (its states: "
                             f"{_state_list(names, keys)})")
        return np.array([float(given.get(k, 0.0)) for k in keys])


def _state_list(names: list[str], keys: list[str]) -> str:
    """Every valid state name of :meth:`StateOffset.as_array`, short enough for one line:
    by role (``<role>_angle_rad`` and ``<role>_rate_rad_per_s``) when the states are each
    role's angle and rate, else the names themselves."""
    roles = [n.removesuffix("_angle") for n in names if n.endswith("_angle")]
    if sorted(names) == sorted([f"{r}_angle" for r in roles] + [f"{r}_rate" for r in roles]):
        return ("<role>_angle_rad and <role>_rate_rad_per_s of the roles "
                + ", ".join(roles))
    return ", ".join(keys)


class FixedPointSettings(Strict):
    """Search for the period-1 fixed point of the Poincaré map (paper Sec. 3.3)."""

    model_config = ConfigDict(populate_by_name=True)

    initial_guess: StateSpec | None = Field(
        None, description="starting point of the root finder, by state name or "
        "{from: <continuation artifact>, at: <parameter value>}; null: found automatically "
        "(scale-free seeds from the slope and the walker's size, ranked on the heel-strike "
        "section; walkerlab.analysis.gait.search)")
    from_: str | None = Field(
        None, alias="from", description="a scene YAML whose gait is known: its gait is "
        "continued along the straight line between the two scenes' numeric walker and slope "
        "fields to this walker (homotopy), and used as the initial guess; relative to this "
        "scene's folder.  The two walkers must have the same structure (the same legs and "
        "bodies, by name, and the same fields): only numbers may differ")
    gait: Literal["stable", "long_period", "short_period", "nearest_guess"] = Field(
        "stable", description="which period-1 gait to use where two exist (Goswami et al. "
        "1996, Garcia et al. 1998: long- and short-period pair): 'stable' (the stable one; "
        "none stable: the one nearest the initial guess), 'long_period', 'short_period', or "
        "'nearest_guess' (where the root finder goes from initial_guess)")
    other_gait: bool = Field(
        True, description="also look for the other gait of the pair (deflated root finding "
        "near the first at a screening tolerance, then polished; about 0.05-0.4 s) and "
        "record both in fixedpoint.h5")
    tolerance: float = Field(1e-12, gt=0, lt=1e-3, description="root-finder xtol [-]")
    max_step_time_s: float = Field(5.0, gt=0, le=MAX_STEP_TIME_S,
                                   description="a step longer than this is a failure [s]")
    fd_step: float = Field(1e-7, gt=0, lt=1e-2,
                           description="finite-difference step for the Jacobian")

    @field_validator("gait")
    @classmethod
    def _guess_for_nearest(cls, v: str, info) -> str:
        if v == "nearest_guess" and info.data.get("initial_guess") is None:
            raise ValueError("'nearest_guess' needs an initial_guess")
        return v


class SimulateSettings(Strict):
    """Forward simulation of the rigid hybrid model."""

    strides: int = Field(5, ge=1, le=MAX_SIMULATE_STRIDES,
                         description="number of strides (2 steps each); at most 1000 "
                         "(measured: 27 s for 1000 at rtol 1e-12 on 2 busy cores)")
    sample_rate_hz: float = Field(500.0, gt=0, le=1e6, description="dense output rate [Hz]")
    initial_state: Literal["fixed_point"] | StateSpec = Field(
        "fixed_point", description="'fixed_point' (from fixedpoint.h5) or an explicit state"
    )
    max_step_time_s: float = Field(5.0, gt=0, le=MAX_STEP_TIME_S,
                                   description="a step longer than this ends the run [s]")
    terrain_seed: int | None = Field(
        None, ge=0, lt=2**63, description="walk the per-step ground of terrain.per_step drawn "
        "from this seed (its Monte Carlo walk 0; walkerlab simulate --terrain-seed): the same "
        "seed walks the same ground again, bit for bit [-]")

    @model_serializer(mode="wrap")
    def _drop_unset(self, handler):
        # a scene without a terrain seed serialises as before (same content hashes)
        return drop_unset(handler(self), ("terrain_seed",))


class WorkPrecisionSettings(Strict):
    """Error against run time for every scipy method over a range of tolerances.

    ``walkerlab report`` measures it with ``--full``, or without it when
    ``in_default_report`` is true (the paper's scene: its error against run time is the
    first thing the project adds to the paper).
    """

    in_default_report: bool = Field(
        False, description="also measured by `walkerlab report` without `--full` (default: "
        "opt-in, `--full` only; the study times every setting: keep it light where true)")

    methods: list[Literal["RK45", "RK23", "DOP853", "Radau", "BDF", "LSODA"]] = Field(
        ["RK45", "DOP853", "Radau", "BDF", "LSODA"], description="scipy solve_ivp methods")
    rtols: list[Annotated[float, Field(gt=0, lt=1)]] = Field(
        [1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12],
        description="relative tolerances [-]; atol = atol_factor * rtol")
    atol_factor: float = Field(1.0, gt=0, description="atol = atol_factor * rtol [state units]")
    repeats: int = Field(3, ge=1, le=50, description="timing repeats (median is kept)")
    strides: int = Field(5, ge=1, le=100, description="strides per run")
    reference_rtol: float = Field(1e-13, gt=0, lt=1e-8, description="reference run rtol [-]")
    target_error: float = Field(1e-8, gt=0, description="error the Pareto-best setting must "
                                "reach [rad, rad/s]")
    models: list[Literal["ideal", "contact"]] = Field(["ideal"], description="models to study")
    contact_methods: list[Literal["odeint", "cyrk_bdf", "LSODA", "Radau", "BDF"]] = Field(
        ["odeint", "cyrk_bdf", "LSODA", "Radau", "BDF"],
        description="methods for the stiff contact model (explicit methods are hopeless there)")
    contact_rtols: list[Annotated[float, Field(gt=0, lt=1)]] = Field(
        [1e-5, 1e-6, 1e-7, 1e-8, 1e-9], description="contact-model tolerances [-]")
    contact_target_error: float = Field(1e-6, gt=0, description="contact-model error the "
                                        "Pareto-best setting must reach [rad, rad/s]")
    contact_reference_rtol: float = Field(1e-12, gt=0, lt=1e-6,
                                          description="contact reference (odeint) rtol [-]")


class BasinSettings(Strict):
    """Basin of attraction over a 2-D slice of the Poincaré section (Schwab & Wisse 2001).

    Each cell is a state just after heel strike: the two axis coordinates come from the grid,
    the coordinate fixed by the heel-strike surface from that constraint, the others from
    the period-1 fixed point.  Axes are named by ``walker.state_names()``.
    """

    x_axis: str = Field("stance_angle", description="state name on the x axis")
    y_axis: str = Field("stance_rate", description="state name on the y axis")
    x_range: Annotated[tuple[float, float] | None, AsTuple] = Field(
        None, description="x axis [rad or rad/s]; null = fixed point -/+ 0.3 rad (angles) or "
        "1.2 rad/s (rates)")
    y_range: Annotated[tuple[float, float] | None, AsTuple] = Field(
        None, description="y axis [rad or rad/s]; null = fixed point -/+ 0.3 rad (angles) or "
        "1.2 rad/s (rates)")
    grid: Annotated[tuple[Annotated[int, Field(ge=2, le=MAX_BASIN_CELLS_PER_AXIS)],
                          Annotated[int, Field(ge=2, le=MAX_BASIN_CELLS_PER_AXIS)]], AsTuple] = \
        Field((200, 200), description=f"cells along x and y (2 to {MAX_BASIN_CELLS_PER_AXIS} "
              "each)")
    max_steps: int = Field(50, ge=1, le=10_000, description="steps simulated per cell at most")
    converge_tol: float = Field(1e-4, gt=0, lt=1, description="a cell has converged to the "
                                "period-1 gait once max|x - x*| < this [rad, rad/s]")
    period_tol: float = Field(1e-6, gt=0, lt=1, description="x_k and x_{k-p} closer than this "
                              "(p >= 2) = another periodic attractor [rad, rad/s]")
    max_period: int = Field(8, ge=2, le=64, description="longest period looked for [steps]")
    rtol: float = Field(1e-8, gt=0, lt=1, description="integrator relative tolerance [-]")
    atol: float = Field(1e-8, gt=0, lt=1, description="integrator absolute tolerance")
    backend: Literal["auto", "scipy", "cyrk", "cyrk_compiled"] = Field(
        "auto", description="integrator library for the cells (DOP853), as "
        "SolverSettings.backend; cyrk_compiled is slower here (most cells fall within a "
        "step, so its fixed chunks overshoot, and each worker imports numba)")
    max_step_time_s: float | None = Field(
        None, gt=0, le=MAX_STEP_TIME_S,
        description="a step longer than this ends the cell as 'stalled' [s]; "
        "null = fixedpoint.max_step_time_s")
    start: Literal["fixed_point", "heel_strike", "phase_plane"] = Field(
        "fixed_point", description="how a cell's other coordinates are set: 'fixed_point' = "
        "from x* (then projected on the heel-strike surface); 'phase_plane' = from x*, not "
        "projected: the cell is any state of the stance phase (the rimless wheel, whose "
        "section has one coordinate); 'heel_strike' = the cell is a "
        "state just after a heel strike, the heel-strike image of a pre-impact state on the "
        "guard that differs from x*'s pre-impact state in the two coordinates the axes depend "
        "on most (Schwab & Wisse 2001; for the simplest walker, whose post-impact states form "
        "a 2-D set, the cell is then unique); a cell no heel strike reaches is 'unreachable'")


class MfptSettings(Strict):
    """Mean first-passage time on per-step random slopes (``walkerlab mfpt``; Byl & Tedrake
    2009).  The slope of each step is normal (or ``terrain.per_step.slope_distribution``)
    about the scene's slope with standard deviation ``sigma``; walks start on the gait."""

    sigma_rad: list[Annotated[float, Field(gt=0, le=0.2)]] = Field(
        [0.002, 0.003, 0.004, 0.006], min_length=1, max_length=64,
        description="standard deviations of the per-step slope [rad]")
    sigma_m: list[Annotated[float, Field(gt=0, le=0.2)]] | None = Field(
        None, min_length=1, max_length=64, description="standard deviations of the per-step "
        "landing height [m] (terrain.per_step.height_distribution): when given, the study's "
        "roughness levels are these, each step's slope drawn with terrain.per_step."
        "slope_sd_rad (default 0: the scene's slope); Monte Carlo only")
    method: Literal["mesh", "montecarlo", "both"] = Field(
        "both", description="mesh (rigid model), Monte Carlo, or both side by side")
    model: Literal["rigid", "contact"] = Field(
        "rigid", description="rigid: the hybrid model (mesh and Monte Carlo); contact: the "
        "compliant-contact model on checkerboard patches at the heights where each step's "
        "slope puts the next footfall, from its periodic gait (Monte Carlo only: set "
        "method montecarlo, and few walks and a short step cap - each walk is a contact "
        "simulation)")
    walks: int = Field(400, ge=1, le=1_000_000, description="Monte Carlo walks per sigma")
    max_steps: int = Field(2000, ge=1, le=1_000_000,
                           description="Monte Carlo step cap per walk (censoring) [steps]")
    seed: int = Field(0, ge=0, description="Monte Carlo seed [-] (terrain.per_step.seed "
                      "when that is given)")
    quadrature_nodes: int = Field(21, ge=3, le=61, description="quadrature nodes of the "
                                  "slope distribution in the mesh (Gauss-Hermite; "
                                  "Gauss-Legendre for a uniform) [-] (they integrate a fall "
                                  "indicator, whose tails 9 nodes resolve too coarsely: +20 % "
                                  "MFPT for the paper walker at 0.004 rad)")
    mesh_cells: int = Field(2000, ge=10, le=1_000_000, description="nodes of the first "
                            "mesh [-]")
    mesh_refine: float = Field(2.0, gt=1, le=8, description="node-count factor per "
                               "refinement [-]")
    mesh_max_cells: int = Field(16000, ge=10, le=2_000_000,
                                description="largest mesh [nodes]; refinement stops there "
                                "(the paper walker at sigma 0.002 rad needs 32000)")
    mesh_rel_change: float = Field(0.05, gt=0, lt=1, description="refine until the MFPT "
                                   "changes by less than this between meshes [-]")
    rtol: float = Field(1e-9, ge=1e-12, lt=1e-3, description="integrator relative "
                        "tolerance per walk [-]")
    atol: float = Field(1e-9, gt=0, lt=1e-3, description="integrator absolute tolerance "
                        "per walk [rad, rad/s]")
    max_step_time_s: float = Field(5.0, gt=0, le=MAX_STEP_TIME_S, description="no heel "
                                   "strike within this = a fall [s]")

    @model_serializer(mode="wrap")
    def _drop_unset(self, handler):
        # a study of per-step slopes serialises as before (same content hashes)
        return drop_unset(handler(self), ("sigma_m",))

    @model_validator(mode="after")
    def _heights_by_montecarlo(self) -> MfptSettings:
        if self.sigma_m is not None and self.method != "montecarlo":
            raise ValueError(f"mfpt.method: {self.method}: the study of per-step heights "
                             "(mfpt.sigma_m) is Monte Carlo only (method: montecarlo)")
        if self.sigma_m is not None and self.model != "rigid":
            raise ValueError("mfpt.sigma_m: per-step heights are a rigid-model study "
                             "(model: rigid)")
        return self


class RobustnessSettings(Strict):
    """Robustness of the gait beyond ``|lambda|`` (``walkerlab robustness``): gait
    sensitivity norms (Hobbelen & Wisse 2007), the largest single step-down and step-up
    (bisection), and the MFPT at one per-step slope sigma by Monte Carlo (Byl & Tedrake 2009)."""

    sigma_rad: float = Field(0.003, gt=0, le=0.2, description="per-step slope standard "
                             "deviation of the MFPT [rad]")
    disturbances: list[Literal["slope", "floor_height", "push"]] = Field(
        ["slope", "floor_height", "push"], min_length=1, description="GSN disturbances: slope "
        "change [rad], floor height step [m] (one step), horizontal push at the hip at "
        "mid-stance (hip velocity change [m/s])")
    montecarlo_walks: int = Field(100, ge=1, le=100_000, description="Monte Carlo walks [-]")
    montecarlo_max_steps: int = Field(500, ge=1, le=1_000_000,
                                      description="step cap per walk (censoring) [steps]")
    seed: int = Field(0, ge=0, description="Monte Carlo seed [-]")
    resolution_m: float = Field(0.001, gt=0, le=0.05, description="bracket width of the "
                                "largest step-down/up bisection [m]")
    push_resolution_m_per_s: float = Field(0.001, gt=0, le=0.1, description="bracket "
                                           "width of the largest push bisection [m/s]")
    push_cap_m_per_s: float = Field(1.0, gt=0, le=10, description="largest push searched "
                                    "(hip velocity change) [m/s]")
    survival_steps: int = Field(40, ge=1, le=1000, description="undisturbed steps a walker "
                                "must take after a disturbance to survive it [steps]")
    contact: bool = Field(False, description="also the contact model's largest step-down "
                          "and step-up (patches at heights, from its periodic gait; each "
                          "bisection round is a few contact walks: minutes)")
    contact_survival_steps: int = Field(10, ge=1, le=200, description="heel strikes the "
                                        "contact model must make after the step to survive "
                                        "it [steps]")

