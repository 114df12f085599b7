"""The rigid walker on a ground other than its slope: the heel strike at a landing below (or
above) the stance foot's level (stairs, footholds).

The generated model of every point- or arc-footed biped has the swing foot's clearance above
the slope line through the stance foot (``guard_swing_clearance``: its lowest point's
distance along the slope's normal, :mod:`walkerlab.codegen.legged`; the free-jointed
biped's and the spoked wheel's generated models have it too).  A landing ``drop_m`` [m]
below that line (a stair ``riser_m`` down; negative: up) is the same guard plus a constant,

    ``heel_strike = swing_clearance + drop_m cos(gamma)``  (zero crossing downward),

so the guard stays the generated, compiled one (:class:`walkerlab.codegen.compiled.
CompiledFlow` carries the constant as the guard's offset) and nothing here knows a walker
family.  The impact map is the walker's own (plastic, paper Eq. 5-8).  On level treads
(``gamma = 0``) of stairs going down ``H``, the heel strike is the swing foot reaching
``-H`` relative to the stance foot.

A walker in 3D (the straight legs with hip width, Kuo 1999: :mod:`walkerlab.codegen.
derive_3d`) walks the same grounds: a height along the walking direction (the fall line,
the world's downhill ``x``), level across it (``z``), so a stair's tread or a foothold is the
plane of the slope through the stance foot shifted along the vertical, whatever the feet's
lateral places (the hip width, the lean).  Its generated ``swing_clearance`` is the swing
foot's height along the slope's normal above the plane through the stance foot, so the
landing is the planar one: the clearance reaching ``-drop_m cos(gamma)``.  The stance foot's
axes are the slope's frame (``s`` the fall line, ``n`` the normal, ``z`` across; the lean and
the pelvis' roll about ``s``, the legs' pitches about their rolled ``z``); on stairs the
treads are level (``gamma = 0``), so that frame is the tread's: ``s`` the horizontal walking
direction, ``n`` up.  The walker's rolls are about that fall line, so a ground whose slope
changes from step to step (footholds of their own slopes, a profile) is refused
(:data:`walkerlab.walker.capability_cells.PROFILE_3D`).

The spoked wheel in 3D (Coleman, Chatterjee & Ruina 1997, "Motions of a rimless spoked
wheel: a simple three-dimensional system with impacts", Dynamics and Stability of Systems
12(3); :func:`walkerlab.codegen.derive_3d.derive_spoked`) lands the same way: its generated
``swing_clearance`` is the next spoke's tip's height ``n . r_next`` along the slope's normal
above the plane through the stance tip, whatever its heading ``psi`` and lean ``phi`` (a tip
at ``w`` in the wheel's plane from the stance tip stands ``cos(phi) (w_x sin(beta) + w_y
cos(beta))`` above it, ``beta`` the spin from the normal), so a leaned or turned wheel's
landing is that tip reaching ``-drop_m cos(gamma)`` along the normal, the ground a height
along the fall line and level across it.  Its section's old stance tip is the spoke behind,
``drop_m cos(gamma)`` above: the next tip's clearance at the spin mirrored about the normal
(``beta -> -beta``, heading and lean kept: :class:`_Mirrored`).  A zero landing is the
slope's walker itself (the plane's gait bit for bit); the upright wheel rolling down the
fall line is the planar wheel (its heading and lean rates stay 0), so on stairs too its
gait is the planar wheel's on them.  On level treads (``gamma = 0``) the landing reads the
riser alone: the section's stance spoke leans back by ``asin(riser / (2 L sin alpha))``,
the slope on which the spokes' chord drops a riser - the stairs' mean slope ``atan(riser /
tread)`` when the tread is the chord's run, where the stairs' gait is that slope's.  A
profile is refused (:data:`walkerlab.walker.capability_cells.PROFILE_WHEEL_3D`: the heading
and lean turn about the plane's normal and fall line).

Poincaré section: the state just after heel strike, where the new swing foot (the old stance
foot) lies ``drop_m`` above the new stance foot's line: ``swing_clearance(x+) = drop_m
cos(gamma)`` (both feet on their treads: for point feet exactly, for arc feet their lowest
points).  The section keeps the coordinates the walker's own section keeps; the one it
solves (and those tied to it, a locked knee's shank) comes from this surface by
``scipy.optimize.newton`` with the generated gradient, started on the slope's surface.
"""

