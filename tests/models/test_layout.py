"""The state layout (walkerlab.walker.layout): names, units and slices of a walker view's
state, its legs, and the rigid -> floating link map the contact model starts from."""

import numpy as np
import pytest

from walkerlab.models.contact.model import state_name
from walkerlab.walker.layout import StateLayout, floating_links_from_rigid


def floating(coords):
    names = [state_name(c) for c in coords] + [state_name(c, rate=True) for c in coords]
    units = [("m" if c.startswith("hip_") else "rad") for c in coords]
    return StateLayout.floating(coords, names, units + [u + "/s" for u in units])


STRAIGHT = floating(("hip_x", "hip_y", "leg1_angle", "leg2_angle"))
KNEED = floating(("hip_x", "hip_y", "leg1_thigh_angle", "leg1_shank_angle",
                  "leg2_thigh_angle", "leg2_shank_angle"))


def test_rigid_layout_names_units_slices():
    lay = StateLayout.rigid(("swing_thigh", "swing_shank", "stance"))
    assert lay.names == ("swing_thigh_angle", "swing_shank_angle", "stance_angle",
                         "swing_thigh_rate", "swing_shank_rate", "stance_rate")
    assert lay.units == ("rad",) * 3 + ("rad/s",) * 3
    x = np.arange(6.0)
    assert lay.q(x).tolist() == [0, 1, 2] and lay.qd(x).tolist() == [3, 4, 5]
    assert lay.join(lay.q(x), lay.qd(x)).tolist() == x.tolist()
    assert lay.rate_of("stance_angle") == "stance_rate"
    assert lay.coordinates_of("swing") == ("swing_thigh", "swing_shank")
    with pytest.raises(ValueError, match="3 coordinates"):
        lay.join([1.0, 2.0], [3.0, 4.0])
    with pytest.raises(KeyError, match="no state 'theta1'"):
        lay.index("theta1")


def test_floating_layout_rates_and_legs():
    assert STRAIGHT.names == ("hip_x", "hip_y", "theta1", "theta2",
                              "vhip_x", "vhip_y", "dtheta1", "dtheta2")
    assert STRAIGHT.units[:2] == ("m", "m") and STRAIGHT.units[-1] == "rad/s"
    assert KNEED.rate_of("theta2_shank") == "dtheta2_shank"
    assert KNEED.coordinates_of("leg1") == ("leg1_thigh_angle", "leg1_shank_angle")
    assert KNEED.leg_of("hip_x") is None


def test_built_rigid_walker_layout_is_its_state_names():
    from walkerlab.models.hybrid.printed_equations import make_compass_gait

    w = make_compass_gait(1.0, 5.0, 10.0, 9.81, 0.5, 0.0174, "derived")
    assert list(w.layout().names) == w.state_names()
    assert list(w.layout().units) == w.state_units()


def test_scale_rates_by_leg_not_by_row():
    # the kneed rigid state: the two swing links' rates take the swing scale, the stance
    # leg's rate the stance scale; angles untouched
    lay = StateLayout.rigid(("swing_thigh", "swing_shank", "stance"))
    x = np.array([0.1, 0.2, 0.3, 1.0, 2.0, 3.0])
    y = lay.scale_rates(x, {"swing": 2.0, "stance": 10.0})
    assert y.tolist() == [0.1, 0.2, 0.3, 2.0, 4.0, 30.0]
    with pytest.raises(ValueError, match="'hip' belongs to no leg"):
        StateLayout.rigid(("stance", "hip")).scale_rates(np.ones(4), {"swing": 1, "stance": 1})


def test_rigid_to_floating_links_straight_and_kneed():
    # straight legs: leg1 = swing, leg2 = stance (paper Eq. 11)
    rig = StateLayout.rigid(("swing", "stance")).named([0.1, -0.2, 1.5, -0.75])
    z = floating_links_from_rigid(rig, STRAIGHT, rate_scale=(2.0, 3.0))
    assert z.tolist() == [0.1, -0.2, 3.0, -2.25]
    # kneed: the stance leg's thigh and shank both take the straight stance angle
    rig = StateLayout.rigid(("swing_thigh", "swing_shank", "stance")).named(
        [0.1, 0.4, -0.2, 1.0, 2.0, 3.0])
    z = floating_links_from_rigid(rig, KNEED, rate_scale=(1.0, 0.5))
    assert z.tolist() == [0.1, 0.4, -0.2, -0.2, 1.0, 2.0, 1.5, 1.5]
    with pytest.raises(KeyError):
        floating_links_from_rigid({"stance_angle": 0.0}, STRAIGHT)
