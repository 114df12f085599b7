"""The compiled powered right-hand side (walkerlab.models.contact.powered_source) against the
reference arithmetic of walkerlab.models.contact.actuation.powered_rhs, on every kind of
actuated contact walker: the actuation is data of one compiled function, and it must give
the same accelerations and ledger powers as the Python formulas (to rounding: 1e-12
relative), with either leg in stance, a push-off pulse on, the ankle push-off on, and a heel
strike carried in the data (the switch).  A virtual-constraint controller's torques are
its compiled law's at the role state, written into the law block by the right-hand side
generated for the pair (walkerlab.models.contact.virtual_constraints.compiled_rhs_module)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from walkerlab.analysis.contact.periodic import ideal_gait
from walkerlab.analysis.contact.sim import scene_start
from walkerlab.config import Scene, load_scene
from walkerlab.models.contact.actuation import powered_rhs
from walkerlab.models.contact.powered_data import powered_data
from walkerlab.models.contact.scene import contact_setup
from walkerlab.walker.plant import Plant

CONFIGS = Path(__file__).resolve().parents[2] / "configs"

HIP = {"stiffness_n_m_per_rad": 3.0, "damping_n_m_s_per_rad": 0.5, "constant_n_m": 0.2}
CASES = {
    "straight legs, push-off pulse": ("powered_compass", None),
    "straight legs, saturated hip law": ("paper", {"torques": [
        {"joint": "hip", "law": HIP, "max_torque_n_m": 1.0}]}),
    "torso on straight legs": ("torso_powered", None),
    "locking knees, hip law and pulse": ("kneed", {"torques": [{"joint": "hip", "law": HIP}],
                                                   "push_off": {"impulse_n_s": 0.5}}),
    "flat feet, hip law and pulse": ("flat_feet", {"torques": [{"joint": "hip", "law": HIP}],
                                                   "push_off": {"impulse_n_s": 0.5}}),
    "flat feet, ankle push-off": ("flat_feet_push_off", None),
    "free joints (RABBIT), phase laws": ("rabbit", None),
    "three-link walker, virtual constraints": ("threelink_hzd", None),
    "RABBIT, virtual constraints": ("rabbit_hzd", None),
}
QUICK = ("straight legs, push-off pulse",)


def _walker(name, act):
    base = load_scene(CONFIGS / f"{name}.yaml")
    d = base.model_dump(mode="json", exclude_none=True)
    if act is not None:
        d["walker"]["actuation"] = act
    scene = Scene.model_validate(d)
    # a state near the walker's gait (the passive one's if added)
    gait = ideal_gait(base, plant=Plant.from_scene(base))
    walker, x0, _, _ = scene_start(contact_setup(scene, plant=Plant.from_scene(scene)), gait.x, 2)
    return walker, x0


@pytest.mark.parametrize("case", [pytest.param(c, marks=() if c in QUICK else pytest.mark.slow)
                                  for c in CASES])
def test_the_compiled_powered_rhs_equals_the_reference_formulas(case):
    walker, x0 = _walker(*CASES[case])
    data = powered_data(walker)
    acts = walker.actuators
    rng = np.random.default_rng(3)
    pushes = acts.spec.push_off is not None
    for trial in range(6):
        x = x0 + rng.normal(0.0, 0.02, x0.size)
        stance = trial % 2
        push = (1 - stance, 300.0) if pushes and trial >= 2 else None
        ankle = acts.ankle is not None and trial % 3 == 1
        dx, pw = powered_rhs(walker, x, stance, push, 0.25 - 0.1, ankle)
        ref = np.concatenate([dx, pw])
        y = np.concatenate([x, np.zeros(data.ny - x.size)])
        out = np.empty(data.ny)
        data.rhs(0.25, y, data.data(stance, 0.1, push, ankle), out)
        np.testing.assert_allclose(out, ref, rtol=1e-12, atol=1e-12 * np.max(np.abs(ref)))
        # the same with the heel strike at 0.2 s in the data: the other leg from then
        sw = np.empty(data.ny)
        data.rhs(0.25, y, data.data(1 - stance, 0.0, None, False, 0.2), sw)
        after = np.empty(data.ny)
        data.rhs(0.25, y, data.data(stance, 0.2), after)
        np.testing.assert_array_equal(sw, after)


def test_an_optimised_torque_of_time_is_the_same_function_as_data():
    """A replay's hip torque (Hermite-Simpson's quadratics through each interval's three
    nodes, held outside the step) as the compiled run's law block (kind
    TIME_FEEDFORWARD) gives the torque of the Lagrange form it was made from, inside the
    step and held outside it, to 1e-12 N m."""
    from types import SimpleNamespace

    from walkerlab.codegen.torque_law import law_torque
    from walkerlab.models.actuation import TorqueOfTime
    from walkerlab.optimal.transcription.step import torque_of_time

    rng = np.random.default_rng(7)
    t = np.linspace(0.0, 0.62, 21)
    u = rng.normal(0.0, 2.0, t.size)
    tau = torque_of_time(SimpleNamespace(t=t, u=u))
    law = TorqueOfTime(tau, [(t, u)])
    block = law.packed()
    for s in np.concatenate([rng.uniform(0.0, 0.62, 40), [-0.1, 0.0, 0.31, 0.62, 0.9]]):
        got = law_torque(block, 0, 0.3, -1.0, 0.1, 0.5, s + block[2])[0]
        assert abs(got - tau(s)) < 1e-12, s
