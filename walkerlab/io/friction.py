"""The friction a rigid gait needs, as a record (:class:`FrictionVerdict`): computed by
:mod:`walkerlab.analysis.gait.friction`, stored in ``fixedpoint.h5``'s
``ground_contact/friction/`` and read back by :mod:`walkerlab.io.schemas.fixedpoint` (the
record lies below both: the artifact layer reads it without the analysis)."""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ["FrictionVerdict"]


@dataclass
class FrictionVerdict:
    """The friction a rigid gait needs against the ground's.

    Attributes
    ----------
    max_ratio : float
        Largest ``|F_t| / F_n`` over every foot on the ground, while its normal force
        pushes [-]; ``inf`` where a foot's normal force falls to 0 (it leaves the ground)
        while it still carries a tangential force (:data:`UNLOADED`); NaN: not checked.
    foot : str
        Where it occurs (``"stance foot"``, ``"trailing toe"`` or ``"leading foot"``: the
        latter two in double support).
    time_s : float
        When, from the start of the map [s].
    single_support_max_ratio, double_support_max_ratio : float
        The largest ratio in single and in double support [-] (NaN: no such phase).
    mu : float
        The ground's static friction coefficient [-].
    mu_source : str
        ``"contact.mu_static"`` or ``"the contact model's default"``.
    not_checked : str
        Why the ratio could not be computed ("" when it was).
    exit_time_s : float
        The first time a foot's force leaves the cone ``|F_t| <= mu F_n`` [s] from the
        map's start (NaN: it never does).
    unloaded_tangential_n : float
        The tangential force [N] a foot carries as its normal force falls to 0 (NaN: none),
        which makes ``max_ratio`` infinite.
    """

    max_ratio: float = math.nan
    foot: str = ""
    time_s: float = math.nan
    single_support_max_ratio: float = math.nan
    double_support_max_ratio: float = math.nan
    mu: float = math.nan
    mu_source: str = ""
    not_checked: str = ""
    exit_time_s: float = math.nan
    unloaded_tangential_n: float = math.nan

    @property
    def inside(self) -> bool | None:
        """True: every foot's force stays inside the friction cone (``max_ratio <= mu``);
        False: it leaves it; None: not checked."""
        if self.not_checked or math.isnan(self.max_ratio) or not math.isfinite(self.mu):
            return None
        return bool(self.max_ratio <= self.mu)

    def needed(self) -> str:
        """``mu >= 0.188``, or ``an unbounded mu``."""
        return "an unbounded mu" if math.isinf(self.max_ratio) else \
            f"mu >= {self.max_ratio:.3g}"

    def text(self) -> str:
        """One line: ``friction: needs mu >= 0.188 (stance foot); the ground's mu is 0.9
        (contact.mu_static): inside the friction cone``."""
        if self.inside is None:
            return f"friction: not checked ({self.not_checked or 'no friction coefficient'})"
        where = self.foot + (" in double support" if self.foot != "stance foot" else "")
        if math.isinf(self.max_ratio):
            when = "in double support " if self.foot != "stance foot" else ""
            need = (f"needs an unbounded mu ({when}the {self.foot}'s normal force falls to 0 "
                    f"at t = {self.time_s:.4g} s while it carries "
                    f"{abs(self.unloaded_tangential_n):.3g} N along the ground)")
        else:
            need = (f"needs mu >= {self.max_ratio:.3g} (largest |F_t/F_n|, {where}, "
                    f"t = {self.time_s:.4g} s)")
        head = f"friction: {need}; the ground's mu is {self.mu:.3g} ({self.mu_source})"
        if self.inside:
            return head + ": inside the friction cone"
        return (head + f": NOT a gait on this ground (the force leaves the cone at "
                f"t = {self.exit_time_s:.4g} s: the foot would slip)")
