"""Reproduce the defects of issues 12 and 19 against a walkerlab checkout, as a user would.

Usage::

    PYTHONPATH=. python scripts/reliability_repro.py repro_base [CASE ...]

(from the checkout's root, which the ``PYTHONPATH`` names; ``repro_base`` is created).

Cases ``d*`` are issue 12's, ``i19_<item>_*`` issue 19's (items 1-14; every case gets its
own user cache, ``WALKERLAB_CACHE_DIR=<case>/uc``).

Each case runs the CLI (``python -m walkerlab.cli``) in a fresh folder under the given
work directory and prints one Markdown table row: case, exit code, the first line of
stderr (or ``TRACEBACK: <last line>``) and what happened on disk.  Nothing is asserted: this
is the measurement behind the before/after table of the closing note.
"""

from __future__ import annotations

import os
import shutil
import signal
import stat
import subprocess
import sys
import time
from pathlib import Path

import yaml

import walkerlab  # noqa: E402  (the checkout under test, from PYTHONPATH)

ROOT = Path(walkerlab.__file__).resolve().parents[1]  # its own configs/paper.yaml
PAPER = yaml.safe_load((ROOT / "configs" / "paper.yaml").read_text())
IDEAL = {k: v for k, v in PAPER.items() if k in ("source", "walker", "slope", "solver",
                                                  "fixedpoint", "simulate")}
PY = sys.executable


def cli(cwd: Path, *args: str, timeout: float = 120, env=None, user=None):
    cmd = [PY, "-m", "walkerlab.cli", *args]
    if user:
        cmd = ["setpriv", f"--reuid={user}", f"--regid={user}", "--clear-groups", *cmd]
    t0 = time.time()
    try:
        p = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True, timeout=timeout,
                           env={**os.environ, **(env or {})})
    except subprocess.TimeoutExpired:
        return None, f"TIMEOUT after {timeout:.0f} s", time.time() - t0
    err = p.stderr.strip().splitlines()
    if any("Traceback" in ln for ln in err):
        first = "TRACEBACK: " + (err[-1] if err else "")
    else:
        # the error line, not a note before it ("simulate: recomputing ... (scene changed ...)")
        first = next((ln for ln in err if ln.startswith("error")), err[0] if err else
                     (p.stdout.strip().splitlines() or [""])[-1])
        if len(err) > 1:
            first += f" (+{len(err) - 1} more lines)"
    return p.returncode, first[:160], time.time() - t0


def scene(d: Path, data: dict, name: str = "s.yaml") -> Path:
    p = d / name
    p.parent.mkdir(parents=True, exist_ok=True)
    p.write_text(yaml.safe_dump(data))
    return p


def with_(base: dict, **dotted) -> dict:
    import copy

    d = copy.deepcopy(base)
    for k, v in dotted.items():
        node = d
        keys = k.split("__")
        for kk in keys[:-1]:
            node = node.setdefault(kk, {})
        node[keys[-1]] = v
    return d


def ls(p: Path) -> str:
    return ", ".join(sorted(str(x.relative_to(p)) for x in p.rglob("*") if x.is_file())) or "-"


CASES = {}


def case(fn):
    CASES[fn.__name__] = fn
    return fn


@case
def d1_name_dotdot(d):
    s = scene(d / "cfg", {**IDEAL, "name": "../evil"})
    rc, msg, _ = cli(d / "cfg", "fixedpoint", str(s), "--runs-dir", "runs")
    return rc, msg, f"cfg/evil exists: {(d / 'cfg' / 'evil').exists()}"


@case
def d1_name_absolute(d):
    target = d / "abs_target"
    s = scene(d / "cfg", {**IDEAL, "name": str(target)})
    rc, msg, _ = cli(d / "cfg", "fixedpoint", str(s), "--runs-dir", "runs")
    return rc, msg, f"absolute target written: {target.exists()}"


@case
def d1_file_named_dots(d):
    s = scene(d / "cfg", IDEAL, "...yaml")
    rc, msg, _ = cli(d / "cfg", "fixedpoint", str(s), "--runs-dir", "runs/inner")
    return rc, msg, f"files: {ls(d / 'cfg' / 'runs')}"


@case
def d1_sweep_name_escape(d):
    s = scene(d / "cfg", IDEAL, "paper.yaml")
    rc, msg, _ = cli(d / "cfg", "sweep", str(s), "--param", "slope.angle_deg=1,1.1",
                     "--name", "../../x", "--workers", "1", "--runs-dir", "runs")
    return rc, msg, f"cfg/x.h5 outside runs/: {(d / 'cfg' / 'x.h5').exists()}"


@case
def d2_sweep_named_like_stage(d):
    s = scene(d / "cfg", IDEAL, "paper.yaml")
    cli(d / "cfg", "fixedpoint", str(s), "--runs-dir", "runs")
    rc, msg, _ = cli(d / "cfg", "sweep", str(s), "--param", "slope.angle_deg=1,1.1",
                     "--name", "fixedpoint", "--workers", "1", "--runs-dir", "runs")
    import h5py

    with h5py.File(d / "cfg/runs/paper/fixedpoint.h5") as f:
        kind = f.attrs["stage"]
    return rc, msg, f"fixedpoint.h5 is now a '{kind}' artifact"


@case
def d2_same_name_two_folders(d):
    a = scene(d / "a", IDEAL, "paper.yaml")
    b = scene(d / "b", with_(IDEAL, slope={"angle_deg": 3.0}), "paper.yaml")
    cli(d, "fixedpoint", str(a), "--runs-dir", "runs")
    rc, msg, _ = cli(d, "fixedpoint", str(b), "--runs-dir", "runs")
    return rc, msg, f"run folders: {sorted(p.name for p in (d / 'runs').iterdir())}"


