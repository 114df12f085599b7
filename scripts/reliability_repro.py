"""Reproduce the defects of issue 12 against a walkerlab checkout, as a user would.

Usage::

    PYTHONPATH=/work/wt/base python scripts/reliability_repro.py /tmp/repro_base [CASE ...]

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
        first = err[0] if err else (p.stdout.strip().splitlines() or [""])[-1]
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
    s = _contact(d, contact__stiffness=float("inf"))
    rc, msg, _ = cli(d / "cfg", "contact-sim", str(s), "--runs-dir", "runs", timeout=400)
    return rc, msg, ""


@case
def d3_contact_inf_rate_scale(d):
    s = _contact(d, contact_sim__initial_rate_scale=[float("inf"), 1.0])
    rc, msg, _ = cli(d / "cfg", "contact-sim", str(s), "--runs-dir", "runs", timeout=400)
    return rc, msg, ""


@case
def d3_contact_inf_damping(d):
    s = _contact(d, contact__max_damping=float("inf"))
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
