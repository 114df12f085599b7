"""The Adams Solver dataset's ground (:mod:`walkerlab.export.adams`): PART/1, its markers,
gravity, and the ground's patches as boxes (the slope's checkerboard or lanes of footfall
patches, or a box per segment of a polyline ground)."""

from __future__ import annotations

import math

import numpy as np

from walkerlab.export.adams_statements import (
    LANE_Z,
    MM,
    AdamsStart,
    _deg,
    _f,
    _fs,
    _stmt,
)
from walkerlab.export.mjcf_scene import point_foot_radius

__all__ = ["ground_patches", "ground_statements"]


def _ground_box(gid: int, corner, angle_rad: float, size) -> list[str]:
    """A patch of the ground: MARKER/``gid`` on PART/1 at ``corner`` (x, y, z) [m], turned
    by ``angle_rad`` [rad] about z (``REULER``), and the GRAPHICS/``gid`` box of ``size``
    (along, across the normal, across the plane) [m] from it."""
    return (_stmt(f"MARKER/{gid}, PART=1", f"QP={_fs(*(x * MM for x in corner))}",
                  f"REULER={_deg(angle_rad)}, 0.0D, 0.0D")
            + _stmt(f"GRAPHICS/{gid}, BOX, CORNER={gid}",
                    f"X={_f(size[0] * MM)}, Y={_f(size[1] * MM)}, Z={_f(size[2] * MM)}"))


def _line_patches(line, r: float, L: float) -> list[str]:
    """Continuous ground (a profile, continuous stairs) as the polyline ``line`` (m, 2) [m]
    of patches: segment ``i`` a box whose top face lies on it, lowered by the foot
    sphere's radius ``r`` [m] along its normal (as the checkerboard's patches), turned by
    the segment's angle (``REULER``), ``L / 5`` wide across the plane; each foot touches
    every segment (its CONTACTs)."""
    out, gid = [], 1001
    for i, (a, b) in enumerate(zip(line[:-1], line[1:])):
        d = b - a
        length = float(np.hypot(*d))
        if length <= 0.0:
            continue
        g = math.atan2(float(d[1]), float(d[0]))  # the segment's angle (downhill: < 0)
        depth = min(length, 1.0) / 10
        nrm = (-math.sin(g), math.cos(g))  # its upward normal
        corner = (a[0] - (r + depth) * nrm[0], a[1] - (r + depth) * nrm[1], -L / 10)
        out.append(f"! segment {i} of the ground line from ({a[0]:.6g}, {a[1]:.6g}) m "
                   f"to ({b[0]:.6g}, {b[1]:.6g}) m")
        out += _ground_box(gid, corner, g, (length, depth, L / 5))
        gid += 1
    return out


def ground_patches(start: AdamsStart) -> int:
    """The patches of the dataset's ground when it is a polyline (segments of positive
    length of :attr:`AdamsStart.ground_line`); 1 (the slope's plane) otherwise."""
    if start.ground_line is None:
        return 1
    d = np.diff(np.asarray(start.ground_line, float), axis=0)
    return int(np.count_nonzero(np.hypot(d[:, 0], d[:, 1]) > 0.0))


def ground_statements(mb, start: AdamsStart, lanes: bool, pin: tuple) -> list[str]:
    """PART/1 (ground), its markers (MARKER/102: the stance-foot pin's, at ``pin`` (x, y)
    [m]), ACCGRAV and the checkerboard's patches (or one plane)."""
    arc = mb.foot == "arc" and mb.foot_radius_m > 0  # the sphere is the arc: no offset
    phi, r = mb.slope_rad, 0.0 if arc else point_foot_radius(mb)
    L = mb.leg_length_m
    out = ["!", "! ---- ground, gravity (along -y) and the tilted ground's patches ----",
           "PART/1, GROUND", "MARKER/101, PART=1, QP=0.0, 0.0, 0.0",
           f"MARKER/102, PART=1, QP={_fs(pin[0] * MM, pin[1] * MM)}, "
           f"{_f(LANE_Z['leg2'] * L * MM if lanes else 0.0)}",
           "MARKER/103, PART=1, QP=0.0, 0.0, 0.0",
           f"ACCGRAV/IGRAVITY=0.0, JGRAVITY={_f(-mb.gravity_m_per_s2 * MM)}, KGRAVITY=0.0"]
    if start.ground_line is not None:  # continuous ground: a box per segment
        return out + _line_patches(start.ground_line, r, L)
    t, n = (math.cos(phi), -math.sin(phi)), (math.sin(phi), math.cos(phi))
    w = start.patch_width_m
    depth = w / 10
    centres = start.lanes if start.lanes is not None else ((0.0,),)
    length = w if start.lanes is not None else 40 * L
    legs = ("leg1", "leg2") if start.lanes is not None else ("both",)
    heights = start.lane_heights or ((), ())
    gid = 1001
    for i, (leg, lane) in enumerate(zip(legs, centres)):
        zw = 0.04 * L if lanes else L / 5
        zc = LANE_Z.get(leg, 0.0) * L if lanes else 0.0
        for j, s in enumerate(lane):
            s0 = s - length / 2 if lanes else -length / 4
            h = heights[i][j] if i < len(heights) and j < len(heights[i]) else 0.0
            d = r + depth - h  # the box's bottom below the ground line (a tread: h lower)
            corner = (s0 * t[0] - d * n[0], s0 * t[1] - d * n[1], zc - zw / 2)
            out.append(f"! patch of {leg} at s = {s:.6g} m"
                       + (f", {h:.6g} m along the normal" if h else ""))
            out += _ground_box(gid, corner, -phi, (length, depth, zw))
            gid += 1
    return out