@case
def d3_readonly_runs(d):
    s = scene(d / "cfg", IDEAL, "paper.yaml")
    (d / "cfg" / "runs").mkdir(parents=True)
    os.chmod(d / "cfg" / "runs", 0o555)
    os.chmod(d, 0o777)
    os.chmod(d / "cfg", 0o777)
    os.chmod(s, 0o644)
    rc, msg, _ = cli(d / "cfg", "fixedpoint", str(s), "--runs-dir", "runs", user="65534",
                     env={"HOME": str(d)})
    return rc, msg, "run as uid 65534 (root ignores modes)"


@case
def d3_readonly_runs_sweep(d):
    s = scene(d / "cfg", IDEAL, "paper.yaml")
    (d / "cfg" / "runs").mkdir(parents=True)
    os.chmod(d / "cfg" / "runs", 0o555)
    os.chmod(d, 0o777)
    os.chmod(d / "cfg", 0o777)
    os.chmod(s, 0o644)
    rc, msg, _ = cli(d / "cfg", "sweep", str(s), "--param", "slope.angle_deg=1", "--workers",
                     "1", "--runs-dir", "runs", user="65534", env={"HOME": str(d)})
    return rc, msg, "run as uid 65534 (root ignores modes)"


def _contact(d, **kw):
    return scene(d / "cfg", with_(PAPER, **{"contact_sim__periodic_gait": False,
                                            "contact_sim__n_strides": 2, **kw}), "paper.yaml")


@case
def d3_contact_inf_stiffness(d):
    s = _contact(d, contact__stiffness_n_per_mm_pow_e=float("inf"))
    rc, msg, _ = cli(d / "cfg", "contact-sim", str(s), "--runs-dir", "runs", timeout=400)
    return rc, msg, ""


@case
def d3_contact_inf_rate_scale(d):
    s = _contact(d, contact_sim__initial_rate_scale=[float("inf"), 1.0])
    rc, msg, _ = cli(d / "cfg", "contact-sim", str(s), "--runs-dir", "runs", timeout=400)
    return rc, msg, ""


@case
def d3_contact_inf_damping(d):
    s = _contact(d, contact__max_damping_n_s_per_mm=float("inf"))
    rc, msg, _ = cli(d / "cfg", "contact-sim", str(s), "--runs-dir", "runs", timeout=400)
    return rc, msg, ""


@case
def d3_contact_rtol_1e14(d):
    s = _contact(d, contact_solver__rtol=1e-14)
    rc, msg, _ = cli(d / "cfg", "contact-sim", str(s), "--runs-dir", "runs", timeout=400)
    return rc, msg, ""


@case
def d3_contact_mu_005(d):
    s = _contact(d, contact__mu_static=0.05, contact__mu_dynamic=0.05)
    rc, msg, _ = cli(d / "cfg", "contact-sim", str(s), "--runs-dir", "runs", timeout=400)
    return rc, msg, ""


@case
def d3_contact_mu_005_periodic(d):
    s = _contact(d, contact__mu_static=0.05, contact__mu_dynamic=0.05,
                 contact_sim__periodic_gait=True)
    rc, msg, _ = cli(d / "cfg", "contact-sim", str(s), "--runs-dir", "runs", timeout=400)
    return rc, msg, ""


@case
def d3_contact_slope_6deg(d):
    s = _contact(d, slope={"angle_deg": 6.0})
    rc, msg, _ = cli(d / "cfg", "contact-sim", str(s), "--runs-dir", "runs", timeout=400)
    return rc, msg, ""


@case
def d3_plot_dataset_removed(d):
    s = scene(d / "cfg", IDEAL, "paper.yaml")
    cli(d / "cfg", "simulate", str(s), "--runs-dir", "runs")
    import h5py

    with h5py.File(d / "cfg/runs/paper/simulate.h5", "a") as f:
        del f["samples/time"]
    rc, msg, _ = cli(d / "cfg", "plot", str(s), "--runs-dir", "runs")
    return rc, msg, ""


@case
def d3_huge_sweep_grid(d):
    s = scene(d / "cfg", IDEAL, "paper.yaml")
    rc, msg, _ = cli(d / "cfg", "sweep", str(s), "--param", "slope.angle_deg=0:99999:1",
                     "--param", "walker.hip_mass_kg=0:99999:1", "--workers", "1",
                     "--runs-dir", "runs", timeout=120)
    return rc, msg, ""


@case
def d3_bench_bad_argument(d):
    rc, msg, _ = cli(d, "bench", "nonsense", "--out", str(d / "bench"))
    return rc, msg, ""


@case
def d4_identical_sweeps_second_killed(d):
    s = scene(d / "cfg", IDEAL, "paper.yaml")
    args = [PY, "-m", "walkerlab.cli", "sweep", str(s), "--param",
            "slope.angle_deg=1:3:0.25", "--workers", "1", "--runs-dir", "runs", "--name", "same"]
    first = subprocess.Popen(args, cwd=d / "cfg", stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True)
    time.sleep(4)
    second = subprocess.Popen(args, cwd=d / "cfg", stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, text=True, start_new_session=True)
    time.sleep(4)
    os.killpg(second.pid, signal.SIGKILL)
    second.wait()
    out, err = first.communicate(timeout=300)
    import h5py

    p = d / "cfg/runs/paper/same.h5"
    info = "no final file"
    if p.is_file():
        with h5py.File(p) as f:
            info = f"complete={bool(f.attrs['complete'])}, rows={f['points/index'].shape[0]}"
    last = (err.strip().splitlines() or [""])[-1]
    return first.returncode, (out.strip().splitlines() or [""])[-1][:100] + " | " + last[:60], info


