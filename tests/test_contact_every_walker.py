"""The contact side's figures and reports for any walker, checked as a user reads them
(issue 17 part 3): a leg and a link keep their colour across models, the models their
line style."""

from __future__ import annotations

import numpy as np

from walkerlab.walker.plant import Plant


def _kneed_trajectory(order: list[str]):
    from walkerlab.io.trajectory import NamedTrajectory

    t = np.linspace(0.0, 1.0, 5)
    coords, units = {}, {}
    for leg in order:
        for part in ("thigh", "shank"):
            coords[f"{leg}_{part}_angle"], units[f"{leg}_{part}_angle"] = t, "rad"
    for leg in order:
        for part in ("thigh", "shank"):
            coords[f"{leg}_{part}_rate"], units[f"{leg}_{part}_rate"] = t, "rad/s"
    z = np.zeros_like(t, dtype=int)
    return NamedTrajectory(time=t, legs=["leg1", "leg2"], coordinates=coords, units=units,
                           stance_leg=z, step_index=z, kinetic=t, potential=t)


def test_fig7_colours_follow_the_coordinate_name_and_styles_the_model():
    """The rigid kneed walker lists the stance leg (leg2) first, the contact walker leg1
    first: before the fix ideal leg2 and contact leg1 were both blue, and ideal shank and
    contact thigh were both dashed.  Now every (leg, link) has one colour in both models and
    each model one line style, so no two curves of the figure share colour and style."""
    import matplotlib.pyplot as plt

    from walkerlab.plotting import figures as F

    fig = F.fig7_angles_rates({"ideal": _kneed_trajectory(["leg2", "leg1"]),
                               "contact": _kneed_trajectory(["leg1", "leg2"])})
    try:
        for ax in fig.axes[:2]:
            seen = {}
            for line in ax.get_lines():
                name, model = line.get_label().split(" - ")
                seen[(name, model)] = (line.get_color(), line.get_linestyle())
            assert len(seen) == 8
            assert len(set(seen.values())) == 8  # no two curves look alike
            for name in ("leg1_thigh", "leg1_shank", "leg2_thigh", "leg2_shank"):
                assert seen[(name, "ideal")][0] == seen[(name, "contact")][0]
            assert {s for (_, m), (_, s) in seen.items() if m == "ideal"} == {"-"}
            assert {s for (_, m), (_, s) in seen.items() if m == "contact"} == {"--"}
    finally:
        plt.close(fig)


def _trajectory(stems: list[str]):
    from walkerlab.io.trajectory import NamedTrajectory

    t = np.linspace(0.0, 1.0, 5)
    coords = {f"{s}_{k}": t for k in ("angle", "rate") for s in stems}
    units = {n: "rad" if n.endswith("_angle") else "rad/s" for n in coords}
    z = np.zeros_like(t, dtype=int)
    return NamedTrajectory(time=t, legs=["leg1", "leg2"], coordinates=coords, units=units,
                           stance_leg=z, step_index=z, kinetic=t, potential=t)


def test_fig7_of_a_five_link_biped_gives_each_link_one_colour_in_both_views():
    """RABBIT: the rigid view lists each leg's hip-to-foot angle beside its thigh and shank
    (``leg2, leg1, leg2_shank, leg2_thigh, leg1_thigh, leg1_shank, torso``), the contact
    view the links only.  Before, leg1's whole-leg and shank curves were both blue and the
    thigh green in the rigid view but blue in the contact one; now each of the 7 links has
    a colour of its own, the same in both views, and each view one line style."""
    import matplotlib.pyplot as plt

    from walkerlab.plotting import figures as F

    rigid = _trajectory(["leg2", "leg1", "leg2_shank", "leg2_thigh", "leg1_thigh",
                         "leg1_shank", "torso"])
    contact = _trajectory(["leg1_thigh", "leg1_shank", "leg2_thigh", "leg2_shank", "torso"])
    fig = F.fig7_angles_rates({"ideal": rigid, "contact": contact})
    try:
        for ax in fig.axes[:2]:
            colour, style = {}, {}
            for line in ax.get_lines():
                name, model = line.get_label().split(" - ")
                colour.setdefault(name, set()).add(line.get_color())
                style.setdefault(model, set()).add(line.get_linestyle())
            assert len(colour) == 7 and all(len(c) == 1 for c in colour.values()), colour
            assert len({c.pop() for c in colour.values()}) == 7  # no two links alike
            assert style == {"ideal": {"-"}, "contact": {"--"}}
    finally:
        plt.close(fig)


