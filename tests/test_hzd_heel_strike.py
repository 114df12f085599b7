"""The heel strike of a virtual-constraint controller (``scripts/hzd_heel_strike.py``, the
diagnosis of issue 59's MuJoCo walk of the optimised RABBIT controllers): the impulse on the
new stance foot from the walker's generated extended impact (``De``, ``E``) equals the
whole walker's linear momentum change computed independently (the pinned impact ``Mi q'+ =
B q'-`` and the bodies' mass points), on configs/rabbit_hzd.yaml's closed loop."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from tests.scripts_loader import load_file
from walkerlab.config import load_scene

ROOT = Path(__file__).resolve().parents[1]


def _script():
    return load_file("scripts/hzd_heel_strike.py")


def test_heel_strike_impulse_equals_the_momentum_change():
    """Two derivations of the rigid heel strike's impulse agree to rounding (1e-9 N s on an
    impulse of ~10 N s; measured 1e-14), the trailing foot lifts off (the rigid impact's
    validity: its normal velocity after the strike > 0; 0.243 m/s measured) and the ground
    pushes (Lambda_n > 0)."""
    r = _script().rigid(load_scene(ROOT / "configs" / "rabbit_hzd.yaml"))
    np.testing.assert_allclose(r["impulse_momentum"], r["impulse_world"], rtol=0, atol=1e-9)
    assert r["rate_gap"] < 1e-9
    assert r["impulse_n"] > 1.0
    assert r["trailing_normal"] > 0.1
    # RABBIT's published-style controller: |Lambda_t / Lambda_n| = 0.513 (measured)
    assert abs(r["impulse_t"] / r["impulse_n"]) == pytest.approx(0.5132, abs=1e-3)