@case
def d4_identical_sweeps_both_run(d):
    s = scene(d / "cfg", IDEAL, "paper.yaml")
    args = [PY, "-m", "walkerlab.cli", "sweep", str(s), "--param",
            "slope.angle_deg=1:3:0.25", "--workers", "1", "--runs-dir", "runs", "--name", "same"]
    first = subprocess.Popen(args, cwd=d / "cfg", stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True)
    time.sleep(4)
    second = subprocess.run(args, cwd=d / "cfg", capture_output=True, text=True, timeout=300)
    first.communicate(timeout=300)
    err = second.stderr.strip().splitlines()
    msg = ("TRACEBACK: " + err[-1]) if any("Traceback" in e for e in err) else \
        (err[0] if err else second.stdout.strip().splitlines()[-1])
    return f"{first.returncode}/{second.returncode}", msg[:160], ""


@case
def d6_edited_artifact_reused(d):
    s = scene(d / "cfg", IDEAL, "paper.yaml")
    cli(d / "cfg", "fixedpoint", str(s), "--runs-dir", "runs")
    import h5py

    with h5py.File(d / "cfg/runs/paper/fixedpoint.h5", "a") as f:
        f["fixed_point/stance_rate"][()] = -3.0
    p = subprocess.run([PY, "-m", "walkerlab.cli", "fixedpoint", str(s), "--runs-dir", "runs"],
                       cwd=d / "cfg", capture_output=True, text=True)
    rc, msg, _ = cli(d / "cfg", "simulate", str(s), "--runs-dir", "runs")
    return rc, msg, "after the edit, fixedpoint says: " + p.stdout.strip().splitlines()[-1][:50]


