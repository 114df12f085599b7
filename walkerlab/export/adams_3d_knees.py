"""The knees of a kneed walker in 3D (``locking_knees_3d``) in its Adams dataset
(:mod:`walkerlab.export.adams_3d`): the knee stop and the knee latch, the planar kneed
dataset's statements (:mod:`walkerlab.export.adams`, :mod:`walkerlab.export.adams_latch`) on
the 3D walker's knee revolutes.

Each knee is a ``REVOLUTE`` between the shank (I: marker ``100 s + 2``, z along its hinge
axis, the leg's own pitch axis) and the thigh (J: marker ``100 t + 10 + s`` at the knee, z
along the same axis), so ``AZ(I, J)`` is the knee angle ``shank - thigh`` (the tree's knee
hinge, limit ``[-pi, 0]``: 0 the straight-leg stop, ``> 0`` past straight), as the planar
dataset's.

Knee stop (``contact.knee_stop``): ``SFORCE/1``, ``2`` ``ROTATION`` with
``FUNCTION = -IMPACT(-AZ, -WZ, 0, k, e, cmax, dmax)``: the stop's law on the
hyperextension, pushing the shank back (Adams Solver function reference: IMPACT).

Knee latch (``contact.knee_stop.latch``): the contact model's smooth weight times the stop's
law mirrored on the flexion, ``SFORCE/3``, ``4`` (:func:`walkerlab.export.adams_latch.
knee_latches`' expression): ``w = STEP(h, 0, 1, h_release, 0) STEP(knee, -capture, 0,
-capture/2, 1)``, ``h`` the foot sphere's centre above the slope's plane through the origin
[mm] (a point foot's sphere centre is the rigid foot point, the patches' tops the sphere's
radius below the plane: its contact point's height), times ``IMPACT(knee, d knee/dt, 0, k,
e, cmax, dmax)``.  On stairs and footholds ``h`` is the height above the tread of the lane's
patch under the foot (``IF`` of the foot's distance along the fall line from each patch's
centre, :func:`walkerlab.export.adams_latch.tread_under`: the planar dataset's rule and the
contact model's), each patch's tread its footfall's height along the slope's normal.
"""

from __future__ import annotations

import numpy as np

from walkerlab.config.contact import ContactSettings
from walkerlab.export.adams_latch import LATCH_VARIABLES, latch_law, latch_sforce, tread_under
from walkerlab.export.adams_statements import MM, _f, _stmt, _var
from walkerlab.export.axes_3d import slope_axes
from walkerlab.models.contact.rigid_limit import contact_si

__all__ = ["KNEE_3D_VARIABLES", "KNEE_STOP_SFORCE", "knee_3d_statements"]

#: SFORCE ids of leg1's and leg2's knee stop (the latches': :data:`walkerlab.export.
#: adams_latch.LATCH_SFORCE`).
KNEE_STOP_SFORCE = {"leg1": 1, "leg2": 2}
#: VARIABLE ids of the latch: the slope normal's x and z, each foot's height [mm], its
#: latch's two factors (foot, knee) and their product.
KNEE_3D_VARIABLES = {"nx": 370, "nz": 375, "height_leg1": 371, "height_leg2": 372,
                     "weight_leg1": 373, "weight_leg2": 374, "foot_leg1": 376,
                     "foot_leg2": 377, "knee_leg1": 378, "knee_leg2": 379,
                     **{k: v for k, v in LATCH_VARIABLES.items() if v >= 380}}


def knee_3d_statements(scene, parts: dict, slope_rad: float, disc_m: float = 0.0,
                       lanes=None, width_m: float = 0.0) -> list[str]:
    """The knee stops and, with ``contact.knee_stop.latch``, the latches (module
    docstring).

    Parameters
    ----------
    scene : walkerlab.config.Scene
        Its ``contact.knee_stop`` (default :class:`~walkerlab.config.contact.
        ContactSettings`'s).
    parts : dict
        PART id by body: ``leg<i>`` (the thigh) and ``leg<i>_shank`` (its foot marker
        ``100 s + 3``).
    slope_rad : float
    disc_m : float
        Round feet's disc radius [m] (0: point feet): the latch's foot height is the disc
        centre's (marker ``100 s + 3``) less it, its lowest point's with the disc's plane
        normal to the slope.
    lanes : (ndarray (k1, 3), ndarray (k2, 3)), optional
        Leg1's and leg2's footfall patches (their tops' reference points, in the dataset's
        axes [m]: :attr:`walkerlab.export.adams_3d.Adams3dStart.lanes`); on stairs and
        footholds the latch reads the foot's height above the tread of its lane's patch
        under it (:func:`walkerlab.export.adams_latch.tread_under`), as the contact model
        does.
    width_m : float
        The patches' length along the fall line [m] (with ``lanes``).

    Returns
    -------
    list of str
    """
    _, ks = contact_si(scene.contact or ContactSettings())
    law = latch_law(ks)
    knees = {}
    out = ["!", "! ---- knees: the stop's IMPACT on the hyperextension shank - thigh (> 0 past",
           "! straight) ----"]
    for leg in ("leg1", "leg2"):
        s, t = parts[f"{leg}_shank"], parts[leg]
        i_m, j_m = 100 * s + 2, 100 * t + 10 + s
        knees[leg] = (i_m, j_m, 100 * s + 3)
        out += _stmt(f"SFORCE/{KNEE_STOP_SFORCE[leg]}, ROTATION, I={i_m}, J={j_m}",
                     f"FUNCTION=-IMPACT(-AZ({i_m},{j_m}),-WZ({i_m},{j_m},{j_m}),0.0,{law})")
    if not ks.latch:
        return out
    terrain = scene.terrain
    treads = lanes is not None and terrain is not None and not terrain.is_slope
    V = KNEE_3D_VARIABLES
    t, n = slope_axes(slope_rad)
    h_rel, cap = ks.latch_height * MM, ks.latch_capture
    out += ["! knee latch (contact.knee_stop.latch): the stop's IMPACT law on the flexion,",
            f"! weighted by STEP(h, 0, 1, {_f(h_rel)}, 0) of the foot's contact height h [mm]",
            f"! and STEP(knee, {_f(-cap)}, 0, {_f(-cap / 2)}, 1) of the knee angle [rad]: the "
            "contact", "! model's latch (a smooth weight of the present state, no event)",
            _var(V["nx"], _f(float(n[0]))), _var(V["nz"], _f(float(n[2])))]
    for k, (leg, (i_m, j_m, foot)) in enumerate(knees.items()):
        h = (f"VARVAL({V['nx']})*DX({foot},101)+VARVAL({V['nz']})*DZ({foot},101)"
             + (f"-{_f(disc_m * MM)}" if disc_m else ""))
        if treads:  # the height above the slope's plane first, then above the tread
            falls = np.asarray(lanes[k], float)
            out += [_var(V[f"line_{leg}"], h), *tread_under(
                V, leg, f"VARVAL({V['nz']})*DX({foot},101)-VARVAL({V['nx']})*DZ({foot},101)",
                falls @ t, _treads(falls @ n), width_m, V[f"height_{leg}"])]
        else:
            out.append(_var(V[f"height_{leg}"], h))
        out += latch_sforce(V, leg, i_m, j_m, h_rel, cap, law)
    return out


def _treads(heights: np.ndarray) -> list[float]:
    """The patches' heights along the normal [m], a round-off one (below 1e-12 m: a
    footfall on the slope's plane) 0."""
    return [0.0 if abs(h) < 1e-12 else float(h) for h in heights]
