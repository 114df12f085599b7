"""Validated run settings of a compliant-contact simulation: the scene's ``contact_sim``
section (:class:`ContactSimSettings`: strides, time, start, sample rate, wall-time limits,
the periodic-gait search), read through :mod:`walkerlab.config`.  The contact law itself is
the ``contact`` section (:mod:`walkerlab.config.contact`, which re-exports these names).
"""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import (
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Field,
    model_serializer,
)

from walkerlab.config.base import _list_to_tuple
from walkerlab.config.studies import StateOffset

# Longest contact run (D8): 100 strides is ~20x the paper's 5 and keeps the artifact < 100 MB.
MAX_CONTACT_STRIDES = 100


class ContactSimSettings(BaseModel):
    """Run settings of a contact simulation."""

    # strict finite numbers, as walkerlab.config.base.Strict (the contact sections' rules)
    model_config = ConfigDict(extra="forbid", strict=True, allow_inf_nan=False)

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
        "multipliers (walkerlab.analysis.contact.periodic; about 5-10 s)."
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
        "happened, even if t_final_s is longer (a passive run at the end of that integration "
        "chunk; a powered run, which asks after each heel strike on the samples before it, "
        "at the heel strike after: 2 * n_strides + 2, its last step complete).")
    periodic_time_limit_s: float | None = Field(
        120.0, gt=0, description="Wall-time limit of the periodic-gait search [s]; when it "
        "runs out the gait is reported as 'time_limit' (null = none).",
        json_schema_extra={"unit": "s"})
    adjust_cpu_budget_s: float | None = Field(
        300.0, gt=0, description="CPU-time budget of the `contact-sim --adjust` search [s], "
        "checked between its contact runs (a run under way is finished); when it is spent "
        "the search keeps the best start found so far and says so (null = none).",
        json_schema_extra={"unit": "s"})
    start: Literal["ideal", "adjusted", "periodic_gait", "mid_stance"] = Field(
        "ideal", description="Initial state of the run: 'ideal' (the rigid fixed point, rates "
        "times initial_rate_scale; the default, for a passive flat-footed walker on its "
        "slope 'mid_stance'), 'adjusted' (rates searched as `contact-sim "
        "--adjust`), 'periodic_gait' (the contact model's own periodic gait at mid-stance, "
        "on patches spaced by its step length: steady state without start-up transients; "
        "adds the periodic-gait search, about 5-10 s), 'mid_stance' (flat feet: the rigid "
        "gait at its mid-stance, the legs parallel and the stance foot flat at its static "
        "deflection, rates times initial_rate_scale; no impact under way at the start).")

    start_offset: StateOffset | None = Field(
        None, description="A change added to the start state (the rigid gait's, or its "
        "mid-stance's), by the rigid state's names with units, e.g. {lean_rate_rad_per_s: "
        "0.05}; states not named are unchanged. For an unstable rigid gait whose unstable "
        "mode the start does not excite (a 3D walker started exactly upright: its lean "
        "grows from round-off only); the patches stay at the rigid gait's footfalls.")

    @model_serializer(mode="wrap")
    def _drop_default_start(self, handler):
        # a scene with the default start serialises as before (same content hashes)
        d = handler(self)
        if isinstance(d, dict) and d.get("start") == "ideal":
            d.pop("start", None)
        if isinstance(d, dict) and d.get("adjust_cpu_budget_s") == 300.0:
            d.pop("adjust_cpu_budget_s", None)  # likewise the default budget
        if isinstance(d, dict) and d.get("start_offset", 0) is None:
            d.pop("start_offset", None)  # and no start offset
        return d
