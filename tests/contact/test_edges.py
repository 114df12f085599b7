"""Contact model at the edges (issue 11): geometric trips, typed outcomes, slip per stance
phase, stiffness families (drop test), layering and named parameter indices."""

import ast
import re
from pathlib import Path

import numpy as np
import pytest

from tests.contact.conftest import FP, STEP_LENGTH
from walkerlab.analysis.contact.drop import restitution_curve
from walkerlab.analysis.contact.gait import gait_events
from walkerlab.analysis.contact.gait import phase_slip as _phase_slip
from walkerlab.analysis.contact.sim import initial_state_from_ideal, simulate_contact
from walkerlab.analysis.contact.verdict import CONTACT_OUTCOMES as OUTCOME_KINDS
from walkerlab.config import ContactSettings, SolverSettings, TerrainSettings
from walkerlab.integrate.contact import ContactLimits
from walkerlab.models.contact import ContactWalker

PKG = Path(__file__).resolve().parents[2] / "walkerlab"


def _walker(k=1e5, width=0.10, family="paper"):
    c = ContactSettings(stiffness_n_per_mm_pow_e=k, stiffness_family=family)
    return ContactWalker.from_settings(c, TerrainSettings(patch_width_m=width),
                                       step_length=STEP_LENGTH, n_steps=12)


def test_stiff_heel_strike_bounce_does_not_tunnel_into_a_trip():
    """Issue 11 item 1: at k = 1e7 N/mm^2.2 the first heel strike bounces the foot; a long
    solver step used to carry it 0.16 mm into the patch during the flight, which counted as
    "dead" (force off) and ended the run as a fall at ~0.63 s.  Now the force is on in every
    state over a patch, so the run goes on through the bounces past the first heel strike
    (~0.58 s with the +10 % stance rate)."""
    w = _walker(k=1e7)
    x0 = initial_state_from_ideal(w, *FP, rate_scale=(1.0, 1.1))
    r = simulate_contact(w, x0, 0.75, SolverSettings.for_contact(rtol=1e-8, atol=1e-11))
    assert r.outcome.kind in ("t_final", "scuff"), r.outcome
    assert r.termination == "t_final"
    assert r.walked_steps >= 1
    assert r.steps[1].bounce_count >= 1  # the heel strike did bounce (elastic at 1e7)


def test_trip_is_a_foot_hitting_a_patch_side():
    """A foot moved sideways into a patch below its top is a trip, typed with the foot, the
    patch edge and the time; nothing here depends on a penetration depth."""
    w = _walker(width=0.10)
    x0 = initial_state_from_ideal(w, *FP)
    # put the walker 6 cm uphill with the stance foot (leg2) 2 mm below the ground level:
    # it is in the gap uphill of its patch [-0.05, 0.05], moving downhill towards its side
    x = x0.copy()
    x[0] -= 0.06 * w.tangent[0]
    x[1] -= 0.06 * w.tangent[1]
    x[0] -= 0.002 * w.normal[0]
    x[1] -= 0.002 * w.normal[1]  # 2 mm below the top, in the gap uphill of the patch
    x[4:6] = 1.0 * w.tangent  # moving downhill towards the patch side at 1 m/s
    r = simulate_contact(w, x, 0.2, SolverSettings.for_contact(rtol=1e-8, atol=1e-11))
    assert r.outcome.kind == "trip", r.outcome
    assert r.termination == "trip"
    assert r.outcome.foot == "leg2"
    assert r.outcome.patch_edge_m == pytest.approx(-0.05, abs=1e-12)
    # the run ends at the event: the last sample is the foot on the edge, below the top
    assert r.t[-1] == pytest.approx(r.outcome.time_s)
    assert r.feet["leg2"].s[-1] == pytest.approx(-0.05, abs=1e-6)
    assert r.feet["leg2"].penetration[-1] > 1e-3
    assert "trip" in r.outcome.message and "leg2" in r.outcome.message


