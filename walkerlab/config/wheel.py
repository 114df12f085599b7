"""The rimless wheel's walker section (``walker: {model: rimless_wheel}``), one of the
walker sections of :mod:`walkerlab.config.walker`."""

from __future__ import annotations

from typing import Literal

from pydantic import Field, model_validator

from walkerlab.config.base import Strict

__all__ = ["RimlessWheelParams"]


class RimlessWheelParams(Strict):
    """A rimless wheel (McGeer 1990, "Passive dynamic walking", IJRR 9(2); Coleman,
    Chatterjee & Ruina 1997, "Motions of a rimless spoked wheel", Dynamics and Stability
    of Systems 12(3)): one rigid body, a hub of mass ``mass_kg`` (a point mass unless
    ``hub_inertia_kg_m2`` is given) with ``spokes`` massless spokes of length
    ``spoke_length_m``, ``2 pi / spokes`` apart.  It rolls about the stance spoke's foot;
    the next spoke's foot striking the slope is the heel strike (plastic, angular momentum
    about the new contact point conserved).  Drake's ``RimlessWheel`` example has the same
    parameters (mass, length, gravity, number_of_spokes)."""

    model: Literal["rimless_wheel"] = Field(description="walker model name")
    spokes: int = Field(ge=3, le=360, description="number of spokes n [-] (the angle "
                        "between neighbouring spokes is 2 pi / n)")
    spoke_length_m: float = Field(gt=0, le=100, description="spoke length L, hub to "
                                  "foot [m]")
    mass_kg: float = Field(gt=0, le=1e4, description="hub mass M [kg]")
    gravity_m_per_s2: float = Field(9.81, gt=0, le=100, description="gravity g [m/s^2]")
    hub_inertia_kg_m2: float | None = Field(None, ge=0, le=1e6, description="moment of "
                                            "inertia of the wheel about its hub [kg m^2] "
                                            "(null: a point mass, 0)")
    space: Literal["2d", "3d"] = Field("2d", description="2d: the wheel rolls in the "
                                       "sagittal plane; 3d: free about every axis of its "
                                       "stance foot (heading, lean and spin; Coleman, "
                                       "Chatterjee & Ruina 1997)")
    diametral_inertia_kg_m2: float | None = Field(
        None, gt=0, le=1e6, description="moment of inertia of the wheel about a diameter "
        "through its hub [kg m^2] (space: 3d only, where it is required; the axle's is "
        "hub_inertia_kg_m2)")

    @model_validator(mode="after")
    def _inertia_3d(self):
        if self.space == "3d" and self.diametral_inertia_kg_m2 is None:
            raise ValueError("walker.diametral_inertia_kg_m2: a wheel in 3d needs its "
                             "inertia about a diameter (> 0: the spin about the stance "
                             "spoke has no other)")
        if self.space == "2d" and self.diametral_inertia_kg_m2 is not None:
            raise ValueError("walker.diametral_inertia_kg_m2: only a wheel in 3d (space: "
                             "3d) turns about a diameter")
        return self

    @property
    def actuation(self) -> None:
        """The wheel is passive: no ``actuation`` section (a key given is refused as any
        unknown key)."""
        return None
