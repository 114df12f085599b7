"""Which actuators, optimisations and exports walkerlab accepts, walker family by family
(issue 48's closing table: "walker family × (hip, knee, ankle, torso torque, push-off,
virtual constraints, optimize, design, MJCF export): before and after").

For each family (the walker of a shipped scene) and each capability a scene variant is
built and handed to the checkout that ``PYTHONPATH`` selects; nothing long is solved:

- **hip / knee / ankle / torso torque, push-off, virtual constraints**: the rigid walker
  with that one actuator (``walker.actuation``, a small PD law; virtual constraints: a PD
  law tracking a phase ``reference`` table) is built (``walkerlab.api.walker.Walker``) and
  one Poincaré-map step runs from the scene's ``fixedpoint.initial_guess``.  Accepted: it
  builds and the step runs (a step that ends in a fall guard is the walker's dynamics, not
  a refusal: marked ``✓ (fell)``).  The step starts from the shipped scene's gait
  (``Walker.fixed_point``; its initial guess if none is found).  A walker shipped with
  actuators (the five-link biped) keeps them, the cell's actuator added where it has none
  at that joint; its virtual constraints are its shipped four-joint law.
- **optimize**: ``walkerlab optimize SCENE`` with CasADi's ``Opti.solve`` replaced by an
  exit: accepted when the stage reaches IPOPT (every refusal check and the transcription's
  set-up passed).  A five-link biped's scene gets configs/rabbit_optimal.yaml's targets
  (its least effort needs one).
- **design**: ``walkerlab optimize SCENE --design slope.angle_rad=LO:HI`` (±10 %) with
  ``scipy.optimize.minimize`` replaced by one evaluation of the objective and its gradient
  at the start, then an exit.
- **MJCF / Adams / OpenSim export**: ``walkerlab export SCENE --format mjcf|adm|osim`` into
  a temporary runs folder (the shipped scene; a warning the command prints is kept in the JSON).

Every cell has a CPU-time limit (``--timeout``); the torque cells of a family share one
child process, every command cell runs in its own.

Usage::

    PYTHONPATH=/path/to/checkout python scripts/capability_table.py RUNS_DIR \
        [--json out.json] [--timeout 120] [--families kneed,torso] [--capabilities hip,mjcf]

prints the markdown table and writes the JSON (default ``RUNS_DIR/capability_table.json``).
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[1]

#: family -> the shipped scene whose walker it is
FAMILIES = {
    "straight": "configs/paper.yaml",
    "kneed": "configs/kneed.yaml",
    "arc feet": "configs/round_feet.yaml",
    "flat feet": "configs/flat_feet.yaml",
    "torso": "configs/torso_bhm.yaml",
    "five-link": "configs/rabbit.yaml",
    "unequal legs": "configs/asymmetric_legs.yaml",
}

#: capability -> column title
CAPABILITIES = {
    "hip": "hip",
    "knee": "knee",
    "ankle": "ankle",
    "torso": "torso torque",
    "push_off": "push-off",
    "virtual_constraints": "virtual constraints",
    "optimize": "optimize",
    "design": "design",
    "mjcf": "MJCF export",
    "adams": "Adams export",
    "osim": "OpenSim export",
}
RIGID = ("hip", "knee", "ankle", "torso", "push_off", "virtual_constraints")
EXIT_REACHED = 77  # a command cell's child: the solver was reached (set-up accepted)
MESSAGE_CHARS = 60

#: a small PD law [N m/rad, N m s/rad] about the joint's zero angle
SMALL_PD = {"stiffness_n_m_per_rad": 0.1, "damping_n_m_s_per_rad": 0.01}


# ---------------------------------------------------------------------------- the scenes

def load(family: str) -> dict:
    """The family's shipped scene as a mapping."""
    with open(ROOT / FAMILIES[family]) as fh:
        return yaml.safe_load(fh)


def legs(walker: dict) -> list[dict]:
    """The walker's leg descriptions (one, or one per leg)."""
    return walker.get("legs") or [walker.get("leg") or {}]


