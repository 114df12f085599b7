"""The feet of the Adams Solver dataset (:mod:`walkerlab.export.adams`), as the walker's body
tree has them: a point or arc foot is a contact sphere on its leg's end (:class:`LegEndFeet`),
a flat foot (a sole of the tree, :attr:`walkerlab.walker.tree.BodyTree.soles`) a PART on an
ankle REVOLUTE with heel and toe spheres (:class:`FlatFeet`); the writer reaches them through
the tree (:func:`adams_feet`), never through the walker's kind or the description's switches.
"""

from __future__ import annotations

import numpy as np

from walkerlab.config import Scene
from walkerlab.export.adams_statements import (
    LANE_Z,
    MM,
    AdamsStart,
    _chain_sum,
    _f,
    _fs,
    _rot,
    _stmt,
    _var,
    marker_id,
    part_statement,
)
from walkerlab.export.mjcf_scene import point_foot_radius

__all__ = ["ANKLE_JOINT", "ANKLE_SPRING", "FOOT_FORCES", "FlatFeet",
           "LegEndFeet", "adams_feet", "contact_pairs", "hip_link", "leg_end", "part_ids"]

#: Flat feet: the ankle revolutes of leg1 and leg2 (``ANKLE_JOINT``, ``+ 1``).
ANKLE_JOINT = 20
#: Flat feet: the ankle SPRINGDAMPERs of leg1 and leg2 (``ANKLE_SPRING``, ``+ 1``).
ANKLE_SPRING = 21
#: Flat feet: VARIABLE ids of each leg's heel and toe normal forces [N] (sums over the
#: CONTACTs of its heel and toe spheres).
FOOT_FORCES = {"leg1": (311, 313), "leg2": (312, 314)}
LEGS = ("leg1", "leg2")


def leg_end(mb, leg: str) -> str:
    """The link that carries ``leg``'s foot (``leg1`` or ``leg1_shank``)."""
    return next(ln.name for ln in mb.links
                if ln.foot_m is not None and ln.name.split("_")[0] == leg)


def hip_link(mb, leg: str) -> str:
    """The link on ``leg``'s hip joint (``leg1`` or ``leg1_thigh``)."""
    return next(ln.name for ln in mb.links if ln.joint == f"{leg}_hip")


def _foot_sphere_m(mb) -> float:
    """Radius [m] of a foot's contact sphere: an arc foot's ``R``, else the point foot's
    :func:`walkerlab.export.mjcf_scene.point_foot_radius` (a flat foot's heel and toe)."""
    return mb.foot_radius_m if mb.foot == "arc" and mb.foot_radius_m > 0 else \
        point_foot_radius(mb)


def _sphere(marker: int, d: float) -> list[str]:
    """The contact sphere (an ELLIPSOID of diameter ``d`` [mm]) centred on ``marker``."""
    return _stmt(f"GRAPHICS/{marker}, ELLIPSOID, CM={marker}",
                 f"XSCALE={_f(d)}, YSCALE={_f(d)}, ZSCALE={_f(d)}")


class LegEndFeet:
    """Point and arc feet: a contact sphere on the foot marker of each leg's end (an arc
    foot's of radius ``R`` on the arc's centre), the start the contact view's state of the
    rigid gait."""

    def foot_parts(self, first: int) -> dict[str, int]:
        """PART ids of foot parts from ``first``: none."""
        return {}

    def scene_feet(self, scene: Scene, data):
        """The feet's numbers from the scene: none (the legs carry them)."""
        return None

    def start(self, scene: Scene, mb, data, ideal, extra, lanes, heights) -> AdamsStart:
        """The rigid gait's post-impact state as the contact view has it (rates times
        ``contact_sim.initial_rate_scale``); a bisecting torso at the legs' mean angle."""
        from walkerlab.models.contact.model import ContactWalker
        from walkerlab.models.contact.rigid_limit import contact_si

        c, knee = contact_si(scene.contact)
        scale = tuple(scene.contact_sim.initial_rate_scale) if scene.contact_sim else (1.0, 1.0)
        walker = ContactWalker(contact=c, data=data, knee_stop=knee)
        z = walker.link_state_from_ideal(ideal.x, scale)
        q, v = walker.layout().coordinate_values(walker.pinned_to_full(z, np.zeros(2)))
        link_of = {ln.joint: ln.name for ln in mb.links}
        for cp in mb.couplings:  # a bisecting torso: its angle held at the legs' mean
            name = link_of[cp.joint]
            q[f"{name}_angle"] = sum(c * q[f"{link_of[j]}_angle"] for j, c in cp.terms)
            v[f"{name}_angle"] = sum(c * v[f"{link_of[j]}_angle"] for j, c in cp.terms)
        return AdamsStart((float(q["hip_x"]), float(q["hip_y"])),
                          (float(v["hip_x"]), float(v["hip_y"])),
                          {ln.name: float(q[f"{ln.name}_angle"]) for ln in mb.links},
                          {ln.name: float(v[f"{ln.name}_angle"]) for ln in mb.links},
                          lanes, float(extra.patch_width_m), float(ideal.period_s),
                          (float(scale[0]), float(scale[1])), None, heights)

    def on_leg(self, mb, marker: int) -> list[str]:
        """The geometry on a leg's foot marker: the contact sphere."""
        return _sphere(marker, 2 * _foot_sphere_m(mb) * MM)

    def parts(self, mb, start: AdamsStart, ids: dict, lanes: bool, frames: dict,
              feet) -> list[str]:
        """Foot PARTs and their markers: none."""
        return []

    def joints(self, mb, ids: dict) -> list[str]:
        """Ankle REVOLUTEs: none."""
        return []

    def pin(self, mb, ids: dict) -> int:
        """The marker the temporary stance-foot pin holds: leg2's foot marker."""
        return marker_id(ids[leg_end(mb, "leg2")], "foot")

    def geoms(self, mb, ids: dict) -> list[tuple[str, str, int]]:
        """``(leg, role, marker)`` of each contact sphere: the legs' foot markers."""
        return [(ln.name.split("_")[0], "foot", marker_id(ids[ln.name], "foot"))
                for ln in mb.links if ln.foot_m is not None]

    def normal_force(self, leg: str, force: int, terms) -> list[str]:
        """VARIABLE ``force``: ``leg``'s normal contact force, the sum of its CONTACTs'
        (``terms(role)``)."""
        return _chain_sum(410 if leg == "leg1" else 460, force, terms("foot"))

    def push_markers(self, ids: dict, feet: dict) -> tuple[dict, dict]:
        """The markers the push-off pushes at and whose touchdown it predicts: the feet."""
        return feet, feet