from __future__ import annotations

import math
from dataclasses import replace
from functools import partial

import numpy as np

from walkerlab.codegen.cache import functions
from walkerlab.models.ground import foothold_steps, landing_drop
from walkerlab.models.hybrid.base import HybridWalker, OffSection, Phase
from walkerlab.models.hybrid.rigid_foot_modes import on_landing_flat
from walkerlab.walker import parts as P
from walkerlab.walker.capability_cells import PROFILE_3D

__all__ = ["foothold_steps", "landing_drop", "on_footholds", "on_landing",
           "with_clearance_guard"]


def check_periodic_ground(terrain, study: str) -> None:
    """Refuse a study of the periodic gait on a ground without one: a height profile, whose
    steps all differ (the scene's slope gait is only where its walk starts).

    Parameters
    ----------
    terrain : walkerlab.config.TerrainSettings or None
    study : str
        What is refused, for the message (``"the basin of attraction"``).

    Raises
    ------
    ValueError
        ``terrain.kind: profile`` (one line naming the field).
    """
    if terrain is not None and terrain.kind == "profile":
        raise ValueError(f"terrain.kind: profile: {study} is a study of a periodic gait, and a "
                         "profile's steps all differ (walkerlab simulate walks it; the scene "
                         "with terrain.kind: slope has the ramp's periodic gait)")


#: the generated guard a landing shifts by a constant: the swing foot's clearance above the
#: slope line, which every kind that lands on stairs in the rigid view has (a kind without
#: it is refused by its cell of :data:`walkerlab.walker.kinds.CAPABILITIES`)
CLEARANCE = "swing_clearance"


def _at(clearance, offset, t, x):
    """``clearance(t, x) + offset``."""
    return clearance(t, x) + offset


def _flip_at(x, idx, shift=0.0):
    """``x`` with its entries ``idx`` (the spin coordinates) ``q`` mirrored to ``-q - shift``
    (``shift = 0``: negated)."""
    y = np.array(x, copy=True)
    y[idx] = -y[idx] - shift
    return y


class _Mirrored:
    """``clearance`` or its ``gradient`` read at the mirror image of the state about the
    slope's normal: the clearance of the spoke behind the stance spoke of a spoked wheel,
    whose generated ``swing_clearance`` is the next spoke's, ahead (the spokes are
    ``2 alpha`` apart, so the spoke behind at ``theta`` from the slope's normal stands as
    the spoke ahead at ``-theta``; its angle ``q`` from the vertical, ``theta = q + phi``,
    mirrors to ``-q - 2 phi``).

    Only the spin (``idx``: the ``stance`` coordinate and its rate's sign) is mirrored: in
    3D (:func:`walkerlab.codegen.derive_3d.derive_spoked`, ``R = Rot(n, psi) Rot(s, phi)
    Rot(z, beta)``, ``beta = q + gamma``) a spoke's tip at ``w`` in the wheel's plane from
    the stance tip is ``cos(phi) (w_x sin(beta) + w_y cos(beta))`` above the slope's plane
    through the stance tip, whatever the heading ``psi``: the trailing tip's
    ``w = (-L sin 2 alpha, L - L cos 2 alpha)`` at ``beta`` is the next tip's
    ``(L sin 2 alpha, L - L cos 2 alpha)`` at ``-beta``, the lean ``phi`` unchanged."""

    def __init__(self, f, idx, gradient: bool, slope_rad: float):
        self.f, self.idx, self.gradient, self.shift = f, list(idx), gradient, 2.0 * slope_rad

    def __call__(self, *args):
        *t, x = args
        out = self.f(*t, _flip_at(x, self.idx, self.shift))
        return _flip_at(np.asarray(out), self.idx) if self.gradient else out