def features(scene: dict) -> dict[str, bool]:
    """What joints the walker has, read from its description."""
    w = scene["walker"]
    ls = legs(w)
    return {"knee": any("knee" in leg for leg in ls),
            "flat": any((leg.get("foot") or {}).get("kind") == "flat" for leg in ls),
            "torso": "torso" in w}


def applicable(scene: dict, cap: str) -> bool:
    """False where the family has no such joint (a straight leg has no knee)."""
    f = features(scene)
    return {"knee": f["knee"], "ankle": f["flat"], "torso": f["torso"]}.get(cap, True)


def torque(joint: str, **law) -> dict:
    return {"joint": joint, "law": {**SMALL_PD, **law}}


#: a phase reference for the hip (swing minus stance leg angle) against the stance leg's
#: angle: about -2 x the phase, the passive gaits' symmetric step
HIP_REFERENCE = {"phase_rad": [-0.4, 0.4], "angle_rad": [0.8, -0.8],
                 "interpolation": "linear"}


def with_actuator(shipped: dict | None, label: str, add: dict) -> tuple[str, dict]:
    """The cell's actuation: the one actuator alone on a passive walker; on a walker shipped
    with actuators (the five-link biped, which falls without them) its own section, with the
    actuator added where it has none at that joint (its own law kept where it has)."""
    if not shipped:
        return label, add
    act = json.loads(json.dumps(shipped))
    if "push_off" in add:
        if act.get("push_off"):
            return "shipped", act
        act["push_off"] = add["push_off"]
        return f"shipped + {label}", act
    joint = add["torques"][0]["joint"]
    if any(t["joint"] == joint for t in act.get("torques", [])):
        return "shipped", act
    act["torques"] = [*act.get("torques", []), *add["torques"]]
    return f"shipped + {label}", act


def actuation_variants(scene: dict, cap: str) -> list[tuple[str, dict]]:
    """The ``walker.actuation`` sections to try for a torque / push-off cell (the first one
    accepted counts), each with a label."""
    shipped = scene["walker"].get("actuation")
    if cap == "hip":
        return [with_actuator(shipped, "hip", {"torques": [torque("hip")]})]
    if cap == "knee":
        return [with_actuator(shipped, j, {"torques": [torque(j)]})
                for j in ("swing_knee", "stance_knee")]
    if cap == "ankle":
        return [with_actuator(shipped, "stance_ankle", {"torques": [torque("stance_ankle")]})]
    if cap == "torso":
        return [with_actuator(shipped, "stance_hip", {"torques": [torque("stance_hip")]})]
    if cap == "push_off":
        return [with_actuator(shipped, "push_off", {"push_off": {"impulse_n_s": 0.05}})]
    if cap == "virtual_constraints":
        if shipped and any(t.get("law", {}).get("reference") for t in
                           shipped.get("torques", [])):
            return [("shipped", shipped)]
        return [("hip", {"torques": [torque("hip", stiffness_n_m_per_rad=1.0,
                                            damping_n_m_s_per_rad=0.1,
                                            reference=HIP_REFERENCE)]})]
    raise ValueError(cap)


# ---------------------------------------------------------------------------- one line

def one_line(text: str) -> str:
    """The message's first meaningful line, without the ``error:`` prefix."""
    lines = [ln.strip() for ln in str(text).splitlines() if ln.strip()]
    errs = [ln for ln in lines if ln.lower().startswith("error")]
    line = (errs[-1] if errs else lines[-1]) if lines else ""
    for prefix in ("error:", "Error:"):
        if line.startswith(prefix):
            line = line[len(prefix):].strip()
    return line


def short(text: str, n: int = MESSAGE_CHARS) -> str:
    text = " ".join(str(text).split())
    return text if len(text) <= n else text[: n - 1] + "…"


# ---------------------------------------------------------------------------- rigid cells

class CellTimeout(Exception):
    """The cell used up its CPU time."""


