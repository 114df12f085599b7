"""Validated run settings of a compliant-contact simulation: the scene's ``contact_sim``
section (:class:`ContactSimSettings`: strides, time, start, sample rate, the work bounds of
a run, of the periodic-gait search and of the adjust search, the optional wall-clock
limits), read through :mod:`walkerlab.config`.  The contact law itself is the ``contact``
section (:mod:`walkerlab.config.contact`, which re-exports these names).
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

#: Default work bound of one contact run (contact_sim.max_rhs_evaluations): right-hand-side
#: evaluations.  The paper's 5 strides take ~28,000 (about 4 us each on the compiled CyRK
#: right-hand side): the bound ends only a run that grinds (a contact chattering), about a
#: minute of a compiled right-hand side's work.
MAX_RHS_EVALUATIONS = 20_000_000

#: Default work bound of the periodic-gait search (contact_sim.periodic_max_step_maps):
#: step-map integrations (the warm-up, the root solves' and the Floquet Jacobians'
#: evaluations; the paper's search makes 60).
PERIODIC_MAX_STEP_MAPS = 5_000


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
        None, gt=0, description="Wall-clock limit of one contact run [s] (null, the default: "
        "none; the run is bounded by max_rhs_evaluations). A run it ends has outcome "
        "'time_limit', depends on the machine's speed and is never kept as the scene's "
        "result: the next run recomputes it.",
        json_schema_extra={"unit": "s"})
    max_rhs_evaluations: int | None = Field(
        MAX_RHS_EVALUATIONS, ge=1, description="Work bound of one contact run: the most "
        "right-hand-side evaluations it may make [-] (the paper's 5 strides make about "
        "28,000); past it the run ends with outcome 'work_limit', the same on any "
        "machine (null = none).")
    stop_after_strides: bool = Field(
        True, description="Strides cap: stop once 2 * n_strides + 1 heel strikes have "
        "happened, even if t_final_s is longer (a passive run at the end of that integration "
        "chunk; a powered run, which asks after each heel strike on the samples before it, "
        "at the heel strike after: 2 * n_strides + 2, its last step complete).")
    periodic_time_limit_s: float | None = Field(
        None, gt=0, description="Wall-clock limit of the periodic-gait search [s] (null, the "
        "default: none; the search is bounded by periodic_max_step_maps). A search it ends "
        "is reported as 'time_limit' and never kept as the scene's result.",
        json_schema_extra={"unit": "s"})
    periodic_max_step_maps: int | None = Field(
        PERIODIC_MAX_STEP_MAPS, ge=1, description="Work bound of the periodic-gait search: "
        "the most step-map integrations it may make [-] (the paper's search makes 60); "
        "past it the gait is reported as 'work_limit' (null = none).")
    adjust_max_contact_runs: int | None = Field(
        None, ge=1, description="Work bound of the `contact-sim --adjust` search: the most "
        "contact runs it may make [-] (null, the default: the search's own, 1 + 8^2 grid "
        "starts + 60 Nelder-Mead runs = 125); when they are spent the search keeps the best start "
        "found so far and says so.")
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
        # a scene with the default start, bounds and no start offset serialises as before
        # (same content hashes)
        d = handler(self)
        if not isinstance(d, dict):
            return d
        for name, default in _DROPPED_DEFAULTS.items():
            if name in d and d[name] == default:
                d.pop(name)
        return d


#: fields left out of a scene's serialisation (its content hash) at these values: the
#: defaults of fields added after scenes were hashed
_DROPPED_DEFAULTS = {"start": "ideal", "start_offset": None,
                     "max_rhs_evaluations": MAX_RHS_EVALUATIONS,
                     "periodic_max_step_maps": PERIODIC_MAX_STEP_MAPS,
                     "adjust_max_contact_runs": None}
