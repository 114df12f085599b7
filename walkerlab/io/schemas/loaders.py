"""Any stage's artifact by stage name: :func:`load_artifact`."""

from __future__ import annotations

from pathlib import Path

from walkerlab.io.stage_files import ARTIFACTS, BIFURCATION, STABILITY_MAP


def load_artifact(stage: str, path: Path):
    """The loaded artifact of ``stage`` at ``path`` (the schema module's typed result,
    :data:`walkerlab.io.stage_files.ARTIFACTS`; ``bifurcation`` and ``bifurcation_<field>``
    load as summaries, ``stability_map_<kind>`` as stability maps).

    Raises
    ------
    KeyError
        No schema for ``stage``.
    walkerlab.io.artifacts.ArtifactError
        As the schema's loader (a missing or unreadable file, a wrong stage).
    """
    kind = (BIFURCATION.name if stage.startswith(BIFURCATION.name)
            else STABILITY_MAP.name if stage.startswith(STABILITY_MAP.name) else stage)
    return ARTIFACTS[kind].load(path)
