"""The generated-code cache: a hit does not touch sympy; a corrupt file is regenerated."""

import numpy as np
import pytest

from walkerlab.codegen import cache, legged
from walkerlab.walker.description import BodySpec, Structure

S = Structure("absolute", (BodySpec("mass", "point_mass"),))
P = (9.81, 1.0, 0.0174, 10.0, 5.0, 0.5)
X = np.array([-0.2042, 0.1694, -0.6058, -0.8610])


@pytest.fixture
def fresh(tmp_path, monkeypatch):
    monkeypatch.setenv("WALKERLAB_CACHE_DIR", str(tmp_path))
    cache.clear_memo()
    yield tmp_path / "models"
    cache.clear_memo()


def _forbid_derivation(monkeypatch):
    def boom(*a, **k):
        raise AssertionError("sympy derivation called on a cache hit")
    monkeypatch.setattr(legged, "derive_legged", boom)


def test_second_build_reads_the_cache_without_deriving(fresh, monkeypatch):
    f1 = cache.generated_module(S)["make"](P)["flow"](0.0, X)
    files = list(fresh.glob("*.py"))
    assert len(files) == 1 and not list(fresh.glob("*.tmp"))  # atomic: no temporary left
    cache.clear_memo()  # as a new process would
    _forbid_derivation(monkeypatch)
    f2 = cache.generated_module(S)["make"](P)["flow"](0.0, X)
    assert np.array_equal(f1, f2)


@pytest.mark.parametrize("damage", ["truncate", "edit", "garbage"])
def test_corrupt_cache_file_is_regenerated(fresh, damage):
    cache.generated_module(S)
    path = next(fresh.glob("*.py"))
    good = path.read_text()
    bad = {"truncate": good[: len(good) // 2],
           "edit": good.replace("sin(", "cos(", 1),
           "garbage": "\x00\x01 not python"}[damage]
    path.write_text(bad)
    cache.clear_memo()
    fns = cache.generated_module(S)["make"](P)
    assert np.all(np.isfinite(fns["flow"](0.0, X)))
    assert path.read_text() == good  # rewritten


def test_key_depends_on_structure_not_on_numbers():
    other = Structure("absolute", (BodySpec("rod", "rod"),))
    same = Structure("absolute", (BodySpec("mass", "point_mass"),))
    assert cache.cache_key(S) == cache.cache_key(same)
    assert cache.cache_key(S) != cache.cache_key(other)
