"""Walker models. A walker is *data*: a :class:`~walkerlab.models.hybrid.base.HybridWalker` bundles
named coordinates, a flow, guards and a reset, so stages, artifacts and plots never need to
know which walker they handle. Use :func:`build_walker` to get one from a scene's plant
(:class:`walkerlab.walker.plant.Plant`)."""

from walkerlab.models.hybrid.base import Guard, HybridWalker, Phase
from walkerlab.models.registry import build_walker

__all__ = ["Guard", "HybridWalker", "Phase", "build_walker"]
