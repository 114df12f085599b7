"""The MJCF ground of an exported scene (:mod:`walkerlab.export.multibody`): the slope plane,
the lanes' patches, stairs' tread boxes, a profile's height field."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from walkerlab.export.mjcf_scene import LANE_BITS, PROFILE_DX_M, MjcfScene
from walkerlab.export.text import nums
from walkerlab.models.contact.terrain import profile_line
from walkerlab.models.ground import landing_drops, stair_treads

if TYPE_CHECKING:
    from walkerlab.walker.multibody import Multibody

__all__ = ["ground_geoms", "lane_tops", "profile_asset", "wheel_ground"]


def ground_geoms(mb: Multibody, extra: MjcfScene | None) -> list[str]:
    """The ground's ``worldbody`` geoms: a plane (lowered by the ground offset with a scene),
    each lane's patches (boxes, footholds a riser lower or higher), stairs' tread boxes or a
    profile's height field (its asset: :func:`profile_asset`).

    Parameters
    ----------
    mb : walkerlab.walker.multibody.Multibody
        The exported walker (its slope, leg length).
    extra : MjcfScene or None
        The scene's ground (None: the walker alone, on the slope plane).

    Returns
    -------
    list of str
        The ``geom`` lines, indented for ``worldbody``.
    """
    phi = mb.slope_rad
    if extra is None:
        return [f'    <geom name="ground" type="plane" size="0 0 1" euler="{nums(0, phi, 0)}"'
                ' contype="6" conaffinity="0" rgba="0.8 0.8 0.8 1"/>']
    n = (math.sin(phi), math.cos(phi))  # slope normal in (x, z)
    t = (math.cos(phi), -math.sin(phi))  # downhill along the slope
    off = extra.ground_offset_m
    if extra.treads is not None:  # stairs: a box per tread, its top the tread
        return _tread_boxes(mb, extra)
    if extra.profile is not None:  # a height profile: a height field (asset: profile_asset)
        return _profile_geom(mb, extra)
    if extra.lanes is None:
        return [f'    <geom name="ground" type="plane" size="0 0 1" euler="{nums(0, phi, 0)}" '
                f'pos="{nums(-off * n[0], 0, -off * n[1])}" contype="6" conaffinity="0" '
                'rgba="0.8 0.8 0.8 1"/>']
    half, depth = (extra.patch_width_m + extra.patch_ahead_m) / 2, extra.patch_width_m / 10
    out = []
    for leg, (y, centres) in zip(LANE_BITS, ((0.05, extra.lanes[0]), (-0.05, extra.lanes[1]))):
        heights = None if extra.lane_heights is None else extra.lane_heights[
            0 if leg == "leg1" else 1]
        for i, s in enumerate(centres):
            s = s + extra.patch_ahead_m / 2  # from footfall - w/2 to footfall + w/2 + ahead
            d = off + depth  # box centre below the surface
            if heights is not None:  # a foothold a riser below (above) the last
                d = d - heights[i]
            size = nums(half, 0.04 * mb.leg_length_m, depth)
            pos = nums(s * t[0] - d * n[0], y * mb.leg_length_m, s * t[1] - d * n[1])
            out.append(f'    <geom name="{leg}_patch{i}" type="box" size="{size}" pos="{pos}"'
                       f' euler="{nums(0, phi, 0)}" contype="{LANE_BITS[leg]}" conaffinity="0"'
                       ' rgba="0.8 0.8 0.8 1"/>')
    return out


def _profile_grid(mb: Multibody, extra: MjcfScene) -> tuple:
    """The profile's height field: ``(x_lo, x_hi, z_lo, z_hi, heights)``, the polyline
    (:attr:`MjcfScene.profile`, lowered by the ground offset) sampled every
    :data:`PROFILE_DX_M` over the leg-length-padded span of its vertices; a flat profile
    gets a 1 mm elevation range (MuJoCo needs one)."""
    line = np.asarray(extra.profile, dtype=float)
    pad = 2 * mb.leg_length_m
    inner = line[1:-1] if len(line) > 3 else line
    x_lo, x_hi = float(inner[0, 0]) - pad, float(inner[-1, 0]) + pad
    n = int(math.ceil((x_hi - x_lo) / PROFILE_DX_M)) + 1
    x = np.linspace(x_lo, x_hi, n)
    z = np.interp(x, line[:, 0], line[:, 1]) - extra.ground_offset_m
    z_lo, z_hi = float(z.min()), float(z.max())
    if z_hi - z_lo < 1e-3:
        z_hi = z_lo + 1e-3
    return x_lo, x_hi, z_lo, z_hi, (z - z_lo) / (z_hi - z_lo)


def profile_asset(mb: Multibody, extra: MjcfScene) -> list[str]:
    """The ``hfield`` asset of a profile (two equal rows across the walker's plane)."""
    x_lo, x_hi, z_lo, z_hi, e = _profile_grid(mb, extra)
    elev = " ".join(f"{v:.6g}" for v in np.concatenate([e, e]))
    size = nums((x_hi - x_lo) / 2, 0.2 * mb.leg_length_m, z_hi - z_lo, mb.leg_length_m)
    return ["  <asset>", f'    <hfield name="profile" nrow="2" ncol="{e.size}" size="{size}" '
            f'elevation="{elev}"/>', "  </asset>"]


def _profile_geom(mb: Multibody, extra: MjcfScene) -> list[str]:
    """The profile's height-field geom (both lanes' contact bits)."""
    x_lo, x_hi, z_lo, _, _ = _profile_grid(mb, extra)
    return [f'    <geom name="ground" type="hfield" hfield="profile" '
            f'pos="{nums((x_lo + x_hi) / 2, 0, z_lo)}" contype="6" conaffinity="0" '
            'rgba="0.8 0.8 0.8 1"/>']


def _tread_boxes(mb: Multibody, extra: MjcfScene, half_width_m: float | None = None
                 ) -> list[str]:
    """Continuous stairs: one box per tread (``extra.treads``), its top the tread at the
    ground offset below it, reaching a leg length below the lowest tread (so each riser is
    a box face a toe can hit), both lanes' contact bits; ``half_width_m`` [m] across the
    fall line each side (default a tenth of the leg length)."""
    off = extra.ground_offset_m
    floor = min(h for _, _, h in extra.treads) - off - mb.leg_length_m
    half = 0.1 * mb.leg_length_m if half_width_m is None else float(half_width_m)
    out = []
    for i, (a, b, h) in enumerate(extra.treads):
        top = h - off
        size = nums((b - a) / 2, half, (top - floor) / 2)
        pos = nums((a + b) / 2, 0, (top + floor) / 2)
        out.append(f'    <geom name="tread{i}" type="box" size="{size}" pos="{pos}" '
                   'contype="6" conaffinity="0" rgba="0.8 0.8 0.8 1"/>')
    return out


def wheel_ground(terrain, spoke_length_m: float, n_treads: int = 60, chord_m: float = 0.0,
                 slope_rad: float = 0.0, half_width_m: float | None = None
                 ) -> tuple[list[str], list[str]]:
    """A spoked wheel's MJCF ground other than its slope plane, laid as its contact model
    lays it (continuous ground, :func:`walkerlab.models.contact.terrain.terrain_ground`),
    the stance spoke's tip at the origin as the ``gait`` keyframe stands it: stairs as one
    box per tread (:func:`walkerlab.models.ground.stair_treads`, tread 0 holding the first
    stance tip, its riser faces walls a tip can hit), a profile as a height field
    (:func:`walkerlab.models.contact.terrain.profile_line`, its first point at the first
    stance tip, sampled every :data:`walkerlab.export.mjcf_scene.PROFILE_DX_M`).  Footholds
    (of one height or several, :func:`walkerlab.models.ground.landing_drops`) are a patch
    per footfall, ``patch_width_m`` long on the slope, where the rigid wheel's spoke tips
    land: two tips are a chord ``c = 2 L sin(pi / spokes)`` apart, so footfall ``k + 1``
    lies ``h_k cos(phi)`` along the slope's normal and ``sqrt(c^2 - (h_k cos phi)^2)``
    along the slope from footfall ``k`` (the rigid heel strike's landing, step ``k``'s
    height ``h_k`` above the stance tip's level).

    Parameters
    ----------
    terrain : walkerlab.config.TerrainSettings
        ``kind: stairs`` or ``profile`` (with ``profile_m``).
    spoke_length_m : float
        The wheel's spoke length [m] (the boxes reach a spoke below the lowest tread; the
        height field runs on two spokes past the profile's vertices).
    n_treads : int
        Treads (footholds: footfalls) ahead of the first (the last tread runs on for 100
        treads).
    chord_m : float
        The distance [m] between two neighbouring spoke tips (footholds;
        :func:`walkerlab.export.spoked.wheel_chord_m`).
    slope_rad : float
        The scene's slope [rad] (footholds lie on it).
    half_width_m : float, optional
        How far [m] the treads and footholds reach across the fall line each side (default:
        the planar wheel's, a tenth of a spoke for the treads, 0.04 spoke for the
        footholds); the 3D wheel's (:func:`walkerlab.export.spoked.wheel3d_mjcf_text`) are
        wider, for its lean and heading.

    Returns
    -------
    asset, geoms : list of str
        The ``asset`` lines (a profile's ``hfield``; none for stairs) and the ``worldbody``
        geoms (contact bit 1, the spoke tips').
    """
    from types import SimpleNamespace

    mb = SimpleNamespace(leg_length_m=float(spoke_length_m))
    if terrain.kind == "stairs":
        extra = SimpleNamespace(treads=stair_treads(terrain, 0.0, n_treads),
                                ground_offset_m=0.0)
        return [], [g.replace('contype="6" conaffinity="0"', 'contype="1" conaffinity="1"')
                    for g in _tread_boxes(mb, extra, half_width_m)]
    if terrain.kind == "profile":
        extra = SimpleNamespace(profile=profile_line(terrain, 0.0, 0.0), ground_offset_m=0.0)
        geoms = [g.replace('contype="6" conaffinity="0"', 'contype="1" conaffinity="1"')
                 for g in _profile_geom(mb, extra)]
        return profile_asset(mb, extra), geoms
    if terrain.kind == "footholds" and chord_m > 0.0:
        return [], _wheel_footholds(terrain, float(spoke_length_m), float(chord_m),
                                    float(slope_rad), n_treads, half_width_m)
    raise ValueError(f"terrain.kind: {terrain.kind}: a spoked wheel's MJCF lays stairs, "
                     "footholds and profiles")


def wheel_footfalls(terrain, c: float, phi: float, n: int) -> dict[int, np.ndarray]:
    """Where a spoked wheel's tips land on footholds (:func:`wheel_ground`'s rule; the Adams
    dataset's footholds, the OpenSim model's patches on stairs and footholds,
    :func:`walkerlab.export.opensim_wheel.wheel_patches`, stairs a riser a step): footfall
    ``k`` [m] (2,) in the world (x downhill, up), footfall 0 (the first stance tip) at the
    origin, footfall -1 behind it, up to ``n`` (a finite list, ``periodic: false``: its own
    footfalls); two tips a chord ``c`` [m] apart, step ``k`` landing ``h_k`` above the
    stance tip's level on the slope ``phi`` [rad]."""
    h = [-d for d in landing_drops(terrain)]  # each step's landing above the stance tip
    t = np.array([math.cos(phi), -math.sin(phi)])
    nrm = np.array([math.sin(phi), math.cos(phi)])
    last = len(terrain.foothold_heights_m) if terrain.periodic is False else n

    def step(k):  # footfall k -> k + 1 [m] in (x, z)
        up = h[k % len(h)] * math.cos(phi)
        return math.sqrt(c * c - up * up) * t + up * nrm

    falls = {0: np.zeros(2), -1: -step(-1)}
    for k in range(last):
        falls[k + 1] = falls[k] + step(k)
    return falls


def _wheel_footholds(terrain, L: float, c: float, phi: float, n: int,
                     half_width_m: float | None = None) -> list[str]:
    """:func:`wheel_ground`'s footholds: a box per footfall (:func:`wheel_footfalls`),
    ``half_width_m`` across the fall line each side (default ``0.04 L``)."""
    nrm = np.array([math.sin(phi), math.cos(phi)])
    falls = wheel_footfalls(terrain, c, phi, n)
    w = float(terrain.patch_width_m)
    depth = w / 10
    half = 0.04 * L if half_width_m is None else float(half_width_m)
    out = []
    for k in sorted(falls):
        centre = falls[k] - depth * nrm
        out.append(f'    <geom name="footfall{k}" type="box" '
                   f'size="{nums(w / 2, half, depth)}" '
                   f'pos="{nums(centre[0], 0, centre[1])}" euler="{nums(0, phi, 0)}" '
                   'contype="1" conaffinity="1" rgba="0.8 0.8 0.8 1"/>')
    return out


def lane_tops(mujoco, model, data, t, n, legs=("leg1", "leg2")) -> tuple | None:
    """Each leg's footfall patches (``leg<i>_patch<k>``) as ``(positions along the slope
    (k,) [m], tops (k,) [m])``, each top above that of the stance foot's patch at the
    keyframe (leg2's nearest the origin; a planar MJCF lowers every patch by its ground
    offset): the ground the knee latch measures its foot's height from
    (:func:`walkerlab.export.mujoco_walk.latch_rule`); None when the file has no such
    patches or all lie at one height (to 1e-9 m: the plain slope, whose latch measures from
    the plane itself).

    Parameters
    ----------
    mujoco : module
    model, data : mujoco.MjModel, mujoco.MjData
        The loaded MJCF after ``mj_forward``.
    t, n : ndarray (3,)
        The slope's tangent and outward normal in MuJoCo's axes.
    legs : tuple of str
        The legs' names.
    """
    out = []
    for leg in legs:
        s, h = [], []
        while (g := mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM,
                                      f"{leg}_patch{len(s)}")) >= 0:
            s.append(float(data.geom_xpos[g] @ t))
            h.append(float(data.geom_xpos[g] @ n) + float(model.geom_size[g][2]))
        if not s:
            return None
        out.append((np.array(s), np.array(h)))
    ref = out[1][1][np.argmin(np.abs(out[1][0]))]
    out = [(s, h - ref) for s, h in out]
    if max(float(np.max(np.abs(h))) for _, h in out) < 1e-9:
        return None
    return tuple(out)
