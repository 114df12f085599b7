"""CPU by phase of one ``walkerlab contact-sim`` process (the warm profile of the main job).

    python scripts/profile_contact_sim.py [--imports] -q contact-sim configs/paper.yaml \
        --force --runs-dir runs_profile

Runs the CLI in this process with the given arguments and prints, on stderr, the process
CPU time (``time.process_time``, user + system) spent in each phase: interpreter start-up,
the CLI import, the command's set-up (typer, pydantic, the stage modules' imports), the
scene, the upstream ``fixedpoint.h5`` check, the step map's imports (scipy.optimize), the
scene build (numba's import, its one-off set-up and the cached kernels' loading), the
walk, the contact periodic gait, the write (fill, netCDF bookkeeping, content hash) and
the summary printed after it.  The phases add up to the whole process (``getrusage``).
``--imports`` also gives the CPU of the imports by top-level package (an import hook: adds
a few per cent).  Phases are found by wrapping functions as their modules load (names
below), so nothing is imported early and the order of the imports is the CLI's own.

What it cannot count: the interpreter's shutdown after the last exit function (until
session 17 a garbage collection there took ~0.4-0.6 s of a warm run that no phase showed);
compare "whole process" with the process's total from outside (``/usr/bin/time``).

Use it warm (fixedpoint done and a first ``contact-sim`` run in the same user cache,
``WALKERLAB_CACHE_DIR``), on both trees of a comparison, several times: the machine is
shared, CPU time varies less than wall time but still by ~10 %.
"""

from __future__ import annotations

import functools
import importlib.abc
import importlib.util
import resource
import sys
import time
from pathlib import Path

T_SCRIPT = time.process_time()  # the interpreter's start-up, before this line

#: module -> functions whose entry and exit (CPU time) are recorded
WRAPPED = {
    "walkerlab.cli.options": ["load"],
    "walkerlab.stages.contact_sim": ["_compute"],
    "walkerlab.io.schemas.fixedpoint": ["load_fixedpoint"],
    "walkerlab.analysis.contact.record": ["contact_sim_run"],
    "walkerlab.analysis.contact.sim": ["scene_start", "simulate_contact"],
    "walkerlab.analysis.contact.periodic": ["find_contact_periodic_gait"],
    "walkerlab.io.artifacts": ["write_artifact", "content_hash_of"],
    "walkerlab.io.netcdf": ["finish"],
    "numba.core.caching": ["Cache.load_overload"],
    "numba.core.base": ["BaseContext.refresh"],
}
SPANS: dict[str, list[tuple[float, float]]] = {}
IMPORTS: dict[str, float] = {}  # top-level package -> CPU of its modules' own code [s]
_stack: list[float] = []


def _wrap(owner, attr: str, key: str) -> None:
    f = getattr(owner, attr)

    @functools.wraps(f)
    def timed(*a, **k):
        t = time.process_time()
        try:
            return f(*a, **k)
        finally:
            SPANS.setdefault(key, []).append((t, time.process_time()))

    setattr(owner, attr, timed)


def _after_load(name: str, module) -> None:
    for path in WRAPPED.get(name, ()):
        owner, attr = module, path
        if "." in path:
            cls, attr = path.split(".")
            owner = getattr(module, cls)
        _wrap(owner, attr, path)


class _Hook(importlib.abc.MetaPathFinder):
    """Wraps :data:`WRAPPED` as their modules load; with ``imports``, times every module."""

    def __init__(self, imports: bool):
        self.imports = imports

    def find_spec(self, fullname, path, target=None):
        if not self.imports and fullname not in WRAPPED:
            return None
        sys.meta_path.remove(self)
        try:
            spec = importlib.util.find_spec(fullname)
        except (ImportError, ValueError):
            spec = None
        finally:
            sys.meta_path.insert(0, self)
        if spec is None or not hasattr(spec.loader, "exec_module"):
            return spec
        run = spec.loader.exec_module

        def exec_module(module):
            t = time.process_time()
            _stack.append(0.0)
            try:
                run(module)
            finally:
                d = time.process_time() - t
                own = d - _stack.pop()
                if _stack:
                    _stack[-1] += d
                top = fullname.split(".")[0]
                IMPORTS[top] = IMPORTS.get(top, 0.0) + own
            _after_load(fullname, module)

        try:
            spec.loader.exec_module = exec_module
        except AttributeError:  # a loader that cannot be patched: not timed
            return spec
        return spec


