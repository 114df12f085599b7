"""The Adams Solver dataset's statements as text (:mod:`walkerlab.export.adams`): numbers as
the file writes them, statements packed into 80 columns, marker ids, expressions of
``VARIABLE`` s, and the dataset's start (:class:`AdamsStart`)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["LANE_Z", "LINE_WIDTH", "MARKER_OFFSET", "MM", "AdamsStart", "marker_id",
           "marker_statement", "part_statement"]

#: Millimetres per metre (the file's length unit).
MM = 1000.0
#: Marker roles on a part: ``100 part + offset``.
MARKER_OFFSET = {"cm": 1, "joint": 2, "foot": 3, "knee": 4, "toe": 5}
#: Lane offsets (z) of leg1's and leg2's feet and patches, in leg lengths.
LANE_Z = {"leg1": 0.05, "leg2": -0.05}


def marker_id(part: int, role: str) -> int:
    """MARKER id of ``role`` (:data:`MARKER_OFFSET`) on PART ``part``."""
    return 100 * part + MARKER_OFFSET[role]



@dataclass(frozen=True)
class AdamsStart:
    """The start and terrain of the dataset (SI, the models' frame: x downhill, y up).

    Attributes
    ----------
    hip : (float, float)
        Hip position [m]; leg2's foot point at the origin.
    hip_velocity : (float, float)
        [m/s].
    angles, rates : dict
        Each link's absolute angle [rad] and rate [rad/s] by link name.
    lanes : (tuple, tuple) or None
        Patch centres along the slope [m] of leg1's and leg2's lane (None: one plane).
    patch_width_m : float
    period_s : float
        The rigid gait's step period [s].
    rate_scale : (float, float)
    ankles : dict or None
        Flat feet: each leg's ankle angle [rad] (the sole from the leg's perpendicular,
        positive toe up) and its rate [rad/s], ``{leg: (a, da)}``; None otherwise.
    lane_heights : (tuple, tuple) or None
        Stairs and footholds: each patch's height along the slope normal [m] (its tread's,
        one per centre of ``lanes``); None: every patch on the slope line.
    ground_line : ndarray (m, 2) or None
        Continuous ground (``terrain.lanes: continuous``: a profile, continuous stairs):
        the polyline's vertices [m] in the world frame (x downhill, y up, leg2's contact
        point at the origin), each segment a patch both feet touch; None: ``lanes`` or
        the slope's plane.
    """

    hip: tuple[float, float]
    hip_velocity: tuple[float, float]
    angles: dict
    rates: dict
    lanes: tuple | None
    patch_width_m: float
    period_s: float
    rate_scale: tuple[float, float]
    ankles: dict | None = None
    lane_heights: tuple | None = None
    ground_line: object = None



def _f(x: float) -> str:
    """A number as the file writes it (shortest round-trip repr, E exponent, no -0.0)."""
    return repr(float(x) + 0.0).upper()


def _fs(*xs: float) -> str:
    return ", ".join(_f(x) for x in xs)


def _deg(rad: float) -> str:
    return _f(math.degrees(rad)) + "D"


#: Longest line the writer makes (Adams Solver datasets are read in 80 columns).
LINE_WIDTH = 80


def _stmt(head: str, *args: str) -> list[str]:
    """A statement: ``head`` and its arguments packed into lines of at most
    :data:`LINE_WIDTH` columns, each further line a continuation (starting with ``,``)."""
    lines = [head]
    for a in args:
        if len(lines[-1]) + 2 + len(a) <= LINE_WIDTH:
            lines[-1] += f", {a}"
        else:
            lines.append(f", {a}")
    return lines


def marker_statement(mid: int, part: int, qp, angles=(0.0, 0.0, 0.0)) -> list[str]:
    """A ``MARKER`` on PART ``part`` at ``qp`` (3,) [m] in the part's frame, turned by the
    body-3-1-3 Euler ``angles`` (3,) [rad] (``REULER``; none written when all are 0), in the
    file's units (mm, degrees; MSC Adams/Solver reference, the MARKER statement).

    Parameters
    ----------
    mid, part : int
        The MARKER's and its PART's ids.
    qp : array_like (3,)
        Its origin [m].
    angles : tuple of float (3,)
        Its orientation [rad].

    Returns
    -------
    list of str
        The statement's lines (:func:`_stmt`).
    """
    args = [f"QP={_fs(*(np.asarray(qp, float) * MM))}"]
    if any(angles):
        args.append(f"REULER={', '.join(_deg(a) for a in angles)}")
    return _stmt(f"MARKER/{mid}, PART={part}", *args)


def _rot(psi: float, p: tuple[float, float]) -> tuple[float, float]:
    c, s = math.cos(psi), math.sin(psi)
    return c * p[0] - s * p[1], s * p[0] + c * p[1]



def _var(vid: int, expr: str) -> str:
    return f"VARIABLE/{vid}, FUNCTION={expr}"


def _plus(x: float) -> str:
    """``+x`` as an expression's term (a negative number in parentheses)."""
    return f"+({_f(x)})" if x < 0 else f"+{_f(x)}"


def _chain_sum(first: int, out_id: int, terms: list[str]) -> list[str]:
    """VARIABLEs summing ``terms`` (two a line), the sum in VARIABLE ``out_id``; partial
    sums in ``first``, ``first + 1``, ..."""
    lines, acc, vid = [], None, first
    chunks = [terms[i:i + 2] for i in range(0, len(terms), 2)] or [["0.0"]]
    for j, chunk in enumerate(chunks):
        target = out_id if j == len(chunks) - 1 else vid
        lines.append(_var(target, "+".join(([f"VARVAL({acc})"] if acc is not None else [])
                                           + chunk)))
        acc, vid = target, vid + 1
    return lines


def part_statement(p: int, mass: float, inertia: float, pos, z: float, psi: float, vel,
                   w: float) -> list[str]:
    """The ``PART`` statement of part ``p``: mass [kg], inertia [kg mm^2] about z and x (none
    along the link's axis), its frame at ``pos`` [m] (x, y) and ``z`` [mm], turned by ``psi``
    [rad], moving at ``vel`` [m/s] and ``w`` [rad/s] (markers ``cm`` and ``joint``)."""
    return _stmt(f"PART/{p}, MASS={_f(mass)}, CM={marker_id(p, 'cm')}",
                 f"IP={_fs(inertia, 0.0, inertia)}",
                 f"QG={_fs(pos[0] * MM, pos[1] * MM, z)}",
                 f"REULER={_deg(psi)}, 0.0D, 0.0D", f"VX={_f(vel[0] * MM)}",
                 f"VY={_f(vel[1] * MM)}", f"WZ={_f(w)}")
