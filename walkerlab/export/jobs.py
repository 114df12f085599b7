"""What the export's writers read and return: the job (:class:`ExportJob`: the scene, its
walker, its body tree, the gait search), a writer's files (:class:`Written`), the written
export (:class:`Exported`) and the format's :class:`Writer` (:mod:`walkerlab.export.writers`
registers them), with the helpers every writer uses (:func:`step_period`,
:func:`xml_lines`, :func:`xml_file`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path

from walkerlab.config import Scene
from walkerlab.export.engine_walk import EngineWalk
from walkerlab.export.mjcf_scene import MjcfOptions
from walkerlab.export.multibody import comments_in_scene_units
from walkerlab.export.text import comment
from walkerlab.units import for_scene
from walkerlab.walker.plant import Plant
from walkerlab.walker.tree import BodyTree
from walkerlab.walker.walker_trees import walker_tree

__all__ = ["ExportJob", "Exported", "Writer", "Written", "step_period", "xml_file",
           "xml_lines"]


@dataclass(frozen=True)
class ExportJob:
    """What a writer writes from.

    Attributes
    ----------
    scene : Scene
    plant : walkerlab.walker.plant.Plant
        The scene's walker described once, by the stage (its ``data``, its ``kind``).
    name : str
        The model's name in the file (the scene's name, else ``walker``).
    walker_only : bool
        The walker alone: no gait, no keyframe (``--walker-only``).
    gait : callable
        ``gait(build) -> (ideal, build(ideal))``: the rigid gait (an up-to-date
        ``fixedpoint.h5``'s, else searched) and what ``build`` makes of it; no rigid gait:
        ValueError, one line.  The export stage's (:func:`walkerlab.stages.export.write`).
    stored : callable
        ``stored() -> gait or None``: the rigid gait of an up-to-date ``fixedpoint.h5``, or
        None (nothing searched; the Adams dataset's start searches its own).
    options : MjcfOptions or None
        The MJCF's contact time constant and timestep (a legged walker's MJCF only).
    """

    scene: Scene
    plant: Plant
    name: str
    walker_only: bool
    gait: Callable
    stored: Callable
    options: MjcfOptions | None = None

    @property
    def kind(self):
        """The walker's kind (:class:`walkerlab.walker.kinds.Kind`)."""
        return self.plant.kind

    @property
    def data(self):
        """The walker's description (:attr:`walkerlab.walker.plant.Plant.data`)."""
        return self.plant.data

    @cached_property
    def tree(self) -> BodyTree:
        """The walker's body tree (:func:`walkerlab.walker.walker_trees.walker_tree`): what
        the writers ask of its form (one body or legs, in the plane or not, soles, knees)."""
        return walker_tree(self.plant.structure)[0]


@dataclass(frozen=True)
class Written:
    """A writer's files, not yet written.

    Attributes
    ----------
    files : tuple of (str, str)
        ``(file name in runs/<scene>/, text)``, the export's file first (a URDF's keyframe
        sidecar, the Adams command file after it).
    left_out : tuple of str
        One line per item the file leaves out (:class:`Exported`).
    step_period_s : float or None
        The rigid gait's step period the file starts from [s]; None without one.
    """

    files: tuple[tuple[str, str], ...]
    left_out: tuple[str, ...] = ()
    step_period_s: float | None = None


@dataclass(frozen=True)
class Exported:
    """An export's file and what it leaves out.

    Attributes
    ----------
    path : Path
        The written file (``walker.urdf``, ``walker.xml``, ``walker.adm``, ``walker.osim``).
    left_out : tuple of str
        One line per item the file leaves out (:mod:`walkerlab.export.omitted`): ``what:
        why``, each the text of the file's comment after ``Left out:`` (an Adams comment's
        lines joined), in the scene's units as the file has it; empty when the file carries
        the whole scene.
    step_period_s : float or None
        The rigid gait's step period the file starts from [s] (a stride's two steps: their
        mean); None without a gait (``--walker-only``, an Adams dataset's start is not
        checked here).
    walk : EngineWalk or None
        The file walked in its engine (``walk=True``,
        :func:`walk_file`); None when not asked.
    """

    path: Path
    left_out: tuple[str, ...] = ()
    step_period_s: float | None = None
    walk: EngineWalk | None = None


@dataclass(frozen=True)
class Writer:
    """One export format.

    Attributes
    ----------
    name : str
        Its ``--format`` name.
    file : str
        The export's file in ``runs/<scene>/`` (``walker.urdf``, ...).
    view : str
        Its column of the capability table (:data:`walkerlab.walker.kinds.VIEWS`).
    write : callable
        ``write(job, writer) -> Written``.
    ground : bool
        The file carries a ground (the URDF has no ground element: a ground other than the
        slope is refused by its column's cell before anything else).
    """

    name: str
    file: str
    view: str
    write: Callable[[ExportJob, Writer], Written]
    ground: bool = True

    @property
    def suffix(self) -> str:
        """The export file's suffix (``.urdf``, ``.xml``, ``.adm``, ``.osim``)."""
        return Path(self.file).suffix


def step_period(ideal) -> float | None:
    """The rigid gait's step period [s]: its period over its steps (legs that differ: a
    stride of two); None without a gait."""
    if ideal is None:
        return None
    return float(ideal.period_s) / max(1, len(getattr(ideal, "step_lengths_m", ()) or ()))


def xml_lines(items, scene: Scene) -> tuple[str, ...]:
    """The items' lines as an XML file's comments have them: ``--`` spaced
    (:func:`walkerlab.export.text.comment`), units in the scene's system
    (:func:`walkerlab.export.multibody.comments_in_scene_units`)."""
    units = for_scene(scene)
    out = []
    for o in items:
        text = comments_in_scene_units(comment(o.line), units)
        out.append(text[len("<!-- "):-len(" -->")])
    return tuple(out)


def xml_file(job: ExportJob, w: Writer, text: str) -> tuple[str, str]:
    """``(w.file, text)``, the text's header comments in the scene's units
    (:func:`walkerlab.export.multibody.comments_in_scene_units`)."""
    return (w.file, comments_in_scene_units(text, for_scene(job.scene)))
