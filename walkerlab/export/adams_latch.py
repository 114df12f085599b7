"""The knee latch of the Adams dataset (:mod:`walkerlab.export.adams`): its VARIABLEs and
SFORCEs.

Knee latch (``contact.knee_stop.latch``, :func:`knee_latches`): the contact model's latch
is a smooth weight of the present state, ``w = STEP(delta, -h, 0, 0, 1) STEP(ext, -a, 0,
-a/2, 1)`` (``delta`` the foot contact point's penetration, ``h`` the release height, ``a``
the capture flexion) times the stop's IMPACT law on the flexion, so it is written as that
expression: an ``SFORCE`` per knee whose ``FUNCTION`` is the product of two ``STEP``s and
``IMPACT`` (Adams Solver function reference: STEP, IMPACT), the contact height the foot
sphere's centre along the slope normal (``DX``, ``DY``) less the arc's radius, on stairs and
footholds less the tread of the patch under the foot (``IF`` of its distance along the slope
from each patch's centre).  A ``SENSOR``
(Adams Solver statement reference, adams_solver/state_sensor.html: an event when an
expression reaches a value, whose actions change the output step or the integration step,
halt, restart, return to the commands or store a value for ``SENVAL``) would make it a
switched law with a memory, which the contact model's latch is not.
"""

from __future__ import annotations

import math

from walkerlab.export.adams_feet import _foot_sphere_m, adams_feet
from walkerlab.export.adams_statements import (
    MM,
    AdamsStart,
    _chain_sum,
    _f,
    _stmt,
    _var,
    marker_id,
)
from walkerlab.export.mjcf_scene import point_foot_radius
from walkerlab.export.opensim_contact import latch_foot_offset

__all__ = ["LATCH_SFORCE", "LATCH_VARIABLES", "TREAD_BLOCK", "knee_latches", "latch_law",
           "latch_sforce", "tread_under"]

#: VARIABLE ids of the knee latch (:func:`knee_latches`): the slope's sine and cosine, each
#: leg's contact height [mm], the latch's engagement and its two factors (foot, knee); on
#: stairs and footholds the height above the slope line, the position along it and the
#: tread under the foot.
LATCH_VARIABLES = {"sin": 370, "cos": 375, "height_leg1": 371, "height_leg2": 372,
                   "weight_leg1": 373, "weight_leg2": 374, "foot_leg1": 376,
                   "foot_leg2": 377, "knee_leg1": 378, "knee_leg2": 379, "line_leg1": 380,
                   "line_leg2": 381, "along_leg1": 382, "along_leg2": 383,
                   "tread_leg1": 384, "tread_leg2": 385, "above_leg1": 386,
                   "above_leg2": 387, "below_top_leg1": 388, "below_top_leg2": 389}
#: First VARIABLE id of each leg's patch terms (stairs, footholds: :func:`_tread_under`; two
#: a patch, the partial sums from ``+ 1000``).
TREAD_BLOCK = {"leg1": 20000, "leg2": 30000}
#: SFORCE ids of the knee latches (the stops are SFORCE/1, 2).
LATCH_SFORCE = {"leg1": 3, "leg2": 4}


