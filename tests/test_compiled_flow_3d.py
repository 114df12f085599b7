"""A walker in 3D: the gait search and the simulation integrate its compiled flow (the
printed Python flow is long: ~100 µs a call on a quiet 2-core machine for
``hip_width_stabilised``, the compiled one a few µs through ctypes), the same function to
round-off: a stride equals the Python flow's to the integrator's tolerance."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np

from walkerlab.config import load_scene
from walkerlab.models.registry import build_walker
from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]


def test_a_3d_stride_runs_the_compiled_flow_and_equals_the_python_one(monkeypatch):
    """``hip_width_stabilised`` (a stable 3D gait, DOP853 at rtol = atol = 1e-12): no call
    of the Python flow, and the stride from the fixed point's guess equals the Python
    flow's to 1e-10 (100 times the integrator's tolerance: the two flows differ in the last
    bits, the step-size control then takes other steps; measured ~1e-13)."""
    import walkerlab.integrate.rigid as rigid
    from walkerlab.analysis.gait.poincare import poincare_map
    from walkerlab.analysis.gait.scene import initial_guess
    from walkerlab.integrate.solver import Solver

    scene = load_scene(ROOT / "configs" / "hip_width_stabilised.yaml")
    w = build_walker(Plant.from_scene(scene))
    assert all(p.compiled is not None for p in w.phases)
    calls = []

    def counted(f):
        return lambda t, x: calls.append(1) or f(t, x)

    w = replace(w, phases=tuple(replace(p, flow=counted(p.flow)) for p in w.phases),
                mirror=replace(w.mirror, phases=tuple(replace(p, flow=counted(p.flow))
                                                      for p in w.mirror.phases))
                if w.mirror is not None else None)
    solver = Solver.from_settings(scene.solver)
    x0 = np.asarray(initial_guess(scene, w), float)
    x1, T1, _ = poincare_map(w, x0, solver)
    assert calls == []
    monkeypatch.setattr(rigid, "_runs_compiled", lambda phase, backend: False)
    x2, T2, _ = poincare_map(w, x0, solver)
    assert calls  # the Python flow, as before
    assert np.max(np.abs(x1 - x2)) < 1e-10 and abs(T1 - T2) < 1e-10
    assert np.max(np.abs(x1 - x0)) < 1e-4  # the guess is the gait: a stride returns to it


def test_a_planar_walker_keeps_its_python_flow():
    """The planar walkers' numbers stay as they were: the paper's compass gait (DOP853)
    runs its Python flow (4 µs a call: nothing to gain)."""
    from walkerlab.integrate.rigid import _runs_compiled
    from walkerlab.integrate.solver import Solver

    scene = load_scene(ROOT / "configs" / "paper.yaml")
    w = build_walker(Plant.from_scene(scene))
    backend = Solver.from_settings(scene.solver).resolved_backend()
    assert not any(_runs_compiled(p, backend) for p in w.phases)
