"""Where a contact run's footfalls landed on the checkerboard laid out for its gait.

Input: the run's per-leg foot traces and heel strikes (:func:`walkerlab.analysis.contact.
gait.gait_events`) and the walker's lanes (:func:`walkerlab.models.contact.model.
checkerboard_lanes`).  Output: a :class:`PatchFit` (each footfall's offset from its patch's
centre, the steps, the drift per step) and its note when the patches do not suit the gait.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["PATCH_EDGE", "PATCH_MARGIN_USED", "PatchFit", "patch_fit"]

#: a footfall this far (as a fraction of the smaller margin of :class:`PatchFit`) from its
#: patch's centre has used up most of the room the checkerboard gives it
PATCH_MARGIN_USED = 0.5
#: ... and this far, at its patch's edge: the patches are what the run met (nearer the
#: centre the footfall landed on its patch, and the note does not blame them)
PATCH_EDGE = 0.9


@dataclass
class PatchFit:
    """Where a contact run's footfalls landed on the checkerboard laid out for its gait.

    Footfall ``k`` of the gait has a patch centred at ``s = k l`` in its leg's lane
    (:func:`walkerlab.models.contact.model.checkerboard_lanes`, ``l`` the patch spacing,
    the rigid gait's step); a patch is ``2 h`` wide.  A footfall lands on ground while it is
    within ``h`` of its patch's centre; at mid-stance the swing foot passes the stance foot
    (a straight leg's swing foot dips below the ground line there) over the gap of its own
    lane, which reaches ``l - h`` either side of the stance footfall's patch centre.  The
    footfalls of a contact gait whose steps differ from the spacing drift through both.

    Attributes
    ----------
    spacing_m : float
        Patch spacing ``l`` [m] (footfall to footfall).
    half_width_m : float
        ``h`` [m] (``terrain.patch_width_m / 2``).
    offsets_m : ndarray (k,)
        Each heel strike's footfall minus its patch's centre [m] (negative: short of it).
    steps_m : ndarray (k,)
        Each step's length, footfall to footfall [m] (the first from the initial stance
        foot).
    """

    spacing_m: float
    half_width_m: float
    offsets_m: np.ndarray
    steps_m: np.ndarray

    @property
    def margin_m(self) -> float:
        """The smaller room [m] a footfall has: ``h`` (on its patch) or ``l - h`` (the swing
        foot over its lane's gap beside it)."""
        return min(self.half_width_m, self.spacing_m - self.half_width_m)

    @property
    def drift_m_per_step(self) -> float:
        """Least-squares slope of the footfalls' offsets over the heel strikes [m/step]
        (NaN with fewer than two)."""
        k = self.offsets_m.size
        return float(np.polyfit(np.arange(k), self.offsets_m, 1)[0]) if k >= 2 else np.nan

    def note(self) -> str:
        """Why the checkerboard does not suit the gait, when the last footfall used more
        than :data:`PATCH_MARGIN_USED` of :attr:`margin_m` ("" otherwise; a footfall short
        of :data:`PATCH_EDGE` of its patch's room is said to be on its patch, not blamed on
        the patches): its offset, the
        drift per step, the contact steps against the spacing, both margins, and the
        patch width that balances them."""
        if self.offsets_m.size < 2 or not np.isfinite(self.margin_m) or self.margin_m <= 0:
            return ""
        last = float(self.offsets_m[-1])
        if abs(last) < PATCH_MARGIN_USED * self.margin_m:
            return ""
        sp, h = self.spacing_m, self.half_width_m
        mean = float(np.mean(self.steps_m))
        head = (f"the patches ({2 * h:.3g} m wide at {sp:.4g} m spacing, the rigid gait's "
                "step) do not suit this gait's step"
                if abs(last) >= PATCH_EDGE * self.margin_m or sp - h < h else
                # well on its patch, whose room binds (not the gap's): not the patches' doing
                f"the footfalls drift on the patches ({2 * h:.3g} m wide at {sp:.4g} m "
                "spacing, the rigid gait's step), the last still on its patch")
        return (f"{head}: its contact steps average {mean:.4g} m, "
                f"its footfalls drifted {1e3 * self.drift_m_per_step:+.3g} mm a step and "
                f"heel strike {self.offsets_m.size} landed {last:+.3f} m from its patch's "
                f"centre, where a footfall has ±{h:.3g} m on its patch and the swing foot "
                f"±{sp - h:.3g} m over its lane's gap at mid-stance (terrain.patch_width_m "
                f"near {sp:.3g} m balances the two; contact_sim.start: periodic_gait lays the "
                "patches at the contact gait's own footfalls)")


def patch_fit(walker, t, feet: dict, hs_t, hs_leg, initial_stance: str = "leg2"
              ) -> PatchFit | None:
    """The footfalls of a contact run against its checkerboard (:class:`PatchFit`); None on
    continuous ground or without heel strikes.

    Parameters
    ----------
    walker : ContactWalker
        Its lanes (``walker.lane(leg)``, patch centres [m]) and ``patch_half_width`` [m].
    t : ndarray (n,)
        Sample times [s].
    feet : dict[str, FootTrace]
        Per leg (:func:`walkerlab.analysis.contact.gait.gait_events`' ``feet``).
    hs_t, hs_leg : sequence
        Heel-strike times [s] and legs.
    initial_stance : str
        The leg in stance at ``t[0]`` (its foot is footfall 0).
    """
    if getattr(walker, "continuous", True) or not len(hs_t):
        return None
    s_prev = float(feet[initial_stance].s[0])
    off, steps = [], []
    for th, leg in zip(hs_t, hs_leg):
        s = float(np.interp(th, t, feet[leg].s))
        lane = np.asarray(walker.lane(leg), float)
        if not lane.size:
            return None
        off.append(s - float(lane[np.argmin(np.abs(lane - s))]))
        steps.append(s - s_prev)
        s_prev = s
    c1, c2 = np.asarray(walker.lane("leg1"), float), np.asarray(walker.lane("leg2"), float)
    spacing = float(abs(c1[0] - c2[0])) if c1.size and c2.size else np.nan
    return PatchFit(spacing, float(walker.patch_half_width), np.array(off), np.array(steps))
