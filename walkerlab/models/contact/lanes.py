"""The footfall lanes of the contact model: the checkerboard's patch centres and each leg's
footprint offset from its reference point (a flat foot's centre lies ahead of its heel)."""

from __future__ import annotations

import numpy as np

from .parts import contact_part

__all__ = ["checkerboard_lanes", "flat_foot_numbers", "footprint_offsets"]


def flat_foot_numbers(data) -> list[dict]:
    """Per leg (leg1, leg2) a flat foot's numbers ``heel``, ``toe`` [m], ``r`` [rad] from the
    parameter vector (leg1 the swing role's when the legs differ); [] for other feet.

    Parameters
    ----------
    data : WalkerData
        The walker; read are ``data.structure`` and ``data.params`` (shape
        ``(len(structure.param_names),)``, named by ``structure.param_names``).

    Returns
    -------
    list of dict
        Two dicts (leg1, leg2) with float values ``heel`` [m], ``toe`` [m], ``r`` [rad]; an
        empty list unless the walker's kind is flat feet (its contact part's
        :meth:`~walkerlab.models.contact.parts.ContactPart.flat_feet`).
    """
    return contact_part(data.structure).flat_feet(data)


def footprint_offsets(data) -> tuple[float, float]:
    """Along-slope offset [m] of each leg's footprint centre from its reference point (the
    point the ideal footfalls are measured to): 0 for point and arc feet, ``(heel + toe) /
    2`` for a flat foot (reference = its heel's touchdown point; the foot lies flat from
    there to ``heel + toe`` downhill)."""
    f = flat_foot_numbers(data)
    return tuple(0.5 * (n["heel"] + n["toe"]) for n in f) if f else (0.0, 0.0)


def checkerboard_lanes(step_length: float, n_steps: int) -> tuple[np.ndarray, np.ndarray]:
    """Patch centres [m] (along-slope s) of each leg's lane.

    leg2 (first stance leg): s = 0, 2l, 4l, ...; leg1: s = l, 3l, ...; ``n_steps + 2`` footfalls
    in total so a run of ``n_steps`` steps never runs out of ground.

    Returns
    -------
    (c1, c2) : tuple of ndarray
        Centres of leg1's and leg2's patches [m].
    """
    k = n_steps // 2 + 2
    c2 = 2.0 * step_length * np.arange(k)
    c1 = step_length * (1.0 + 2.0 * np.arange(k))
    return c1, c2
