"""Any stage's artifact by stage name: :func:`load_artifact`."""

from __future__ import annotations

import importlib
from pathlib import Path

#: stage name -> (schema module under walkerlab.io.schemas, loader); ``bifurcation`` and
#: ``bifurcation_<field>`` load as summaries, ``stability_map_<kind>`` as stability maps
LOADERS = {"fixedpoint": ("fixedpoint", "load_fixedpoint"),
           "simulate": ("simulate", "load_simulate"),
           "contact-sim": ("contact_sim", "load_contact_sim"),
           "compare": ("compare", "load_compare"),
           "workprecision": ("workprecision", "load_workprecision"),
           "basin": ("basin", "load_basin"), "robustness": ("robustness", "load"),
           "mfpt": ("mfpt", "load"), "attribution": ("attribution", "load_attribution"),
           "optimize": ("optimize", "load"),
           "bifurcation": ("bifurcation", "load_bifurcation_summary"),
           "stability_map": ("stability_map", "load_stability_map")}


def load_artifact(stage: str, path: Path):
    """The loaded artifact of ``stage`` at ``path`` (the schema module's typed result).

    Raises
    ------
    KeyError
        No schema for ``stage``.
    walkerlab.io.artifacts.ArtifactError
        As the schema's loader (a missing or unreadable file, a wrong stage).
    """
    kind = ("bifurcation" if stage.startswith("bifurcation")
            else "stability_map" if stage.startswith("stability_map") else stage)
    module, name = LOADERS[kind]
    return getattr(importlib.import_module(f"walkerlab.io.schemas.{module}"), name)(path)