def _total(key: str) -> float:
    return sum(b - a for a, b in SPANS.get(key, ()))


def _first(key: str, end: bool = False) -> float:
    spans = SPANS.get(key)
    return (spans[-1][1] if end else spans[0][0]) if spans else float("nan")


def phases(t_cli: float, t_end: float, whole: float) -> list[tuple[str, float]]:
    """(phase, CPU [s]) rows that add up to ``whole`` (see the module docstring)."""
    load0, load1 = _first("load"), _first("load", True)
    comp0, fp0 = _first("_compute"), _first("load_fixedpoint")
    run0, run1 = _first("contact_sim_run"), _first("contact_sim_run", True)
    w0, w1 = _first("write_artifact"), _first("write_artifact", True)
    walk, gait = _total("simulate_contact"), _total("find_contact_periodic_gait")
    build = _total("scene_start")  # simulate_from: scene_start, then simulate_contact
    rows = [
        ("interpreter start-up", T_SCRIPT),
        ("import walkerlab.cli (typer)", t_cli - T_SCRIPT),
        ("command set-up: typer, pydantic, stage imports", load0 - t_cli),
        ("scene: YAML + pydantic validation", load1 - load0),
        ("stage set-up, upstream fixedpoint.h5 check", comp0 - load1),
        ("step-map imports (scipy.optimize)", fp0 - comp0),
        ("read fixedpoint.h5", _total("load_fixedpoint")),
        ("scene build (numba import, set-up, kernels)", build),
        ("walk (simulate_contact)", walk),
        ("contact periodic gait", gait),
        ("rest of the run (drop test, records)", (run1 - run0) - build - walk - gait),
        ("between run and write", w0 - run1),
        ("write contact_sim.h5", w1 - w0),
        ("after the write: summary, exit", t_end - w1),
    ]
    rest = whole - sum(v for _, v in rows)
    return rows + [("unaccounted (atexit, rounding)", rest), ("whole process", whole)]


def details() -> list[tuple[str, float]]:
    """Sub-phases, already counted in :func:`phases`."""
    n = len(SPANS.get("Cache.load_overload", ()))
    return [
        ("numba one-off set-up (target context refresh)", _total("BaseContext.refresh")),
        (f"numba cached kernels loaded: {n} (incl. the set-up)", _total("Cache.load_overload")),
        ("write: netCDF dimension bookkeeping", _total("finish")),
        ("write: content hash", _total("content_hash_of")),
    ]


def main() -> None:
    args = sys.argv[1:]
    imports = "--imports" in args
    args = [a for a in args if a != "--imports"]
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
    sys.meta_path.insert(0, _Hook(imports))
    from walkerlab.cli import app

    t_cli = time.process_time()
    code = 0
    try:
        app(args)
    except SystemExit as exc:
        code = exc.code or 0
    t_end = time.process_time()
    ru = resource.getrusage(resource.RUSAGE_SELF)
    err = sys.stderr
    for name, v in phases(t_cli, t_end, ru.ru_utime + ru.ru_stime):
        print(f"{name:52s} {v:7.3f} s", file=err)
    for name, v in details():
        print(f"  {name:50s} {v:7.3f} s", file=err)
    if imports:
        top = sorted(IMPORTS.items(), key=lambda kv: -kv[1])
        print("imports by package (own code): " + ", ".join(
            f"{k} {v:.3f}" for k, v in top if v >= 0.005), file=err)
    sys.exit(code)


if __name__ == "__main__":
    main()
