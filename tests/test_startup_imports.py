"""Start-up of the main job (``walkerlab contact-sim``): what its process imports and hashes.

A warm ``contact-sim`` is mostly start-up (imports, numba's cache, artifact checks), so the
path keeps out what it does not use: the command layer and the stage modules import no
plotting, symbolic, optimal-control or parallel package, no rigid-walker analysis (the
upstream ``fixedpoint.h5`` is only checked) and no ``scipy.integrate`` (the compiled contact
integrator needs none); checked in a fresh interpreter through ``sys.modules``.  The content
hash of an unchanged upstream artifact is remembered across processes in the private user
cache, and an edit is still detected.
"""

from __future__ import annotations

import hashlib
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import h5py
import numpy as np
import pytest

from walkerlab.config import scene_from_dict
from walkerlab.io import artifacts as A

ROOT = Path(__file__).resolve().parents[1]

#: never imported by the command layer, the stage modules of ``contact-sim`` (and its
#: upstream check) or the contact integrator's modules
NOT_ON_THE_PATH = ("matplotlib", "sympy", "casadi", "mujoco", "dask", "xarray", "pandas",
                   "scipy.integrate", "scipy.optimize", "walkerlab.plotting",
                   "walkerlab.studies", "walkerlab.optimal", "walkerlab.analysis.gait.poincare")

_CHILD = """
import json, sys
import walkerlab.cli
from walkerlab.cli import errors
from walkerlab.stages import contact_sim, fixedpoint, pipeline
import walkerlab.integrate.contact, walkerlab.integrate.contact_powered
print(json.dumps(sorted(m for m in sys.argv[1:] if m in sys.modules)))
"""


