"""walkerlab.integrate.brentq: scipy's Brent root finder loaded without scipy.optimize's
package import gives scipy.optimize.brentq's roots bit for bit, its errors, and keeps a
process that never imports scipy.optimize free of it."""

from __future__ import annotations

import inspect
import math
import subprocess
import sys

import numpy as np
import pytest
from scipy.optimize import brentq as scipy_brentq

from walkerlab.integrate import brentq as loader

CASES = [  # (f, a, b, xtol, rtol): smooth, flat, steep, near-double and event-like roots
    (lambda x: x**3 - 2.0 * x - 5.0, 2.0, 3.0, 1e-13, loader.DEFAULT_RTOL),
    (lambda x: math.cos(x) - x, 0.0, 1.0, 4 * np.finfo(float).eps, 4 * np.finfo(float).eps),
    (lambda x: math.tanh(50.0 * (x - 0.3)), -1.0, 2.0, 1e-13, 1e-13),
    (lambda x: (x - 1.0) ** 3 + 1e-9, 0.0, 3.0, 1e-15, loader.DEFAULT_RTOL),
    (lambda x: 0.5 - math.exp(-x) - 1e-3 * x, 0.0, 5.0, 1e-12, loader.DEFAULT_RTOL),
]


@pytest.fixture(scope="module")
def core():
    c = loader._load_core()
    if c is None:  # pragma: no cover - a scipy without the extension where it was
        pytest.fail("scipy.optimize._zeros not found: walkerlab.integrate.brentq falls back "
                    "to the plain import on this scipy (update the loader)")
    return c


@pytest.mark.parametrize("case", range(len(CASES)))
def test_loaded_brent_gives_scipys_root_bit_for_bit(core, case):
    f, a, b, xtol, rtol = CASES[case]
    ours = loader._with_core(core, f, a, b, xtol, rtol)
    assert ours == scipy_brentq(f, a, b, xtol=xtol, rtol=rtol)
    assert abs(f(ours)) < 1e-6


def test_loaded_brent_raises_scipys_errors(core):
    with pytest.raises(ValueError, match="different signs"):
        loader._with_core(core, lambda x: x * x + 1.0, -1.0, 1.0, 1e-12, loader.DEFAULT_RTOL)
    with pytest.raises(ValueError, match="NaN"):
        loader._with_core(core, lambda x: math.nan if x > 0.2 else x - 0.5, 0.0, 1.0, 1e-12,
                          loader.DEFAULT_RTOL)
    with pytest.raises(ValueError, match="rtol too small"):
        loader.brentq(lambda x: x, -1.0, 1.0, 1e-12, rtol=1e-17)


def test_defaults_are_scipys():
    sig = inspect.signature(scipy_brentq).parameters
    assert sig["rtol"].default == loader.DEFAULT_RTOL
    assert sig["maxiter"].default == loader.DEFAULT_MAXITER


def test_a_located_root_imports_no_scipy_optimize():
    code = ("import sys; from walkerlab.integrate.brentq import brentq; "
            "r = brentq(lambda x: x * x - 2.0, 0.0, 2.0, 1e-14); "
            "print(r, 'scipy.optimize' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout.split()
    assert float(out[0]) == scipy_brentq(lambda x: x * x - 2.0, 0.0, 2.0, xtol=1e-14)
    assert out[1] == "False"


def test_a_later_plain_import_gets_the_whole_package():
    code = ("import sys; from walkerlab.integrate.brentq import brentq; "
            "r = brentq(lambda x: x * x - 2.0, 0.0, 2.0, 1e-14); "
            "loaded = 'scipy.optimize._zeros' in sys.modules; "
            "import scipy.optimize as so; "
            "print(loaded, so._zeros is sys.modules['scipy.optimize._zeros'], "
            "so.brentq(lambda x: x * x - 2.0, 0.0, 2.0, xtol=1e-14) == r, "
            "abs(so.root_scalar(lambda x: x * x - 2.0, bracket=(0.0, 2.0)).root ** 2 - 2) < 1e-12)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout.split()
    assert out == ["False", "True", "True", "True"]
