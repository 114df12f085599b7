"""A spoked wheel (the rolling polygon: ``model: rimless_wheel``) in the exchange formats of
multibody libraries, URDF and MJCF, in the x-z plane and with the joint names of
:mod:`walkerlab.export.multibody` (x downhill, z up, hinge axis world -y): a hub on two slide
joints and a hinge ``wheel``, massless spokes with a contact sphere at each tip (McGeer 1990,
"Passive dynamic walking"; Coleman, Chatterjee & Ruina 1997, "Motions of a rimless spoked
wheel").  Its kind has no tree of leg links, so it has its own URDF writers; its MJCF, planar
or 3D, is written by the legged walkers' one MJCF writer
(:func:`walkerlab.export.mjcf_document.walker_mjcf_text`: the hub one body, its spokes its geoms).
"""

from __future__ import annotations

import math
from xml.sax.saxutils import quoteattr

import numpy as np

from walkerlab.export.axes_3d import TO_MUJOCO  # the axes' one place (re-exported)
from walkerlab.export.mjcf_document import MjcfContact, WalkerMjcf, walker_mjcf_text
from walkerlab.export.mjcf_scene import MJCF_MIN_INERTIA_KG_M2
from walkerlab.export.omitted import URDF_GROUND, xml_comments
from walkerlab.export.text import comment, num, nums

__all__ = ["TO_MUJOCO", "WHEEL_3D_GROUND_HALF_WIDTH", "WHEEL_TIP_FRACTION",
           "WHEEL_URDF_OMISSIONS", "wheel3d_keyframe", "wheel3d_mjcf_text", "wheel3d_urdf_text",
           "spoke_point", "wheel_chord_m", "wheel_mjcf_text", "wheel_numbers",
           "wheel_urdf_text"]

#: Radius of a rimless wheel's tip spheres as a fraction of its spoke length [-] (the point
#: feet's ``L/1000``, :func:`walkerlab.export.mjcf_scene.point_foot_radius`).
WHEEL_TIP_FRACTION = 1e-3
#: How far the 3D wheel's MJCF treads and footholds reach across the fall line each side, in
#: spokes [-] (:func:`walkerlab.export.mjcf_ground.wheel_ground`'s ``half_width_m``): a
#: leaning or turning wheel's tips stay on them
WHEEL_3D_GROUND_HALF_WIDTH = 2.0


def wheel_numbers(data, hub_inertia_kg_m2: float | None) -> dict:
    """A spoked wheel's numbers by name (:data:`walkerlab.walker.description.SPOKED_PARAMS`)
    with its hub inertia [kg m^2]: the walker's, else ``hub_inertia_kg_m2`` (the contact
    view's regularisation), else :data:`MJCF_MIN_INERTIA_KG_M2`."""
    p = dict(zip(data.structure.param_names, data.params))
    if p["I_hub"] <= 0.0:
        p["I_hub"] = hub_inertia_kg_m2 if hub_inertia_kg_m2 is not None else MJCF_MIN_INERTIA_KG_M2
    p["n"] = data.structure.spokes
    p["r"] = WHEEL_TIP_FRACTION * p["L"]
    return p


def wheel_chord_m(data) -> float:
    """The distance [m] between two neighbouring spoke tips of a spoked wheel,
    ``2 L sin(pi / spokes)`` (where its footfalls lie apart; McGeer 1990)."""
    p = wheel_numbers(data, None)
    return 2.0 * p["L"] * math.sin(math.pi / p["n"])


def spoke_point(p: dict, k: int, to: float) -> tuple[float, float]:
    """(x, z) [m] in the hub's frame of the point at ``to`` [m] along spoke ``k`` (wheel
    angle 0: spoke 0 hangs straight down; spoke k at ``2 pi k / n`` ahead of it)."""
    psi = 2.0 * math.pi * k / p["n"]
    return to * math.sin(psi), -to * math.cos(psi)