def _probe(walker: HybridWalker, z: np.ndarray) -> np.ndarray:
    """``walker.from_section`` at the first of ``z, -z, z / 10, -z / 10`` the post-impact
    surface has a state at (the 3D walker's surface needs the stance pitch to outweigh its
    rolls against the hip width: ``z``'s alternating signs can put it off the surface)."""
    for p in (z, -z, 0.1 * z, -0.1 * z):
        try:
            return np.asarray(walker.from_section(p), dtype=float)
        except OffSection:
            continue
    raise OffSection("no state on the walker's own post-impact surface at the probes of "
                     "its section's coordinates")


class _LandingSection:
    """``from_section`` of the post-impact surface ``swing_clearance(x) = level`` (see the
    module docstring): the walker's own ``from_section`` (its slope's surface) as the start,
    then the solved group of coordinates set to the root of the clearance."""

    def __init__(self, walker: HybridWalker, clearance, gradient, level: float):
        self.base, self.clearance, self.gradient, self.level = \
            walker.from_section, clearance, gradient, level
        m = 2 * walker.n_coordinates
        keep = np.asarray(walker.section(np.arange(m, dtype=float)), dtype=float)
        keep = [int(round(k)) for k in keep]
        z = np.linspace(0.137, 0.419, len(keep)) * (-1.0) ** np.arange(len(keep))
        x = _probe(walker, z)
        dropped = [i for i in range(m) if i not in keep]
        # a dropped coordinate equal to a kept one is tied to it (e.g. the shank's rate to
        # the thigh's); the others are the solved group (one value)
        self.group = [i for i in dropped if not any(x[i] == x[j] for j in keep)]

    def __call__(self, z):
        z = np.asarray(z)
        if np.iscomplexobj(z):  # a complex step: the root's first-order change, exactly
            x = self(z.real)
            dx = np.imag(np.asarray(self.base(z)))
            grad = np.asarray(self.gradient(x), dtype=float)
            rest = [i for i in range(x.size) if i not in self.group]
            dx[self.group] = -float(grad[rest] @ dx[rest]) / float(np.sum(grad[self.group]))
            return x + 1j * dx
        x = np.array(self.base(z), dtype=float)
        g = self.group

        def h(s):
            x[g] = s
            return self.clearance(0.0, x) - self.level

        def dh(s):
            x[g] = s
            return float(np.sum(np.asarray(self.gradient(x))[g]))

        from scipy.optimize import newton  # the stairs' section only: no import at start-up

        try:
            s = newton(h, float(x[g[0]]), fprime=dh, tol=1e-15, maxiter=50)
        except (RuntimeError, ZeroDivisionError) as exc:  # no root, or Newton lost it
            raise OffSection(f"no post-impact state with the old stance foot {self.level:g} m "
                             f"above the new stance foot's line here ({exc})") from None
        if not math.isfinite(s):
            raise OffSection(f"no post-impact state with the old stance foot {self.level:g} m "
                             "above the new stance foot's line here")
        x[g] = s
        return x


def on_landing(walker: HybridWalker, data, drop_m: float) -> HybridWalker:
    """``walker`` with its heel strike at a landing ``drop_m`` [m] below the slope line through
    the stance foot (negative: above), the same for every step.

    Parameters
    ----------
    walker : HybridWalker
        Built from the generated model of ``data`` (:func:`walkerlab.models.hybrid.rigid.
        make_rigid_walker`), passive (actuators are added after).
    data : walkerlab.walker.description.WalkerData
        Its description (the generated functions' key).
    drop_m : float
        Landing depth [m] (stairs: the riser, negative going up).

    Returns
    -------
    HybridWalker
        The same walker (flows, impact maps, fall guards, points) with the heel-strike guard
        ``swing_clearance + drop_m cos(gamma)`` and the section of the post-impact surface
        ``swing_clearance = drop_m cos(gamma)``; ``params["landing_drop_m"]`` records the
        drop.  ``drop_m == 0`` returns ``walker`` unchanged (today's guard, bit for bit).

    Raises
    ------
    ValueError
        A kind that does not land on stairs in the rigid view
        (:meth:`walkerlab.walker.kinds.Kind.require`) or printed equations replacing the
        generated ones: one line.
    """
    if drop_m == 0.0:
        return walker
    return _landing(walker, data, float(drop_m))


