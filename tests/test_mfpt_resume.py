"""An interrupted MFPT study resumes where it stopped (as sweeps and basin maps do): the
finished Monte Carlo chunks and mesh images in ``mfpt.h5.partial`` are kept, an edited
piece is computed again, and the resumed study gives the same numbers, bit for bit, as an
uninterrupted one."""

from pathlib import Path

import h5py
import numpy as np
import pytest

from walkerlab.config import MfptSettings
from walkerlab.io.mfpt_partial import MfptPartial
from walkerlab.studies import mfpt as work
from walkerlab.walker.plant import Plant

SIGMA = [0.008, 0.006]


@pytest.fixture
def small_chunks(monkeypatch):
    """Walks in chunks of 3, and a count of the chunks / image rows computed."""
    monkeypatch.setattr(work, "WALKS_PER_TASK", 3)
    monkeypatch.setattr(work, "ROWS_PER_TASK", 50)
    calls = {"walks": 0, "images": 0, "stop_walks": None, "stop_images": None}
    walks, images = work.run_walks, work.run_images

    def counted_walks(task):
        if calls["stop_walks"] is not None and calls["walks"] >= calls["stop_walks"]:
            raise KeyboardInterrupt
        calls["walks"] += 1
        return walks(task)

    def counted_images(task):
        if calls["stop_images"] is not None and calls["images"] >= calls["stop_images"]:
            raise KeyboardInterrupt
        calls["images"] += len(task.X)
        return images(task)

    monkeypatch.setattr(work, "run_walks", counted_walks)
    monkeypatch.setattr(work, "run_images", counted_images)
    return calls


@pytest.fixture
def few_nodes(monkeypatch):
    """The mesh's candidate nodes from 10 walks of 10 steps per sigma (not 100 of 20)."""
    from walkerlab.analysis.robustness import mfpt as M

    visited = M.visited_states
    monkeypatch.setattr(M, "visited_states", lambda sm, x0, sds, walks, steps, seed, **kw:
                        visited(sm, x0, sds, 10, 10, seed, **kw))


def _study(scene, x, method, partial=None, sigma=SIGMA):
    st = MfptSettings(sigma_rad=sigma, method=method, walks=10, max_steps=15,
                      mesh_cells=40, mesh_max_cells=80, quadrature_nodes=5)
    return work.mfpt_study(scene, x, st, workers=1, partial=partial, plant=Plant.from_scene(scene))


def _mesh(scene, x, partial=None):
    return _study(scene, x, "mesh", partial, SIGMA[:1])


def _same(a, b):
    """Every number equal bit for bit, but the wall times and the two numbers from the
    quasi-stationary distribution (ARPACK starts from a random vector: 1e-14 apart between
    two uninterrupted runs)."""
    for k in a.values:
        if "wall_time" in k:
            continue
        if k in ("mfpt_steps_mesh_quasi_stationary", "mesh_escaped"):
            np.testing.assert_allclose(a[k], b[k], rtol=1e-10, err_msg=k)
        else:
            np.testing.assert_array_equal(a[k], b[k], err_msg=k)


