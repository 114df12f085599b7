"""Every shipped scene through fixedpoint -> simulate -> report -> a 3-point sweep.

Parametrised over ``configs/*.yaml``, so a new scene is picked up without editing this file.
Each scene is reduced to keep the test fast (1 stride, no work-precision study, no periodic
contact gait, 1 contact stride, a 6 x 5 basin); the contact stages run only where the scene
has contact.
Every artifact must open with ``xarray.open_dataset(engine="h5netcdf")`` in every group,
with named dimensions (no anonymous "phony" dimensions) and ``units`` on every variable.
"""

from __future__ import annotations

from pathlib import Path

import h5py
import numpy as np
import pytest
import yaml

from walkerlab.config import load_scene
from walkerlab.io.schemas.fixedpoint import load_fixedpoint
from walkerlab.stages.pipeline import report_plan
from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]
SCENES = sorted((ROOT / "configs").glob("*.yaml"))
#: Scenes whose whole report is not built here: another scene of the same walker family (same
#: model, the same report sections) builds it.  Every other scene, a new one too, gets one.
#: schwab_wisse2001 stands for the simplest walker because it alone has a basin section.
REPORT_BUILT_BY = {"goswami1996": "paper_rods", "simplest": "schwab_wisse2001"}
#: Scenes without a gait of their own (nothing for fixedpoint to find): their one stage is
#: ``optimize``, run end to end (artifact, figure, report) by the test file named.
NO_GAIT = {"rabbit_optimal": "tests/test_optimize_five_link.py"}


def reduced(path: Path, tmp: Path):
    """A fast copy of a scene: one stride, no work-precision or robustness study, one contact
    stride, no phase-variable replays."""
    d = yaml.safe_load(path.read_text())
    d.setdefault("name", path.stem)
    d.pop("workprecision", None)
    d.pop("robustness", None)  # ~80 s for flat feet; tests/test_flat_feet_robustness.py
    if "simulate" in d:
        d["simulate"]["strides"] = 1
        d["simulate"]["sample_rate_hz"] = min(100, d["simulate"].get("sample_rate_hz", 100))
    if "basin" in d:
        d["basin"]["grid"] = [6, 5]
        d["basin"]["max_steps"] = 10
    if "contact_sim" in d:
        d["contact_sim"]["n_strides"] = 1
        d["contact_sim"]["periodic_gait"] = False
    if "optimize" in d:  # ~75 s CPU for kneed: tests/test_optimize_phases.py checks them
        d["optimize"]["phase_replay"] = False
    p = tmp / path.name
    p.write_text(yaml.safe_dump(d))
    return load_scene(p)


def _has_damper(d) -> bool:
    """True if any ``damping_n_m_s_per_rad`` in a walker's mapping is positive."""
    if isinstance(d, dict):
        return any((k == "damping_n_m_s_per_rad" and v and v > 0) or _has_damper(v)
                   for k, v in d.items())
    if isinstance(d, list):
        return any(_has_damper(v) for v in d)
    return False


def groups(path: Path) -> list[str | None]:
    out: list[str | None] = [None]
    with h5py.File(path, "r") as f:
        f.visititems(lambda n, o: out.append(n) if isinstance(o, h5py.Group) else None)
    return out


def assert_netcdf(path: Path) -> None:
    """Every group opens in xarray with named dimensions and units on every variable."""
    import warnings

    xr = pytest.importorskip("xarray")
    pytest.importorskip("h5netcdf")
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # h5netcdf warns on anonymous dimensions
        for g in groups(path):
            with xr.open_dataset(path, engine="h5netcdf", group=g) as ds:
                assert not [d for d in ds.dims if str(d).startswith("phony_dim")], (path, g)
                for name, v in ds.variables.items():
                    assert "units" in v.attrs, f"{path}:{g}/{name} has no units"