def _on_alarm(signum, frame):
    raise CellTimeout


def rigid_cell(scene: dict, cap: str, timeout_s: float, start=None) -> dict:
    """Build the rigid walker with the cell's actuator and run one map step from ``start``
    (the shipped scene's gait; None: the scene's initial guess)."""
    if not applicable(scene, cap):
        return {"status": "n/a", "message": "", "detail": ""}
    out: dict = {}
    first: dict | None = None
    for label, act in actuation_variants(scene, cap):
        s = json.loads(json.dumps(scene))
        s["walker"]["actuation"] = act
        t0 = time.process_time()
        signal.signal(signal.SIGPROF, _on_alarm)
        signal.setitimer(signal.ITIMER_PROF, timeout_s)
        try:
            out = run_step(s, start)
        except CellTimeout:
            out = {"status": "timeout", "message": f"no answer in {timeout_s:g} s CPU",
                   "detail": ""}
        finally:
            signal.setitimer(signal.ITIMER_PROF, 0)
        out["variant"] = label
        out["start"] = "initial guess" if start is None else "shipped gait"
        out["cpu_s"] = round(time.process_time() - t0, 2)
        if out["status"] == "accepted":
            return out
        first = first or out
    return first or out


def run_step(scene: dict, start=None) -> dict:
    """Build ``Walker.from_scene(scene)`` and step once from ``start`` (None: the scene's
    initial guess)."""
    from walkerlab.analysis.gait.poincare import StepFailed
    from walkerlab.analysis.gait.scene import initial_guess
    from walkerlab.api.walker import Walker

    try:
        w = Walker.from_scene(scene, step_time_limit_s=60.0)
        x0 = initial_guess(w.scene, w.model) if start is None else start
    except CellTimeout:
        raise
    except Exception as exc:  # noqa: BLE001 - any refusal is the cell's answer
        return {"status": "refused", "message": one_line(exc),
                "detail": f"{type(exc).__name__}: {exc}"}
    try:
        step = w.step(x0)
    except CellTimeout:
        raise
    except StepFailed as exc:
        return {"status": "accepted", "message": "fell",
                "detail": f"step: {one_line(exc)}"}
    except Exception as exc:  # noqa: BLE001
        return {"status": "refused", "message": one_line(exc),
                "detail": f"step {type(exc).__name__}: {exc}"}
    return {"status": "accepted", "message": "",
            "detail": f"one step: period {step.period:.6g} s"}


def rigid_family(family: str, caps: list[str], timeout_s: float) -> dict:
    """All rigid cells of a family (in this process)."""
    scene = load(family)
    start = shipped_gait(scene, timeout_s)
    return {cap: rigid_cell(scene, cap, timeout_s, start) for cap in caps}


def shipped_gait(scene: dict, timeout_s: float):
    """The shipped scene's period-1 gait (``Walker.fixed_point``) as the steps' start, or
    None (then the initial guess) if it is not found within ``timeout_s`` of CPU."""
    from walkerlab.api.walker import Walker

    signal.signal(signal.SIGPROF, _on_alarm)
    signal.setitimer(signal.ITIMER_PROF, timeout_s)
    try:
        return Walker.from_scene(scene).fixed_point().x
    except (CellTimeout, Exception):  # noqa: BLE001 - the initial guess then
        return None
    finally:
        signal.setitimer(signal.ITIMER_PROF, 0)


# ---------------------------------------------------------------------------- command cells

#: an ``optimize`` section a family's optimisation needs (a five-link biped's least effort
#: needs a target: configs/rabbit_optimal.yaml's 0.5 m in 0.7 s)
OPTIMIZE_SECTION = {"five-link": {"target_step_length_m": 0.5, "target_step_period_s": 0.7}}


