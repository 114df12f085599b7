"""The walkers' one MJCF writer (the legged walkers, planar and 3D, and the spoked wheels):
the document's skeleton written from the walker's export bodies
(:class:`walkerlab.export.tree_bodies.ExportBody`) and a record of what differs per walker
(:class:`WalkerMjcf`).

The skeleton (MuJoCo XML Reference, https://mujoco.readthedocs.io/en/stable/XMLreference.html),
in this order: the header comments, ``mujoco``, the scene's notes and what the file leaves
out, ``compiler``, ``option`` and ``default`` (MuJoCo's default contact without a scene's,
:class:`MjcfContact`), ``asset``, ``worldbody`` (the ground, then the bodies,
:func:`walkerlab.export.tree_bodies.mjcf_body_lines`), ``tendon`` (the motors' tendons,
:func:`walkerlab.export.motors.mjcf_motor_tendons`, then the walker's fixed tendons),
``actuator`` (:func:`walkerlab.export.motors.mjcf_actuator_lines`), ``equality``,
``custom`` (the numbers and texts a stepping loop reads, :mod:`walkerlab.export.mujoco_walk`)
and ``keyframe``; an empty section is not written.

The record is made by the code that knows the walker: a planar walker's by
:func:`walkerlab.export.multibody.planar_legs_mjcf`, a 3D walker's by
:func:`walkerlab.export.legs_3d_mjcf.legs3d_mjcf`, a spoked wheel's (its spokes the legs,
the hub one body on slides and a hinge or, in 3D, a free joint) by
:func:`walkerlab.export.spoked.wheel_mjcf_text` and
:func:`~walkerlab.export.spoked.wheel3d_mjcf_text`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING
from xml.sax.saxutils import quoteattr

from walkerlab.export.motors import mjcf_actuator_lines, mjcf_motor_tendons, motors
from walkerlab.export.omitted import xml_comments
from walkerlab.export.text import comment, num, nums

if TYPE_CHECKING:  # the bodies' module loads sympy: read lazily (the writers load light)
    from walkerlab.export.tree_bodies import ExportBody

__all__ = ["COMPILER", "GEOM_DEFAULTS", "WalkerMjcf", "MjcfContact", "walker_mjcf_text",
           "tree_mjcf_text"]

#: ``compiler`` of every walker's MJCF: radians, inertias as written, limits from ranges
COMPILER = '  <compiler angle="radian" inertiafromgeom="false" autolimits="true"/>'
#: the geoms' defaults before a scene's contact: no collisions but the ground's and the feet's
GEOM_DEFAULTS = 'contype="0" conaffinity="0" rgba="0.3 0.4 0.8 1"'


@dataclass(frozen=True)
class MjcfContact:
    """A scene's contact and integration as the MJCF's ``option`` and the geoms' ``default``
    carry them (:func:`walker_mjcf_text`).

    Attributes
    ----------
    timestep_s : float
        ``option timestep`` [s] (the integrator ``implicitfast``).
    solref : (float, float)
        Contact time constant [s] and damping ratio [-].
    solimp : tuple of float or None
        ``solimp`` (d0, dwidth, width [m], midpoint, power); None: MuJoCo's default (a
        spoked wheel's tips).
    friction : (float, float, float)
        Sliding [-], torsional [m] and rolling [m] friction.
    condim : int
        Contact dimensionality (3: sliding friction; 4: and torsional).
    cone : str
        ``option cone`` (``elliptic``); empty: MuJoCo's default (pyramidal).
    ccd_tolerance_m : float or None
        ``option ccd_tolerance`` [m]: the convex collider's (a cylinder on a box: the 3D
        walker's round feet); None: MuJoCo's default (1e-6).
    libccd : bool
        ``option/flag nativeccd="disable"``: the convex collider is libccd's, not MuJoCo's
        native one, which (MuJoCo 3.x) turns the normal of a spheroid resting on a box at
        zero depth upward, into the foot (measured on configs/toroidal_feet_3d.yaml's
        keyframe: a 449 N pull on the trailing foot in the first step, the step 9 % long;
        with libccd +0.03 %).
    """

    timestep_s: float
    solref: tuple
    solimp: tuple
    friction: tuple
    condim: int = 3
    cone: str = ""
    ccd_tolerance_m: float | None = None
    libccd: bool = False


@dataclass(frozen=True)
class WalkerMjcf:
    """What a walker's MJCF carries beyond the skeleton :func:`walker_mjcf_text`
    writes: its bodies, and what differs from one walker to another.

    Attributes
    ----------
    name : str
        The model's name (the scene's).
    bodies : ExportBody
        The floating root with every body below it
        (:func:`walkerlab.export.tree_bodies.export_bodies`).
    gravity_m_per_s2 : float
        ``g`` along -z [m/s^2].
    header : tuple of str
        Comment lines before ``<mujoco>`` (the conventions).
    notes : tuple of str
        The scene's notes, each written as a comment after ``<mujoco>``.
    left_out : tuple of Omission
        What the file leaves to a stepping loop (:mod:`walkerlab.export.omitted`).
    contact : MjcfContact or None
        The scene's contact; None: MuJoCo's default contact and timestep.
    geoms : callable
        ``geoms(body, pad) -> list of str``: each body's geoms and sites
        (:func:`walkerlab.export.tree_bodies.mjcf_body_lines`).
    joint_attrs : callable
        ``joint_attrs(joint) -> str``: a joint's attributes after its axis and range (a
        spring's ``stiffness``, ``springref``, ``damping``); empty for none.
    asset : tuple of str
        Lines of the ``asset`` element (a ground profile's height field), or empty.
    ground : tuple of str
        The ground's geoms in the world body.
    actuation : Actuation or None
        ``walker.actuation``: its motors (:func:`walkerlab.export.motors.motors`), their
        tendons and actuators.
    tendons : tuple of str
        The walker's fixed tendons (springs, couplings), after the motors'.
    equality : tuple of str
        The equality constraints (couplings, knee latches).
    numerics : tuple of (str, float)
        The ``custom`` numerics ``(name, value)``; with ``texts`` empty: no ``custom``.
    texts : tuple of (str, str)
        The ``custom`` texts ``(name, data)``.
    keyframes : tuple of (str, tuple, tuple or None)
        ``(name, qpos, qvel)`` of each key (no ``qvel``: None); empty: no ``keyframe``.
    """

    name: str
    bodies: ExportBody
    gravity_m_per_s2: float
    header: tuple = ()
    notes: tuple = ()
    left_out: tuple = ()
    contact: MjcfContact | None = None
    geoms: Callable = lambda b, pad: []
    joint_attrs: Callable = lambda j: ""
    asset: tuple = ()
    ground: tuple = ()
    actuation: object = None
    tendons: tuple = ()
    equality: tuple = ()
    numerics: tuple = ()
    texts: tuple = ()
    keyframes: tuple = ()


def _option_and_default(g: float, c: MjcfContact | None) -> list[str]:
    """``option`` (gravity; a scene's timestep, integrator, cone and convex collider's
    tolerance) and the geoms' ``default`` (a scene's contact)."""
    if c is None:
        return [f'  <option gravity="{nums(0, 0, -g)}"/>',
                f"  <default><geom {GEOM_DEFAULTS}/></default>"]
    cone = f' cone="{c.cone}"' if c.cone else ""
    if c.ccd_tolerance_m is not None:
        cone += f' ccd_tolerance="{num(c.ccd_tolerance_m)}"'
    solimp = "" if c.solimp is None else f' solimp="{nums(*c.solimp)}"'
    close = '><flag nativeccd="disable"/></option>' if c.libccd else "/>"
    return [f'  <option gravity="{nums(0, 0, -g)}" timestep="{num(c.timestep_s)}" '
            f'integrator="implicitfast"{cone}{close}',
            f'  <default><geom {GEOM_DEFAULTS} solref="{nums(*c.solref)}"{solimp} '
            f'friction="{nums(*c.friction)}" condim="{c.condim}"/></default>']


def _block(tag: str, lines) -> list[str]:
    """``lines`` in the element ``tag`` (nothing when there are none)."""
    return [f"  <{tag}>", *lines, f"  </{tag}>"] if lines else []


def walker_mjcf_text(m: WalkerMjcf) -> str:
    """A legged walker, planar or 3D (a spoked wheel too), as a MuJoCo model (MJCF; module
    docstring).

    Parameters
    ----------
    m : WalkerMjcf
        The walker's bodies and what its MJCF carries beyond the skeleton
        (:func:`walkerlab.export.multibody.planar_legs_mjcf`,
        :func:`walkerlab.export.legs_3d_mjcf.legs3d_mjcf`, ``walkerlab.export.spoked``'s
        ``_wheel_mjcf``).

    Returns
    -------
    str
        MJCF XML, ending in a newline.
    """
    from walkerlab.export.tree_bodies import mjcf_body_lines  # light: sympy with the bodies

    motor_list = motors(m.actuation)
    bodies = mjcf_body_lines(m.bodies, m.geoms, joint_attrs=m.joint_attrs)
    # the upper body's hinge: a planar walker's torso_hip, a 3D walker's torso_pitch
    torso = "torso_pitch" if any('joint name="torso_pitch"' in b for b in bodies) \
        else "torso_hip"
    custom = [*(f'    <numeric name="{k}" data="{num(v)}"/>' for k, v in m.numerics),
              *(f"    <text name=\"{k}\" data={quoteattr(v)}/>" for k, v in m.texts)]
    keys = [f'    <key name="{k}" qpos="{nums(*qpos)}"'
            + ("" if qvel is None else f' qvel="{nums(*qvel)}"') + "/>"
            for k, qpos, qvel in m.keyframes]
    out = [*m.header, f"<mujoco model={quoteattr(m.name)}>", *map(comment, m.notes),
           *xml_comments(m.left_out), COMPILER,
           *_option_and_default(m.gravity_m_per_s2, m.contact), *m.asset,
           "  <worldbody>", *m.ground, *bodies, "  </worldbody>",
           *_block("tendon", [*mjcf_motor_tendons(motor_list, torso), *m.tendons]),
           *mjcf_actuator_lines(m.actuation, motor_list),
           *_block("equality", m.equality), *_block("custom", custom),
           *_block("keyframe", keys), "</mujoco>", ""]
    return "\n".join(out)


def tree_mjcf_text(tree, coords, values: dict, roles=None, name: str = "walker") -> str:
    """A body tree's walker alone as MJCF (:func:`walker_mjcf_text`: no ground, contact or
    keyframe; gravity ``g`` along -z): the bodies of
    :func:`walkerlab.export.tree_bodies.export_bodies` and their couplings.

    Parameters
    ----------
    tree : walkerlab.walker.tree.BodyTree
    coords : walkerlab.walker.tree.CoordinateMap
    values : dict
        Each of the tree's parameters' value (SI).
    roles : PelvisRoles, optional
        Default: :class:`walkerlab.export.tree_bodies.PelvisRoles` ``()``.
    name : str

    Returns
    -------
    str
        MJCF XML.
    """
    from walkerlab.export.tree_bodies import (  # light: sympy with the bodies
        PelvisRoles,
        export_bodies,
        mjcf_coupling_lines,
    )

    root, couplings = export_bodies(tree, coords, values, roles or PelvisRoles())
    g = tree.root.gravity_m_per_s2
    tendons, equality = mjcf_coupling_lines(couplings)
    gravity = float(values[g] if isinstance(g, str) else g)
    return walker_mjcf_text(WalkerMjcf(name, root, gravity, tendons=tendons,
                                       equality=equality))