def _urdf_spokes(p: dict) -> list[str]:
    """Each spoke of a wheel (numbers :func:`wheel_numbers`) as a URDF cylinder (visual) and
    its tip's sphere (collision), in the hub link's frame."""
    L, r, n = p["L"], p["r"], p["n"]
    out = []
    for k in range(n):
        mx, mz = spoke_point(p, k, (L - r) / 2)
        tx, tz = spoke_point(p, k, L - r)
        pitch = -2.0 * math.pi * k / n  # the cylinder's z axis turned onto the spoke
        out += [f'    <visual name="spoke{k}"><origin xyz="{nums(mx, 0, mz)}" '
                f'rpy="0 {num(pitch)} 0"/><geometry><cylinder radius="{num(L / 100)}" '
                f'length="{num(L - r)}"/></geometry></visual>',
                f'    <collision name="spoke{k}_tip"><origin xyz="{nums(tx, 0, tz)}"/>'
                f'<geometry><sphere radius="{num(r)}"/></geometry></collision>']
    return out


def _wheel_mjcf(p: dict, name: str, joints, inertia, timestep_s: float, solref,
                friction: float, qpos, qvel) -> dict:
    """What a wheel's MJCF carries beyond the skeleton of the legged walkers' one writer
    (:class:`walkerlab.export.mjcf_document.WalkerMjcf`, by field name; a header and a ground to
    add): the hub body on ``joints`` (:class:`~walkerlab.export.tree_bodies.ExportJoint`)
    with the principal moments ``inertia`` (3,) [kg m^2] about x, y, z, its geoms and
    spokes, the spokes' contact (sliding friction ``friction``, ``condim 3``, no ``solimp``)
    and the ``gait`` keyframe (none without ``qpos``; ``qvel`` None: at rest)."""
    from walkerlab.export.tree_bodies import ExportBody  # light: sympy with the bodies

    hub = ExportBody("hub", "hub", np.zeros(3), tuple(joints), p["M_hub"], np.zeros(3),
                     np.diag(inertia))
    qv = None if qpos is None else (0.0,) * len(qpos) if qvel is None else qvel
    return dict(name=name, bodies=hub, gravity_m_per_s2=p["g"],
                contact=MjcfContact(timestep_s, solref, None, (friction, 0, 0)),
                geoms=lambda b, pad: [f'{pad}<geom name="hub" type="sphere" '
                                      f'size="{num(p["L"] / 25)}"/>', *_mjcf_spokes(p, pad)],
                keyframes=() if qpos is None else (("gait", qpos, qv),))


def _mjcf_spokes(p: dict, pad: str) -> list[str]:
    """Each spoke as an MJCF capsule (no contact) and its tip's sphere ``spoke<k>_tip`` (the
    only geoms that touch the ground), in the hub body's frame (lines at the indent
    ``pad``)."""
    L, r = p["L"], p["r"]
    out = []
    for k in range(p["n"]):
        tx, tz = spoke_point(p, k, L - r)
        out += [f'{pad}<geom name="spoke{k}" type="capsule" size="{num(L / 100)}" '
                f'fromto="0 0 0 {nums(tx, 0, tz)}"/>',
                f'{pad}<geom name="spoke{k}_tip" type="sphere" size="{num(r)}" '
                f'pos="{nums(tx, 0, tz)}" contype="1" conaffinity="1"/>']
    return out


def _wheel_header(name: str, fmt: str, version: str, p: dict, slope: float) -> list[str]:
    return [comment(f"rimless wheel {name!s} exported by walkerlab {version} ({fmt})."),
            comment("Planar wheel in the x-z plane: x downhill (horizontal), z up; joints "
                    "hip_x, hip_z (the hub's position) and wheel (spoke 0's angle from the "
                    "downward vertical, axis -y: positive = its tip ahead of the hub)."),
            comment(f"{p['n']} massless spokes of length {num(p['L'])} m, 2 pi / {p['n']} "
                    f"apart, on a hub of mass {num(p['M_hub'])} kg and inertia "
                    f"{num(p['I_hub'])} kg m^2; a sphere of radius {num(p['r'])} m at each "
                    f"spoke's tip (its lowest point at the spoke length); gravity "
                    f"{num(p['g'])} m/s^2; the ground falls towards +x at {num(slope)} rad "
                    "(McGeer 1990; Coleman, Chatterjee & Ruina 1997).")]


#: What a spoked wheel's URDF leaves out (:mod:`walkerlab.export.omitted`): its ground and
#: contact; its MJCF leaves out nothing.
WHEEL_URDF_OMISSIONS = (URDF_GROUND,)


