"""The ``optimize:`` section: a periodic gait of a powered walker by direct collocation
(``walkerlab optimize``; :mod:`walkerlab.optimal.transcription.step`).

Sources: Kelly (2017), "An introduction to trajectory optimization: how to do your own
direct collocation", SIAM Review 59(4):849-904 (Hermite-Simpson collocation); CasADi's
``Opti`` with IPOPT (Andersson et al. 2019, Math. Prog. Comp. 11:1-36).
"""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import ConfigDict, Field, model_serializer, model_validator

from walkerlab.config.base import AsTuple, Strict, drop_unset

__all__ = ["OptimizeGuess", "OptimizeSettings"]

#: the objectives of one step (``weighted``: a sum of them with ``weights``)
OBJECTIVE_NAMES = ("effort", "push_off_work", "cost_of_transport", "peak_torque")


class OptimizeGuess(Strict):
    """The collocation's starting step read from an artifact instead of the scene's gait:
    another ``optimize.h5`` (its states, torque, period and push-off), or a continuation
    artifact's branch at a parameter value (its gait there, one step of the scene's
    walker simulated from it; legs that differ: one stride, from another stride's
    ``optimize.h5`` or the stride map's start)."""

    model_config = ConfigDict(populate_by_name=True)

    from_: str = Field(alias="from", min_length=1, description="optimize.h5 or "
                       "continuation_<field>.h5, relative to the current folder")
    at: float | None = Field(None, description="continuation artifact: the parameter value "
                             "on the branch [the artifact's field unit]")
    branch: int = Field(0, ge=0, le=1000, description="continuation artifact: the branch")