def test_patch_width_map_on_continuous_ground_says_it_does_not_apply(tmp_path):
    """kneed.yaml walks on continuous ground: before, ``stability-map --kind patch_width``
    computed 9 cells of 'no_ideal_gait'/'unsupported' and exited 0; now one line, rc 1,
    naming the field, and ``--kind all`` skips that map with a note."""
    import pytest

    from walkerlab.config import load_scene
    from walkerlab.config.options import map_not_applicable
    from walkerlab.stages import stability_map
    from walkerlab.stages.common import StageError

    scene = load_scene("configs/kneed.yaml")
    with pytest.raises(StageError, match=r"does not apply.*continuous.*terrain\.lanes") as e:
        stability_map.run(scene, tmp_path, kind="patch_width", n=2)
    assert "\n" not in str(e.value)
    assert not list(tmp_path.rglob("*.h5"))
    assert map_not_applicable(scene, "friction") == ""
    assert map_not_applicable(load_scene("configs/paper_rods.yaml"), "patch_width") == ""


def test_stability_map_figure_names_scene_units_and_unsupported_cells():
    """round_feet.yaml is nondimensional (its SI contact fields read metres as l): before,
    its patch-width map's axis read 'patch width [m]'; a kneed cell whose periodic-gait
    search has no section read '?'."""
    from walkerlab.io.schemas.stability_map import StabilityMap
    from walkerlab.plotting.gait_map_figure import gait_map_figure, plt
    from walkerlab.studies.stability import MAP_KINDS, REASONS, MapSpec

    assert "unsupported" in REASONS
    reason = np.array([["", "unsupported"]], dtype=object)
    d = StabilityMap(
        attrs={"kind": "patch_width", "y_label": MAP_KINDS["patch_width"][1],
               "scene_units": "nondimensional"},
        y_values=np.array([0.2]), slopes_deg=np.array([1.0, 2.0]),
        cells={"exists": np.array([[1, 0]]), "stable": np.array([[1, 0]]),
               "max_abs_multiplier": np.array([[0.5, np.nan]]), "reason": reason,
               "wall_time_s": np.array([[1.0, 2.0]])})
    fig = gait_map_figure(d)
    try:
        assert fig.axes[0].get_ylabel() == "patch width [l]"
        assert "not sup-\nported" in [t.get_text() for t in fig.axes[0].texts]
    finally:
        plt.close(fig)
    si_map = MapSpec("stiffness", (4e9,), (1.0,), y_field="stiffness_n_per_m_pow_e")
    d.attrs = {**d.attrs, "kind": "stiffness", "y_label": si_map.y_label}
    fig = gait_map_figure(d)
    try:
        assert fig.axes[0].get_ylabel().startswith("contact stiffness k [M g/l^e]")
    finally:
        plt.close(fig)
    d.attrs = {**d.attrs, "scene_units": "SI", "y_label": MAP_KINDS["stiffness"][1]}
    fig = gait_map_figure(d)
    try:
        assert fig.axes[0].get_ylabel().startswith("contact stiffness k [N/mm^e]")
    finally:
        plt.close(fig)