def wheel_urdf_text(data, name: str, version: str = "",
                    hub_inertia_kg_m2: float | None = None) -> str:
    """A rimless wheel (``model: rimless_wheel``) as URDF: a massless carriage on two
    prismatic joints (``hip_x``, ``hip_z``), the hub on a continuous joint ``wheel`` (axis
    -y), each spoke a capsule-like cylinder (visual) and a sphere at its tip (collision).

    Parameters
    ----------
    data : WalkerData
        From :func:`walkerlab.walker.description.walker_data` (``structure.spokes`` > 0).
    name, version : str
        Model name, walkerlab version (header comment).
    hub_inertia_kg_m2 : float, optional
        A point-mass hub's inertia [kg m^2] (``contact.hub_inertia_kg_m2``; default
        :data:`~walkerlab.export.mjcf_scene.MJCF_MIN_INERTIA_KG_M2`).

    Returns
    -------
    str
        URDF XML (ROS URDF XML specification).
    """
    p = wheel_numbers(data, hub_inertia_kg_m2)
    out = ['<?xml version="1.0"?>', *_wheel_header(name, "URDF", version, p, data.slope_rad),
           *xml_comments(WHEEL_URDF_OMISSIONS), f"<robot name={quoteattr(name)}>",
           '  <link name="world"/>',
           '  <link name="carriage_x"/>', '  <link name="carriage"/>',
           '  <joint name="hip_x" type="prismatic"><parent link="world"/>'
           '<child link="carriage_x"/><axis xyz="1 0 0"/>'
           '<limit lower="-1000" upper="1000" effort="0" velocity="1000"/></joint>',
           '  <joint name="hip_z" type="prismatic"><parent link="carriage_x"/>'
           '<child link="carriage"/><axis xyz="0 0 1"/>'
           '<limit lower="-1000" upper="1000" effort="0" velocity="1000"/></joint>',
           '  <link name="hub">',
           f'    <inertial><origin xyz="0 0 0"/><mass value="{num(p["M_hub"])}"/>'
           f'<inertia ixx="{num(p["I_hub"])}" ixy="0" ixz="0" iyy="{num(p["I_hub"])}" iyz="0" '
           f'izz="{num(p["I_hub"])}"/></inertial>', *_urdf_spokes(p)]
    out += ["  </link>", '  <joint name="wheel" type="continuous"><parent link="carriage"/>'
            '<child link="hub"/><axis xyz="0 -1 0"/></joint>', "</robot>", ""]
    return "\n".join(out)


def wheel_mjcf_text(data, name: str, version: str = "", hub_inertia_kg_m2: float | None = None,
                    qpos=None, qvel=None, timestep_s: float = 1e-4,
                    solref=(0.002, 1.0), friction: float = 1.0, ground=None) -> str:
    """A rimless wheel (``model: rimless_wheel``) as a MuJoCo model (MJCF): the ground plane
    tilted by the slope, the hub body on slide joints ``hip_x``, ``hip_z`` and a hinge
    ``wheel`` (axis -y), each spoke a capsule (no contact) and a sphere ``spoke<k>_tip`` at
    its tip (the only geoms that touch the ground).

    Parameters
    ----------
    data, name, version, hub_inertia_kg_m2
        The wheel, model name, walkerlab version and hub inertia, as for
        :func:`wheel_urdf_text`.
    qpos, qvel : sequence of 3 floats, optional
        A keyframe ``gait`` [m, m, rad] and [m/s, m/s, rad/s] (the floating view's state
        ``[hip_x, hip_y, wheel_angle]`` and its rates: MuJoCo's z is walkerlab's y).
    timestep_s : float
        Integration step [s].
    solref : (float, float)
        MuJoCo's contact time constant [s] and damping ratio [-] (critically damped: the
        plastic impact of the rigid view).
    friction : float
        Sliding friction coefficient [-].
    ground : (list of str, list of str), optional
        The ground's ``asset`` lines and ``worldbody`` geoms in place of the slope's plane
        (stairs, a profile: :func:`walkerlab.export.mjcf_ground.wheel_ground`).

    Returns
    -------
    str
        MJCF XML (MuJoCo XML Reference).
    """
    from walkerlab.export.tree_bodies import ExportJoint  # light: sympy with the bodies

    p = wheel_numbers(data, hub_inertia_kg_m2)
    phi = data.slope_rad
    joints = [ExportJoint("hip_x", "slide", (1.0, 0.0, 0.0)),
              ExportJoint("hip_z", "slide", (0.0, 0.0, 1.0)),
              ExportJoint("wheel", "hinge", (0.0, -1.0, 0.0))]
    plane = (f'    <geom name="ground" type="plane" size="200 2 0.1" euler="0 {num(phi)} 0" '
             'contype="1" conaffinity="1" rgba="0.8 0.8 0.8 1"/>',)
    return walker_mjcf_text(WalkerMjcf(
        **_wheel_mjcf(p, name, joints, (p["I_hub"],) * 3, timestep_s, solref, friction,
                      qpos, qvel),
        header=tuple(_wheel_header(name, "MJCF", version, p, phi)),
        asset=tuple(ground[0]) if ground is not None else (),
        ground=plane if ground is None else tuple(ground[1])))