def command_args(family: str, cap: str, runs: Path) -> list[str]:
    """The walkerlab command of a command cell (a changed scene written into ``runs``)."""
    scene = str(ROOT / FAMILIES[family])
    if cap in ("optimize", "design") and family in OPTIMIZE_SECTION:
        d = load(family)
        d.setdefault("optimize", OPTIMIZE_SECTION[family])
        runs.mkdir(parents=True, exist_ok=True)
        scene = str(runs / Path(FAMILIES[family]).name)
        Path(scene).write_text(yaml.safe_dump(d, sort_keys=False))
    if cap == "optimize":
        return ["optimize", scene, "--runs-dir", str(runs)]
    if cap == "design":  # the slope, +-10 % (level ground: +-0.005 rad)
        phi = float(load(family)["slope"]["angle_rad"])
        lo, hi = (0.9 * phi, 1.1 * phi) if phi > 0 else (phi - 0.005, phi + 0.005)
        return ["optimize", scene, "--runs-dir", str(runs), "--design",
                f"slope.angle_rad={lo:.6g}:{hi:.6g}"]
    if cap == "mjcf":
        return ["export", scene, "--format", "mjcf", "--runs-dir", str(runs)]
    if cap == "adams":
        return ["export", scene, "--format", "adm", "--runs-dir", str(runs)]
    if cap == "osim":
        return ["export", scene, "--format", "osim", "--runs-dir", str(runs)]
    raise ValueError(cap)


def _reached(what: str):
    sys.stdout.write(f"REACHED {what}\n")
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(EXIT_REACHED)


def command_child(cap: str, args: list[str], timeout_s: float) -> None:
    """In the child: stop at the solver, run the command (never returns)."""
    resource.setrlimit(resource.RLIMIT_CPU, (int(timeout_s) + 1, int(timeout_s) + 2))
    if cap == "optimize":
        import casadi

        casadi.Opti.solve = lambda self, *a, **k: _reached("Opti.solve")
    elif cap == "design":
        import scipy.optimize

        def minimize(fun, x0, *a, jac=None, **k):
            fun(x0)  # one evaluation at the start: its refusals are the cell's
            _reached("minimize")

        scipy.optimize.minimize = minimize
    from walkerlab.cli import app

    app(args, prog_name="walkerlab")
    sys.exit(0)


def command_cell(family: str, cap: str, runs: Path, timeout_s: float) -> dict:
    """Run one command cell in a child process bounded to ``timeout_s`` of CPU."""
    scene = load(family)
    if not applicable(scene, cap):
        return {"status": "n/a", "message": "", "detail": ""}
    args = command_args(family, cap, runs)
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    cmd = [sys.executable, str(Path(__file__).resolve()), "--child", cap,
           "--timeout", str(timeout_s), "--", *args]
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=8 * timeout_s + 60)
        rc, stdout, stderr = p.returncode, p.stdout, p.stderr
    except subprocess.TimeoutExpired as exc:
        rc, stdout, stderr = None, exc.stdout or "", exc.stderr or ""
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime + after.ru_stime) - (before.ru_utime + before.ru_stime)
    out = {"command": "walkerlab " + " ".join(args), "returncode": rc,
           "cpu_s": round(cpu, 2)}
    if rc == EXIT_REACHED or rc == 0:
        warn = [ln.strip() for ln in stderr.splitlines()
                if "warn" in ln.lower() or "not exported" in ln.lower()]
        out.update(status="accepted", message="", detail=(stdout.strip().splitlines()
                                                          or [""])[-1],
                   warnings=warn)
    elif rc is None or rc in (-signal.SIGXCPU, -signal.SIGKILL, 128 + signal.SIGXCPU):
        out.update(status="timeout", message=f"no answer in {timeout_s:g} s CPU",
                   detail=stderr[-500:])
    else:
        out.update(status="refused",
                   message=one_line(stderr or stdout).replace(f"{runs}/", ""),
                   detail=(stderr or stdout)[-2000:])
    return out


# ---------------------------------------------------------------------------- the table

def mark(cell: dict) -> str:
    """A cell of the markdown table."""
    st = cell["status"]
    if st == "n/a":
        return "n/a"
    if st == "accepted":
        return "✓ (fell)" if cell.get("message") == "fell" else "✓"
    if st == "timeout":
        return f"⏱ {cell['message']}"
    return "✗ " + short(cell["message"]).replace("|", "/")