def test_sweep_artifact_units_follow_a_nondimensional_scene(tmp_path):
    """round_feet.yaml is nondimensional: every other artifact labels its lengths 'l' and
    times '√(l/g)', but a sweep's columns said 'm' and 's' (the store never relabelled).
    Wall times stay real seconds."""
    import h5py

    from walkerlab.config import load_scene
    from walkerlab.stages.sweep import run

    scene = load_scene("configs/round_feet.yaml")
    out = run(scene, ["walker.hip_mass_kg=1.0"], stage="fixedpoint", workers=1,
              runs_root=tmp_path, progress=False, pool=False)
    with h5py.File(out) as f:
        assert f.attrs["scene_units"] == "nondimensional"
        p = f["points"]
        assert p["outcome"][0] == b"ok"
        assert p["step_period_s"].attrs["unit"] == "√(l/g)"
        assert p["stance_rate_rad_per_s"].attrs["unit"] == "rad/√(l/g)"
        assert p["param/walker.hip_mass_kg"].attrs["unit"] == "M"
        assert p["wall_time_s"].attrs["unit"] == "s"


def test_drop_test_uses_the_walkers_mass_and_brackets_its_own_stiffness():
    """The drop test dropped the paper walker (20 kg, k from 1e4 to 1e9 scene units) for every
    scene: for round_feet.yaml (SI, k = 4e9 N/m^2.2, mass 2) its grid stopped below the
    scene's stiffness and the rigid-limit family started from the paper's 1e5, read as
    N/m^2.2 (restitution 0 throughout).  Now the grid is the scene's k x 0.1 ... 1e4 and
    both families pass through the scene's own contact; the paper scene's numbers do not
    move."""
    from walkerlab.analysis.contact.drop import drop_restitution
    from walkerlab.analysis.contact.record import drop_test
    from walkerlab.config import load_scene

    rf = load_scene("configs/round_feet.yaml")
    d = drop_test(rf.contact, 2.0)
    k = rf.contact.stiffness_n_per_m_pow_e
    assert d["unit"] == "N/m^e"
    assert d["stiffness"][0] < k < d["stiffness"][-1]
    i = int(np.argmin(abs(d["stiffness"] - k)))
    own = drop_restitution(rf.contact, mass_kg=2.0, v_in_m_per_s=0.3)["restitution"]
    assert 0 < own < 0.2  # near-plastic, as the scene's comment intends
    assert d["paper"]["restitution"][i] == own
    # the rigid-limit family keeps the scene contact's restitution at every k (self-similar
    # drop without gravity; Radau rtol 1e-10 -> ~1e-6 between the k)
    np.testing.assert_allclose(d["rigid_limit"]["restitution"], own, atol=1e-5)
    # the paper scene (k = 1e5 N/mm^2.2, 20 kg, reference_stiffness = its k) keeps its grid
    from walkerlab.analysis.contact.record import DROP_STIFFNESS_RATIO

    paper = load_scene("configs/paper.yaml").contact
    assert paper.stiffness_n_per_mm_pow_e == paper.reference_stiffness_n_per_mm_pow_e == 1e5
    np.testing.assert_allclose(np.multiply(DROP_STIFFNESS_RATIO, paper.stiffness_n_per_mm_pow_e),
                               [1e4, 3e4, 1e5, 3e5, 1e6, 3e6, 1e7, 3e7, 1e8, 3e8, 1e9],
                               rtol=1e-15)


def test_contact_law_units_relabel_in_a_nondimensional_scene():
    """The drop test's stiffness axis and the SI contact parameters of round_feet.yaml read
    'N/m^e' and 'N s/m' in a scene whose lengths are l and masses M."""
    from walkerlab.units import Units

    u = Units("nondimensional")
    assert u("N/m^e") == "M g/l^e"
    assert u("N s/m") == "M √(g/l)"  # kg/s
    assert u("N/mm^e") == "N/mm^e"  # the ADAMS mm-kg-s system is not the scene's
    assert Units()("N/m^e") == "N/m^e"