class OptimizeSettings(Strict):
    """One step of the walker with a hip torque ``u`` (and the scene's push-off) found by
    Hermite-Simpson collocation: minimise the objective (``effort`` ``int u^2 dt`` by
    default, with the push-off's squared impulse added when it is ``free``) within the
    targets and constraints given; the result is replayed on the rigid model and called a
    gait only if the replay returns to its start within ``replay_tolerance``.  On massless
    legs (Kuo's walker) ``u`` is the torque per foot mass [N m/kg] on the swing leg."""

    objective: Literal["effort", "push_off_work", "cost_of_transport", "peak_torque",
                       "weighted"] = Field(
        "effort", description="effort: int u^2 dt [N^2 m^2 s] (plus push_off_weight P^2 "
        "when the push-off is free); push_off_work [J]; cost_of_transport: positive hip "
        "work (exact, slack variables) + push-off work per weight and step length [-], "
        "plus cost_of_transport_effort_weight * effort; peak_torque: max "
        "|u| [N m] (epigraph form); weighted: sum of weights[name] * name")
    weights: dict[Literal["effort", "push_off_work", "cost_of_transport", "peak_torque"],
                  float] | None = Field(None, description="objective: weighted: the terms' "
                                        "weights [1 / the term's unit]")
    cost_of_transport_effort_weight: float = Field(
        1e-4, ge=0, le=1e3, description="objective: cost_of_transport: the weight of "
        "int u^2 dt added to it, a small regularisation (the cost of transport alone leaves "
        "the torque free where it does negative or no work; 1e-6 let IPOPT end at 150 N m "
        "braking torques that do not replay on the compass walker at 0.6 m/s) "
        "[1 / (N^2 m^2 s); per kg^2 on massless legs]")
    intervals: int = Field(40, ge=4, le=400, description="Hermite-Simpson intervals [-]")
    push_off: Literal["fixed", "free"] = Field(
        "fixed", description="the push-off impulse: the scene's (fixed) or a decision "
        "variable in [0, push_off_max_n_s] (free)")
    push_off_max_n_s: float = Field(100.0, gt=0, le=1e4, description="largest free push-off "
                                    "[N s]")
    push_off_weight_per_s: float = Field(1.0, ge=0, le=1e6, description="weight of P^2 in "
                                         "the objective [1/s: N^2 s^2 -> N^2 m^2 s]")
    max_torque_n_m: float | None = Field(None, gt=0, le=1e5, description="|u| <= this [N m]")
    target_speed_m_per_s: float | None = Field(None, gt=0, le=20, description="step length "
                                               "/ step period [m/s]")
    target_step_length_m: float | None = Field(None, gt=0, le=10, description="[m]")
    target_step_period_s: float | None = Field(None, gt=0, le=20, description="[s]")
    min_clearance_m: float | None = Field(None, ge=-1, le=1, description="the swing foot at "
                                          "least this high above the slope at every point "
                                          "but the first and the last (no scuffing) [m]")
    friction_coefficient: float | None = Field(None, gt=0, le=10, description="the stance "
                                               "foot's normal force >= 0 and |tangential| "
                                               "<= this times it [-]")
    hip_angle_range_rad: Annotated[tuple[float, float] | None, AsTuple] = Field(
        None, description="the hip joint's limits on the swing - stance angle [rad]")
    touchdown_rate_rad_per_s: float = Field(0.05, gt=0, le=100, description="the heel-"
                                            "strike guard falls at least this fast at the "
                                            "end (no grazing touchdown) [rad/s]")
    initial_guess: OptimizeGuess | None = Field(None, description="start from another "
                                                "optimize.h5 or a continuation branch "
                                                "(default: the scene's gait)")
    replay_tolerance: float = Field(1e-6, gt=0, le=1.0, description="largest return error "
                                    "of the replay for a gait [rad, rad/s]")
    phase_replay: bool | None = Field(
        None, description="also replay the step with the torques as a function of the "
        "phase variable (the stance leg's angle): feed-forward + PD closed to its fixed "
        "point, and the feed-forward alone (optimize.h5's replay/phase_*); default: on for "
        "a five-link biped, off for the others (~20 step maps: on compiled flows for "
        "massive straight or kneed legs with point feet, ~10 ms each; massless legs and "
        "flat feet run the law in Python, ~2-3 s of CPU each)")
    design: Literal["virtual_constraints"] | None = Field(
        None, description="virtual_constraints: the walker's Bezier coefficients "
        "(walker.actuation.virtual_constraints) are the decision variables, with the step "
        "(FROST's formulation: the output dynamics at every point, impact invariance, "
        "delta^2 <= max_multiplier); the optimum is a feedback controller, written as a "
        "scene into the run folder (null: open-loop torques)")
    max_multiplier: float | None = Field(
        None, gt=0, lt=1, description="design: virtual_constraints: the restricted Poincare "
        "map's multiplier delta^2 at most this (the closed loop's stability) [-]")
    target_speeds_m_per_s: list[Annotated[float, Field(gt=0, le=20)]] | None = Field(
        None, min_length=1, max_length=8, description="design: virtual_constraints: one "
        "controller per speed (step length / step period) [m/s]")
    max_iterations: int | None = Field(
        None, ge=1, le=100_000, description="design: virtual_constraints: IPOPT's "
        "iterations per controller at most (default 1000; status "
        "Maximum_Iterations_Exceeded): a bound on work, the same on any machine")
    cpu_budget_s: float | None = Field(
        None, gt=0, le=86400, description="design: virtual_constraints: a CPU-time limit "
        "per controller a user may ask for [s] (default none: IPOPT is bounded by "
        "optimize.max_iterations); a design it stops (Maximum_CpuTime_Exceeded) depends on "
        "the machine: it is said so and never reused, a rerun designs again")

    @model_serializer(mode="wrap")
    def _as_given(self, handler):
        return drop_unset(handler(self), ("design", "max_multiplier",
                                          "target_speeds_m_per_s", "max_iterations",
                                          "cpu_budget_s"))

    @model_validator(mode="after")
    def _design(self) -> OptimizeSettings:
        if self.design is None:
            for k in ("max_multiplier", "target_speeds_m_per_s", "max_iterations",
                      "cpu_budget_s"):
                if getattr(self, k) is not None:
                    raise ValueError(f"optimize.{k}: give it with design: "
                                     "virtual_constraints (and only then)")
            return self
        if self.target_speeds_m_per_s is not None and self.target_speed_m_per_s is not None:
            raise ValueError("optimize.target_speeds_m_per_s: give it or target_speed_m_per_s,"
                             " not both")
        if self.objective != "effort":
            raise ValueError(f"optimize.objective: design: virtual_constraints minimises the "
                             f"effort per step length (int u^2 dt / step length), not "
                             f"{self.objective}: leave objective out")
        if self.push_off != "fixed" or self.initial_guess is not None:
            raise ValueError("optimize.push_off / initial_guess: design: virtual_constraints "
                             "starts from the scene's own controller and has no push-off")
        return self

    @model_validator(mode="after")
    def _targets(self) -> OptimizeSettings:
        given = [t for t in (self.target_speed_m_per_s, self.target_step_length_m,
                             self.target_step_period_s) if t is not None]
        if len(given) == 3:
            raise ValueError("optimize: speed, step length and step period together fix "
                             "one another: give at most two")
        if (self.objective == "weighted") != bool(self.weights):
            raise ValueError("optimize.weights: give them with objective: weighted (and "
                             "only then)")
        r = self.hip_angle_range_rad
        if r is not None and not r[0] < r[1]:
            raise ValueError("optimize.hip_angle_range_rad: [lo, hi] with lo < hi")
        return self