@pytest.mark.slow
def test_killed_montecarlo_resumes_with_the_finished_chunks(tmp_path, paper_scene,
                                                            paper_fixed_point, small_chunks):
    """10 walks in chunks of 3 (4 chunks per sigma, 8 in all): killed after 5 chunks, the
    rerun computes only the 3 left and gives the uninterrupted numbers bit for bit; a chunk
    edited in the file (its falls flipped) fails its digest and is computed again."""
    x = paper_fixed_point.x
    ref = _study(paper_scene, x, "montecarlo")
    assert small_chunks["walks"] == 8
    part = tmp_path / "mfpt.h5.partial"
    small_chunks.update(walks=0, stop_walks=5)
    with pytest.raises(KeyboardInterrupt), MfptPartial(part, "key") as p:
        _study(paper_scene, x, "montecarlo", p)
    small_chunks.update(walks=0, stop_walks=None)
    with MfptPartial(part, "key") as p:
        got = _study(paper_scene, x, "montecarlo", p)
    assert small_chunks["walks"] == 3
    _same(got, ref)
    with h5py.File(part, "a") as f:  # a user edits a finished chunk
        g = f[f"montecarlo/sigma={SIGMA[0]!r}/chunk=1/fell"]
        g[...] = 1 - g[()]
    small_chunks["walks"] = 0
    with MfptPartial(part, "key") as p:
        again = _study(paper_scene, x, "montecarlo", p)
        assert p.dropped == 1
    assert small_chunks["walks"] == 1
    _same(again, ref)
    small_chunks["walks"] = 0
    with MfptPartial(part, "another input hash") as p:  # other inputs: start afresh
        _study(paper_scene, x, "montecarlo", p)
    assert small_chunks["walks"] == 8


@pytest.mark.slow
def test_killed_mesh_resumes_at_the_mesh_under_way(tmp_path, paper_scene, paper_fixed_point,
                                                   small_chunks, few_nodes):
    """The mesh refinement (40 then 80 nodes, 5 slope nodes, one sigma) killed during the
    second mesh: the rerun takes the first mesh's images from the file, evaluates only the
    new nodes, and gives the uninterrupted MFPT bit for bit."""
    x = paper_fixed_point.x
    ref = _mesh(paper_scene, x)
    full = small_chunks["images"]
    first = ref.mesh_history[0]["cells"] * 5  # images of the first mesh at the first sigma
    part = tmp_path / "mfpt.h5.partial"
    small_chunks.update(images=0, stop_images=first)
    with pytest.raises(KeyboardInterrupt), MfptPartial(part, "key") as p:
        _mesh(paper_scene, x, p)
    small_chunks.update(images=0, stop_images=None)
    with MfptPartial(part, "key") as p:
        got = _mesh(paper_scene, x, p)
    assert small_chunks["images"] == full - first
    _same(got, ref)
    assert np.all(np.isfinite(got["mfpt_steps_mesh"]))


@pytest.mark.slow
def test_killed_mfpt_stage_resumes_and_keeps_pieces_across_sigma_lists(tmp_path,
                                                                        small_chunks):
    """walkerlab mfpt killed after 3 of its 4 Monte Carlo chunks (sigma 0.008, 10 walks in
    chunks of 3): mfpt.h5.partial holds them, and a rerun asking for sigma 0.008 and 0.01
    computes only the 1 chunk left at 0.008 and the 4 at 0.01; the partial file is gone
    once mfpt.h5 is written, and the numbers at 0.008 equal an uninterrupted run's."""
    import yaml

    from walkerlab.config import load_scene
    from walkerlab.io.schemas.mfpt import load
    from walkerlab.stages import pipeline

    d = yaml.safe_load((Path(__file__).resolve().parents[1] / "configs" / "paper.yaml")
                       .read_text())
    for k in ("contact", "terrain", "contact_sim", "contact_solver", "workprecision",
              "simulate"):
        d.pop(k, None)
    d["mfpt"] = {"walks": 10, "max_steps": 15, "method": "montecarlo"}
    p = tmp_path / "paper_mfpt.yaml"
    p.write_text(yaml.safe_dump(d))
    sc = load_scene(p)
    ref = load(pipeline.run("mfpt", sc, tmp_path / "ref", sigma_rad=[0.008], workers=1).path)
    small_chunks.update(walks=0, stop_walks=3)
    with pytest.raises(KeyboardInterrupt):
        pipeline.run("mfpt", sc, tmp_path / "runs", sigma_rad=[0.008], workers=1)
    part = tmp_path / "runs" / sc.name / "mfpt.h5.partial"
    assert part.is_file()
    small_chunks.update(walks=0, stop_walks=None)
    out = pipeline.run("mfpt", sc, tmp_path / "runs", sigma_rad=[0.008, 0.01], workers=1)
    assert small_chunks["walks"] == 1 + 4
    assert not part.exists()
    got = load(out.path)
    for k in ("mfpt_steps_montecarlo", "montecarlo_heel_strikes", "montecarlo_falls"):
        assert got[k][0] == ref[k][0], k