@pytest.fixture()
def png_only(monkeypatch):
    """Figures as small PNGs only (SVG and 150 dpi cost half of this test's time and are
    tested elsewhere: tests/test_stages.py draws the full set)."""
    import matplotlib.pyplot as plt

    from walkerlab.plotting import figures

    def save(fig, folder, stem, svg=True, key=None):
        p = Path(folder) / f"{stem}.png"
        p.parent.mkdir(parents=True, exist_ok=True)
        try:
            fig.savefig(p, dpi=30)
        finally:
            plt.close(fig)
        return [p]

    monkeypatch.setattr(figures, "save", save)


@pytest.mark.slow  # end to end: a whole report
@pytest.mark.parametrize("scene_path", [p for p in SCENES if p.stem not in NO_GAIT],
                         ids=[p.stem for p in SCENES if p.stem not in NO_GAIT])
def test_scene_end_to_end(scene_path, tmp_path, png_only):
    from walkerlab.io.sweep_store import load_sweep
    from walkerlab.stages import fixedpoint, report, simulate
    from walkerlab.stages import sweep as sweep_stage

    scene = reduced(scene_path, tmp_path)
    runs = tmp_path / "runs"
    fp = fixedpoint.run(scene, runs)
    art = load_fixedpoint(fp.path)
    assert art.residual < 1e-8  # the root finder's tolerance is far below this
    assert art.x.shape == (len(art.state_names),)
    sim = simulate.run(scene, runs)
    with h5py.File(sim.path, "r") as f:
        names = [str(n) for n in f["samples"].attrs["coordinates"]]
        tot, step = f["samples/energy/total"][()], f["samples/step_index"][()]
        phase = f["samples/phase"][()]
        phases = [str(n) for n in f["samples"].attrs["phases"]]
        assert str(f.attrs["termination"]) == "heel_strike"
    # every coordinate of the walker appears by physical name (a kneed walker also names
    # the stance leg's locked thigh and shank), each angle with its rate
    angles = [n for n in names if n.endswith("_angle")]
    assert len(names) >= len(art.state_names) and len(names) == 2 * len(angles)
    assert all(a.removesuffix("_angle") + "_rate" in names for a in angles)
    # a passive rigid walker conserves energy between impacts (heel strike, knee strike):
    # within each phase of each step (relative bound far above the solver's rtol 1e-10);
    # with a damper (an ankle's, a spring's) it can only lose energy there
    damped = _has_damper(scene.walker.model_dump())
    act = scene.walker.actuation
    # joint torques that do work (not Kuo's, per foot mass: none in his limit) and an ankle
    # push-off change the energy between impacts: tests/test_powered.py and
    # tests/test_rabbit.py close the ledger
    working = act is not None and (any(t.scaled_by == "none" for t in act.torques)
                                   or act.ankle_push_off is not None
                                   or act.virtual_constraints is not None)
    # a 3D walker's hip-roll law works too (its ledger: tests/test_hip_roll_3d.py)
    working = working or getattr(scene.walker, "hip_roll", None) is not None
    for k in np.unique(step) if not working else ():
        for ph in np.unique(phase[step == k]):
            if phases[ph].startswith("double_support:"):
                # a flat foot's trailing ankle spring, outside the walker's energy, pushes
                # it off here (on stairs its release outweighs the dampers': +0.63 J):
                # the walker's energy plus that spring's only falls, checked in
                # tests/test_flat_feet_terrain.py
                continue
            e = tot[(step == k) & (phase == ph)]
            if damped:
                assert np.all(np.diff(e) < 1e-6 * np.max(np.abs(tot)))
            else:
                assert np.ptp(e) < 1e-6 * np.max(np.abs(tot))

    if scene_path.stem not in REPORT_BUILT_BY:  # one report per walker family
        html = report.run(scene, runs, echo=lambda s: None)
        md = (html.parent / "report.md").read_text()
        assert md.index("## Summary") < md.index("## Fixed point")
        assert "<details>" in md
        # a contact section runs contact-sim where the walker's kind walks the ground in
        # the contact view (flat feet on stairs: the section is the MJCF's)
        has_contact = "contact-sim" in report_plan(scene)
        assert ("## Comparison ideal vs contact" in md) == has_contact
        assert ("work-precision" in md) is False  # reduced scenes have no work-precision section
        assert (("published (" in md) == (scene.published is not None))
        figs = {p.name for p in (html.parent / "figures").glob("*.png")}
        assert {"fig7_angles_rates.png", "fig9_limit_cycles.png", "fig2_stick_ideal.png"} <= figs
        assert ("fig8_errors.png" in figs) == has_contact
        # a scene that declares a basin gets it in its report (table of outcomes and figure)
        has_basin = scene.basin is not None
        assert ("## Basin of attraction" in md) == has_basin
        assert ("basin.png" in figs) == has_basin
        if has_basin:
            assert "6 × 5 cells" in md

    if scene_path.stem == "rabbit":  # a fixed point takes ~2.5 min (ten states, high-gain
        for p in (fp.path, sim.path):  # PD): its sweep would repeat it three times at slope 0
            assert_netcdf(p)
        return
    slope = scene.slope.angle_deg if scene.slope.angle_deg is not None else \
        float(np.degrees(scene.slope.angle_rad))
    grid = ",".join(f"{slope * f:.6g}" for f in (0.98, 1.0, 1.02))
    sw = sweep_stage.run(scene, [f"slope.angle_deg={grid}"], "fixedpoint", workers=1,
                         runs_root=runs, name="tiny", progress=False)
    data = load_sweep(sw)["points"]
    assert list(data["outcome"]).count("ok") >= 2, list(data["message"])
    # column names carry the SI unit spelling (identifiers, as the config's field names),
    # also in a nondimensional scene whose artifacts label rates rad/√(l/g)
    from walkerlab.models.registry import build_walker

    for n, u in zip(art.state_names, build_walker(Plant.from_scene(scene)).state_units()):
        col = f"{n}_{u.replace('/', '_per_')}"
        assert col in data  # one column per state, named by the walker
    mid = data["outcome"] == "ok"
    assert np.all(np.isfinite(data[f"multiplier_{len(art.state_names) - 1}_re"][mid]))

    for p in [fp.path, sim.path, sw, *(runs / scene.name).glob("compare.h5")]:
        assert_netcdf(p)


