"""The compliant-contact walker's compiled kernels, generated per walker structure.

The generated module is the floating view of the walker (:mod:`walkerlab.codegen.floating`:
``dyn``, ``dyn_jac``, ``feet``, ``feet_jac``, numba), the straight-line right-hand sides
``rhs`` and ``rhs_q`` (:mod:`walkerlab.models.contact.rhs_lines`) and a few lines of glue
(:mod:`walkerlab.codegen.contact_glue`) that hand the generated positions, velocities,
Jacobians, mass matrix and bias, as arrays, to the walker-independent kernels of two
ordinary numba modules: :mod:`walkerlab.models.contact.assembly` (contact geometry into
forces with the laws of :mod:`walkerlab.models.contact._kernels` - IMPACT normal force,
ADAMS Coulomb friction, patch membership -, the knee stops and latch, ``Q = J^T F - h``,
the solve of ``M qdd = Q - h``, the tables) and
:mod:`walkerlab.models.contact.powered_kernels` (the actuators of
:mod:`walkerlab.models.contact.powered_source`).  No mechanics is written by hand: every
position, velocity, Jacobian, mass matrix and bias comes from the generator.  The module is
cached on disk next to the rigid models' code (:func:`walkerlab.codestore.cache_dir`),
keyed on the structure, the generators, the glue and the kernels' files (``_SOURCES``).

Contact parameter vector ``PC`` (float64, (NPC,)), read through named indices:

========  ========================================  ==============
name      meaning                                   unit
========  ========================================  ==============
I_PHI     slope phi                                 rad
I_K       IMPACT stiffness k                        N/m^e
I_E       IMPACT exponent e                         -
I_CMAX    IMPACT max damping                        N s/m
I_DMAX    penetration at max damping                m
I_MUS     static friction coefficient               -
I_MUD     dynamic friction coefficient              -
I_VS      stiction transition velocity              m/s
I_VD      friction transition velocity              m/s
I_HW      patch half width                          m
I_CONT    continuous ground (1/0)                   -
I_KK      knee-stop stiffness                       N m/rad^e
I_KE      knee-stop exponent                        -
I_KC      knee-stop max damping                     N m s/rad
I_KD      knee-stop penetration at max damping      rad
I_KL      knee latch on (1/0)                       -
I_KF      latch release height of the foot          m
I_KA      latch capture angle                       rad
I_TOR     torsional friction coefficient (3D)       m
I_WEPS    load share's regularising force           N
========  ========================================  ==============

Knee latch (``contact.knee_stop.latch``): while a leg's foot is on (or within the release
height I_KF of) the ground, its knee stop acts in both directions (flexion too, with the
same IMPACT law mirrored), weighted by ``STEP(delta, -I_KF, 0, 0, 1)`` of that foot's
penetration delta (so it holds through the heel strike of the other leg, as the rigid
model's locked knee does, and releases as the foot rises) and by
``STEP(ext, -I_KA, 0, -I_KA / 2, 1)`` of the knee's extension (a latch captures a knee only
near straight: a bent knee whose foot touches down is not snapped straight).  A pinned
stance foot (``rhs_pinned``) counts as on the ground.  The analytic Jacobian holds the
weight constant (left out: its dependence on the foot's height; Newton directions only).

Packed data vector of the compiled integrators (``_cyrk``, ``numbalsoda_backend``):
``[n1, n2, PC (NPC), p (NP), c1 (n1), c2 (n2), nfev]`` (``p`` the floating view's parameter
vector, :func:`walkerlab.codegen.floating.param_names`; ``c1``/``c2`` the kernel lanes of
leg1's / leg2's patches: their centres [m], their heights [m] along the outward normal and the
largest height [m], ``n = 2 patches + 1``;
:meth:`walkerlab.models.contact.model.ContactWalker.kernel_lanes`).  A foot's penetration is
measured below the top of the patch under it (all heights 0: the flat ground, bit for bit).

Contact points: ``NF`` of them, named ``CONTACTS`` (``('leg1', 'leg2')`` for point and arc
feet, ``('leg1_heel', 'leg1_toe', 'leg2_heel', 'leg2_toe')`` for flat feet), each with the
IMPACT and Coulomb laws on its leg's lane (``POINT_LEG``); ``PIN`` is leg2's first point
(the point a pinned stance foot holds).

The module's functions (``x = [q, dq]`` (NX,), see :mod:`walkerlab.codegen.floating` for
``q``; ``rhs`` generated straight-line code, the others glue on the kernels named):

=======================================  =================================================
``rhs(x, PC, p, c1, c2)``                dx/dt (NX,) (``assembly.point``, ``knee_torque``)
``jac(x, PC, p, c1, c2)``                d rhs / dx (NX, NX), patch membership locally
                                         constant (``assembly.contact_forces``,
                                         ``jac_assembly``); a walker in 3D: the
                                         torsional friction held constant, a hip-roll
                                         law left out (Newton directions only)
``rhs_pinned(z, PC, p, c1, c2, foot2)``  leg2's point PIN held at ``foot2``:
                                         ``z = [link angles, their rates]`` -> dz/dt
                                         (``assembly.pinned_dynamics``)
``pinned_to_full(z, p, foot2)``          full state (NX,) of a pinned state
``contact_table(X, PC, p, c1, c2)``      (n, NF, 8) per point: penetration, its rate, slip
                                         velocity, s, Fn, Ff, power, on_ground
                                         (``assembly.contact_row``)
``knee_table(X, PC, p, c1, c2)``         (n, 2, 4) per knee: extension, its rate, stop
                                         torque, power (``assembly.knee_row``)
``rhs_packed(y, d, dy)``                 rhs from the packed data vector, counts calls
``powered_rhs(x, PC, p, c1, c2, ...)``   a powered walker's rhs and ledger powers (hip
                                         torque, push-off force; compiled actuation hook)
``build_cyrk()``, ``build_lsoda(sig)``   addresses of cfuncs of ``rhs_packed``
``powered_packed(t, y, d, dy)``          a powered walker's rhs from the data vector
                                         (``powered_kernels``; ``build_cyrk_powered()``)
=======================================  =================================================
"""

