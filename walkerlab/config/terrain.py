"""Validated settings of the ground under the walker (pydantic v2): the ``terrain`` section
(:class:`TerrainSettings`: slope, stairs, footholds or a height profile, and the contact
model's lanes on it) and the rigid model's per-step ground (:class:`PerStepTerrain`).

Read through :mod:`walkerlab.config` (and importable from :mod:`walkerlab.config.contact`, where
they were first written); this module imports no model.
"""

from __future__ import annotations

import math
from typing import Annotated, Literal

from pydantic import BaseModel, BeforeValidator, Field, model_serializer, model_validator

from walkerlab.config.base import _list_to_tuple, check_one_of, drop_unset

__all__ = ["GROUND_KINDS", "LANE_KINDS", "PerStepTerrain", "TerrainSettings", "check_profile"]

# Numbers are strict and finite, unknown keys rejected (as the contact sections'; a pydantic
# ``ConfigDict`` is this dict).
_STRICT = {"extra": "forbid", "strict": True, "allow_inf_nan": False}


def _points_to_tuples(v):
    return tuple(_list_to_tuple(p) for p in v) if isinstance(v, list) else v

class PerStepTerrain(BaseModel):
    """Per-step ground of the rigid model (Byl & Tedrake 2009, "Metastable walking machines").

    Step ``n`` is taken on the straight line through the stance foot at slope ``gamma_n``
    (for a compass walker the heel-strike guard becomes ``theta_swing + theta_stance =
    -2 gamma_n``).  ``gamma_n`` is drawn i.i.d. about the scene's slope (``slope_sd_rad``;
    ``normal`` or ``uniform`` with the same standard deviation), reproducibly from ``seed``.
    With ``height_sd_m``, step ``n``'s landing also lies ``h_n`` [m] above that line
    (``h_n`` i.i.d. about 0, ``height_distribution``; its own stream of the same seed): the
    heel strike is the swing foot's clearance above the line reaching ``h_n cos(gamma_n)``.
    """

    model_config = _STRICT

    slope_distribution: Literal["normal", "uniform"] = Field(
        "normal", description="distribution of each step's slope about the scene's slope")
    slope_sd_rad: float = Field(0.0, ge=0, le=0.2,
                                description="standard deviation of each step's slope [rad]")
    seed: int = Field(0, ge=0, description="seed of the per-step draws [-]")
    height_distribution: Literal["normal", "uniform"] | None = Field(
        None, description="distribution of each step's landing height about the stance "
        "foot's level (default normal)")
    height_sd_m: float | None = Field(
        None, ge=0, le=0.2, description="standard deviation of each step's landing height "
        "above the slope line through the stance foot [m] (default 0: the slope)",
        json_schema_extra={"unit": "m"})

    @model_serializer(mode="wrap")
    def _drop_unset(self, handler):
        # a scene without per-step heights serialises as before (same content hashes)
        return drop_unset(handler(self), ("height_distribution", "height_sd_m"))

    @property
    def heights(self) -> tuple[str, float]:
        """``(distribution, sd [m])`` of the per-step landing heights (normal, 0 unset)."""
        return (self.height_distribution or "normal",
                0.0 if self.height_sd_m is None else float(self.height_sd_m))


#: Ground kinds of the ``terrain`` section (:class:`TerrainSettings`); ``slope`` is the
#: scene's straight ramp (``slope.angle_*``), the ground of every scene before stairs,
#: footholds and profiles.
GROUND_KINDS = ("slope", "stairs", "footholds", "profile")
#: The contact model's lanes (:attr:`TerrainSettings.lanes`), once written as ``kind``.
LANE_KINDS = ("checkerboard", "continuous")


