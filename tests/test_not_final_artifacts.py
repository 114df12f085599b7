"""Issue 96: an artifact whose run a wall-clock limit cut short (``not_final``) is written
and read like any other but never reused as up to date; any other artifact is."""

from pathlib import Path

from walkerlab.config import load_scene
from walkerlab.io.freshness import NOT_FINAL_ATTR, not_final, write_if_stale

ROOT = Path(__file__).resolve().parents[1]


def _stage(tmp_path, cut: str, told: list):
    scene = load_scene(ROOT / "configs" / "paper.yaml")
    computed = []

    def compute():
        computed.append(1)

        def writer(f):
            f.attrs["answer"] = 42
            if cut:
                f.attrs[NOT_FINAL_ATTR] = cut
        return writer, {}
    out = write_if_stale("probe", scene, tmp_path / "runs", ("walker",), (), compute,
                         tell=told.append)
    return out, len(computed)


def test_a_cut_short_artifact_is_recomputed_every_time_saying_why(tmp_path):
    told = []
    out1, n1 = _stage(tmp_path, "the contact run: contact_sim.wall_time_limit_s", told)
    assert n1 == 1 and not out1.reused
    assert not_final(out1.path) == "the contact run: contact_sim.wall_time_limit_s"
    out2, n2 = _stage(tmp_path, "the contact run: contact_sim.wall_time_limit_s", told)
    assert n2 == 1 and not out2.reused  # computed again, inputs unchanged
    assert any("cut short by a wall-clock limit" in t and "never kept as a result" in t
               for t in told), told


def test_a_final_artifact_is_reused_and_replaces_a_cut_short_one(tmp_path):
    told = []
    _stage(tmp_path, "the contact run: contact_sim.wall_time_limit_s", told)
    out1, n1 = _stage(tmp_path, "", told)  # this time the run was not cut: a result
    assert n1 == 1 and not_final(out1.path) == ""
    out2, n2 = _stage(tmp_path, "", told)
    assert n2 == 0 and out2.reused
