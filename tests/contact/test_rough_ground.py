"""Rough ground for the compliant-contact model (issue 24): checkerboard patches at heights.

The kernels measure a foot's penetration below the top of the patch under it; all heights 0
must be the flat checkerboard bit for bit, and a raised patch must act as the flat ground
moved along its normal (translation invariance of the contact law: an independent check of
the height, not a rerun of the same formula)."""

import numpy as np
import pytest

from walkerlab.analysis.contact import rough as C
from walkerlab.config import ContactSettings
from walkerlab.models.contact import terrain as T
from walkerlab.models.contact.laws import contact_params_si
from walkerlab.models.contact.model import ContactWalker
from walkerlab.walker.plant import Plant

SPACING = 0.372


def _walker(**kw):
    return ContactWalker(contact=contact_params_si(ContactSettings()), continuous=False,
                         lane1=np.array([SPACING, 3 * SPACING]),
                         lane2=np.array([0.0, 2 * SPACING]), **kw)


def _states(w, n=12, seed=0):
    """States with leg2's foot pressed 0-4 mm into its patch at s = 0 (leg1's foot at a
    random angle, often in a gap), moving: the contact law is active."""
    rng = np.random.default_rng(seed)
    m = w.nq - 2
    X = []
    for _ in range(n):
        z = np.concatenate([[-0.2, 0.2] + 0.1 * rng.standard_normal(m),
                            0.3 * rng.standard_normal(m)])
        x = w.kernels.pinned_to_full(z, w.walker_params, np.zeros(2))
        x[:2] -= rng.uniform(0.0, 0.004) * w.normal
        x[w.nq:w.nq + 2] += 0.05 * rng.standard_normal(2)
        X.append(x)
    return np.array(X)


def test_zero_heights_are_the_flat_checkerboard_bit_for_bit():
    """heights 0 everywhere: rhs, Jacobian and the contact table equal the walker without
    heights exactly (the kernels add 0.0 to the penetration only)."""
    a = _walker()
    b = _walker(heights1=np.zeros(2), heights2=np.zeros(2))
    for x in _states(a):
        np.testing.assert_array_equal(a.rhs(0, x), b.rhs(0, x))
        np.testing.assert_array_equal(a.jac(0, x), b.jac(0, x))
    X = _states(a)
    ca, cb = a.contact_quantities(X), b.contact_quantities(X)
    for foot in ca:
        for k in ca[foot]:
            np.testing.assert_array_equal(ca[foot][k], cb[foot][k], err_msg=f"{foot} {k}")


def test_raised_patch_is_the_flat_ground_moved_along_its_normal():
    """Every patch raised by h = 3 mm along the slope's outward normal n: the walker at x
    feels what the flat-ground walker feels at x moved by -h n (penetrations below the
    patch tops equal, forces and accelerations to round-off; a foot in a gap reports its
    depth below the slope line); one patch raised
    alone changes only the foot on it (the penetration differs by exactly h)."""
    h = 0.003
    flat = _walker()
    up = _walker(heights1=np.full(2, h), heights2=np.full(2, h))
    names = flat.state_names()
    ix, iy = names.index("hip_x"), names.index("hip_y")
    n = flat.normal
    moved = 0
    for x in _states(flat, 20):
        y = x.copy()
        y[ix] -= h * n[0]
        y[iy] -= h * n[1]
        np.testing.assert_allclose(up.rhs(0, x), flat.rhs(0, y), rtol=1e-9, atol=1e-9)
        cu, cf = up.contact_quantities(x), flat.contact_quantities(y)
        for foot in cu:  # on a patch: below its top; in a gap: below the slope line
            gap = h if cu[foot]["on_ground"][0] < 0.5 else 0.0
            np.testing.assert_allclose(cu[foot]["penetration"] + gap,
                                       cf[foot]["penetration"], rtol=0, atol=1e-12)
            moved += int(cu[foot]["normal_force"][0] > 0)
    assert moved >= 10  # the feet were on the ground in most states
    one = _walker(heights1=np.array([h, 0.0]))  # leg1's first patch only
    X = _states(flat, 20)
    c1, c0 = one.contact_quantities(X), flat.contact_quantities(X)
    on = c0["leg1"]["on_ground"] > 0.5
    s1 = np.abs(c0["leg1"]["s"] - SPACING) <= flat.patch_half_width
    d = c1["leg1"]["penetration"] - c0["leg1"]["penetration"]
    np.testing.assert_allclose(d[s1], h, rtol=0, atol=1e-15)
    np.testing.assert_array_equal(d[~s1], 0.0)
    np.testing.assert_array_equal(c1["leg2"]["penetration"], c0["leg2"]["penetration"])
    assert (on == (c1["leg1"]["on_ground"] > 0.5)).all()