def knee_latches(mb, ids: dict, ks, start: AdamsStart | None = None) -> list[str]:
    """The contact model's knee latch (:func:`walkerlab.models.contact.generated._knee`) as
    statements: per leg the contact point's height above the ground [mm]
    (:data:`LATCH_VARIABLES`: the foot sphere's centre above the slope line less
    :func:`walkerlab.export.opensim_contact.latch_foot_offset`; the lower of a foot's spheres),
    the engagement ``w = STEP(h, 0, 1, h_release, 0) STEP(ext, -capture, 0, -capture/2, 1)``
    (the contact model's ``STEP(delta, -h_release, 0, 0, 1)`` in the height ``h = -delta``)
    and an SFORCE (:data:`LATCH_SFORCE`) ``w IMPACT(ext, d ext/dt, 0, k, e, cmax, dmax)`` on
    the knee's flexion: the stop's law mirrored, pushing the shank straight (Adams Solver
    function reference: STEP, IMPACT = max(0, k (x1 - x)^e - STEP(x, x1 - d, cmax, x1, 0)
    x') for x < x1, else 0; SFORCE/ROTATION: the torque on I about J's z).  On stairs and
    footholds (``start.lane_heights``) the height is above the tread of the lane's patch
    under the foot (:func:`_tread_under`), as the contact model reads it.

    Parameters
    ----------
    mb : walkerlab.walker.multibody.Multibody
        The exported walker (kneed).
    ids : dict
        Part ids by link name (:func:`walkerlab.export.adams_feet.part_ids`).
    ks : walkerlab.models.contact.laws.KneeStopSI
        The knee stop with its latch (``latch_height`` [m], ``latch_capture`` [rad]).
    start : AdamsStart, optional
        The dataset's start; its ``lanes``, ``lane_heights`` and ``patch_width_m`` on
        stairs and footholds.

    Returns
    -------
    list of str
        The dataset's lines (comments, VARIABLEs, SFORCEs).
    """
    V = LATCH_VARIABLES
    arc = mb.foot == "arc" and mb.foot_radius_m > 0
    lift = latch_foot_offset(_foot_sphere_m(mb), 0.0 if arc else point_foot_radius(mb)) * MM
    h_rel, cap = ks.latch_height * MM, ks.latch_capture
    out = ["! knee latch (contact.knee_stop.latch): the stop's IMPACT law on the flexion,",
           f"! weighted by STEP(h, 0, 1, {_f(h_rel)}, 0) of the foot's contact height h [mm]",
           f"! and STEP(knee, {_f(-cap)}, 0, {_f(-cap / 2)}, 1) of the knee angle [rad]: the "
           "contact", "! model's latch (a smooth weight of the present state, no event)",
           _var(V["sin"], _f(math.sin(mb.slope_rad))), _var(V["cos"], _f(math.cos(mb.slope_rad)))]
    spheres: dict[str, list[int]] = {}
    for leg, _role, marker in adams_feet(mb).geoms(mb, ids):
        spheres.setdefault(leg, []).append(marker)
    for leg in ("leg1", "leg2"):
        heights = [f"VARVAL({V['sin']})*DX({m},101)+VARVAL({V['cos']})*DY({m},101)"
                   + (f"-{_f(lift)}" if lift else "") for m in spheres[leg]]
        h = heights[0] if len(heights) == 1 else f"MIN({heights[0]},{heights[1]})"
        sh, th = ids[f"{leg}_shank"], ids[f"{leg}_thigh"]
        i_m, j_m = marker_id(sh, "joint"), marker_id(th, "knee")
        treads = _tread_under(leg, spheres[leg][0], start, V[f"height_{leg}"])
        if treads:  # the height above the slope line first, then above the tread
            out += [_var(V[f"line_{leg}"], h), *treads]
        else:
            out.append(_var(V[f"height_{leg}"], h))
        out += latch_sforce(V, leg, i_m, j_m, h_rel, cap, latch_law(ks))
    return out


def latch_law(ks) -> str:
    """The latch's ``IMPACT`` law arguments ``k, e, cmax, dmax`` in the dataset's units
    (N/mm-scaled stiffness and damping) of the contact model's knee stop ``ks``."""
    return f"{_f(ks.k * MM)},{_f(ks.e)},{_f(ks.cmax * MM)},{_f(ks.dmax)}"


def latch_sforce(V: dict, leg: str, i_m: int, j_m: int, h_rel: float, cap: float,
                 law: str) -> list[str]:
    """One knee's latch (the planar and the 3D datasets'): its weight, ``STEP`` of the
    foot's contact height ``VARVAL(V['height_<leg>'])`` [mm] up to ``h_rel`` times ``STEP``
    of the knee angle ``AZ(i_m, j_m)`` [rad] within ``cap`` of straight, on the
    ``SFORCE/ROTATION`` ``IMPACT`` torque of ``law`` (:func:`latch_law`)."""
    return [_var(V[f"foot_{leg}"], f"STEP(VARVAL({V[f'height_{leg}']}),0.0,1.0,"
                 f"{_f(h_rel)},0.0)"),
            _var(V[f"knee_{leg}"], f"STEP(AZ({i_m},{j_m}),{_f(-cap)},0.0,{_f(-cap / 2)},"
                 "1.0)"),
            _var(V[f"weight_{leg}"], f"VARVAL({V[f'foot_{leg}']})*"
                 f"VARVAL({V[f'knee_{leg}']})"),
            *_stmt(f"SFORCE/{LATCH_SFORCE[leg]}, ROTATION, I={i_m}, J={j_m}",
                   f"FUNCTION=VARVAL({V[f'weight_{leg}']})*IMPACT(AZ({i_m},{j_m}),"
                   f"WZ({i_m},{j_m},{j_m}),0.0,{law})")]