def markdown(table: dict, caps: list[str]) -> str:
    """The table: a row per family, a column per capability."""
    head = "| family | " + " | ".join(CAPABILITIES[c] for c in caps) + " |"
    rule = "|---|" + "---|" * len(caps)
    rows = [f"| {fam} | " + " | ".join(mark(cells[c]) for c in caps) + " |"
            for fam, cells in table.items()]
    return "\n".join([head, rule, *rows])


def build_table(runs: Path, families: list[str], caps: list[str],
                timeout_s: float) -> dict:
    """Every cell: ``{family: {capability: cell}}``."""
    table: dict = {}
    rigid = [c for c in caps if c in RIGID]
    for fam in families:
        cells: dict = {}
        if rigid:
            cmd = [sys.executable, str(Path(__file__).resolve()), "--rigid-family", fam,
                   "--capabilities", ",".join(rigid), "--timeout", str(timeout_s)]
            p = subprocess.run(cmd, capture_output=True, text=True,
                               timeout=len(rigid) * 3 * timeout_s + 120)
            try:
                cells.update(json.loads(p.stdout.strip().splitlines()[-1]))
            except (IndexError, json.JSONDecodeError):
                for c in rigid:
                    cells[c] = {"status": "error", "message": one_line(p.stderr),
                                "detail": p.stderr[-2000:]}
        for c in caps:
            if c not in RIGID:
                cells[c] = command_cell(fam, c, runs / fam.replace(" ", "_") / c, timeout_s)
            print(f"{fam:>13} {c:>20}: {mark(cells[c])}", file=sys.stderr, flush=True)
        table[fam] = {c: cells[c] for c in caps}
    return table


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("runs_dir", nargs="?", type=Path)
    ap.add_argument("--json", type=Path, default=None)
    ap.add_argument("--timeout", type=float, default=120.0,
                    help="CPU seconds per cell")
    ap.add_argument("--families", default=",".join(FAMILIES))
    ap.add_argument("--capabilities", default=",".join(CAPABILITIES))
    ap.add_argument("--rigid-family", default=None, help=argparse.SUPPRESS)
    ap.add_argument("--child", default=None, help=argparse.SUPPRESS)
    ap.add_argument("rest", nargs="*", help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    caps = [c.strip() for c in a.capabilities.split(",") if c.strip()]
    if a.child:
        rest = ([str(a.runs_dir)] if a.runs_dir else []) + a.rest
        command_child(a.child, rest, a.timeout)
    if a.rigid_family:
        print(json.dumps(rigid_family(a.rigid_family, caps, a.timeout)))
        return 0
    families = [f.strip() for f in a.families.split(",") if f.strip()]
    bad = [f for f in families if f not in FAMILIES] + [c for c in caps
                                                        if c not in CAPABILITIES]
    if bad or a.runs_dir is None:
        ap.error(f"unknown {bad}" if bad else "give RUNS_DIR")
    a.runs_dir.mkdir(parents=True, exist_ok=True)
    runs = Path(tempfile.mkdtemp(prefix="captable_", dir=a.runs_dir))
    import walkerlab

    t0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    table = build_table(runs, families, caps, a.timeout)
    t1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (t1.ru_utime + t1.ru_stime) - (t0.ru_utime + t0.ru_stime)
    md = markdown(table, caps)
    print(md)
    out = a.json or a.runs_dir / "capability_table.json"
    tmp = out.with_suffix(".json.tmp")
    tmp.write_text(json.dumps({"walkerlab": str(Path(walkerlab.__file__).parent),
                               "cpu_s": round(cpu, 1), "timeout_s": a.timeout,
                               "markdown": md, "table": table}, indent=1,
                              ensure_ascii=False))
    tmp.replace(out)
    print(f"\n(CPU {cpu:.0f} s; {out})", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
