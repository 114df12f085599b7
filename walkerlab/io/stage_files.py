"""The stages' artifacts: stage name -> its file in ``runs/<scene>/`` and its schema loader.

The lowest place that names the stages: :mod:`walkerlab.io.runpaths` (the file names a
sweep may not take), :mod:`walkerlab.io.schemas.loaders` (any artifact by stage name), the
studies' per-stage tables and the stage registry
(:data:`walkerlab.stages.registry.STAGES`) read their names here.  Nothing here imports a
schema: a loader is imported on first use (:meth:`StageArtifact.load`).
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass
from pathlib import Path


@dataclass(frozen=True)
class StageArtifact:
    """One stage's artifact.

    Attributes
    ----------
    name : str
        The stage's name: its CLI command (``walkerlab contact-sim``) and its key in a
        ``{stage: artifact}`` mapping.
    schema : str
        Its schema module under :mod:`walkerlab.io.schemas` (also the artifact's file
        stem: ``contact_sim`` -> ``contact_sim.h5``); by default the name with ``_`` for
        ``-``.
    loader : str
        The schema module's loader; by default ``load_<schema>`` (``load_contact_sim``).
    """

    name: str
    schema: str = ""
    loader: str = ""

    def __post_init__(self):
        if not self.schema:
            object.__setattr__(self, "schema", self.name.replace("-", "_"))
        if not self.loader:
            object.__setattr__(self, "loader", f"load_{self.schema}")

    @property
    def file(self) -> str:
        """The artifact's file name in ``runs/<scene>/`` (``contact_sim.h5``)."""
        return f"{self.schema}.h5"

    def load(self, path: Path):
        """The loaded artifact at ``path`` (the schema's typed result).

        Raises
        ------
        walkerlab.io.artifacts.ArtifactError
            As the schema's loader (a missing or unreadable file, a wrong stage).
        """
        module = importlib.import_module(f"walkerlab.io.schemas.{self.schema}")
        return getattr(module, self.loader)(path)


FIXEDPOINT = StageArtifact("fixedpoint")
SIMULATE = StageArtifact("simulate")
CONTACT_SIM = StageArtifact("contact-sim")
COMPARE = StageArtifact("compare")
WORKPRECISION = StageArtifact("workprecision")
BASIN = StageArtifact("basin")
ROBUSTNESS = StageArtifact("robustness", loader="load")
MFPT = StageArtifact("mfpt", loader="load")
ATTRIBUTION = StageArtifact("attribution")
OPTIMIZE = StageArtifact("optimize", loader="load")
#: ``bifurcation`` and ``bifurcation_<field>`` load as summaries
BIFURCATION = StageArtifact("bifurcation", loader="load_bifurcation_summary")
#: ``stability_map_<kind>.h5``
STABILITY_MAP = StageArtifact("stability_map")

#: stage name -> its artifact
ARTIFACTS: dict[str, StageArtifact] = {a.name: a for a in (
    FIXEDPOINT, SIMULATE, CONTACT_SIM, COMPARE, WORKPRECISION, BASIN, ROBUSTNESS, MFPT,
    ATTRIBUTION, OPTIMIZE, BIFURCATION, STABILITY_MAP)}
