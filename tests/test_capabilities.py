"""The capability table (:data:`walkerlab.walker.kinds.CAPABILITIES`) tells the truth.

For each walker kind, its shipped scene, and each cell of the table (a feature in a view),
the cell is tried in the view, cheaply (nothing long is solved):

- ``rigid``: the rigid walker with the feature (``walkerlab.api.walker.Walker``, its model
  built);
- ``contact``: the compliant-contact set-up (:func:`walkerlab.models.contact.scene.
  contact_setup`, no run);
- ``mjcf`` / ``urdf`` / ``adams`` / ``osim``: the export written into a temporary runs folder (its
  keyframe's rigid gait searched as ``walkerlab export`` does; no gait is the walker's
  dynamics, not a refusal);
- ``gym``: the Gymnasium environment built (:class:`walkerlab.gym.env.WalkerEnv`);
- ``optimize``: ``walkerlab optimize`` up to IPOPT (CasADi's ``Opti.solve`` replaced by an
  exit: every refusal and the transcription's set-up passed).

A supported cell must be accepted; a refused cell refused with the table's reason in its
one line (whatever the field named first).  The quick suite tries the cells that take
under a second (the rigid and contact set-ups, the refusals that come before any gait
search); ``pytest -m slow`` tries every cell.  This replaces issue 48's probing script
(issue 48's ``scripts/capability_table.py``).
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

from tests.scripts_loader import load_file
from walkerlab.walker.capability_cells import CAPABILITIES
from walkerlab.walker.kinds import FEATURES, KINDS, VIEWS
from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]

from walkerlab.walker.reference_cases import (  # noqa: E402 - the cases the table is tried on
    FIVE_LINK_JOINT,
    JOINT,
    SCENES,
    TORSO_HIPS,
    scene_for,
)

# ---------------------------------------------------------------------------- the probes

class Reached(Exception):
    """The optimisation reached IPOPT: its set-up was accepted."""


def _rigid(d, tmp):
    from walkerlab.api.walker import Walker

    w = Walker.from_scene(d)
    assert w.model is not None  # built (its refusals said)
    if (d.get("terrain") or {}).get("kind") == "profile":
        # a profile is walked step by step, each step's walker landing on its segment
        # (analysis.gait.profile_walk): the ground as `walkerlab simulate` builds it for a
        # passive walker (a driven one's is the gym's cell, PROFILE_PASSIVE), and the
        # landing of the first step
        from walkerlab.analysis.gait.rigid_run import profile_ground
        from walkerlab.models.hybrid.ground import on_landing
        from walkerlab.walker.description import walker_data

        sc = w.scene
        if sc.walker.actuation is None:
            profile_ground(sc, Plant.from_scene(sc))
        on_landing(w.model, walker_data(sc.walker, sc.slope.phi_rad), 0.001)


def _contact(d, tmp):
    from walkerlab.api.walker import Walker
    from walkerlab.config import scene_from_dict
    from walkerlab.models.contact.scene import contact_setup

    # contact-sim starts from the rigid gait (fixedpoint.h5; on a profile the slope's): its
    # walker
    assert Walker.from_scene(d).model is not None
    sc = scene_from_dict(d)
    contact_setup(sc, plant=Plant.from_scene(sc))


def _export(fmt):
    def probe(d, tmp):
        from walkerlab.config import scene_from_dict
        from walkerlab.stages import export

        export.run(scene_from_dict(d), tmp, fmt)
    return probe


def _gym(d, tmp):
    from walkerlab.gym.env import WalkerEnv

    WalkerEnv(d).close()


def _optimize(d, tmp, monkeypatch):
    import casadi

    from walkerlab.config import scene_from_dict
    from walkerlab.stages import pipeline

    def solve(self, *a, **k):
        raise Reached

    monkeypatch.setattr(casadi.Opti, "solve", solve)
    try:
        pipeline.run("optimize", scene_from_dict(d), tmp, False)
    except Reached:
        pass


PROBES = {"rigid": _rigid, "contact": _contact, "mjcf": _export("mjcf"),
          "urdf": _export("urdf"), "adams": _export("adm"), "osim": _export("osim"),
          "gym": _gym, "optimize": _optimize}

#: a message that says the walker has no gait (its dynamics, not a refusal of the cell)
NO_GAIT = ("no rigid gait", "no period-1 gait found", "FixedPointNotFound", "GaitNotFound",
           "no fixed point", "did not converge", "has no gait of its own to start from")


def outcome(kind: str, feature: str, view: str, tmp: Path, monkeypatch) -> tuple[str, str]:
    """``("accepted" | "refused", one line)`` of the cell tried in its view."""
    from walkerlab.analysis.gait.poincare import FixedPointNotFound
    from walkerlab.stages.common import StageError

    try:
        from walkerlab.analysis.gait.search import GaitNotFound
    except ImportError:  # pragma: no cover - where the search names it otherwise
        GaitNotFound = FixedPointNotFound
    d = scene_for(kind, feature, view)
    probe = PROBES[view]
    try:
        with warnings.catch_warnings():
            # a gait search on an odd walker (a knee torque's law on RABBIT's gait) warns on
            # its way to no gait (a zero denominator, a complex step cast); the cell is about
            # what the view accepts, not that search's numerics
            warnings.simplefilter("ignore", RuntimeWarning)
            warnings.simplefilter("ignore", np.exceptions.ComplexWarning)
            if view == "optimize":
                probe(d, tmp, monkeypatch)
            else:
                probe(d, tmp)
    except (FixedPointNotFound, GaitNotFound) as exc:
        return "accepted", f"no gait: {type(exc).__name__}"
    except (ValueError, StageError) as exc:
        line = " ".join(str(exc).split())
        if any(s in line for s in NO_GAIT):
            return "accepted", f"no gait: {line}"
        return "refused", line
    return "accepted", ""


def cells():
    for kind in KINDS:
        for feature in FEATURES:
            for view in VIEWS:
                yield kind, feature, view


def absent_part(kind: str, feature: str) -> tuple[str, ...]:
    """The one lines in which the scene's own checks refuse a part the walker does not have,
    before its kind is asked (each says what the table's reason says): a joint the walker
    lacks (:func:`walkerlab.models.hybrid.actuators.joint_links` names the joints it has)
    and ``walker.actuation`` on a walker model without actuators, ``walker.hip_roll`` on
    one other than the compass gait (the scene's schema), ``walker.foot_radius_m`` on one
    other than the compass gait or on a planar one (its check)."""
    out = []
    if feature in JOINT:
        joint = (FIVE_LINK_JOINT.get(feature, JOINT[feature]) if kind in TORSO_HIPS
                 else JOINT[feature])
        out += [f"{joint} is not a joint of this walker (its joints: ",
                f"{joint} is not a joint of the "]  # an export's joints (the walker's)
    if kind in ("rolling_polygon", "rolling_polygon_3d") and feature in (
            *JOINT, "push_off", "ankle_push_off", "virtual_constraints"):
        out.append("walker.actuation: unknown field")
    if feature == "hip_roll":  # a field of the compass gait's section only
        out.append("walker.hip_roll: unknown field")
    if feature == "round_feet_3d":  # the compass gait's, in 3D only
        out += ["walker.foot_radius_m: unknown field", "walker.foot_radius_m: needs space: 3d"]
    return tuple(out)


def _reasons_on_the_way(kind: str, feature: str, view: str) -> tuple[str, ...]:
    """The table's reasons a probe of ``(feature, view)`` may meet first: the feature's in
    every view (each probe builds the rigid walker and lays the scene's ground) and the
    walker's own in ``view``."""
    k = KINDS[kind]
    out = [k.cell(feature, v) for v in VIEWS] + [k.cell("walk", view)]
    return tuple(r for r in out if r)


def _check(kind, feature, view, tmp_path, monkeypatch):
    why = KINDS[kind].cell(feature, view)
    status, line = outcome(kind, feature, view, tmp_path, monkeypatch)
    if why is None:
        assert status == "accepted", f"the table says supported; the view refuses: {line}"
    else:
        if status == "accepted" and line.startswith("no gait"):
            pytest.skip(f"no gait before the view's check ({line[:80]})")
        assert status == "refused", f"the table refuses ({why}); the view accepts {line}"
        # every view's probe passes through others first (the rigid gait, the scene's
        # ground): the refusal may be the table's for this feature in another view, or for
        # the walker itself in this one - still one of the table's reasons
        said = (why, *absent_part(kind, feature), *_reasons_on_the_way(kind, feature, view))
        assert any(s in line for s in said), \
            f"none of the table's reasons {said!r} is in the refusal {line!r}"


#: features whose walker no other quick test derives: their cold derivation takes minutes
#: (the 3D kneed walker with hip-roll joints: ~3 min; the 3D upper body with hip-roll
#: joints and a torso torque: ~6 min; the 3D kneed walker with an upper body: ~10 min),
#: so the slow suite tries their cells
COLD_DERIVATIONS = {("locking_knees_3d", "hip_roll"), ("straight_legs_3d", "torso_torque"),
                    ("locking_knees_3d", "torso_torque")}

#: the cells the quick suite tries (each under ~1 s with the walkers' code cached: set-ups
#: and the refusals that come before any gait search)
QUICK = [c for c in cells() if c[2] in ("rigid", "contact") and c[:2] not in COLD_DERIVATIONS]


@pytest.mark.parametrize("kind,feature,view", QUICK)
def test_the_table_tells_the_truth(kind, feature, view, tmp_path, monkeypatch):
    _check(kind, feature, view, tmp_path, monkeypatch)


@pytest.mark.slow
@pytest.mark.parametrize("kind,feature,view", [c for c in cells() if c not in QUICK])
def test_the_table_tells_the_truth_in_every_view(kind, feature, view, tmp_path,
                                                 monkeypatch):
    _check(kind, feature, view, tmp_path, monkeypatch)


def test_every_kind_has_a_row_and_a_scene():
    assert set(CAPABILITIES) == set(KINDS) == set(SCENES)
    for row in CAPABILITIES.values():
        for feature, view in row:
            assert feature in FEATURES and (view == "*" or view in VIEWS)


def test_the_command_and_the_docs_show_the_table():
    """``walkerlab capabilities`` (text and --json) and the docs' page are the table."""
    import json

    from typer.testing import CliRunner

    from walkerlab.cli import app
    from walkerlab.walker.kinds import table_rows

    r = CliRunner().invoke(app, ["capabilities", "--json"])
    assert r.exit_code == 0 and json.loads(r.output) == table_rows()
    r = CliRunner().invoke(app, ["capabilities"])
    assert r.exit_code == 0
    for kind in KINDS.values():
        assert f"{kind.name}: {kind.title}" in r.output
        for row in CAPABILITIES[kind.name].values():
            assert row is None or row in r.output  # None: supported past a refused walk
    ext = load_file("docs/_ext/capability_table.py")
    page = ext.rst()
    assert all(kind.name in page for kind in KINDS.values())
    assert "capability-table" in (ROOT / "docs" / "reference" / "capabilities.rst").read_text()


#: the layers that give the kinds' parts their behaviour (imported: each provides its own)
_PART_LAYERS = ("walkerlab.models.hybrid.rigid", "walkerlab.models.hybrid.ground",
                "walkerlab.models.hybrid.actuated", "walkerlab.models.hybrid.ground_reaction",
                "walkerlab.models.contact.parts", "walkerlab.analysis.contact.verdict",
                "walkerlab.optimal.driver", "walkerlab.optimal.transcription.phases")

#: the part slots each supported cell needs: (feature, view) -> slots
_CELL_PARTS = {("walk", "rigid"): ("rigid", "reaction", "actuators"),
               ("stairs", "rigid"): ("landing",), ("footholds", "rigid"): ("landing",),
               ("walk", "contact"): ("contact", "scuff"),
               ("walk", "optimize"): ("collocation",)}


def _missing_parts(kinds) -> list[str]:
    """``kind: slot`` of every supported cell's part that is absent or has no behaviour."""
    import importlib

    for m in _PART_LAYERS:
        importlib.import_module(m)
    out = []
    for kind in kinds:
        for (feature, view), slots in _CELL_PARTS.items():
            if not kind.supports(feature, view):
                continue
            for slot in slots:
                part = getattr(kind, slot)
                if part is None or not part.provided:
                    out.append(f"{kind.name}: {slot} ({feature} in {view})")
        c = kind.collocation  # a transcription of phases needs their symbolic pieces
        phased = c is not None and not c.one_step and not c.from_targets
        if kind.supports("walk", "optimize") and phased \
                and (kind.phases is None or not kind.phases.provided):
            out.append(f"{kind.name}: phases (walk in optimize)")
    return out


def test_every_kind_has_the_parts_of_every_cell_its_row_supports():
    """Each supported cell's parts (the rigid maker, reaction and actuators of the rigid
    view, the landing on stairs and footholds, the contact part and its scuff cause, the
    collocation and its phases) are objects on the kind whose layer gave them their
    behaviour; a view without a part for the kind refuses the walker (or the ground)
    itself.  Every part object of a kind is given its behaviour by its layer."""
    assert _missing_parts(KINDS.values()) == []
    for kind in KINDS.values():
        assert (kind.landing is None) == (kind.cell("stairs", "rigid") is not None), kind
        assert (kind.contact is None) == (kind.cell("walk", "contact") is not None), kind
        assert (kind.collocation is None) == (kind.cell("walk", "optimize") is not None), kind
        for slot, part in kind.parts().items():
            assert part is None or part.provided, f"{kind.name}: {slot} {part}"


def test_a_kind_missing_a_part_its_row_claims_is_named():
    """A kind whose supported cell has no part (or a part without behaviour) is named with
    the part's slot: the check above can fail."""
    from dataclasses import replace

    from walkerlab.walker.parts import Part, PartMissing

    bare = replace(KINDS["straight_legs"], contact=Part("contact", "unprovided: a test part"))
    assert _missing_parts([bare]) == ["straight_legs: contact (walk in contact)"]
    with pytest.raises(PartMissing, match="contact part 'unprovided: a test"):
        _ = bare.contact.step_length


def test_parts_pickle_as_the_same_objects():
    """A kind's parts reach a worker process as the same objects (found by slot and name),
    their behaviour with them."""
    import pickle

    from walkerlab.models.hybrid import rigid  # noqa: F401  (gives the rigid parts theirs)

    kind = KINDS["locking_knees"]
    assert pickle.loads(pickle.dumps(kind.rigid)) is kind.rigid
    assert pickle.loads(pickle.dumps(kind)).rigid is kind.rigid


# ------------------------------------------- a refusal the table decides comes first (64, 6)
class GaitSearched(Exception):
    """A gait search started: the refusal came after costly work."""


def _no_gait_search(*_a, **_k):
    raise GaitSearched


def test_contact_sim_refuses_flat_feet_on_stairs_before_any_gait_search(tmp_path,
                                                                        monkeypatch):
    """Issue 64 item 6: ``contact-sim configs/flat_feet_stairs.yaml`` refused after 21 s of
    rigid gait search (the fixed point upstream) what the table knows from the scene."""
    from walkerlab.config import load_scene
    from walkerlab.stages import fixedpoint, pipeline

    monkeypatch.setattr(fixedpoint, "run", _no_gait_search)
    with pytest.raises(ValueError) as exc:
        pipeline.run("contact-sim", load_scene(ROOT / "configs" / "flat_feet_stairs.yaml"),
                     tmp_path)
    assert KINDS["flat_feet"].cell("stairs", "contact") in str(exc.value)
    assert "\n" not in str(exc.value)


def test_the_gym_contact_view_refuses_its_ground_before_any_gait_search(monkeypatch):
    pytest.importorskip("gymnasium")
    from walkerlab.gym import env

    monkeypatch.setattr(env, "_gait", _no_gait_search)
    with pytest.raises(ValueError) as exc:
        env.WalkerEnv(str(ROOT / "configs" / "flat_feet_stairs.yaml"), view="contact")
    assert KINDS["flat_feet"].cell("stairs", "contact") in str(exc.value)


# ------------------------------------------- the URDF's column (issue 64 leftovers, item 4)
@pytest.mark.parametrize("kind", ["straight_legs", "rolling_polygon"])
@pytest.mark.parametrize("ground", ["stairs", "footholds", "profile"])
def test_the_urdf_refuses_a_ground_other_than_the_slope_with_its_cells_reason(
        kind, ground, tmp_path, monkeypatch):
    """The URDF had no column: ``export --format urdf`` refused stairs, footholds and
    profiles with a message of its own that the table did not show.  Now the table's urdf
    cells of those grounds refuse them, and the export reads its one line from them (a
    changed reason is the export's), before any gait search."""
    from walkerlab.config import scene_from_dict
    from walkerlab.stages import export
    from walkerlab.walker.capability_cells import URDF_GROUND

    assert KINDS[kind].cell(ground, "urdf") == URDF_GROUND
    monkeypatch.setattr(export, "_gait", _no_gait_search)
    d = scene_for(kind, ground, "urdf")
    with pytest.raises(ValueError) as exc:
        export.run(scene_from_dict(d), tmp_path, "urdf")
    assert str(exc.value) == f"terrain.kind: {ground}: {URDF_GROUND}"
    monkeypatch.setitem(CAPABILITIES[kind], (ground, "urdf"), "the table's own words")
    with pytest.raises(ValueError, match=f"^terrain.kind: {ground}: the table's own words$"):
        export.run(scene_from_dict(d), tmp_path, "urdf")
    assert not list(tmp_path.rglob("*.urdf"))


def test_the_urdf_column_supports_what_the_urdf_writer_takes():
    """The URDF's column: the walker of every kind the URDF writer takes (flat feet too:
    soles on ankle hinges, tests/test_flat_feet_urdf.py), and no ground but the slope."""
    from walkerlab.walker.kinds import VIEWS

    assert "urdf" in VIEWS
    took = {k for k in KINDS if KINDS[k].supports("walk", "urdf")}
    # every legged kind and the wheels (flat feet: soles on ankle hinges; the kneed
    # walker in 3D: knees with their straight-leg stop)
    assert took == set(KINDS)
    for k in KINDS.values():
        assert not any(k.supports(g, "urdf") for g in ("stairs", "footholds", "profile"))


# ------------------------------------- the OpenSim knee latch (issue 64 leftovers, item 6)
def test_the_osim_cells_of_a_kind_with_a_knee_latch_say_walkerlabs_loop_switches_it():
    """A kneed walker's OpenSim model walks only under walkerlab's stepping loop, which
    switches its knee latch (the file alone falls); the table's ✓ did not say so.  Now every
    supported osim cell of each kind whose export has knee stops (the latch: the export's
    own parts table) carries the note: in the grid (a numbered note), in the JSON's
    ``note`` and ``detail``, and on the docs' page; no other kind's cells do."""

    from walkerlab.config import load_scene
    from walkerlab.export.parts import tree_part
    from walkerlab.walker.capability_cells import CELL_NOTES, FEATURE_NOTES, KNEE_LATCH_OSIM
    from walkerlab.walker.capability_tables import kind_grid, text
    from walkerlab.walker.kinds import table_rows
    from walkerlab.walker.plant import Plant

    # the kinds whose OpenSim model is written with knee stops (the planar kneed walker's
    # and, from its body tree, the kneed walker in 3D's)
    def knee_stops(kind):  # the export's part, read from the kind's walker's body tree
        from walkerlab.walker.walker_trees import walker_tree

        structure = Plant.from_scene(load_scene(kind.scene)).structure
        return tree_part(walker_tree(structure)[0]).knee_stops

    latched = {k for k, kind in KINDS.items() if kind.supports("walk", "osim")
               and knee_stops(kind)}
    assert latched == {"locking_knees", "locking_knees_3d"}
    for row in table_rows():
        if row["supported"] and row["view"] == "osim":
            has = row["kind"] in latched
            assert (row["note"] == KNEE_LATCH_OSIM) == has, row
            assert (KNEE_LATCH_OSIM in row["detail"]) == has, row
        elif row["supported"]:  # another note of the table's own (a cell's, the kind's
            # in the view: FEATURE_NOTES, CELL_NOTES), or none
            assert row["note"] == (FEATURE_NOTES.get((row["kind"], row["feature"], row["view"]))
                                   or CELL_NOTES.get((row["kind"], row["view"]), "")), row
    for kind in KINDS.values():
        g = kind_grid(kind)
        notes = [i + 1 for i, r in enumerate(g.reasons) if r == f"note: {KNEE_LATCH_OSIM}"]
        col = g.views.index("osim")
        for feature, cells in zip(g.features, g.rows):
            if kind.supports(feature, "osim"):
                assert cells[col].endswith(f" ({notes[0]})") if kind.name in latched \
                    else not notes, (kind.name, feature, cells[col])
    assert KNEE_LATCH_OSIM in text()
    ext = load_file("docs/_ext/capability_table.py")
    assert KNEE_LATCH_OSIM in " ".join(ext.rst().split())
    page = " ".join((ROOT / "docs" / "reference" / "capabilities.rst").read_text().split())
    assert "knee latch" in page


@pytest.mark.parametrize("name, stage", [
    ("rimless_wheel_3d", "optimize"),
    ("rimless_wheel_3d", "robustness")])
def test_a_stage_a_3d_walker_does_not_take_is_refused_before_any_work(tmp_path, name, stage):
    """Every pipeline stage a 3D kind does not take - its view's cell
    (:data:`walkerlab.walker.capability_cells.STAGE_VIEWS`) or its study's
    (:data:`~walkerlab.walker.capability_cells.STAGE_CELLS`) - is refused in one line naming
    walker.space before any upstream stage runs, and nothing is written.  (contact-sim and
    compare take both 3D kinds: tests/test_contact_3d.py; optimize the 3D straight legs and
    locking knees: tests/test_optimize_3d.py; robustness the 3D straight legs and locking knees:
    tests/test_robustness_3d.py.)"""
    from walkerlab.config import load_scene
    from walkerlab.stages import pipeline
    from walkerlab.stages.common import StageError

    scene = load_scene(ROOT / "configs" / f"{name}.yaml")
    with pytest.raises(StageError, match=r"^walker\.space: 3d: "):
        pipeline.run(stage, scene, tmp_path)
    assert not any(tmp_path.iterdir())


def test_a_3d_walkers_work_precision_without_its_section_is_refused_at_once(tmp_path):
    """``workprecision`` on a 3D walker without a ``workprecision`` section: the stage's
    check says so in one line before the fixed point upstream runs (it ran first, then
    failed), nothing written.  (Its contact model takes the 3D walkers since they have a
    contact view.)"""
    import yaml

    from walkerlab.config import scene_from_dict
    from walkerlab.stages import pipeline
    from walkerlab.stages.common import StageError

    raw = yaml.safe_load((ROOT / "configs" / "paper_3d.yaml").read_text())
    with pytest.raises(StageError, match="has no 'workprecision' section"):
        pipeline.run("workprecision", scene_from_dict(raw), tmp_path)
    assert not any(tmp_path.iterdir())
