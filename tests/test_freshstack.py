"""walkerlab.freshstack: a module imported on a fresh thread's call stack is the ordinary
module (in sys.modules, the same object as a plain import), and a failing import raises in
the caller, as a plain import would."""

import sys

import pytest

from walkerlab.freshstack import import_on_fresh_stack


def test_module_is_imported_once_and_shared(monkeypatch):
    monkeypatch.delitem(sys.modules, "colorsys", raising=False)
    mod = import_on_fresh_stack("colorsys")
    import colorsys

    assert mod is colorsys is sys.modules["colorsys"]
    assert mod.rgb_to_hsv(1.0, 0.0, 0.0) == (0.0, 1.0, 1.0)


def test_missing_module_raises_in_caller():
    with pytest.raises(ModuleNotFoundError, match="walkerlab_no_such_module"):
        import_on_fresh_stack("walkerlab_no_such_module")