@case
def d7_sigkill_sweep_orphans(d):
    s = scene(d / "cfg", IDEAL, "paper.yaml")
    main = subprocess.Popen([PY, "-m", "walkerlab.cli", "sweep", str(s), "--param",
                             "slope.angle_deg=1:4:0.05", "--workers", "2", "--runs-dir", "runs"],
                            cwd=d / "cfg", stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    kids = _wait_workers(main.pid)
    time.sleep(3)
    kids = _children(main.pid)
    os.kill(main.pid, signal.SIGKILL)
    main.wait()
    time.sleep(5)
    alive = [k for k in kids if _alive(k)]
    for k in alive:
        os.kill(k, signal.SIGKILL)
    return -9, "", f"{len(kids)} descendants, {len(alive)} still alive 5 s after SIGKILL"


def _wait_workers(pid, n=3, timeout=180):
    t0 = time.time()
    kids = []
    while time.time() - t0 < timeout:
        kids = _children(pid)
        if len(kids) >= n:
            break
        time.sleep(0.2)
    return kids


def _children(pid):
    out = subprocess.run(["ps", "-e", "-o", "pid=,ppid="], capture_output=True, text=True).stdout
    tree = {}
    for ln in out.split("\n"):
        if ln.strip():
            a, b = map(int, ln.split())
            tree.setdefault(b, []).append(a)
    res, todo = [], [pid]
    while todo:
        for c in tree.get(todo.pop(), []):
            res.append(c)
            todo.append(c)
    return res


def _alive(pid):
    try:
        st = Path(f"/proc/{pid}/stat").read_text().split()[2]
        return st != "Z"
    except OSError:
        return False


@case
def d8_simulate_10000_strides(d):
    s = scene(d / "cfg", IDEAL, "paper.yaml")
    cli(d / "cfg", "fixedpoint", str(s), "--runs-dir", "runs")
    rc, msg, t = cli(d / "cfg", "simulate", str(s), "--strides", "10000", "--runs-dir", "runs",
                     timeout=60)
    return rc, msg, f"{t:.0f} s"


@case
def d8_contact_n_strides_huge(d):
    s = _contact(d, contact_sim__n_strides=10_000_000, contact_sim__t_final_s=0.1)
    rc, msg, t = cli(d / "cfg", "contact-sim", str(s), "--runs-dir", "runs", timeout=120)
    size = sum(p.stat().st_size for p in (d / "cfg").rglob("contact_sim.h5"))
    return rc, msg, f"{t:.0f} s, contact_sim.h5 {size / 1e6:.1f} MB"


@case
def d9_strides_1e7(d):
    s = scene(d / "cfg", IDEAL, "paper.yaml")
    rc, msg, _ = cli(d / "cfg", "simulate", str(s), "--strides", "10000000", "--runs-dir", "runs")
    return rc, msg, ""


@case
def d9_binary_scene(d):
    (d / "b.yaml").write_bytes(bytes(range(256)) * 4)
    rc, msg, _ = cli(d, "fixedpoint", str(d / "b.yaml"), "--runs-dir", "runs")
    return rc, msg, ""


@case
def d9_directory_scene(d):
    (d / "dir.yaml").mkdir()
    rc, msg, _ = cli(d, "fixedpoint", str(d / "dir.yaml"), "--runs-dir", "runs")
    return rc, msg, ""


@case
def d9_nan_initial_state(d):
    s = scene(d / "cfg", with_(IDEAL, simulate={"strides": 2, "initial_state": {
        "swing_angle_rad": float("nan"), "stance_angle_rad": 0.1674,
        "swing_rate_rad_per_s": -0.6, "stance_rate_rad_per_s": -0.84}}), "paper.yaml")
    rc, msg, _ = cli(d / "cfg", "simulate", str(s), "--runs-dir", "runs")
    return rc, msg, ""


@case
def d10_bool_as_mass(d):
    s = scene(d / "cfg", with_(IDEAL, walker__leg_mass_kg=True), "paper.yaml")
    rc, msg, _ = cli(d / "cfg", "fixedpoint", str(s), "--runs-dir", "runs")
    return rc, msg, ""


@case
def d10_string_as_number(d):
    s = scene(d / "cfg", with_(IDEAL, walker__leg_mass_kg="5"), "paper.yaml")
    rc, msg, _ = cli(d / "cfg", "fixedpoint", str(s), "--runs-dir", "runs")
    return rc, msg, ""


@case
def d10_nan_initial_guess(d):
    s = scene(d / "cfg", with_(IDEAL, fixedpoint__initial_guess__swing_rate_rad_per_s=float("nan")),
              "paper.yaml")
    rc, msg, _ = cli(d / "cfg", "fixedpoint", str(s), "--runs-dir", "runs")
    return rc, msg, ""


@case
def d10_inf_patch_width(d):
    s = _contact(d, terrain__patch_width_m=float("inf"))
    rc, msg, _ = cli(d / "cfg", "contact-sim", str(s), "--runs-dir", "runs", timeout=400)
    return rc, msg, ""


@case
def d11_contact_fall_exit_code(d):
    s = _contact(d, contact_sim__initial_rate_scale=[1.0, 0.5])
    rc, msg, _ = cli(d / "cfg", "contact-sim", str(s), "--runs-dir", "runs", timeout=400)
    return rc, msg, ""


@case
def d11_simulate_fall_exit_code(d):
    s = scene(d / "cfg", with_(IDEAL, simulate={"strides": 2, "initial_state": {
        "swing_angle_rad": -0.2022, "stance_angle_rad": 0.1674,
        "swing_rate_rad_per_s": -0.6, "stance_rate_rad_per_s": -0.3}}), "paper.yaml")
    rc, msg, _ = cli(d / "cfg", "simulate", str(s), "--runs-dir", "runs")
    return rc, msg, ""


@case
def d12_sweep_rows_saved_early(d):
    s = scene(d / "cfg", IDEAL, "paper.yaml")
    main = subprocess.Popen([PY, "-m", "walkerlab.cli", "sweep", str(s), "--param",
                             "slope.angle_deg=1:4:0.01", "--workers", "2", "--runs-dir", "runs",
                             "--name", "prog"], cwd=d / "cfg", stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL, start_new_session=True)
    _wait_workers(main.pid)
    time.sleep(15)
    os.killpg(main.pid, signal.SIGINT)
    main.wait(timeout=300)
    import h5py

    p = d / "cfg/runs/paper/prog.h5.partial"
    rows = "no partial file"
    if p.is_file():
        with h5py.File(p) as f:
            rows = f["points/index"].shape[0]
    return main.returncode, "", (f"SIGINT 15 s after the workers started (301 points): "
                                 f"{rows} rows saved")


@case
def perms(d):
    s = scene(d / "cfg", IDEAL, "paper.yaml")
    cli(d / "cfg", "fixedpoint", str(s), "--runs-dir", "runs")
    cli(d / "cfg", "sweep", str(s), "--param", "slope.angle_deg=1", "--workers", "1",
        "--runs-dir", "runs", "--name", "sw")
    modes = {p.name: oct(stat.S_IMODE(p.stat().st_mode)) for p in (d / "cfg/runs/paper").iterdir()}
    return 0, "", str(modes)


@case
def version(d):
    rc, msg, _ = cli(d, "--version")
    return rc, msg, ""


# ------------------------------------------------------------------ issue 19
def _uc(d: Path) -> dict:
    return {"WALKERLAB_CACHE_DIR": str(d / "uc")}


def _cmdline(pid: int) -> str:
    try:
        return Path(f"/proc/{pid}/cmdline").read_bytes().replace(b"\0", b" ").decode()
    except OSError:
        return ""


def _kill_tree(pid: int) -> None:
    for k in [pid, *_children(pid)]:
        try:
            os.kill(k, signal.SIGKILL)
        except OSError:
            pass


def _orphans_after(main: subprocess.Popen, sig: int, wait_s: float = 5.0) -> tuple[list, list]:
    kids = _children(main.pid)
    main.send_signal(sig)
    main.wait()
    time.sleep(wait_s)
    alive = [k for k in kids if _alive(k)]
    return kids, alive


def _rerun_waits(cwd: Path, args: list[str], env: dict, seconds: float = 8.0) -> str:
    """Start the same command again; after ``seconds``: does it wait on the dead lock?"""
    p = subprocess.Popen([PY, "-m", "walkerlab.cli", *args], cwd=cwd, text=True,
                         stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                         env={**os.environ, **env})
    time.sleep(seconds)
    _kill_tree(p.pid)
    p.wait()
    err = p.stderr.read()
    p.stderr.close()
    return "rerun WAITS on the dead pid" if "waiting" in err else "rerun proceeds"


def _stability_kill(d: Path, sig: int):
    s = scene(d / "cfg", PAPER, "paper.yaml")
    args = ["stability-map", str(s), "--kind", "friction", "--n", "4", "--time-limit", "20",
            "--runs-dir", "runs"]
    main = subprocess.Popen([PY, "-m", "walkerlab.cli", *args], cwd=d / "cfg",
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                            env={**os.environ, **_uc(d)})
    time.sleep(12)
    kids, alive = _orphans_after(main, sig)
    rerun = _rerun_waits(d / "cfg", args, _uc(d))
    for k in alive:
        os.kill(k, signal.SIGKILL)
    return (main.returncode, "", f"{len(kids)} descendants, {len(alive)} alive 5 s after "
            f"{signal.Signals(sig).name}; {rerun}")


@case
def i19_1_stability_map_sigkill(d):
    return _stability_kill(d, signal.SIGKILL)


@case
def i19_1_stability_map_sigterm(d):
    return _stability_kill(d, signal.SIGTERM)


@case
def i19_1_report_workprecision_sigterm(d):
    s = scene(d / "cfg", PAPER, "paper.yaml")
    main = subprocess.Popen([PY, "-m", "walkerlab.cli", "report", str(s), "--runs-dir", "runs"],
                            cwd=d / "cfg", stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                            env={**os.environ, **_uc(d)})
    t0 = time.time()
    spawned: list = []
    while time.time() - t0 < 600 and main.poll() is None:  # until measuring workers run
        spawned = [k for k in _children(main.pid) if "spawn_main" in _cmdline(k)]
        if len(spawned) >= 1 and (d / "cfg/runs/paper/.cache/workprecision").is_dir():
            break
        time.sleep(0.5)
    time.sleep(3)
    kids, alive = _orphans_after(main, signal.SIGTERM)
    names = sorted({("tracker" if "resource_tracker" in _cmdline(k) else "worker")
                    for k in alive})
    for k in alive:
        os.kill(k, signal.SIGKILL)
    return (main.returncode, "", f"after {time.time() - t0:.0f} s: {len(kids)} descendants "
            f"({len(spawned)} spawn workers), {len(alive)} alive 5 s after SIGTERM {names}")


@case
def i19_2_tampered_model_cache(d):
    """Prepend a statement to every generated model file walkerlab left (runs/.cache/models
    before, the user cache after), recompute its sha256 header, make it group-writable (as
    in a shared folder) and rerun: does the statement run?"""
    import hashlib

    s = scene(d / "cfg", IDEAL, "paper.yaml")
    cli(d / "cfg", "fixedpoint", str(s), "--runs-dir", "runs", env=_uc(d))
    flag = d / "PWNED"
    files = [p for p in d.rglob("*.py") if "__pycache__" not in p.parts]
    for p in files:
        body = f"open({str(flag)!r}, 'w').write('x')\n" + p.read_text().split("\n", 1)[1]
        p.write_text(f"# sha256 {hashlib.sha256(body.encode()).hexdigest()}\n{body}")
        os.chmod(p, 0o664)
    rc, msg, _ = cli(d / "cfg", "fixedpoint", str(s), "--runs-dir", "runs", "--force",
                     env=_uc(d))
    where = sorted({str(p.parent.relative_to(d)) for p in files})
    return rc, msg, f"model files in {where}; planted statement ran: {flag.exists()}"


@case
def i19_2_runs_folder_holds_no_code(d):
    s = scene(d / "cfg", IDEAL, "paper.yaml")
    rc, msg, _ = cli(d / "cfg", "fixedpoint", str(s), "--runs-dir", "runs", env=_uc(d))
    code = [str(p.relative_to(d / "cfg/runs")) for p in (d / "cfg/runs").rglob("*.py")]
    modes = {str(p.relative_to(d)): oct(stat.S_IMODE(p.stat().st_mode))
             for p in (d / "uc").rglob("*")} if (d / "uc").is_dir() else {}
    return rc, msg, f"code under runs/: {code or 'none'}; user cache: {modes}"


@case
def i19_14_numba_cache_location(d):
    pkg = ROOT / "walkerlab" / "contact" / "__pycache__"
    before = {p: p.stat().st_mtime_ns for p in pkg.glob("*.nb*")} if pkg.is_dir() else {}
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    env.update(_uc(d))
    p = subprocess.run([PY, "-c", "from walkerlab.models.contact import _kernels as K; "
                        "K.friction_mu(0.1, 0.9, 0.7, 0.01, 0.02)"], env=env,
                       capture_output=True, text=True)
    after = {q: q.stat().st_mtime_ns for q in pkg.glob("*.nb*")} if pkg.is_dir() else {}
    touched = [q.name for q in after if before.get(q) != after[q]]
    ucn = list((d / "uc").rglob("*.nbi")) if (d / "uc").is_dir() else []
    return (p.returncode, (p.stderr.strip().splitlines() or [""])[-1][:100],
            f"package __pycache__ index files written: {len(touched)} "
            f"(present: {sum(1 for q in after if q.suffix == '.nbi')}); user cache: {len(ucn)}")


@case
def i19_3_lock_symlink(d):
    s = scene(d / "cfg", IDEAL, "paper.yaml")
    cli(d / "cfg", "fixedpoint", str(s), "--runs-dir", "runs", env=_uc(d))
    victim = d / "victim.txt"
    victim.write_text("precious\n")
    lock = d / "cfg/runs/paper/.fixedpoint.h5.lock"
    lock.unlink(missing_ok=True)
    lock.symlink_to(victim)
    rc, msg, _ = cli(d / "cfg", "fixedpoint", str(s), "--runs-dir", "runs", "--force",
                     env=_uc(d))
    return rc, msg, f"victim.txt now {victim.read_text()!r}"


@case
def i19_3_basin_partial_symlink(d):
    s = scene(d / "cfg", IDEAL, "paper.yaml")
    (d / "cfg/runs/paper").mkdir(parents=True)
    victim = d / "victim.txt"
    victim.write_text("precious\n")
    (d / "cfg/runs/paper/basin.h5.partial").symlink_to(victim)
    rc, msg, _ = cli(d / "cfg", "basin", str(s), "--grid", "2x2", "--workers", "1",
                     "--runs-dir", "runs", env=_uc(d))
    head = victim.read_bytes()[:8]
    return rc, msg, f"victim.txt starts {head!r}"


@case
def i19_3_report_dir_symlink(d):
    s = scene(d / "cfg", IDEAL, "paper.yaml")
    outside = d / "outside"
    outside.mkdir()
    (d / "cfg/runs/paper").mkdir(parents=True)
    (d / "cfg/runs/paper/report").symlink_to(outside)
    cli(d / "cfg", "simulate", str(s), "--strides", "2", "--runs-dir", "runs", env=_uc(d))
    rc, msg, _ = cli(d / "cfg", "plot", str(s), "--runs-dir", "runs", env=_uc(d))
    return rc, msg, f"files written outside runs/: {len(list(outside.rglob('*.*')))}"


def _limited_cli(cwd: Path, limit: int, *args: str, env=None):
    import resource

    def pre():
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))
    p = subprocess.run([PY, "-m", "walkerlab.cli", *args], cwd=cwd, capture_output=True,
                       text=True, env={**os.environ, **(env or {})}, preexec_fn=pre)
    return p.returncode, p.stderr.strip().splitlines()