def test_typed_outcomes_fall_time_limit_and_slip():
    w = _walker(width=0.30)
    x0 = initial_state_from_ideal(w, *FP)
    # far too slow a swing: the walker falls backwards/forwards -> "fall" with hip height
    r = simulate_contact(w, initial_state_from_ideal(w, *FP, rate_scale=(0.2, 0.2)), 3.0)
    assert r.outcome.kind == "fall" and r.outcome.hip_height_m == pytest.approx(0.5, abs=1e-3)
    # wall-time limit (tiny) -> time_limit after the first chunk
    r = simulate_contact(w, x0, 3.0,
                         SolverSettings.for_contact(),
                         ContactLimits(wall_time_limit_s=1e-6, chunk_s=0.05))
    assert r.outcome.kind == "time_limit" and r.t[-1] < 3.0
    # slip limit below the ~0.5 mm creep of the regularized friction -> slip
    r = simulate_contact(w, x0, 1.6, slip_limit_mm=0.01)
    assert r.outcome.kind == "slip" and r.outcome.foot in ("leg1", "leg2")
    assert set(OUTCOME_KINDS) >= {"heel_strike", "t_final", "trip", "fall", "scuff", "slip",
                                  "airborne", "no_heel_strike", "solver_failure",
                                  "time_limit"}


def test_slip_window_is_one_stance_phase():
    """Slip = s(lift-off) - s(touchdown) per contact phase; flight excluded; NaN when the
    phase has not ended."""
    t = np.linspace(0.0, 1.0, 101)
    s = np.where(t < 0.5, 0.01 * t, 0.005 + 1.0 * (t - 0.5))  # creeps, then flies away
    # phase 1: touchdown 0, lift-off 0.3 -> 3 mm; flight 0.3..0.6; phase 2 from 0.6, open
    assert _phase_slip(t, s, np.array([0.0]), np.array([0.3]), 0.0, 1.0) == pytest.approx(
        0.003)
    assert np.isnan(_phase_slip(t, s, np.array([0.0, 0.6]), np.array([0.3]), 0.0, 1.0))
    # the paper run: every stance phase that ended slid < 2 mm, and the last, open phase of
    # a run cut in double support is NaN, not hundreds of mm of creep
    w = _walker(width=0.10)
    r = simulate_contact(w, initial_state_from_ideal(w, *FP, rate_scale=(1.0, 1.1)), 1.45,
                         SolverSettings.for_contact(rtol=1e-8, atol=1e-11))
    ended = [st for st in r.steps if np.isfinite(st.stance_slip_mm)]
    assert ended and all(abs(st.stance_slip_mm) < 2.0 for st in ended)
    assert np.isnan(r.steps[-1].stance_slip_mm)
    assert all(np.isfinite(st.double_support_creep_mm) for st in r.steps)


class _TwoFeet:
    """A stand-in walker whose two point feet follow given traces (``gait_events`` reads
    the contact table through ``foot_quantities`` and ``contact_names`` only)."""

    def __init__(self, traces):
        self.traces = traces

    def contact_names(self):
        return tuple(self.traces)

    def foot_quantities(self, X):
        return self.traces


def _scuffing_walk():
    """Stance leg2 creeps to and fro (0.01 m/s, 10 Hz; net 0) from 0 to its lift-off at
    0.6 s; leg1 strikes at 0.5 s; leg2 swings from 0.7 s at 1 m/s, scuffs the ground
    (0.8-0.85 s) and strikes at 1.3 s; friction F = -200 v on a loaded foot."""
    t = np.linspace(0.0, 1.6, 1601)
    on2 = (t < 0.6) | ((t >= 0.8) & (t < 0.85)) | (t >= 1.3)
    v2 = np.where(t < 0.6, 0.01 * np.sin(2 * np.pi * t / 0.1),
                  np.where((t >= 0.7) & (t < 1.3), 1.0, 0.0))
    s2 = np.concatenate([[0.0], np.cumsum(0.5 * (v2[1:] + v2[:-1]) * np.diff(t))])
    on1 = t >= 0.5

    def trace(on, v, s):
        pen = np.where(on, 1e-4, -1e-3)
        return {"normal_force": 100.0 * on, "friction_force": -200.0 * v * on,
                "penetration": pen, "penetration_rate": np.gradient(pen, t),
                "slip_velocity": v, "s": s, "on_ground": np.ones_like(t)}

    feet = {"leg1": trace(on1, np.zeros_like(t), np.full_like(t, 0.3)),
            "leg2": trace(on2, v2, s2)}
    return gait_events(_TwoFeet(feet), t, np.zeros((t.size, 1)))