from __future__ import annotations

from pathlib import Path

from walkerlab.codegen.contact_glue import contact_glue
from walkerlab.codegen.floating_equations import legs_axial_inertia
from walkerlab.models.contact.assembly import NPC
from walkerlab.models.contact.rhs_lines import rhs_source
from walkerlab.walker.description import Structure

__all__ = ["NPC", "contact_module", "contact_source", "rhs_source"]

_HERE = Path(__file__).parent
#: The files whose text the generated module's source is made of, or whose compiled code
#: numba links into it (its cache key): the glue, the straight-line rhs, the kernels.
_SOURCES = (Path(__file__), _HERE / "powered_source.py", _HERE / "rhs_lines.py",
            _HERE / "assembly.py", _HERE / "powered_kernels.py", _HERE / "_kernels.py",
            _HERE.parent.parent / "codegen" / "torque_law.py",
            _HERE.parent.parent / "codegen" / "contact_glue.py",
            _HERE.parent.parent / "codegen" / "floating_equations.py")  # legs_axial_inertia

def contact_source(structure: Structure, key: str, held_heading: bool = False) -> str:
    """Source of the generated contact module of ``structure`` (its floating view, the
    constants ``NP``, ``KNEE`` (knee stops: kneed legs whose knees are not free), ``KNEES``
    (2, 2) (each knee's thigh and shank coordinates in ``q``), ``NF``,
    ``POINT_LEG``, ``PIN``, ``CONTACTS``, ``STANCE_LAW`` (internal forces by stance: a
    hip-roll law, :attr:`walkerlab.codegen.floating.FloatingEquations.stance_forces`), then
    the glue of
    :func:`walkerlab.codegen.contact_glue.contact_glue` that hands the generated
    kinematics to :mod:`walkerlab.models.contact.assembly`, the straight-line ``rhs`` and
    ``rhs_q``, and the powered glue of
    :func:`~walkerlab.models.contact.powered_source.powered_source`).

    Raises
    ------
    ValueError
        A kneed walker with more than one contact point per leg (flat feet).
    """
    from walkerlab.codegen import floating

    from .powered_source import powered_source

    # a 3D walker of zero hip width: its legs' axial inertia (legs_axial_inertia)
    eq = legs_axial_inertia(structure, floating.derive_floating(structure, held_heading))
    if structure.knee and len(eq.feet) != 2:
        raise ValueError("a kneed walker's contact model needs one contact point per leg")
    fl = floating.generate_floating(eq, key)
    legs = tuple(eq.point_legs)
    # each knee's thigh and shank coordinates (a placeholder without knee stops: unread)
    knees = tuple(tuple(k) for k in eq.knees) or ((0, 0), (0, 0))
    return (fl + f"\nNP = {len(eq.params)}\nKNEE = {bool(eq.knees)}\n"
            f"KNEES = np.array({knees!r}, dtype=np.int64)\n"
            f"NF = {len(eq.feet)}\nPOINT_LEG = {legs!r}\nPIN = {legs.index(1)}\n"
            f"CONTACTS = {tuple(eq.contacts)!r}\nSTANCE_LAW = {bool(eq.stance_forces)}\n"
            + contact_glue() + "\n\n" + rhs_source(eq)
            + "\n\n" + rhs_source(eq, forced=True) + "\n\n" + powered_source())


def _tag(held_heading: bool) -> str:
    """The generated contact module's name tag: ``contact``, or ``contact_held`` with the
    heading held (``contact.hold_heading``: another floating view of the same structure)."""
    return "contact_held" if held_heading else "contact"


def contact_module(structure: Structure, held_heading: bool = False):
    """The imported generated contact module of ``structure`` (compiled lazily by numba,
    cached on disk); ``held_heading``: its floating view without the heading
    (:func:`walkerlab.codegen.floating_equations.derive_floating`).

    Raises
    ------
    ValueError
        Massless bodies (a floating model needs positive leg masses).
    """
    from walkerlab.codegen import floating

    floating.check_masses(structure)
    return floating.load_generated(structure, _tag(held_heading),
                                   lambda key: contact_source(structure, key, held_heading),
                                   sources=_SOURCES)


def contact_module_state(structure: Structure, held_heading: bool = False
                         ) -> tuple[str, bool | None]:
    """The module name :func:`contact_module` gives ``structure``'s generated contact module
    (``ContactWalker.kernels.__name__``) and whether its source is in the user cache already
    (:func:`walkerlab.codegen.floating.generated_state`: False on the first contact run of
    this walker structure with this cache and generator; None without a user cache
    folder), without generating or importing it."""
    from walkerlab.codegen import floating

    return floating.generated_state(structure, _tag(held_heading), sources=_SOURCES)