def test_work_precision_axis_follows_the_scene_units():
    """round_feet.yaml's work-precision study (models: [ideal, contact]) wrote its errors in
    rad/√(l/g) but the diagram's axis said rad/s."""
    from walkerlab.plotting import figures as F
    from walkerlab.units import Units

    rows = {"cyrk_bdf": {"time": np.array([0.01, 0.03]), "error": np.array([3e-6, 5e-7]),
                         "rtol": np.array([1e-6, 1e-7])}}
    for units, label in ((Units("nondimensional"), "[rad, rad/√(l/g)]"),
                         (Units(), "[rad, rad/s]")):
        fig = F.work_precision(rows, "work-precision, contact model", units=units)
        try:
            assert fig.axes[0].get_ylabel().endswith(label)
            assert fig.axes[0].get_xlabel().startswith("wall time [s]")  # real seconds
        finally:
            F.plt.close(fig)


def test_work_precision_contact_runner_reads_a_kneed_walkers_legs_by_name():
    """The work-precision study's contact series on the kneed walker: the final vector is
    the four link angles [rad] and their four rates, read by name (no hip position: |angle|
    < 1 rad, where hip_x is ~0.95 m after a stride), and it converges with the tolerance."""
    from walkerlab.analysis.gait.poincare import find_fixed_point
    from walkerlab.bench.workprecision import contact_runner
    from walkerlab.config import load_scene
    from walkerlab.integrate.solver import Solver
    from walkerlab.models.registry import build_walker

    scene = load_scene("configs/kneed.yaml")
    walker = build_walker(Plant.from_scene(scene))
    g = scene.fixedpoint.initial_guess.model_dump()
    guess = np.array([g[n + ("_rad" if n.endswith("_angle") else "_rad_per_s")]
                      for n in walker.state_names()])
    fp = find_fixed_point(walker, guess, Solver("DOP853", 1e-12, 1e-12), fd_check=False)
    run = contact_runner(scene, fp.x, fp.period_s, strides=1)
    loose, _, _ = run("cyrk_bdf", 1e-6, 1e-8)
    tight, nfev, cpu = run("cyrk_bdf", 1e-8, 1e-10)
    assert loose is not None and tight is not None and nfev > 0 and cpu > 0
    assert loose.shape == tight.shape == (8,)
    assert np.all(np.abs(tight[:4]) < 1.0)
    # within 5e-3 of the state's size: the loose run's error is not smooth in its start (the
    # contact onsets' steps): a start moved by 1e-14 (a rigid model's round-off) moved it
    # from 5e-5 to 6.1e-3 absolute on rates of ~7 rad/s (measured), the tight runs agreeing
    # to 1e-8
    assert np.abs(loose - tight).max() < 5e-3 * np.abs(tight).max()


def test_stability_map_default_axes_bracket_the_scenes_own_contact():
    """The stiffness axis was 1e3 ... 1e9 and the patch widths 0.02 ... 0.20 in scene units
    for every scene: round_feet.yaml (k = 4e9 N/m^2.2, patches 0.30 l) lay outside both.
    Now the axes are the scene's own value x 1e-2 ... 1e4 and x 0.2 ... 2; the paper
    scene's grids are unchanged (bit for bit: its cached maps stay valid)."""
    from walkerlab.studies.stability import default_spec

    k = default_spec("stiffness", 3, stiffness=4e9).y_values
    w = default_spec("patch_width", 3, patch_width_m=0.30).y_values
    assert k[0] < 4e9 < k[-1] and np.allclose(k, [4e7, 4e10, 4e13], rtol=1e-12)
    assert w[0] < 0.30 < w[-1] and np.allclose(w, [0.06, 0.33, 0.60], rtol=1e-12)
    for n in (3, 8):
        assert default_spec("stiffness", n).y_values == tuple(
            float(v) for v in np.round(np.logspace(3, 9, n), 6))
        assert default_spec("patch_width", n).y_values == tuple(
            float(v) for v in np.round(np.linspace(0.02, 0.20, n), 6))