def test_the_stance_slip_is_the_stance_foots_and_its_path_and_friction_work_are_reported():
    """Issue 56 item 15: the net stance slip counted the swing foot's scuff (here 50 mm,
    0.05 s at 1 m/s) and hid the to-and-fro creep; the stance foot's slip path (the
    integral of |v| over its stance, 0.6 s x 0.01 m/s x 2/pi = 3.82 mm) and its friction
    work (200 N s/m x 0.6 s x (0.01 m/s)^2 / 2 = 6 mJ) are reported per step."""
    ev = _scuffing_walk()
    assert ev["hs_leg"] == ["leg1", "leg2"] and ev["steps"][1].scuff_count == 1
    first = ev["steps"][0]
    # six whole creep periods: the net slip is ~0 (the trapezoid on 1 ms samples: < 1e-3 mm)
    assert abs(first.stance_slip_mm) < 1e-3
    # 1 ms trapezoids of a 10 Hz sine: relative error ~1e-3
    assert first.stance_slip_path_mm == pytest.approx(1e3 * 0.6 * 0.01 * 2 / np.pi, rel=5e-3)
    assert first.friction_work_j == pytest.approx(200 * 0.6 * 0.01 ** 2 / 2, rel=5e-3)


def test_drop_restitution_monotone_per_family_rigid_limit_near_plastic():
    """Issue 11 item 4 numbers (c = 90 N s/mm, dmax = 0.1 mm fixed): e = 0.03 (1e5), 0.16
    (1e6), 0.58 (1e7), 0.91 (1e8), 0.99 (1e9).  The rigid-limit family keeps the reference
    restitution (exact self-similarity of the drop without gravity)."""
    ks = [1e5, 1e6, 1e7, 1e8, 1e9]
    r = restitution_curve(ContactSettings(), ks, rtol=1e-8)
    e_p, e_r = r["paper"]["restitution"], r["rigid_limit"]["restitution"]
    assert np.all(np.diff(e_p) > 0)
    np.testing.assert_allclose(e_p, [0.03, 0.16, 0.58, 0.91, 0.99], atol=0.01)
    assert np.all(np.abs(np.diff(e_r)) < 1e-3)  # monotone (constant within 1e-3)
    assert np.all(e_r < 0.05)  # near-plastic
    # and the rigid-limit family's impacts get shorter like k^(-1/(e+1))
    tc = r["rigid_limit"]["contact_time_s"]
    np.testing.assert_allclose(tc[1:] / tc[:-1], 10 ** (-1 / 3.2), rtol=1e-3)


def test_kernels_read_parameters_through_named_indices():
    from walkerlab.codegen.contact_glue import contact_glue

    for src in ((PKG / "models" / "contact" / "_kernels.py").read_text(),
                (PKG / "models" / "contact" / "assembly.py").read_text(), contact_glue()):
        assert not re.findall(r"\bPC?\[\d+\]", src), "bare P[number] in the contact kernels"


def _imports(path):
    """Absolute module names imported by ``path`` (relative imports resolved)."""
    pkg = ".".join(path.relative_to(PKG.parent).with_suffix("").parts[:-1])
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = pkg.rsplit(".", node.level - 1)[0] if node.level > 1 else pkg
                yield f"{base}.{node.module}" if node.module else base
            else:
                yield node.module or ""
        elif isinstance(node, ast.Import):
            yield from (a.name for a in node.names)