@case
def i19_7_disk_full_ulimit(d):
    s = scene(d / "cfg", IDEAL, "paper.yaml")
    cli(d / "cfg", "simulate", str(s), "--strides", "1", "--runs-dir", "runs", env=_uc(d))
    art = d / "cfg/runs/paper/simulate.h5"
    old = art.read_bytes()
    rc, err = _limited_cli(d / "cfg", 300 * 1024, "simulate", str(s), "--strides", "200",
                           "--runs-dir", "runs", env=_uc(d))
    stray = [p.name for p in (d / "cfg/runs").rglob("*") if p.name.endswith(".tmp")]
    return (rc, (err[0] if err else "")[:160],
            f"{len(err)} stderr lines; old artifact kept: {art.read_bytes() == old}; "
            f"stray: {stray or 'none'}")


@case
def i19_7_disk_full_tmpfs(d):
    mnt = d / "tmpfs"
    mnt.mkdir()
    if subprocess.run(["mount", "-t", "tmpfs", "-o", "size=600k", "tmpfs", str(mnt)],
                      capture_output=True).returncode != 0:
        return "-", "cannot mount a tmpfs here (needs root)", ""
    try:
        s = scene(d / "cfg", IDEAL, "paper.yaml")
        runs = mnt / "runs"
        cli(d / "cfg", "simulate", str(s), "--strides", "1", "--runs-dir", str(runs),
            env=_uc(d))
        art = runs / "paper/simulate.h5"
        if not art.is_file():
            return "-", "the 1-stride artifact does not fit the tmpfs (setup)", ""
        old = art.read_bytes()
        p = subprocess.run([PY, "-m", "walkerlab.cli", "simulate", str(s), "--strides", "400",
                            "--runs-dir", str(runs)], cwd=d / "cfg", capture_output=True,
                           text=True, env={**os.environ, **_uc(d)})
        err = p.stderr.strip().splitlines()
        stray = [q.name for q in runs.rglob("*") if q.name.endswith(".tmp")]
        kept = art.is_file() and art.read_bytes() == old
        line = next((ln for ln in err if ln.startswith("error")), err[0] if err else "")
        return (p.returncode, line[:160],
                f"{len(err)} stderr lines; old artifact kept: {kept}; stray: {stray or 'none'}")
    finally:
        subprocess.run(["umount", str(mnt)], capture_output=True)