class FlatFeet(LegEndFeet):
    """Flat feet: a foot PART per leg on an ankle REVOLUTE at the leg's end, the contact
    model's regularising mass, the ankle spring, contact spheres at heel and toe; the start
    the MJCF keyframe (the rigid heel strike's double support)."""

    def foot_parts(self, first: int) -> dict[str, int]:
        """``leg1_foot``, ``leg2_foot`` from ``first``."""
        return {"leg1_foot": first, "leg2_foot": first + 1}

    def scene_feet(self, scene: Scene, data):
        """:func:`walkerlab.export.scene_feet.flat_foot_bodies`."""
        from walkerlab.export.scene_feet import flat_foot_bodies

        return flat_foot_bodies(scene, data)

    def start(self, scene: Scene, mb, data, ideal, extra, lanes, heights) -> AdamsStart:
        """The MJCF keyframe: the rigid heel strike's double support (rates not scaled)."""
        qp, qv = [float(x) for x in extra.qpos], [float(x) for x in extra.qvel]
        return AdamsStart((qp[0], qp[1]), (qv[0], qv[1]), {"leg1": qp[2], "leg2": qp[4]},
                          {"leg1": qv[2], "leg2": qv[4]}, lanes, float(extra.patch_width_m),
                          float(ideal.period_s), (1.0, 1.0),
                          {"leg1": (qp[3], qv[3]), "leg2": (qp[5], qv[5])}, heights)

    def on_leg(self, mb, marker: int) -> list[str]:
        """A flat foot's leg marker is its ankle: no geometry."""
        return []

    def parts(self, mb, start: AdamsStart, ids: dict, lanes: bool, frames: dict,
              feet) -> list[str]:
        """:func:`_flat_foot_parts`."""
        return _flat_foot_parts(mb, start, ids, lanes, frames, feet)

    def joints(self, mb, ids: dict) -> list[str]:
        """The ankle REVOLUTEs (I the foot, J the leg's foot marker)."""
        out = []
        for k, leg in enumerate(LEGS):
            out.append(f"! {leg}_ankle: the ankle angle (toe up > 0) is AZ(foot, leg)")
            out.append(f"JOINT/{ANKLE_JOINT + k}, REVOLUTE, "
                       f"I={marker_id(ids[f'{leg}_foot'], 'joint')}, "
                       f"J={marker_id(ids[leg_end(mb, leg)], 'foot')}")
        return out

    def pin(self, mb, ids: dict) -> int:
        """leg2's heel."""
        return marker_id(ids["leg2_foot"], "foot")

    def geoms(self, mb, ids: dict) -> list[tuple[str, str, int]]:
        """Each foot's heel (role ``foot``) and toe sphere."""
        return [(leg, role, marker_id(ids[f"{leg}_foot"], role))
                for leg in LEGS for role in ("foot", "toe")]

    def normal_force(self, leg: str, force: int, terms) -> list[str]:
        """The heel's and the toe's force (:data:`FOOT_FORCES`), then the foot's."""
        heel, toe = FOOT_FORCES[leg]
        return [*_chain_sum(410 if leg == "leg1" else 460, heel, terms("foot")),
                *_chain_sum(430 if leg == "leg1" else 480, toe, terms("toe")),
                _var(force, f"VARVAL({heel})+VARVAL({toe})")]

    def push_markers(self, ids: dict, feet: dict) -> tuple[dict, dict]:
        """At the toe; the touchdown the heel's."""
        return ({g: marker_id(ids[f"{g}_foot"], "toe") for g in LEGS},
                {g: marker_id(ids[f"{g}_foot"], "foot") for g in LEGS})


