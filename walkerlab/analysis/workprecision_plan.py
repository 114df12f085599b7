"""The cases of a work-precision study planned from a scene: models, methods, tolerances,
references, target errors, warm-up cases, and the key under which a measured case is kept
(its inputs and the sources it runs).  Measured by :mod:`walkerlab.analysis.workprecision`
for the ``workprecision`` stage.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

from walkerlab.analysis.workprecision import CYRK_PREFIX
from walkerlab.config import Scene

#: the sources a case's result depends on (a change elsewhere - report text, plots, other
#: stages - keeps the measured cases)
CASE_SOURCES = {
    "ideal": ("analysis", "models", "integrate", "config"),
    "contact": ("analysis", "models", "contact", "integrate", "config"),
}


def sources_hash(parts: tuple[str, ...]) -> str:
    """SHA-256 over the walkerlab sources under ``parts`` (files or subpackages)."""
    import walkerlab

    root = Path(walkerlab.__file__).parent
    h = hashlib.sha256(walkerlab.__version__.encode())
    for part in parts:
        p = root / part
        for f in sorted(p.rglob("*.py")) if p.is_dir() else [p]:
            h.update(str(f.relative_to(root)).encode())
            h.update(f.read_bytes())
    return h.hexdigest()


def case_key(model: str, sections_json: str, x0: tuple, strides: int, method: str,
              rtol: float, atol: float, repeats: int) -> str:
    """Key of one case: its inputs (the fixed point by value, so a recomputed but equal fixed
    point keeps the cases) and the sources it runs."""
    h = hashlib.sha256(json.dumps([model, sections_json, [repr(v) for v in x0], strides,
                                   method, rtol, atol, repeats]).encode())
    h.update(sources_hash(CASE_SOURCES[model]).encode())
    return h.hexdigest()[:32]


IDEAL_SECTIONS = ("walker", "slope", "ideal", "fixedpoint")
CONTACT_SECTIONS = IDEAL_SECTIONS + ("contact", "terrain", "contact_sim")


def reference_method() -> str:
    """The ideal model's reference integrator: CyRK's DOP853 when installed (the same steps
    as scipy's DOP853, measured: the two reference vectors at rtol 1e-13 differ by 1.0e-13,
    the accuracy both reach, at 0.06 s instead of 0.7 s CPU), else scipy's."""
    from walkerlab.integrate.solver import available_backends

    return CYRK_PREFIX + "DOP853" if "cyrk" in available_backends() else "DOP853"


def plan(scene: Scene) -> dict:
    """``{model: (methods, rtols, atol_factor, reference (method, rtol, atol), target error,
    scene sections of the model)}`` of the scene's ``workprecision`` section."""
    wp = scene.workprecision
    if wp is None:
        raise ValueError(f"scene '{scene.name}' has no 'workprecision' section")
    out = {}
    if "ideal" in wp.models:
        from walkerlab.integrate.solver import CYRK_METHODS, available_backends

        extra = ([CYRK_PREFIX + m for m in wp.methods if m in CYRK_METHODS]
                 if "cyrk" in available_backends() else [])
        out["ideal"] = (list(wp.methods) + extra, list(wp.rtols), wp.atol_factor,
                        (reference_method(), wp.reference_rtol, wp.reference_rtol),
                        wp.target_error, scene.section_json(*IDEAL_SECTIONS))
    if "contact" in wp.models and scene.contact is not None:
        out["contact"] = (list(wp.contact_methods), list(wp.contact_rtols), 1e-2,
                          ("odeint", wp.contact_reference_rtol,
                           wp.contact_reference_rtol * 1e-2), wp.contact_target_error,
                          scene.section_json(*CONTACT_SECTIONS))
    return out


def warm_cases(model_plan) -> tuple:
    """Each method of a model at its loosest tolerance: the warm-up runs."""
    methods, rtols, af = model_plan[:3]
    r = max(rtols)
    return tuple((m, r, af * r) for m in methods)