@case
def i19_7_cache_write_full_disk(d):
    import resource

    def pre():
        resource.setrlimit(resource.RLIMIT_FSIZE, (2048, 2048))
    code = ("from walkerlab.codegen import cache\n"
            "from walkerlab.walker.description import BodySpec, Structure\n"
            "cache.generated_module(Structure('absolute', (BodySpec('mass', 'point_mass'),)))\n")
    for _ in range(2):
        p = subprocess.run([PY, "-c", code], cwd=d, capture_output=True, text=True,
                           env={**os.environ, **_uc(d)}, preexec_fn=pre)
    stray = [q.name for q in d.rglob("*") if q.is_file()]
    err = p.stderr.strip().splitlines()
    return p.returncode, (err[-1] if err else "")[:160], f"files left: {stray or 'none'}"


@case
def i19_10_damaged_workprecision_cache(d):
    data = {**IDEAL, "workprecision": {"methods": ["RK45"], "rtols": [1e-3, 1e-4],
                                       "repeats": 1, "strides": 1, "models": ["ideal"]}}
    s = scene(d / "cfg", data, "wp.yaml")
    cli(d / "cfg", "workprecision", str(s), "--runs-dir", "runs", env=_uc(d))
    cache = sorted((d / "cfg/runs/wp/.cache/workprecision").glob("*.json"))
    cache[0].write_text("{}")
    (d / "cfg/runs/wp/workprecision.h5").unlink()  # the report needs the artifact again
    rc, msg, _ = cli(d / "cfg", "workprecision", str(s), "--runs-dir", "runs", env=_uc(d))
    return rc, msg, f"damaged entry now {cache[0].read_text()[:30]!r}"


@case
def i19_14_debug_false(d):
    rc, msg, _ = cli(d, "fixedpoint", "missing.yaml", env={"WALKERLAB_DEBUG": "false"})
    return rc, msg, ""


@case
def i19_14_runs_dir_empty(d):
    s = scene(d / "cfg", IDEAL, "paper.yaml")
    rc, msg, _ = cli(d / "cfg", "fixedpoint", str(s), "--runs-dir", "", env=_uc(d))
    return rc, msg, f"written into the current folder: {(d / 'cfg' / 'paper').exists()}"


@case
def i19_14_report_md_script(d):
    s = scene(d / "cfg", {**IDEAL, "source": "Smith <script>alert(1)</script>"}, "paper.yaml")
    rc, msg, _ = cli(d / "cfg", "report", str(s), "--runs-dir", "runs", env=_uc(d),
                     timeout=600)
    md = (d / "cfg/runs/paper/report/report.md")
    if not md.is_file():
        return rc, msg, "no report"
    # code fences show HTML as text: only what lies outside them counts
    prose = "".join(md.read_text().split("```")[::2])
    return rc, msg, f"report.md holds a raw <script> outside code blocks: {'<script>' in prose}"


@case
def i19_14_dev_zero(d):
    rc, msg, _ = cli(d, "fixedpoint", "/dev/zero", env=_uc(d))
    return rc, msg, ""


@case
def i19_14_bench_out_file(d):
    (d / "FILE").write_text("keep")
    rc, msg, _ = cli(d, "bench", "ideal", "--out", "FILE", env=_uc(d))
    return rc, msg, f"FILE kept: {(d / 'FILE').read_text() == 'keep'}"


# ------------------------------------------------------------------ issue 19 (rel-b)


def _wait_rows(p: Path, n: int, proc, timeout: float = 300) -> None:
    import h5py

    t0 = time.time()
    while time.time() - t0 < timeout and proc.poll() is None:
        try:
            with h5py.File(p, "r", locking=False) as f:
                if f["points/index"].shape[0] >= n:
                    return
        except (OSError, KeyError):
            pass
        time.sleep(0.5)


def _sweep_rows(p: Path) -> dict:
    import h5py

    with h5py.File(p, "r") as f:
        return {k: v[()] for k, v in f["points"].items()
                if isinstance(v, h5py.Dataset) and k != "wall_time_s"}