def test_heights_are_checked_and_footfalls_map_to_lanes():
    """One height per patch (one-line error otherwise); footfall k of the gait lands on
    leg2's lane for even k, leg1's for odd k; per-step slopes become heights by the line
    through each footfall."""
    with pytest.raises(ValueError, match="heights1: one finite height"):
        _walker(heights1=np.zeros(3))
    w = T.footfall_lanes(_walker(), np.array([0.0, -1.0, -2.0, -3.0, -4.0]))
    np.testing.assert_array_equal(w.heights2, [0.0, -2.0])
    np.testing.assert_array_equal(w.heights1, [-1.0, -3.0])
    g = np.array([0.01, 0.02, 0.0])
    h = T.slope_heights(g, 0.01, 0.4)
    np.testing.assert_allclose(h, [0.0, 0.0, -0.4 * np.tan(0.01), -0.4 * np.tan(0.01)
                                   + 0.4 * np.tan(0.01)], rtol=0, atol=1e-15)
    np.testing.assert_array_equal(T.step_heights(4, -0.005), [0.0, -0.005, -0.005, -0.005])
    with pytest.raises(ValueError, match="lanes of footfalls"):
        T.footfall_lanes(ContactWalker(contact=contact_params_si(ContactSettings())), h)
    cont = ContactWalker(contact=contact_params_si(ContactSettings()),
                         lane1=np.array([-0.4, 0.4, 1.2]),
                         lane2=np.array([-0.8, 0.0, 0.8]))  # continuous: contiguous patches
    steps = T.footfall_lanes(cont, np.zeros(6))
    assert not steps.continuous and steps.patch_half_width == pytest.approx(0.4)
    x = _states(cont, 6)
    for xx in x:
        np.testing.assert_allclose(steps.rhs(0, xx), cont.rhs(0, xx), rtol=0, atol=0)


@pytest.fixture(scope="module")
def paper_start(paper_scene, paper_fixed_point):
    """The paper contact walker's own contact-sim start (no periodic-gait search)."""
    return C.contact_start(paper_scene, paper_fixed_point.x, periodic=False,
                           plant=Plant.from_scene(paper_scene))


@pytest.mark.slow
def test_contact_walker_survives_flat_ground_and_falls_off_a_deep_step(paper_start):
    """From the contact run's start the paper walker makes 3 heel strikes on the flat
    checkerboard and on a 1 mm step-down, and does not on a 40 mm step-down (the rigid
    model survives about 5 mm)."""
    assert C.contact_walk(paper_start, T.step_heights(10, 0.0), 3)[:2] == (3, False)
    assert C.contact_walk(paper_start, T.step_heights(10, -0.001), 3)[:2] == (3, False)
    n, fell, kind = C.contact_walk(paper_start, T.step_heights(10, -0.04), 3)
    assert fell and n < 3, kind


@pytest.mark.slow
def test_contact_monte_carlo_same_on_dask_as_in_process(paper_start):
    """Contact Monte Carlo walks (3 walks, 2 steps, sigma 0.01 rad) on a Dask LocalCluster
    give the walks run in this process, walk by walk (each walk's terrain is its own random
    stream)."""
    distributed = pytest.importorskip("distributed")
    from walkerlab.studies.contact_rough import contact_monte_carlo

    here, kinds = contact_monte_carlo(paper_start, 0.01, 3, 2, seed=7, workers=1)
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False,
                                  dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        there, kinds2 = contact_monte_carlo(paper_start, 0.01, 3, 2, seed=7,
                                            scheduler=client)
    np.testing.assert_array_equal(here.steps, there.steps)
    np.testing.assert_array_equal(here.fell, there.fell)
    assert kinds == kinds2


def test_robustness_contact_steps_only_when_asked(paper_scene):
    """robustness.contact off: the contact brackets are NaN (nothing runs).  (A scene
    without a contact section runs on the section's defaults, as ``contact: {}``: no longer a
    refusal; the contact start of such a scene is tested in tests/test_daily_loop.py.)"""
    import math

    from walkerlab.config import RobustnessSettings
    from walkerlab.studies.robustness_study import contact_steps

    off = contact_steps(paper_scene, None, RobustnessSettings(), 0.05,
                        plant=Plant.from_scene(paper_scene))
    assert len(off) == 4 and all(math.isnan(v) for v in off.values())