def adams_feet(mb) -> LegEndFeet:
    """The dataset's feet of the multibody walker ``mb``
    (:class:`walkerlab.walker.multibody.Multibody`) as its body tree has them: flat feet
    where the tree has soles (:attr:`walkerlab.walker.tree.BodyTree.soles`), else the legs'
    ends (the rolling polygon has no Adams dataset:
    :data:`walkerlab.walker.kinds.CAPABILITIES`)."""
    return FlatFeet() if mb.tree.soles else LegEndFeet()


def part_ids(mb) -> dict[str, int]:
    """PART ids: ``ground`` 1, ``hip`` 2, the links from 3 in ``mb.links`` order, then flat
    feet's foot parts ``leg1_foot``, ``leg2_foot``."""
    ids = {"ground": 1, "hip": 2, **{ln.name: 3 + i for i, ln in enumerate(mb.links)}}
    ids.update(adams_feet(mb).foot_parts(3 + len(mb.links)))
    return ids


def contact_pairs(mb, ids: dict, lanes: bool, n_patches: tuple) -> list[tuple]:
    """The CONTACTs the dataset writes, in id order from 1: ``(cid, leg, role, IGEOM,
    JGEOM)`` with ``role`` ``"foot"`` (a point or arc foot's sphere; a flat foot's heel)
    or ``"toe"`` (a flat foot's toe); each foot sphere against every patch of its leg's
    lane (or the one plane, GRAPHICS/1001)."""
    geoms = adams_feet(mb).geoms(mb, ids)
    first = {"leg1": 1001, "leg2": 1001 + n_patches[0]} if lanes else \
        {"leg1": 1001, "leg2": 1001}
    out, cid = [], 1
    for leg, role, m in geoms:
        count = n_patches[0 if leg == "leg1" else 1] if lanes else n_patches[0]
        for g in range(first[leg], first[leg] + count):
            out.append((cid, leg, role, m, g))
            cid += 1
    return out


def _flat_foot_parts(mb, start: AdamsStart, ids: dict, lanes: bool, frames: dict,
                     feet: tuple) -> list[str]:
    """Flat feet: a foot PART per leg with its frame at the ankle (the leg's foot marker),
    ``REULER`` the leg's angle plus the ankle angle (its x axis along the sole, heel ->
    toe), the contact model's regularising mass at the ankle and inertia about it
    (``contact.flat_foot_mass_kg``, ``contact.flat_foot_inertia_kg_m2``: the rigid view's
    feet are massless), its frame in its leg's lane (z as the leg's ankle marker: the
    revolute's markers coincide), contact spheres at heel (``foot`` marker) and toe
    (``toe`` marker),
    radius :func:`walkerlab.export.mjcf_scene.point_foot_radius` as a point foot's.
    ``feet``: :func:`walkerlab.export.scene_feet.flat_foot_bodies`."""
    out = ["!", "! ---- flat feet: parts on the ankles (the contact model's mass) ----"]
    for k, leg in enumerate(LEGS):
        heel, toe, _k, _c, _rest, mass, inertia = feet[k]
        ln = next(x for x in mb.links if x.name == leg_end(mb, leg))
        joint, vjoint = frames[ln.name]
        psi, w = start.angles[ln.name], start.rates[ln.name]
        a, da = start.ankles[leg]
        r = np.array(_rot(psi, (0.0, -ln.foot_m)))
        pos, vel = joint + r, vjoint + w * np.array((-r[1], r[0]))
        p = ids[f"{leg}_foot"]
        zl = LANE_Z[leg] * mb.leg_length_m * MM if lanes else 0.0
        out += [f"! {leg}_foot: {mass:g} kg at the ankle, heel {heel:g} m, toe {toe:g} m"]
        out += part_statement(p, mass, inertia * MM * MM, pos, zl, psi + a, vel, w + da)
        out += [f"MARKER/{marker_id(p, 'cm')}, PART={p}, QP=0.0, 0.0, 0.0",
                f"MARKER/{marker_id(p, 'joint')}, PART={p}, QP=0.0, 0.0, 0.0"]
        d = 2 * _foot_sphere_m(mb) * MM
        for role, x in (("foot", -heel), ("toe", toe)):
            out += _stmt(f"MARKER/{marker_id(p, role)}, PART={p}", f"QP={_fs(x * MM, 0.0, 0.0)}")
            out += _sphere(marker_id(p, role), d)
    return out
