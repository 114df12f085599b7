"""The optional numbalsoda route (LSODA from compiled code) against scipy's odeint."""

import numpy as np
import pytest

from walkerlab.analysis.contact.sim import initial_state_from_ideal, simulate_contact
from walkerlab.bench.contact import EXAMPLE_IDEAL, leg_angle_columns
from walkerlab.config import ContactSettings, SolverSettings, TerrainSettings
from walkerlab.integrate import numbalsoda_backend
from walkerlab.models.contact import ContactWalker


def _bench_case():
    """The `walkerlab bench contact` case: paper walker, 0.3 m patches, 5 strides."""
    ide = EXAMPLE_IDEAL
    w = ContactWalker.from_settings(ContactSettings(), TerrainSettings(patch_width_m=0.3),
                                    step_length=ide["step_length"], n_steps=12)
    x0 = initial_state_from_ideal(w, ide["theta1"], ide["theta2"], ide["dtheta1"],
                                  ide["dtheta2"])
    return w, x0, 1.03 * 10 * ide["step_period"]


def test_numbalsoda_five_strides_match_odeint():
    """Same run, rtol 1e-10: both integrators are within ~6e-9 rad of the rtol-1e-12
    reference (bench), so they must agree to 1e-7 rad in the leg angles (margin ~10x for
    the machine-dependent step sequence) and to 1e-6 s in every heel-strike time."""
    # not importorskip: `import numbalsoda` compiles for ~7 s
    if not numbalsoda_backend.available():
        pytest.skip("numbalsoda (optional extra) not installed")
    w, x0, tf = _bench_case()
    a = simulate_contact(w, x0, tf,
                         SolverSettings.for_contact(method="odeint", rtol=1e-10, atol=1e-13))
    b = simulate_contact(w, x0, tf,
                         SolverSettings.for_contact(method="numbalsoda", rtol=1e-10, atol=1e-13))
    assert b.method == "numbalsoda" and b.termination == a.termination == "t_final"
    assert b.nfev > 0 and b.walked_steps == a.walked_steps == 10
    assert b.heel_strike_legs == a.heel_strike_legs
    np.testing.assert_allclose(b.heel_strike_times, a.heel_strike_times, atol=1e-6)
    assert np.array_equal(a.t, b.t)
    assert np.abs(b.x[:, leg_angle_columns(w)] - a.x[:, leg_angle_columns(w)]).max() < 1e-7


def test_numbalsoda_missing_or_unsupported_is_one_clear_error(monkeypatch):
    w, x0, _ = _bench_case()
    with pytest.raises(ValueError, match="max_step_s"):
        simulate_contact(w, x0, 0.01,
                         SolverSettings.for_contact(method="numbalsoda", max_step_s=1e-3))
    monkeypatch.setattr(numbalsoda_backend, "lsoda", None)
    with pytest.raises(ValueError, match=r"pip install -e '\.\[numbalsoda\]'"):
        simulate_contact(w, x0, 0.01, SolverSettings.for_contact(method="numbalsoda"))