# -------------------- mfpt's partial file under a lost worker or damage
@pytest.fixture
def chunked_walks(monkeypatch):
    """Walks in chunks of 3; ``calls["lose_after"]`` chunks, then the Dask cluster is lost
    (as :class:`walkerlab.execution.dask.DaskExecutor` reports it)."""
    from walkerlab.execution.dask import DaskLost
    from walkerlab.studies import mfpt as work

    monkeypatch.setattr(work, "WALKS_PER_TASK", 3)
    calls = {"walks": 0, "lose_after": None}
    walks = work.run_walks

    def counted(task):
        if calls["lose_after"] is not None and calls["walks"] >= calls["lose_after"]:
            raise DaskLost("Dask scheduler tcp://x:1 has had no worker for 60 s (2 task(s) "
                           "waiting); the work finished so far is kept: start workers and "
                           "{rerun}")
        calls["walks"] += 1
        return walks(task)

    monkeypatch.setattr(work, "run_walks", counted)
    return calls


def _mc(scene, x, part, key="key"):
    from walkerlab.config import MfptSettings
    from walkerlab.studies import mfpt as work

    st = MfptSettings(sigma_rad=[0.008], method="montecarlo", walks=12, max_steps=10)
    return work.resumable_mfpt_study(scene, x, st, part, key, workers=1,
                                     plant=Plant.from_scene(scene))


def _damage_a_group(part: Path, which: int) -> None:
    """Overwrite the signature of the ``which``-th HDF5 symbol-table node (a group's list
    of links): opening the group fails ("bad symbol table node signature")."""
    data = bytearray(part.read_bytes())
    at = [i for i in range(len(data) - 3) if data[i:i + 4] == b"SNOD"][which]
    data[at:at + 4] = b"XXXX"
    part.write_bytes(bytes(data))


def test_lost_dask_worker_keeps_finished_mfpt_chunks_and_advises_a_rerun(
        tmp_path, paper_scene, paper_fixed_point, chunked_walks):
    from walkerlab.execution.dask import DaskLost

    part = tmp_path / "mfpt.h5.partial"
    chunked_walks["lose_after"] = 2
    with pytest.raises(DaskLost) as info:  # before: MfptStudyError, the partial file removed
        _mc(paper_scene, paper_fixed_point.x, part)
    msg = str(info.value)
    assert "no worker for 60 s" in msg and "--resume" not in msg  # mfpt has no --resume
    assert "rerun the same command" in msg
    assert part.is_file()
    chunked_walks.update(walks=0, lose_after=None)
    _mc(paper_scene, paper_fixed_point.x, part)
    assert chunked_walks["walks"] == 2  # 4 chunks of 3 walks; the 2 finished ones kept


@pytest.mark.parametrize("which", [0, -1])  # the sigma group (every chunk), one chunk's group
def test_damaged_mfpt_partial_pieces_are_dropped_and_computed_again(
        tmp_path, paper_scene, paper_fixed_point, chunked_walks, which):
    part = tmp_path / "mfpt.h5.partial"
    ref = _mc(paper_scene, paper_fixed_point.x, part)[0]
    assert chunked_walks["walks"] == 4 and part.is_file()  # the stage removes it, not the study
    _damage_a_group(part, which)
    chunked_walks["walks"] = 0
    # before: "Unable to synchronously check link existence" on every rerun
    data, p = _mc(paper_scene, paper_fixed_point.x, part)
    assert p.dropped >= 1 and 1 <= chunked_walks["walks"] <= 4
    assert np.array_equal(data["mfpt_steps_montecarlo"], ref["mfpt_steps_montecarlo"])