@case
def i19_4_edited_basin_partial(d):
    import h5py
    import numpy as np

    s = scene(d / "cfg", {**IDEAL, "basin": {"grid": [12, 12]}}, "paper.yaml")
    cli(d / "cfg", "fixedpoint", str(s), "--runs-dir", "runs")
    p = subprocess.Popen([PY, "-m", "walkerlab.cli", "basin", str(s), "--workers", "1",
                          "--runs-dir", "runs"], cwd=d / "cfg", stdout=subprocess.DEVNULL,
                         stderr=subprocess.DEVNULL)
    part = d / "cfg/runs/paper/basin.h5.partial"
    t0 = time.time()
    while time.time() - t0 < 120:
        try:
            with h5py.File(part, "r", locking=False) as f:
                if np.sum(f["outcome"][()] >= 0) >= 24:
                    break
        except (OSError, KeyError):
            pass
        time.sleep(0.3)
    p.send_signal(signal.SIGTERM)
    p.wait(timeout=60)
    with h5py.File(part, "a") as f:
        o = f["outcome"][()]
        edited = int(np.sum(o > 0))
        o[o > 0] = 0  # every done cell "converged"
        f["outcome"][...] = o
    rc, msg, _ = cli(d / "cfg", "basin", str(s), "--workers", "1", "--runs-dir", "runs")
    with h5py.File(d / "cfg/runs/paper/basin.h5", "r") as f:
        conv = int(f["counts/converged"][()])
    ref = d / "ref"
    scene(ref, {**IDEAL, "basin": {"grid": [12, 12]}}, "paper.yaml")
    cli(ref, "basin", str(ref / "paper.yaml"), "--workers", "1", "--runs-dir", "runs")
    with h5py.File(ref / "runs/paper/basin.h5", "r") as f:
        conv_ref = int(f["counts/converged"][()])
    return rc, msg, (f"{edited} done cells edited to 'converged'; converged after resume "
                     f"{conv}, uninterrupted {conv_ref}")


def _interrupted_sweep(d, edit=None):
    s = scene(d / "cfg", IDEAL, "paper.yaml")
    args = ["sweep", str(s), "--param", "slope.angle_deg=1:5:0.01", "--param",
            "walker.hip_mass_kg=8,10,12", "--workers", "2", "--runs-dir", "runs",
            "--name", "sw"]
    p = subprocess.Popen([PY, "-m", "walkerlab.cli", *args], cwd=d / "cfg",
                         stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                         start_new_session=True)
    part = d / "cfg/runs/paper/sw.h5.partial"
    _wait_rows(part, 150, p)
    os.killpg(p.pid, signal.SIGTERM)
    p.wait(timeout=60)
    if edit is not None:
        edit(part)
    rc, msg, _ = cli(d / "cfg", *args, "--resume", timeout=600)
    shutil.copytree(d / "cfg", d / "ref", ignore=shutil.ignore_patterns("runs"))
    cli(d / "ref", *args, timeout=600)
    return rc, msg, _sweep_rows(d / "cfg/runs/paper/sw.h5"), \
        _sweep_rows(d / "ref/runs/paper/sw.h5")


@case
def i19_4_edited_sweep_partial(d):
    import h5py
    import numpy as np

    def edit(part):
        with h5py.File(part, "a") as f:
            f["points/step_period_s"][...] = 999.0

    rc, msg, got, ref = _interrupted_sweep(d, edit)
    return rc, msg, (f"rows with step_period_s = 999 after resume: "
                     f"{int(np.sum(got['step_period_s'] == 999))}; rows differing from an "
                     f"uninterrupted run: {_n_diff(got, ref)}")


def _n_diff(got, ref) -> str:
    import numpy as np

    n = got["index"].size
    diff = np.zeros(n, bool)
    worst = 0.0
    for k, v in ref.items():
        if k == "row_hash" or k not in got:
            continue
        a, b = got[k], v
        if a.dtype.kind in "fc":
            same = (a == b) | (np.isnan(a) & np.isnan(b))
            if (~same).any():
                worst = max(worst, float(np.nanmax(np.abs(a - b)[~same])))
        else:
            same = a == b
        diff |= ~same
    return f"{int(diff.sum())} of {n} (largest difference {worst:.2g})"


@case
def i19_13_sigterm_resume_identical(d):
    rc, msg, got, ref = _interrupted_sweep(d)
    return rc, msg, f"rows differing from an uninterrupted run: {_n_diff(got, ref)}"


def _bad_scene_text(d, text: str, name="s.yaml"):
    p = d / name
    p.write_text(text)
    return cli(d, "fixedpoint", str(p), "--runs-dir", "runs")[:2]


@case
def i19_5_basin_grid_5000(d):
    s = scene(d, IDEAL, "paper.yaml")
    rc, msg, _ = cli(d, "basin", str(s), "--grid", "5000x5000", "--runs-dir", "runs", timeout=30)
    return rc, msg, ""


@case
def i19_5_basin_grid_100000(d):
    s = scene(d, IDEAL, "paper.yaml")
    rc, msg, _ = cli(d, "basin", str(s), "--grid", "100000x100000", "--runs-dir", "runs",
                     timeout=60)
    return rc, msg, ""


@case
def i19_5_simulate_samples(d):
    s = scene(d, with_(IDEAL, simulate={"strides": 1000, "sample_rate_hz": 1e6}), "paper.yaml")
    rc, msg, _ = cli(d, "simulate", str(s), "--runs-dir", "runs", timeout=300)
    return rc, msg, ""


@case
def i19_5_max_step_tiny(d):
    s = scene(d, with_(IDEAL, solver__max_step_s=1e-12), "paper.yaml")
    rc, msg, _ = cli(d, "fixedpoint", str(s), "--runs-dir", "runs", timeout=60)
    return rc, msg, ""


