"""Read the results of stage artifacts by name (used by later stages and the report)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from walkerlab.io.artifacts import open_artifact


def load_fixed_point(path: Path) -> tuple[np.ndarray, dict]:
    """Fixed point (role-ordered state) and metadata from ``fixedpoint.h5``.

    Returns
    -------
    x : ndarray (2n,)
        State just after heel strike, in ``meta["state_names"]`` order [rad, rad/s].
    meta : dict
        ``step_period_s`` [s], ``state_names``, ``state_units``, ``stable``,
        ``multipliers`` (complex ndarray (2n,)), ``max_abs_multiplier``, ``residual``.

    Raises
    ------
    ArtifactError
        Missing or unreadable artifact.
    """
    with open_artifact(path, "fixedpoint") as f:
        names = [str(n) for n in f.attrs["state_names"]]
        x = np.array([f[f"fixed_point/{n}"][()] for n in names])
        mult = f["floquet/variational/real"][()] + 1j * f["floquet/variational/imag"][()]
        meta = {"step_period_s": float(f["step_period"][()]), "state_names": names,
                "state_units": [str(f[f"fixed_point/{n}"].attrs["unit"]) for n in names],
                "stable": bool(f["floquet/stable"][()]), "multipliers": mult,
                "max_abs_multiplier": float(np.max(np.abs(mult))),
                "residual": float(f["residual"][()])}
    return x, meta