@pytest.mark.parametrize("package,never", [
    # the model holds the model only: no integration, analysis, sweep or stage above it
    ("models/contact", ("walkerlab.stages", "walkerlab.analysis", "walkerlab.integrate",
                        "walkerlab.studies", "walkerlab.report")),
    # the rigid view knows no contact model; neither view imports anything above them
    ("models/hybrid", ("walkerlab.models.contact", "walkerlab.stages", "walkerlab.analysis",
                       "walkerlab.integrate", "walkerlab.studies", "walkerlab.report")),
    # generated code sits under both views, the description under the generator
    ("codegen", ("walkerlab.models", "walkerlab.stages", "walkerlab.analysis",
                 "walkerlab.integrate", "walkerlab.studies", "walkerlab.report")),
    ("walker", ("walkerlab.codegen", "walkerlab.models", "walkerlab.stages",
                "walkerlab.analysis", "walkerlab.integrate", "walkerlab.studies")),
    # settings lie under every model (no config <-> contact cycle)
    ("config", ("walkerlab.models.contact", "walkerlab.models", "walkerlab.analysis",
                "walkerlab.integrate", "walkerlab.stages")),
    # integration knows no gait analysis and no stage
    ("integrate", ("walkerlab.analysis", "walkerlab.stages", "walkerlab.studies")),
])
def test_package_imports_point_down(package, never):
    paths = list((PKG / package).glob("*.py"))
    assert paths
    for path in paths:
        bad = [n for n in _imports(path) if n.startswith(never)]
        assert not bad, f"{path.name} imports {bad}"


def test_one_mass_matrix():
    """The mass matrix the right-hand side solves with is the generated one, and equals the
    independent numpy reference (written from the Lagrangian by hand)."""
    from independent.contact_reference import mass_matrix_ref

    w = _walker()
    q = np.array([0.1, 1.2, 0.3, -0.2])
    M = w.mass_matrix(q)
    np.testing.assert_allclose(M, mass_matrix_ref(q, w.L, w.m, w.MH, w.a), rtol=1e-14,
                               atol=1e-14)
    x = np.concatenate([q, [0.2, -0.1, 0.7, -1.1]])  # feet in the air: no contact force
    qdd = w.rhs(0.0, x)[4:]
    np.testing.assert_allclose(qdd, _ref(w, x)[4:], rtol=1e-12, atol=1e-12)


def _ref(w, x):
    """The independent numpy right-hand side (tests/independent/contact_reference.py)."""
    from independent.contact_reference import rhs_ref

    return rhs_ref(np.asarray(x, float), w.L, w.m, w.MH, w.a, w.g, w.phi, w.contact,
                   (w.lane1, w.lane2), w.patch_half_width, w.continuous)


def test_the_drop_test_is_computed_once_per_law_and_a_damaged_entry_is_a_miss(tmp_path,
                                                                              monkeypatch):
    """The second drop of the same law reads the user cache, bit for bit; garbage in the
    cache file is recomputed, not trusted."""
    from walkerlab.analysis.contact import drop

    monkeypatch.setenv("WALKERLAB_CACHE_DIR", str(tmp_path / "cache"))
    calls = []
    real = drop._drop
    monkeypatch.setattr(drop, "_drop", lambda *a: calls.append(a) or real(*a))
    a = drop.drop_restitution(ContactSettings())
    b = drop.drop_restitution(ContactSettings())
    assert len(calls) == 1 and a == b
    (entry,) = (tmp_path / "cache" / "drop").glob("*.json")
    entry.write_text("{not json")
    assert drop.drop_restitution(ContactSettings()) == a and len(calls) == 2


DROP_CHILD = r"""
import json
from walkerlab.analysis.contact import drop
from walkerlab.analysis.contact.record import drop_test
from walkerlab.config import load_scene
calls = []
real = drop._drop
drop._drop = lambda *a: calls.append(a) or real(*a)
d = drop_test(load_scene("configs/paper.yaml").contact, 20.0)
print(json.dumps({"drops": len(calls), "e": d["paper"]["restitution"].tolist()
                  + d["rigid_limit"]["restitution"].tolist()}))
"""


def test_a_second_process_computes_no_drop(tmp_path):
    """The paper's drop test (22 drops, 21 laws) is computed by the first process of a fresh
    user cache and read by the next, the same numbers bit for bit."""
    import json
    import os
    import subprocess
    import sys

    env = {**os.environ, "WALKERLAB_CACHE_DIR": str(tmp_path / "cache"),
           "PYTHONPATH": str(PKG.parent)}

    def run() -> dict:
        p = subprocess.run([sys.executable, "-c", DROP_CHILD], cwd=PKG.parent, env=env,
                           capture_output=True, text=True, timeout=300)
        assert p.returncode == 0, p.stderr[-2000:]
        return json.loads(p.stdout.strip().splitlines()[-1])

    first, second = run(), run()
    assert first["drops"] == 21 and second["drops"] == 0
    assert first["e"] == second["e"]