@case
def i19_5_stability_map_n(d):
    rc, msg, _ = cli(d, "stability-map", str(ROOT / "configs/paper.yaml"), "--n", "100000",
                     "--runs-dir", "runs", timeout=60)
    return rc, msg, ""


@case
def i19_5_stability_map_workers(d):
    rc, msg, _ = cli(d, "stability-map", str(ROOT / "configs/paper.yaml"), "--workers", "300",
                     "--kind", "friction", "--n", "2", "--runs-dir", "runs", timeout=60)
    return rc, msg, ""


@case
def i19_5_scene_marker_dev_zero(d):
    s = scene(d, IDEAL, "paper.yaml")
    (d / "runs/paper").mkdir(parents=True)
    os.symlink("/dev/zero", d / "runs/paper/.scene")
    rc, msg, _ = cli(d, "fixedpoint", str(s), "--runs-dir", "runs", timeout=60)
    return rc, msg, ""


@case
def i19_5_scene_marker_fifo(d):
    s = scene(d, IDEAL, "paper.yaml")
    (d / "runs/paper").mkdir(parents=True)
    os.mkfifo(d / "runs/paper/.scene")
    rc, msg, _ = cli(d, "fixedpoint", str(s), "--runs-dir", "runs", timeout=30)
    return rc, msg, ""


@case
def i19_5_source_50mb(d):
    s = scene(d, {**IDEAL, "source": "x" * 50_000_000}, "paper.yaml")
    rc, msg, _ = cli(d, "fixedpoint", str(s), "--runs-dir", "runs", timeout=120)
    h5 = d / "runs/paper/fixedpoint.h5"
    return rc, msg, f"fixedpoint.h5: {h5.stat().st_size if h5.exists() else 0:,} bytes"


@case
def i19_11_force_keeps_downstream(d):
    s = scene(d, IDEAL, "paper.yaml")
    cli(d, "simulate", str(s), "--runs-dir", "runs")
    cli(d, "fixedpoint", str(s), "--runs-dir", "runs", "--force")
    rc, msg, _ = cli(d, "simulate", str(s), "--runs-dir", "runs")
    return rc, msg, "after fixedpoint --force"


@case
def i19_12_deep_nesting(d):
    return (*_bad_scene_text(d, "a: " + "[" * 20000 + "]" * 20000 + "\n"), "")


@case
def i19_12_5000_digit_int(d):
    return (*_bad_scene_text(d, yaml.safe_dump(IDEAL) + "foo: " + "9" * 5000 + "\n"), "")


@case
def i19_12_duplicate_key(d):
    return (*_bad_scene_text(d, yaml.safe_dump(IDEAL) + "slope:\n  angle_deg: 3.0\n"), "")


@case
def i19_6_contact_flies_away(d):
    s = scene(d, with_(PAPER, contact_sim__initial_rate_scale=[1000.0, 1000.0]), "paper.yaml")
    rc, msg, t = cli(d, "contact-sim", str(s), "--runs-dir", "runs", env=_uc(d), timeout=300)
    return rc, msg, f"{t:.1f} s"


@case
def i19_6_contact_rate_1e10(d):
    s = scene(d, with_(PAPER, contact_sim__initial_rate_scale=[1e10, 1.0]), "paper.yaml")
    rc, msg, t = cli(d, "contact-sim", str(s), "--runs-dir", "runs", env=_uc(d), timeout=300)
    return rc, msg, f"{t:.1f} s"


@case
def i19_6_rigid_never_moves(d):
    sc = with_(IDEAL, slope__angle_rad=0.0)
    sc["simulate"] = {"strides": 5, "sample_rate_hz": 500, "initial_state": {
        "swing_angle_rad": 0.0, "stance_angle_rad": 0.0, "swing_rate_rad_per_s": 0.0,
        "stance_rate_rad_per_s": 0.0}}
    s = scene(d, sc, "paper.yaml")
    rc, msg, t = cli(d, "simulate", str(s), "--runs-dir", "runs", env=_uc(d))
    return rc, msg, f"{t:.1f} s"


def _sweep_unknown(d, param):
    s = scene(d, IDEAL, "paper.yaml")
    rc, msg, _ = cli(d, "sweep", str(s), "--param", param, "--workers", "1",
                     "--runs-dir", "runs", env=_uc(d))
    return rc, msg, f"files: {ls(d / 'runs') if (d / 'runs').exists() else '-'}"


@case
def i19_8_sweep_misspelt_field(d):
    return _sweep_unknown(d, "slope.angel_deg=1:3:0.5")


@case
def i19_8_sweep_unknown_section(d):
    return _sweep_unknown(d, "foo.bar=1")


@case
def i19_8_sweep_bad_method(d):
    return _sweep_unknown(d, "solver.method=Euler")


@case
def i19_9_contact_time_limit_20s(d):
    s = scene(d, with_(PAPER, contact_sim__initial_rate_scale=[1e6, 1e6],
                       contact_sim__wall_time_limit_s=20.0), "paper.yaml")
    rc, msg, t = cli(d, "contact-sim", str(s), "--runs-dir", "runs", env=_uc(d), timeout=600)
    return rc, msg, f"command {t:.1f} s (limit 20 s on the integration)"


def main():
    work = Path(sys.argv[1])
    names = sys.argv[2:] or list(CASES)
    os.umask(0o022)
    print("| case | exit | stderr (first line) | on disk |\n|---|---|---|---|")
    for n in names:
        d = work / n
        shutil.rmtree(d, ignore_errors=True)
        d.mkdir(parents=True)
        try:
            rc, msg, disk = CASES[n](d)
        except Exception as exc:  # noqa: BLE001 - a measurement, report and go on
            rc, msg, disk = "?", f"harness error: {exc!r}"[:160], ""
        msg = str(msg).replace("|", "/")
        print(f"| {n} | {rc} | {msg} | {disk} |", flush=True)


if __name__ == "__main__":
    main()