def _tread_under(leg: str, marker: int, start: AdamsStart | None, out_id: int) -> list[str]:
    """VARIABLE ``out_id``: ``leg``'s contact height [mm] above the tread of its lane's patch
    under ``marker`` (the foot sphere's centre: its position along the slope is the contact
    point's) on stairs and footholds (:func:`tread_under` on the start's lanes).  None ([])
    without tread heights (the slope's patches lie on its line)."""
    if start is None or start.lane_heights is None or start.lanes is None:
        return []
    i = 0 if leg == "leg1" else 1
    V = LATCH_VARIABLES
    along = (f"VARVAL({V['cos']})*DX({marker},101)-VARVAL({V['sin']})*"
             f"DY({marker},101)")
    return tread_under(V, leg, along, start.lanes[i], start.lane_heights[i],
                       start.patch_width_m, out_id)


def tread_under(V: dict, leg: str, along: str, centres, heights, width_m: float,
                out_id: int) -> list[str]:
    """VARIABLE ``out_id``: ``leg``'s contact height [mm] above the tread of its lane's patch
    under its foot, from its height above the slope's plane through the origin (VARIABLE
    ``V["line_<leg>"]``) and the expression ``along`` of its position along the fall line
    [mm] (the planar and the 3D datasets'); the contact model's rule
    (:func:`walkerlab.models.contact.assembly.pressed`): a patch is under the point when its
    centre lies within half the patch width along the slope, and a point above the lane's
    highest tread reads its height above the slope line.

    Parameters
    ----------
    V : dict
        VARIABLE ids: ``line_<leg>``, ``along_<leg>``, ``tread_<leg>``, ``above_<leg>``,
        ``below_top_<leg>`` (:data:`LATCH_VARIABLES`); the patch terms' ids from
        :data:`TREAD_BLOCK`.
    leg : {"leg1", "leg2"}
    along : str
        The foot's position along the fall line [mm] (an Adams expression).
    centres, heights : sequence of float
        The lane's patch centres along the fall line and their tops' heights along the
        normal [m] (a height of 0: a tread on the slope's plane, no term).
    width_m : float
        The patches' length along the fall line [m].
    out_id : int

    Returns
    -------
    list of str
    """
    line, along_id = V[f"line_{leg}"], V[f"along_{leg}"]
    base, half = TREAD_BLOCK[leg], width_m / 2 * MM
    out = [_var(along_id, along)]
    terms = []
    for j, (c, h) in enumerate(zip(centres, heights)):
        if h == 0.0:
            continue  # a tread on the slope line
        d, t = base + 2 * j, base + 2 * j + 1
        off = f"-{_f(c * MM)}" if c >= 0 else f"+{_f(-c * MM)}"
        out += [_var(d, f"ABS(VARVAL({along_id}){off})"),
                _var(t, f"{_f(h * MM)}*IF(VARVAL({d})-{_f(half)}:1,1,0)")]
        terms.append(f"VARVAL({t})")
    top = max([0.0, *heights]) * MM
    tread = V[f"tread_{leg}"]
    out += _chain_sum(base + 1000, tread, terms)
    above, below = V[f"above_{leg}"], V[f"below_top_{leg}"]
    out += [_var(above, f"VARVAL({line})-VARVAL({tread})"),
            _var(below, f"VARVAL({line})-{_f(top)}"),
            _var(out_id, f"IF(VARVAL({below}):VARVAL({above}),VARVAL({line}),VARVAL({line}))")]
    return out