def wheel3d_keyframe(points, velocities, x, slope_rad: float,
                     tip_radius_m: float) -> tuple[tuple, tuple]:
    """The ``gait`` keyframe of a 3D spoked wheel (``walker.space: 3d``) at the rigid state
    ``x`` (just after a heel strike): its free joint's ``qpos`` (hub position [m], then
    orientation as the unit quaternion ``w, x, y, z``) and ``qvel`` (hub velocity [m/s] in
    world axes, angular velocity [rad/s] in the body's), MuJoCo's axes (:data:`TO_MUJOCO`).

    The body's frame and rates are read from the walker's own points (the stance foot, the
    hub, the axle's tip) and their velocities - a rigid body's, whatever its coordinates:
    body y from the stance foot to the hub (the stance spoke), body z along the axle.  The
    stance tip's sphere (radius ``tip_radius_m``) touches the slope at the origin.

    Parameters
    ----------
    points, velocities : callable ``x -> dict[str, ndarray (3,)]``
        The rigid 3D wheel's generated ``points`` and ``point_velocities``
        (:func:`walkerlab.codegen.cache.functions`): ``stance_foot``, ``hip``, ``axle_tip``.
    x : ndarray (2n,)
    slope_rad : float
    tip_radius_m : float

    Returns
    -------
    (qpos (7,), qvel (6,)) : tuple of float
    """
    import numpy as np
    from scipy.spatial.transform import Rotation

    C = np.array(TO_MUJOCO)
    pts = {k: np.asarray(v, float) for k, v in points(x).items()}
    vel = {k: np.asarray(v, float) for k, v in velocities(x).items()}
    d1 = pts["hip"] - pts["stance_foot"]
    d2 = pts["axle_tip"] - pts["hip"]
    ey, ez = d1 / np.linalg.norm(d1), d2 / np.linalg.norm(d2)
    R = np.column_stack([np.cross(ey, ez), ey, ez])         # walkerlab body -> world

    def skew(v):
        return np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])
    # v_p - v_q = omega x (p - q) for the two spans: least squares (exact for a rigid body)
    A = np.vstack([-skew(d1), -skew(d2)])
    b = np.concatenate([vel["hip"] - vel["stance_foot"], vel["axle_tip"] - vel["hip"]])
    omega = np.linalg.lstsq(A, b, rcond=None)[0]
    nrm = np.array([math.sin(slope_rad), math.cos(slope_rad), 0.0])
    # the stance tip's sphere centre at L - r along the spoke, its lowest point at the origin
    hub = d1 * (1.0 - tip_radius_m / np.linalg.norm(d1)) + tip_radius_m * nrm
    Rm = C @ R @ C.T                                        # MuJoCo body -> MuJoCo world
    qx, qy, qz, qw = Rotation.from_matrix(Rm).as_quat()
    v_hub = np.cross(omega, hub)                            # turning about the foot
    qpos = (*(C @ hub), qw, qx, qy, qz)
    qvel = (*(C @ v_hub), *(Rm.T @ (C @ omega)))
    return tuple(float(v) for v in qpos), tuple(float(v) for v in qvel)