def test_contact_sim_path_imports_nothing_it_does_not_use():
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    r = subprocess.run([sys.executable, "-c", _CHILD, *NOT_ON_THE_PATH], env=env, cwd=ROOT,
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    assert json.loads(r.stdout) == []


def test_guard_still_reports_a_fixed_point_not_found_in_one_line(capsys):
    """The guard looks the rigid analysis' error up only once its module is loaded."""
    import typer

    from walkerlab.analysis.gait.poincare import FixedPointNotFound
    from walkerlab.cli.errors import guard

    def boom():
        raise FixedPointNotFound("diverged", 0.5)

    try:
        guard(boom)()
    except typer.Exit as exc:
        assert exc.exit_code == 1
    err = capsys.readouterr().err
    assert err.startswith("error: no fixed point found: diverged") and "internal" not in err


def _artifact(path: Path, value: float) -> Path:
    scene = scene_from_dict({"name": "memo", "walker": {"leg_length_m": 1.0,
                                                        "leg_mass_kg": 5.0,
                                                        "hip_mass_kg": 10.0,
                                                        "leg_mass_from_foot_m": 0.5},
                             "slope": {"angle_rad": 0.0174}})
    return A.write_artifact(path, "simulate", scene, "k",
                            lambda f: f.create_dataset("a", data=np.arange(3.0) * value), 0.0)


def test_content_hash_remembered_across_processes_and_an_edit_still_seen(tmp_path,
                                                                          monkeypatch):
    """A second process (the per-process memo emptied) verifies an unchanged artifact from
    the user cache without hashing it; an edit (same size) changes the file's stamp and is
    hashed and detected; a damaged memo entry is a miss."""
    monkeypatch.setenv("WALKERLAB_CACHE_DIR", str(tmp_path / "cache"))
    path = _artifact(tmp_path / "memo" / "x.h5", 1.0)
    now = time.time_ns()
    monkeypatch.setattr(A.time, "time_ns", lambda: now + 10_000_000_000)  # the file is "old"
    hashed = []
    real = A.content_hash_of
    monkeypatch.setattr(A, "content_hash_of", lambda f: hashed.append(1) or real(f))
    monkeypatch.setattr(A, "_HASH_MEMO", {})
    assert A.verified_hash(path) == "k" and len(hashed) == 1
    monkeypatch.setattr(A, "_HASH_MEMO", {})  # a new process
    assert A.verified_hash(path) == "k" and len(hashed) == 1  # remembered on disk
    entries = list((tmp_path / "cache" / "hashes").iterdir())
    assert len(entries) == 1 and entries[0].stat().st_mode & 0o777 == 0o600
    time.sleep(0.02)
    with h5py.File(path, "r+") as f:  # same size, new value
        f["a"][1] = 7.0
    monkeypatch.setattr(A.time, "time_ns", lambda: now + 20_000_000_000)
    monkeypatch.setattr(A, "_HASH_MEMO", {})
    assert A.verified_hash(path) is None and len(hashed) == 2
    entries[0].write_text("{not json")
    monkeypatch.setattr(A, "_HASH_MEMO", {})
    assert A.verified_hash(path) is None and len(hashed) == 3


def test_a_recently_changed_artifact_is_always_hashed(tmp_path, monkeypatch):
    """Within the time-stamp window (2 s) nothing is remembered: each check hashes."""
    monkeypatch.setenv("WALKERLAB_CACHE_DIR", str(tmp_path / "cache"))
    path = _artifact(tmp_path / "memo" / "x.h5", 1.0)
    hashed = []
    real = A.content_hash_of
    monkeypatch.setattr(A, "content_hash_of", lambda f: hashed.append(1) or real(f))
    monkeypatch.setattr(A, "_HASH_MEMO", {})
    assert A.verified_hash(path) == "k" and A.verified_hash(path) == "k"
    assert len(hashed) == 2 and not (tmp_path / "cache" / "hashes").exists()


#: never in the process of a whole (warm) ``contact-sim`` run either: besides the packages
#: above (scipy.optimize is the periodic gait's root finder and the step map's brentq), no
#: other scipy subpackage with a heavy import, no terminal-rendering or process-pool
#: machinery, and none of the rigid analysis or the ``--adjust`` search (the rigid gait's
#: friction verdict, a record fixedpoint.h5 holds, is read with it: numpy alone)
NOT_IN_THE_RUN = tuple(m for m in NOT_ON_THE_PATH if m != "scipy.optimize") + (
    "rich", "multiprocessing", "concurrent.futures.process", "scipy.interpolate",
    "scipy.stats", "scipy.signal", "walkerlab.analysis.gait.search",
    "walkerlab.analysis.gait.poincare", "walkerlab.analysis.gait.scene",
    "walkerlab.analysis.gait.rigid_run",
    "walkerlab.analysis.contact.adjust", "walkerlab.analysis.contact.variational")

_RUN = """
import json, sys
from walkerlab.cli import app
try:
    app(["-q", "contact-sim", "configs/paper.yaml", "--force", "--runs-dir", sys.argv[1]])
except SystemExit as exc:
    assert not exc.code, exc.code
print(json.dumps(sorted(m for m in sys.argv[2:] if m in sys.modules)))
"""


@pytest.mark.slow  # two contact-sim processes (~3 s CPU each warm; a cold cache compiles)
def test_a_whole_contact_sim_run_loads_only_what_it_uses(tmp_path):
    """The process of a second (warm) ``walkerlab contact-sim configs/paper.yaml --force``
    (the main job's warm profile, ``scripts/profile_contact_sim.py``) loads none of
    :data:`NOT_IN_THE_RUN`: only the command layer, the stage, the contact model's
    kernels, CyRK, numba, h5py and scipy.optimize."""
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    cmd = [sys.executable, "-c", _RUN, str(tmp_path / "runs"), *NOT_IN_THE_RUN]
    for _ in range(2):  # the first fills the runs folder (fixedpoint.h5) and the caches
        r = subprocess.run(cmd, env=env, cwd=ROOT, capture_output=True, text=True,
                           timeout=600)
        assert r.returncode == 0, r.stderr[-2000:]
    assert json.loads(r.stdout.strip().splitlines()[-1]) == []
    assert (tmp_path / "runs" / "paper" / "contact_sim.h5").is_file()


def test_the_remembered_hashes_stay_bounded(tmp_path, monkeypatch):
    """The user cache's ``hashes/`` (one entry per artifact path: a test suite or a sweep
    writes thousands) keeps at most ``MAX_HASH_ENTRIES``: past it the oldest half (by
    modification time) goes, the newest entries stay, and a pruned artifact is hashed
    again when next asked (a miss, not an error)."""
    monkeypatch.setenv("WALKERLAB_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.setattr(A, "MAX_HASH_ENTRIES", 6)
    now = time.time_ns()
    monkeypatch.setattr(A.time, "time_ns", lambda: now + 10_000_000_000)  # files are "old"
    paths = [_artifact(tmp_path / "memo" / f"x{k}.h5", float(k)) for k in range(7)]
    folder = tmp_path / "cache" / "hashes"

    def entry(p):  # the user cache's file of an artifact path (artifacts._disk_memo)
        name = hashlib.sha256(os.fsencode(os.path.realpath(p))).hexdigest()[:32]
        return folder / f"{name}.json"

    for k, p in enumerate(paths):
        monkeypatch.setattr(A, "_HASH_MEMO", {})
        assert A.verified_hash(p) == "k"
        if entry(p).exists():  # modification times in the past, increasing with k: the
            t = now - (100 - k) * 10**8  # one being written (the 7th) is the newest
            os.utime(entry(p), ns=(t, t))
    left = {e.name for e in folder.iterdir()}
    assert left == {entry(p).name for p in paths[4:]}  # 7 > 6: down to 6 // 2, the newest
    hashed = []
    real = A.content_hash_of
    monkeypatch.setattr(A, "content_hash_of", lambda f: hashed.append(1) or real(f))
    monkeypatch.setattr(A, "_HASH_MEMO", {})
    assert A.verified_hash(paths[0]) == "k" and len(hashed) == 1  # pruned: hashed again
    monkeypatch.setattr(A, "_HASH_MEMO", {})
    assert A.verified_hash(paths[-1]) == "k" and len(hashed) == 1  # kept: not hashed
