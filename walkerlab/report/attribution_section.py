"""Report section: the paper's Section-5 attribution (``attribution.h5``, opt-in with
``walkerlab report --full``).  Reads the loaded
:class:`walkerlab.io.schemas.attribution.AttributionArtifact` only."""

from __future__ import annotations

import numpy as np

from walkerlab.report.markdown import num, table
from walkerlab.units import for_scene

_CAUSES = (("gap", "total: contact periodic gait − rigid gait"),
           ("creep", "friction creep (stiction regularisation → 0)"),
           ("compliance", "compliance (rigid-limit family ×1e3, creep off)"),
           ("residual", "residual (both off)"))


def attribution_section(scene, arts: dict) -> list[str]:
    """The contact-vs-rigid gap split by cause, the energy per step by sink and whether
    the scene's (adjusted) start lies in the rigid walker's basin; [] without the artifact."""
    a = arts.get("attribution")
    if a is None:
        return []
    u = for_scene(scene)
    ts, tl = (1e3, "ms") if not u.nondimensional else (1.0, u.time)
    ls, ll = u.small_scale, u.small_length

    def cell(v, scale):
        return "failed" if not np.isfinite(v) else f"{num(v * scale, 4):>s}"
    rows = [[label, cell(a.gaps[c][0], ts), cell(a.gaps[c][1], ls)] for c, label in _CAUSES]
    out = ["## Why the contact gait differs from the rigid one (Section 5)", "",
           "Each cause switched off in turn on the contact model's own periodic gait "
           f"(rigid step period {num(a.rigid_period_s, 6)} {u.time}):", "",
           table(["cause", f"step-period gap [{tl}]", f"step-length gap [{ll}]"], rows), "",
           "Energy dissipated per step of the periodic gait: "
           + ", ".join(f"{k.replace('_', ' ')} {num(v, 4)} {u.energy}"
                       for k, v in a.energy_J.items()) + "."]
    scale = tuple(float(s) for s in a.rate_scale)
    if scale != (1.0, 1.0):
        unadj = ("the run from the unscaled start fell" if not np.isfinite(
            a.unadjusted_period_s) else f"from the unscaled start {num(a.unadjusted_period_s, 5)}"
                 f" {u.time}")
        # inside: every step of the rigid run ended in a heel strike
        basin = "inside" if a.rigid_from_adjusted == "heel_strike" else "outside"
        out += ["", f"Initial-rate adjustment ×({num(scale[0], 3)}, {num(scale[1], 3)}): mean "
                f"step period of the contact run {num(a.adjusted_period_s, 5)} {u.time} ({unadj}"
                f"); the rigid walker started there ends with '{a.rigid_from_adjusted}' after "
                f"{a.rigid_heel_strikes} heel strikes: the adjusted start is {basin} the rigid "
                "walker's basin."]
    return out + [""]
