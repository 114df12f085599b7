"""The ``optimize:`` section: a periodic gait of a powered walker by direct collocation
(``walkerlab optimize``; :mod:`walkerlab.optimal.collocation`).

Sources: Kelly (2017), "An introduction to trajectory optimization: how to do your own
direct collocation", SIAM Review 59(4):849-904 (Hermite-Simpson collocation); CasADi's
``Opti`` with IPOPT (Andersson et al. 2019, Math. Prog. Comp. 11:1-36).
"""

from __future__ import annotations

from typing import Literal

from pydantic import Field, model_validator

from walkerlab.config.base import Strict

__all__ = ["OptimizeSettings"]


class OptimizeSettings(Strict):
    """One step of the walker with a hip torque ``u`` (and the scene's push-off) found by
    Hermite-Simpson collocation: minimise ``int u^2 dt`` (objective ``effort``), with the
    push-off's squared impulse added when it is ``free``; the result is replayed on the rigid
    model and called a gait only if the replay returns to its start within
    ``replay_tolerance``."""

    objective: Literal["effort"] = Field("effort", description="int u^2 dt [N^2 m^2 s] (plus "
                                         "push_off_weight P^2 when the push-off is free)")
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
    replay_tolerance: float = Field(1e-6, gt=0, le=1.0, description="largest return error "
                                    "of the replay for a gait [rad, rad/s]")

    @model_validator(mode="after")
    def _targets(self) -> OptimizeSettings:
        given = [t for t in (self.target_speed_m_per_s, self.target_step_length_m,
                             self.target_step_period_s) if t is not None]
        if len(given) == 3:
            raise ValueError("optimize: speed, step length and step period together fix "
                             "one another: give at most two")
        return self
