"""Flat feet (Wisse et al. 2006, "Ankle springs instead of arc-shaped feet for passive dynamic
walkers", IEEE-RAS Humanoids) printed from the body tree: every field the printers read of
:func:`walkerlab.codegen.foot_modes.derive_flat` (the three stance modes' flows, the foot
slap and both heel strikes, the guards, the ground reactions, the points and energies per
pinned point, the leg angles, the push-off's extended systems and the double support's
closed-chain systems) equals the leg-vector sums' derivation
(``tests/independent/flat_feet_link_sums.py``, which shares no kinematics with the tree:
each point a sum of ``length * e(angle)`` of absolute link angles), at random states and the
scene's numbers."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
import sympy as sp

from tests.independent.flat_feet_link_sums import derive_flat as leg_vector_sums
from walkerlab.codegen.foot_modes import derive_flat
from walkerlab.config import load_scene
from walkerlab.walker.plant import Plant


def _numbers(scene: str, asymmetric: bool, rng) -> tuple:
    plant = Plant.from_scene(load_scene(f"configs/{scene}.yaml"))
    structure = plant.data.structure
    numbers = dict(zip(structure.param_names, plant.data.params))
    if asymmetric:   # the legs' and feet's numbers per role, each within 20 % of the scene's
        structure = replace(structure, asymmetric=True)
        numbers = {n: numbers.get(n.replace("_sw", "").replace("_st", "")) * rng.uniform(0.8, 1.2)
                   for n in structure.param_names}
    return structure, numbers


def _pairs(e, f) -> list:
    """(what, reference, tree) for every printed field; the double support's with its own
    symbols (the trailing ankle ``b, db``, the toe's force) as extra arguments."""
    dq = sp.Matrix(e.dq)
    pairs = []
    for m in e.flows:
        a, b = e.flows[m], f.flows[m]
        pairs.append((f"{m} accelerations", a.M.LUsolve(-(a.C * dq + a.G)),
                      b.M.LUsolve(-(b.C * dq + b.G))))
        if m != "foot_flat":   # the lock's rows are a convention; its solution the physics
            pairs += [(f"{m} M", a.M, b.M), (f"{m} C dq", a.C * dq, b.C * dq),
                      (f"{m} G", a.G, b.G)]
    for r in e.resets:
        a, b = e.resets[r], f.resets[r]
        pairs += [(f"{r} rates after", a.Mi.LUsolve(a.B * dq), b.Mi.LUsolve(b.B * dq)),
                  (f"{r} swap", a.relabel_q, b.relabel_q)]
    assert list(e.guards) == list(f.guards)   # the compiled flows write them in this order
    pairs += [(f"guard {k}", sp.Matrix([e.guards[k]]), sp.Matrix([f.guards[k]]))
              for k in e.guards]
    pairs += [(f"ground {k}", sp.Matrix(e.ground[k]), sp.Matrix(f.ground[k])) for k in e.ground]
    for pin, ke in e.kinematics.items():
        kf = f.kinematics[pin]
        assert set(ke["points"]) == set(kf["points"])
        pairs += [(f"{pin} point {k}", ke["points"][k], kf["points"][k]) for k in ke["points"]]
        pairs.append((f"{pin} energies", sp.Matrix([ke["kinetic"], ke["potential"]]),
                      sp.Matrix([kf["kinetic"], kf["potential"]])))
    assert set(e.leg_angles) == set(f.leg_angles)
    pairs += [(f"leg angle {k}", sp.Matrix([e.leg_angles[k]]), sp.Matrix([f.leg_angles[k]]))
              for k in e.leg_angles]
    for pin in e.push_off:
        pairs += [(f"push-off {pin} {k}", sp.Matrix(e.push_off[pin][k]),
                   sp.Matrix(f.push_off[pin][k]))
                  for k in ("De", "Jt", "Jh", "Mi", "Be", "push")]
    de, df = e.double_support, f.double_support
    pairs += [(f"double support {k}", sp.Matrix([de[k]]), sp.Matrix([df[k]]))
              for k in ("b_of", "db_of", "trailing_spring", "foot_angle", "lead_normal",
                        "trail_normal", "trail_tangential")]
    pairs += [(f"double support {lead} {k}", de[lead][k], df[lead][k])
              for lead in ("heel_contact", "foot_flat") for k in ("K", "rhs", "Ki", "Ki_rhs")]
    return pairs


@pytest.mark.parametrize(("scene", "asymmetric"), [
    ("flat_feet", False),                          # massless feet
    pytest.param("flat_feet_foot_mass", False, marks=pytest.mark.slow),   # feet with mass
    pytest.param("flat_feet_foot_mass", True, marks=pytest.mark.slow),    # legs that differ
])
def test_flat_feet_printed_from_the_tree_equal_the_leg_vector_sums(scene, asymmetric):
    """Every printed field of the tree's flat feet equals the leg-vector sums' at three
    random states (angles within 0.4 rad, rates and accelerations within 2 and 5 rad/s,
    s^-2; the double support's trailing ankle and the toe's force random too) and the scene's
    numbers (per role within 20 % of them, ``asymmetric``): 1e-12 relative to the largest
    entry (both are exact; they differ by round-off on terms of order 1-100)."""
    rng = np.random.default_rng(98)
    structure, numbers = _numbers(scene, asymmetric, rng)
    e, f = leg_vector_sums(structure), derive_flat(structure)
    assert tuple(map(str, f.q + f.dq + f.qdd + f.params)) == tuple(
        map(str, e.q + e.dq + e.qdd + e.params))
    de = e.double_support
    extra = [de["b"], de["db"], *de["lam"]]
    args = [*e.q, *e.dq, *e.qdd, *e.params, *extra]
    states = [np.concatenate([rng.uniform(-0.4, 0.4, 3), rng.uniform(-2, 2, 3),
                              rng.uniform(-5, 5, 3), [numbers[str(p)] for p in e.params],
                              rng.uniform(-0.3, 0.3, len(extra))]) for _ in range(3)]
    for what, reference, tree in _pairs(e, f):
        fa, fb = sp.lambdify(args, reference), sp.lambdify(args, tree)
        for x in states:
            a, b = np.array(fa(*x), float), np.array(fb(*x), float)
            scale = max(np.max(np.abs(a)), 1.0)
            np.testing.assert_allclose(b, a, rtol=0, atol=1e-12 * scale, err_msg=what)
