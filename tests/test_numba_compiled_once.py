"""numba compiles once per machine: a second process loads every kernel of the main job from
the private user cache (numba's ``cache=True``), compiles nothing and writes nothing there.

The child runs the kernels the paper's main job runs - the contact walker's right-hand side,
Jacobian, contact table, hip heights and CyRK cfunc, a short contact walk, the rigid
walker's compiled flows (Poincare map on ``cyrk_compiled``), the batched step map and the
compiled Monte Carlo walks - and
reports numba's compile events (``numba:compile`` is broadcast only on a cache miss:
``numba.core.dispatcher.Dispatcher.compile``), the dispatchers with more than one
specialisation, and the compiled walks' cache statistics.
"""

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

CHILD = r"""
import json
from numba.core import event as ev
seen = []
class Count(ev.Listener):
    def on_start(self, e):
        pass
    def on_end(self, e):
        d = e.data["dispatcher"]
        seen.append(f"{d.py_func.__module__}.{d.py_func.__qualname__}")
ev.register("numba:compile", Count())

import numpy as np
from numba.core.registry import CPUDispatcher
from walkerlab.config import load_scene
from walkerlab.walker.plant import Plant
from walkerlab.models.contact import scene as S
from walkerlab.analysis.contact.sim import initial_state_from_ideal, simulate_contact
from walkerlab.analysis.gait.poincare import poincare_map
from walkerlab.integrate.solver import Solver
from walkerlab.models.registry import build_walker
from walkerlab.studies.mfpt import step_map_for

sc = load_scene("configs/paper.yaml")
ideal = np.array([-0.2022, 0.1674, -0.6, -0.84])
w, _ = S.build(sc, ideal, 4, plant=Plant.from_scene(sc))
x = initial_state_from_ideal(w, *ideal)
w.rhs(0.0, x); w.jac(0.0, x); w.hip_height(x[None])
w.kernels.contact_table(x[None], *w._args())
simulate_contact(w, x, 0.05)
rw = build_walker(Plant.from_scene(sc))
xs = sc.fixedpoint.initial_guess.as_array(rw.state_names())
poincare_map(rw, xs, Solver("DOP853", 1e-10, 1e-10, None, "cyrk_compiled"), jacobian=True)
sm = step_map_for(sc.model_dump(mode="json"), plant=Plant.from_scene(sc))
sm.step(np.tile(xs, (3, 1)), np.array([0.017, 0.0174, 0.018]))
sm.walk(np.tile(xs, (2, 1)), np.full((2, 3), 0.0174))
multi = sorted(f"{v.py_func.__module__}.{v.py_func.__name__}"
               for m in (w.kernels,) for v in vars(m).values()
               if isinstance(v, CPUDispatcher) and len(v.signatures) > 1)
print(json.dumps({"compiled": seen, "multi": multi}))
"""


def _numba_files(cache: Path) -> dict:
    root = cache / "numba"
    return {str(p): (p.stat().st_mtime_ns, p.stat().st_size)
            for p in root.rglob("*") if p.is_file()} if root.is_dir() else {}


@pytest.mark.slow
def test_second_process_compiles_nothing(tmp_path):
    cache = Path(os.environ["WALKERLAB_CACHE_DIR"])  # the test session's user cache
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    env["PYTHONPATH"] = str(ROOT)

    def run() -> dict:
        p = subprocess.run([sys.executable, "-c", CHILD], cwd=ROOT, env=env,
                           capture_output=True, text=True, timeout=600)
        assert p.returncode == 0, p.stderr[-2000:]
        return json.loads(p.stdout.strip().splitlines()[-1])

    first = run()  # compiles whatever this cache does not hold yet
    assert first["multi"] == [], f"kernels compiled for more than one signature: {first}"
    before = _numba_files(cache)
    second = run()
    assert second["compiled"] == [], f"a second process compiled {second['compiled']}"
    after = _numba_files(cache)
    changed = [f for f in after if before.get(f) != after[f]]
    assert changed == [], f"a second process wrote numba cache files: {changed[:5]}"