def with_clearance_guard(walker: HybridWalker, data) -> HybridWalker:
    """``walker`` with its heel strike written as the swing foot's clearance above the slope
    line (:func:`on_landing`'s guard at a landing of depth 0: the same surface as the
    walker's own heel strike, located on another function): the guard whose offset a
    per-step landing height shifts (:meth:`walkerlab.integrate.batch_step.BatchStepMap.step`
    ``height_m``).

    Raises
    ------
    ValueError
        As :func:`on_landing`.
    """
    return _landing(walker, data, 0.0)


def _landing(walker: HybridWalker, data, drop_m: float) -> HybridWalker:
    """:func:`on_landing`'s walker for any ``drop_m`` (0 included): the kind's part of
    its landing part (:attr:`walkerlab.walker.kinds.Kind.landing`)."""
    data.structure.kind.require("stairs", "rigid", "terrain.kind")
    return data.structure.kind.landing(walker, data, drop_m)


def _on_clearance(walker: HybridWalker, data, drop_m: float) -> HybridWalker:
    """The landing of a kind whose heel strike is the generated swing clearance
    (:data:`CLEARANCE`): that guard plus ``drop_m cos(gamma)``, the section of the
    post-impact surface (:class:`_LandingSection`)."""
    f = functions(data)
    name = CLEARANCE
    clear, grad = f[f"guard_{name}"], f[f"grad_{name}"]
    offset = float(drop_m) * math.cos(float(data.slope_rad))
    phases = []
    for ph in walker.phases:
        guards, comp = list(ph.guards), ph.compiled
        cg = list(comp.guards) if comp is not None and comp.guards is not None else None
        for j, g in enumerate(guards):
            if g.outcome != "heel_strike":
                continue
            guards[j] = replace(g, function=partial(_at, clear, offset), gradient=grad)
            if cg is not None:
                cg[j] = (name, offset)
        if cg is not None:
            comp = replace(comp, guards=tuple(cg), _memo={})
        phases.append(Phase(ph.name, ph.flow, tuple(guards), jacobian=ph.jacobian,
                            variational=ph.variational, compiled=comp,
                            constraint=ph.constraint, jacobian_rtol=ph.jacobian_rtol))
    mirror = walker.mirror
    if mirror is not None and data.mirror is not None:  # legs that differ: the next step's
        mirror = _on_clearance(mirror, replace(data.mirror, mirror_params=None), drop_m)
    s_clear, s_grad = clear, grad
    if data.structure.kind.spoked:  # (:class:`_Mirrored`): a spoked wheel's old stance
        # spoke is behind, its generated clearance the spoke's ahead; the legged kinds'
        # swing foot is the old stance foot
        spin = [walker.roles.index("stance")]  # the spin: the planar wheel's one
        g = float(data.slope_rad)  # coordinate, the 3D wheel's third (after heading, lean)
        s_clear, s_grad = _Mirrored(clear, spin, False, g), _Mirrored(grad, spin, True, g)
    return replace(walker, phases=tuple(phases),
                   heel_strike_guard=partial(_at, clear, offset),
                   from_section=_LandingSection(walker, s_clear, s_grad, offset),
                   params={**walker.params, "landing_drop_m": float(drop_m)},
                   mirror=mirror)


def _on_flat_feet(walker: HybridWalker, data, drop_m: float) -> HybridWalker:
    """Flat feet: every stance mode's heel-strike guard and the double support's trailing
    toe (:func:`walkerlab.models.hybrid.rigid_foot_modes.on_landing_flat`)."""
    return on_landing_flat(walker, data, drop_m)


