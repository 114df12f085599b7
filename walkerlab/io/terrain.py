"""Reader of the contact walker's ground (``terrain/`` of ``contact_sim.h5``), for figures
and the animation: the checkerboard's patch centres per leg lane and their half width."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from walkerlab.io.artifacts import artifact_loader
from walkerlab.io.stage_files import CONTACT_SIM


@artifact_loader(CONTACT_SIM.name)
def load_terrain(f, path: Path | str) -> dict | None:
    """The ground the contact walker of ``contact_sim.h5`` walked on.

    Returns
    -------
    dict or None
        ``lanes``: {leg: patch centres (n,) [m, along the slope from the first stance
        foot]}, ``half_width`` [m], ``continuous`` (bool); None for an artifact without a
        ``terrain`` group.
    """
    if "terrain" not in f:
        return None
    g = f["terrain"]
    lanes = {k.removeprefix("lane_"): np.asarray(g[k][()], float)
             for k in g if k.startswith("lane_")}
    return {"lanes": lanes, "half_width": float(g["patch_half_width"][()]),
            "continuous": bool(g["continuous"][()])}