class TerrainSettings(BaseModel):
    """The ground under the walker, for every stage: its geometry (``kind``) and the contact
    model's lanes on it (``lanes``).

    Ground (``kind``)
        ``slope`` (default): the straight ramp of the scene's ``slope`` section (today's
        ground).  ``stairs``: level treads ``tread_m`` deep, each ``riser_m`` below
        (``direction: down``) or above (``up``) the last, one step per stair (the feet land
        on the treads; the scene's slope must then be 0).  ``footholds``: one foothold per
        step, the landing ``foothold_heights_m[k]`` [m] above the stance foot's level
        (negative: below), on ground of slope ``foothold_slopes_rad[k]`` [rad]; ``periodic``
        repeats the list, else the walk ends after it.  ``profile``: a piecewise-linear
        height profile ``y(x)`` [m], inline (``profile_m: [[x, y], ...]``, x increasing) or
        from a two-column CSV (``profile_csv``, relative to the scene's file).
    Lanes (``lanes``, the compliant contact model's option on any ground)
        ``checkerboard``: each leg has its own lane with ground patches of width
        ``patch_width_m`` centred on that leg's ideal footfalls: leg2 at ``s = 0, 2l, 4l,
        ...``, leg1 at ``s = l, 3l, ...`` (``l`` = ideal step length, given at run time);
        elsewhere in the lane there is no ground (a gap), so the swing foot is not scuffed at
        mid-stance.  ``continuous``: ground everywhere.  Written before as ``kind:
        checkerboard|continuous`` (still read so, and a plain slope is written back so: the
        scene's content hash is unchanged).
    ``per_step``
        Ground that changes from step to step (rigid model's MFPT), as before.

    Raises
    ------
    ValueError
        (one line, naming the field) a field of another ground kind, stairs without their
        riser or tread, a profile that is not a function of x (x not increasing), an empty
        foothold list.
    """

    model_config = _STRICT

    kind: Literal["slope", "stairs", "footholds", "profile"] = Field(
        "slope", description="ground: 'slope' (the scene's ramp, default), 'stairs', "
        "'footholds' or 'profile'; 'checkerboard'/'continuous' (read as lanes) as before")
    lanes: Literal["checkerboard", "continuous"] = Field(
        "checkerboard", description="contact model: 'checkerboard' (per-leg patches at "
        "footfalls) or 'continuous' ground")
    patch_width_m: float = Field(
        0.10, gt=0, description="Width of each checkerboard patch along the slope [m]."
    )
    riser_m: float | None = Field(
        None, gt=0, le=10, description="stairs: height of each riser [m]",
        json_schema_extra={"unit": "m"})
    tread_m: float | None = Field(
        None, gt=0, le=100, description="stairs: depth of each tread [m] (longer than the "
        "walker's foot)", json_schema_extra={"unit": "m"})
    direction: Literal["down", "up"] | None = Field(
        None, description="stairs: 'down' (default) or 'up' in the walking direction")
    first_foothold_m: float | None = Field(
        None, ge=0, le=100, description="stairs: where the first stance foot stands on its "
        "tread, from the tread's back (riser) end [m]; default mid-tread",
        json_schema_extra={"unit": "m"})
    foothold_heights_m: Annotated[tuple[float, ...] | None, BeforeValidator(_list_to_tuple)] = \
        Field(None, description="footholds: height of each step's landing above the stance "
              "foot's level [m] (negative: a step down)", json_schema_extra={"unit": "m"})
    foothold_slopes_rad: Annotated[tuple[float, ...] | None,
                                   BeforeValidator(_list_to_tuple)] = Field(
        None, description="footholds: each step's ground slope [rad] (default the scene's "
        "slope)", json_schema_extra={"unit": "rad"})
    periodic: bool | None = Field(
        None, description="footholds: repeat the list (default true); false: finite ground")
    profile_m: Annotated[tuple[tuple[float, float], ...] | None,
                         BeforeValidator(_points_to_tuples)] = Field(
        None, description="profile: points [[x, y], ...] of a piecewise-linear ground height "
        "y(x) [m], x increasing", json_schema_extra={"unit": "m"})
    profile_csv: str | None = Field(
        None, max_length=1000, description="profile: a CSV file of x, y [m] rows (relative "
        "to the scene's file)")
    per_step: PerStepTerrain | None = Field(
        None, description="Ground that changes from step to step (rough terrain, a step-down); "
        "used by the rigid model's metastability and disturbance studies (walkerlab mfpt)")

    @model_validator(mode="before")
    @classmethod
    def _lanes_written_as_kind(cls, data):
        # today's scenes write the contact lanes as ``kind: checkerboard|continuous``
        if isinstance(data, dict) and data.get("kind") in LANE_KINDS:
            if "lanes" in data:
                raise ValueError(f"terrain: kind: {data['kind']} is the contact lanes; "
                                 "give lanes once (kind: slope|stairs|footholds|profile, "
                                 "lanes: checkerboard|continuous)")
            data = {**data, "lanes": data["kind"], "kind": "slope"}
        return data

    @model_validator(mode="after")
    def _ground_fields(self) -> TerrainSettings:
        own = {"stairs": ("riser_m", "tread_m", "direction", "first_foothold_m"),
               "footholds": ("foothold_heights_m", "foothold_slopes_rad", "periodic"),
               "profile": ("profile_m", "profile_csv"), "slope": ()}
        for kind, names in own.items():
            if kind == self.kind:
                continue
            for name in names:
                if getattr(self, name) is not None:
                    raise ValueError(f"terrain.{name}: only for kind: {kind} "
                                     f"(this ground is kind: {self.kind})")
        if self.kind == "stairs":
            for name in ("riser_m", "tread_m"):
                if getattr(self, name) is None:
                    raise ValueError(f"terrain.{name}: kind: stairs needs riser_m and tread_m")
            if self.first_foothold_m is not None and self.first_foothold_m > self.tread_m:
                raise ValueError(f"terrain.first_foothold_m ({self.first_foothold_m:g} m) is "
                                 f"past the tread's end (tread_m {self.tread_m:g} m)")
        if self.kind == "footholds":
            h, g = self.foothold_heights_m, self.foothold_slopes_rad
            if not h and not g:
                raise ValueError("terrain.foothold_heights_m: kind: footholds needs a list of "
                                 "heights and/or foothold_slopes_rad")
            if h and g and len(h) != len(g):
                raise ValueError(f"terrain.foothold_slopes_rad: {len(g)} slopes for "
                                 f"{len(h)} heights (one of each per step)")
            bad = [v for v in (*(h or ()), *(g or ())) if not math.isfinite(v)]
            if bad or any(abs(v) >= math.pi / 2 for v in (g or ())):
                raise ValueError("terrain.foothold_*: finite heights [m] and slopes within "
                                 "(-pi/2, pi/2) [rad]")
        if self.kind == "profile":
            check_one_of(self, "profile_m", "profile_csv", "terrain.profile_m: kind: profile "
                         "needs profile_m or profile_csv (one of them)")
            if self.profile_m is not None:
                check_profile(self.profile_m, "terrain.profile_m")
        return self

    @property
    def is_slope(self) -> bool:
        """Whether the ground is the scene's straight slope (today's ground)."""
        return self.kind == "slope"

    def ground(self) -> dict:
        """The ground's own fields (no lanes, patches or per-step draws): what the rigid
        model's stages depend on (:meth:`walkerlab.config.Scene.section_json`)."""
        d = self.model_dump(mode="json")
        return {k: v for k, v in d.items()
                if k not in ("lanes", "patch_width_m", "per_step")}

    @model_serializer(mode="wrap")
    def _drop_unset(self, handler):
        # a scene of today's ground serialises as before (same content hashes): no unset
        # field, the lanes written as ``kind``
        d = drop_unset(handler(self), (
            "per_step", "riser_m", "tread_m", "direction", "first_foothold_m",
            "foothold_heights_m", "foothold_slopes_rad", "periodic", "profile_m", "profile_csv"))
        if not isinstance(d, dict):
            return d
        if d.get("kind") == "slope":
            d["kind"] = d.pop("lanes")
            d = {"kind": d.pop("kind"), **d}
        return d


def check_profile(points, where: str) -> None:
    """Check a height profile ``[(x, y), ...]`` [m] is a function of x: at least two points,
    finite, x strictly increasing.

    Raises
    ------
    ValueError
        One line naming ``where`` and the first offending point.
    """
    if len(points) < 2:
        raise ValueError(f"{where}: a profile needs at least two points [x, y]")
    for i, (x, y) in enumerate(points):
        if not (math.isfinite(x) and math.isfinite(y)):
            raise ValueError(f"{where}: point {i} ({x}, {y}) is not finite")
        if i and not x > points[i - 1][0]:
            raise ValueError(f"{where}: point {i} has x = {x:g} m after x = "
                             f"{points[i - 1][0]:g} m: the height profile must be a function "
                             "of x (x strictly increasing)")