def test_report_family_stand_ins_are_shipped_scenes():
    stems = {p.stem for p in SCENES}
    assert set(NO_GAIT) <= stems and all((ROOT / t).is_file() for t in NO_GAIT.values())
    assert set(REPORT_BUILT_BY) | set(REPORT_BUILT_BY.values()) <= stems
    assert not set(REPORT_BUILT_BY) & set(REPORT_BUILT_BY.values())


def test_paper_scene_is_table1():
    """configs/paper.yaml carries the parameters printed in the paper's Table 1."""
    from walkerlab.published import for_scene, paper

    scene = load_scene(ROOT / "configs" / "paper.yaml")
    assert for_scene(scene) is paper
    for key, value in paper.TABLE1.items():
        assert getattr(scene.walker, key) == value, key
    # "the mass of the links is concentrated and placed in the middle of the legs"
    assert scene.walker.leg_mass_from_foot_m == paper.TABLE1["leg_length_m"] / 2


def test_unknown_published_module_is_one_line(tmp_path):
    from walkerlab.config import SceneError

    d = yaml.safe_load((ROOT / "configs" / "goswami1996.yaml").read_text())
    d["published"] = "nobody2099"
    p = tmp_path / "bad.yaml"
    p.write_text(yaml.safe_dump(d))
    with pytest.raises(SceneError, match=r"bad.yaml: .*published.*nobody2099") as exc:
        load_scene(p)
    assert "\n" not in str(exc.value)