def wheel3d_mjcf_text(data, name: str, version: str = "", qpos=None, qvel=None,
                      timestep_s: float = 1e-4, solref=(0.002, 1.0),
                      friction: float = 1.0, ground=None) -> str:
    """A spoked wheel in three dimensions (``walker.space: 3d``) as a MuJoCo model (MJCF):
    the ground plane tilted by the slope, the wheel one body on a free joint ``free`` (no
    plane constraint), its axle along the body's y (MuJoCo axes, :data:`TO_MUJOCO`), the
    inertia ``I_diam``, ``I_hub``, ``I_diam`` about body x, y, z, each spoke a capsule (no
    contact) and a sphere ``spoke<k>_tip`` at its tip.  The tips' contact is ``condim 3``:
    sliding friction only, no torsional or rolling friction, as the rigid model's stance
    foot turns freely about every axis (Coleman, Chatterjee & Ruina 1997).

    Parameters
    ----------
    data, name, version
        The wheel (:data:`walkerlab.walker.description.SPOKED_3D_PARAMS`), model name,
        walkerlab version.
    qpos, qvel : sequence of 7 and 6 floats, optional
        The ``gait`` keyframe (:func:`wheel3d_keyframe`).
    timestep_s : float
        Integration step [s].
    solref : (float, float)
        MuJoCo's contact time constant [s] and damping ratio [-].
    friction : float
        Sliding friction coefficient [-].
    ground : (list of str, list of str), optional
        The ground's ``asset`` lines and ``worldbody`` geoms in place of the slope's plane:
        stairs (a box per tread, across the fall line ``2 L`` wide each side) or footholds
        (a patch per footfall of the upright wheel rolling down the fall line),
        :func:`walkerlab.export.mjcf_ground.wheel_ground` with ``half_width_m``.

    Returns
    -------
    str
        MJCF XML (MuJoCo XML Reference).
    """
    from walkerlab.export.tree_bodies import ExportJoint  # light: sympy with the bodies

    p = wheel_numbers(data, None)
    n, L, phi, I_axle = p["n"], p["L"], data.slope_rad, p["I_hub"]
    head = comment(f"rimless wheel {name!s} in 3D exported by walkerlab {version} (MJCF): "
                   f"{n} spokes of {num(L)} m, hub {num(p['M_hub'])} kg, inertia "
                   f"{num(I_axle)} kg m^2 about the axle and {num(p['I_diam'])} kg m^2 about "
                   f"a diameter; slope {num(phi)} rad; a free body, no plane constraint")
    return walker_mjcf_text(WalkerMjcf(
        **_wheel_mjcf(p, name, [ExportJoint("free", "free")],
                      (p["I_diam"], I_axle, p["I_diam"]), timestep_s, solref, friction,
                      qpos, qvel),
        header=(head,),
        asset=tuple(ground[0]) if ground is not None else (),
        ground=(f'    <geom name="ground" type="plane" size="400 400 0.1" '
                f'euler="0 {num(phi)} 0" contype="1" conaffinity="1" rgba="0.8 0.8 0.8 1"/>',
                ) if ground is None else tuple(ground[1])))


def wheel3d_urdf_text(data, name: str, version: str = "") -> str:
    """A spoked wheel in three dimensions (``walker.space: 3d``) as URDF: one link ``hub``
    (no joint: a loader gives it a floating base, Pinocchio's ``JointModelFreeFlyer``,
    Drake's free body), its axle along the link's y (MuJoCo's and URDF's axes, z up:
    :data:`TO_MUJOCO`), the inertia ``I_diam``, ``I_hub``, ``I_diam`` about x, y, z, each
    spoke a cylinder (visual) and a sphere at its tip (collision).  URDF has no ground,
    contact or keyframe element: the slope is stated in the header.

    Parameters
    ----------
    data : WalkerData
        The 3D wheel (:data:`walkerlab.walker.description.SPOKED_3D_PARAMS`).
    name, version : str

    Returns
    -------
    str
        URDF XML (ROS URDF XML specification).
    """
    p = wheel_numbers(data, None)
    n, L, I_axle = p["n"], p["L"], p["I_hub"]
    out = ['<?xml version="1.0"?>',
           comment(f"rimless wheel {name!s} in 3D exported by walkerlab {version} (URDF): "
                   f"{n} spokes of {num(L)} m, hub {num(p['M_hub'])} kg, inertia "
                   f"{num(I_axle)} kg m^2 about the axle (y) and {num(p['I_diam'])} kg m^2 "
                   f"about a diameter; slope {num(data.slope_rad)} rad (not in the file: "
                   "URDF has no ground); a free body"),
           f"<robot name={quoteattr(name)}>", '  <link name="hub">',
           f'    <inertial><origin xyz="0 0 0"/><mass value="{num(p["M_hub"])}"/>'
           f'<inertia ixx="{num(p["I_diam"])}" ixy="0" ixz="0" iyy="{num(I_axle)}" iyz="0" '
           f'izz="{num(p["I_diam"])}"/></inertial>', *_urdf_spokes(p),
           "  </link>", "</robot>", ""]
    return "\n".join(out)
