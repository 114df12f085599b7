"""``attribution.h5``: the contact-vs-rigid gap of the periodic gait split by cause, the
energy per step by sink and the initial-rate adjustment's effect (writer and loader).

Layout (scalars, each with unit and description): ``gap/period``, ``gap/step_length`` (the
scene's contact periodic gait - the rigid gait [s, m]); ``creep/period``,
``creep/step_length``, ``compliance/...``, ``residual/...`` (the split,
:class:`walkerlab.analysis.contact.attribution.Attribution`; NaN where a search failed);
``energy/<sink>`` [J] per step (``normal_damping``, ``friction_impact``, ``friction_stance``);
``adjustment/adjusted_period``, ``adjustment/unadjusted_period`` [s] (mean step period of
the contact run from the scene's start and from the unscaled ideal start),
``adjustment/rate_scale`` (2,) [-].  Root attributes: ``rigid_period_s``,
``rigid_from_adjusted`` (the rigid run's end from the adjusted start),
``rigid_heel_strikes``.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from walkerlab.io.artifacts import artifact_loader, put

STAGE = "attribution"
CAUSES = ("gap", "creep", "compliance", "residual")
SINKS = ("normal_damping", "friction_impact", "friction_stance")


@dataclass
class AttributionRun:
    """What the attribution stage computed (the writer's input).

    Attributes
    ----------
    attribution : walkerlab.analysis.contact.attribution.Attribution
    adjustment : dict
        :func:`walkerlab.analysis.contact.attribution.adjustment_effect`'s result.
    rigid_period_s : float
        The rigid gait's step period [s].
    """

    attribution: object
    adjustment: dict
    rigid_period_s: float


def write_attribution(f, run: AttributionRun) -> None:
    """Fill an open (in-memory) artifact with ``run`` (layout in the module docstring)."""
    a, adj = run.attribution, run.adjustment
    vals = {"gap": (a.period_gap_s, a.step_gap_m), "creep": (a.creep_s, a.creep_m),
            "compliance": (a.compliance_s, a.compliance_m),
            "residual": (a.residual_s, a.residual_m)}
    what = {"gap": "contact periodic gait - rigid gait",
            "creep": "share of friction creep (stiction regularisation -> 0)",
            "compliance": "share of compliance (rigid-limit family x1e3, creep off)",
            "residual": "gap left with creep and compliance off"}
    for cause, (T, L) in vals.items():
        put(f, f"{cause}/period", float(T), "s", f"step period: {what[cause]}")
        put(f, f"{cause}/step_length", float(L), "m", f"step length: {what[cause]}")
    for sink in SINKS:
        put(f, f"energy/{sink}", float(a.energy_J[sink]), "J",
            f"dissipated per step of the periodic gait: {sink.replace('_', ' ')}")
    put(f, "adjustment/adjusted_period", float(adj["adjusted_s"]), "s",
        "mean step period of the contact run from the scene's start (NaN: fell)")
    put(f, "adjustment/unadjusted_period", float(adj["unadjusted_s"]), "s",
        "mean step period of the contact run from the unscaled ideal start (NaN: fell)")
    put(f, "adjustment/rate_scale", np.asarray(adj["rate_scale"], float), "-",
        "multipliers on the initial rates of the scene's start")
    f.attrs["rigid_period_s"] = float(run.rigid_period_s)
    f.attrs["rigid_from_adjusted"] = str(adj["rigid_from_adjusted"])
    f.attrs["rigid_heel_strikes"] = int(adj["rigid_heel_strikes"])


@dataclass
class AttributionArtifact:
    """A loaded ``attribution.h5``.

    Attributes
    ----------
    gaps : dict[str, tuple[float, float]]
        Per cause (:data:`CAUSES`): (period [s], step length [m]).
    energy_J : dict[str, float]
        Per sink (:data:`SINKS`) [J per step].
    adjusted_period_s, unadjusted_period_s : float
    rate_scale : ndarray (2,)
    rigid_period_s : float
    rigid_from_adjusted : str
    rigid_heel_strikes : int
    """

    path: Path
    gaps: dict
    energy_J: dict
    adjusted_period_s: float
    unadjusted_period_s: float
    rate_scale: np.ndarray
    rigid_period_s: float
    rigid_from_adjusted: str
    rigid_heel_strikes: int


@artifact_loader(STAGE)
def load_attribution(f, path: Path) -> AttributionArtifact:
    """Load ``attribution.h5``."""
    gaps = {c: (float(f[f"{c}/period"][()]), float(f[f"{c}/step_length"][()]))
            for c in CAUSES}
    energy = {s: float(f[f"energy/{s}"][()]) for s in SINKS}
    return AttributionArtifact(
        Path(path), gaps, energy, float(f["adjustment/adjusted_period"][()]),
        float(f["adjustment/unadjusted_period"][()]),
        np.asarray(f["adjustment/rate_scale"][()], float),
        float(f.attrs["rigid_period_s"]), str(f.attrs["rigid_from_adjusted"]),
        int(f.attrs["rigid_heel_strikes"]))