# each kind's landing part (:attr:`walkerlab.walker.kinds.Kind.landing`) given its
# ``(walker, data, drop_m) -> HybridWalker``: the kinds whose rigid view lands on stairs and
# footholds (the rimless wheel's rolling polygon and the legged kinds with the generated
# swing clearance; flat feet, a guard per stance mode)
P.LANDING_CLEARANCE.provide(_on_clearance)
P.LANDING_FLAT_FEET.provide(_on_flat_feet)


def on_footholds(walker_at, data_at, steps, periodic: bool = True,
                 finish=None) -> HybridWalker:
    """The walker on footholds that differ from step to step: step ``k`` lands
    ``steps[k][0]`` [m] below the stance foot's level on ground of slope ``steps[k][1]``
    [rad] (its heel strike the generated clearance above that slope's line plus
    ``drop cos(slope)``, :func:`on_landing`); one Poincaré map walks the whole list (a
    period-``p`` map, ``p = len(steps)``; legs that differ: ``lcm(p, 2)`` steps, each step the
    leg in stance's own walker, as the stride of :attr:`HybridWalker.mirror`).

    Parameters
    ----------
    walker_at : callable ``slope [rad] -> HybridWalker``
        The scene's passive walker on a slope (absolute coordinates: the state is carried
        from one step's slope to the next).
    data_at : callable ``slope [rad] -> WalkerData``
        Its description.
    steps : sequence of (float, float)
        ``(drop_m, slope_rad)`` per step (:func:`foothold_steps`).
    periodic : bool
        The list repeats (False: a walk ends after it).
    finish : callable ``(HybridWalker, WalkerData) -> HybridWalker``, optional
        Applied to each step's walker on its landing (the scene's actuators,
        :func:`walkerlab.models.hybrid.actuated.actuate`: the torques act on every step's
        walker, the heel strike's guard is its landing's).

    Returns
    -------
    HybridWalker
        Step 0's walker with :attr:`~HybridWalker.cycle` the walkers of every step of one
        map; its section (``from_section``) is the post-impact surface of the map's last
        step (the old stance foot ``drop cos(slope)`` above the last landing's line).

    Raises
    ------
    ValueError
        Coordinates measured from the slope with footholds of several slopes, or the
        refusals of :func:`on_landing` (one line).
    """
    steps = tuple((float(d), float(g)) for d, g in steps)
    base = {g: walker_at(g) for g in sorted({g for _, g in steps})}
    data = {g: data_at(g) for g in base}
    if len(base) > 1 and any(d.structure.in_3d for d in data.values()):
        raise ValueError(f"terrain.foothold_slopes_rad: {PROFILE_3D}")
    if len(base) > 1 and any(d.structure.coordinates != "absolute" for d in data.values()):
        raise ValueError("terrain.foothold_slopes_rad: the walker's coordinates are measured "
                         "from the slope (walker.coordinates); footholds of several slopes "
                         "need absolute coordinates")
    first = base[steps[0][1]]
    legs_differ = first.mirror is not None
    p = len(steps)
    n = p * 2 if legs_differ and p % 2 else p
    cycle = []
    for k in range(n):
        drop, g = steps[k % p]
        w, d = base[g], data[g]
        if legs_differ and k % 2 == 1:  # legs[0] in stance: the other leg's numbers
            w, d = w.mirror, replace(d.mirror, mirror_params=None)
        step = on_landing(replace(w, mirror=None), d, drop)
        cycle.append(step if finish is None else finish(step, d))
    last = cycle[-1]
    if legs_differ and data[steps[0][1]].structure.in_3d:  # the map's section is step 0's
        # walker's post-impact surface (its swing clearance: the hip offset of its side,
        # which the last step's mirrored walker has negated) at the last step's landing
        last = on_landing(replace(first, mirror=None), data[steps[0][1]], steps[(n - 1) % p][0])
    return replace(cycle[0], cycle=tuple(cycle), ground_steps=None if periodic else p,
                   mirror=cycle[1] if legs_differ else None,
                   section=last.section, from_section=last.from_section,
                   params={**cycle[0].params,  # the mean drop: downhill on average
                           "landing_drop_m": sum(d for d, _ in steps) / p})
