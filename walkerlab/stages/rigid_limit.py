"""Stage ``rigid-limit``: the contact walker's periodic gait along the one rigid-limit family
-> ``rigid_limit.h5`` (``walkerlab compare --rigid-limit``).

For each stiffness factor ``kappa`` (default :data:`KAPPAS`) the scene's contact is scaled by
:mod:`walkerlab.contact.rigid_limit` and the contact walker's own periodic gait is found
(:func:`walkerlab.analysis.rigid_limit.convergence`); the artifact holds its step period, step
length and slow Floquet multipliers against ``kappa``, the rigid gait's as scalars, and the
observed orders of convergence.  Any walker with a ``contact`` and a ``fixedpoint`` section.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from walkerlab.config import Scene
from walkerlab.io.artifacts import put
from walkerlab.io.netcdf import coordinate
from walkerlab.stages.common import StageOutcome, require, run_cached

SECTIONS = ("walker", "slope", "ideal", "solver", "fixedpoint", "contact", "terrain")
#: Default stiffness factors [-]: the scene's contact and three decades stiffer.
KAPPAS = (1.0, 10.0, 100.0, 1000.0)


def run(scene: Scene, runs_root: Path | str = "runs", force: bool = False,
        kappas=KAPPAS) -> StageOutcome:
    """Compute (or reuse) ``rigid_limit.h5``.

    Raises
    ------
    StageError
        No ``contact`` or ``fixedpoint`` section (one line).
    """
    require(scene, "contact", "rigid-limit")
    require(scene, "fixedpoint", "rigid-limit")
    kappas = tuple(float(k) for k in kappas)

    def compute():
        from walkerlab.analysis.contact_periodic import ideal_gait
        from walkerlab.analysis.rigid_limit import convergence, observed_order
        from walkerlab.contact.rigid_limit import expected_order
        from walkerlab.contact.scene import build

        ideal = ideal_gait(scene)
        walker, _ = build(scene, ideal.x, 2)
        tab = convergence(walker, ideal, kappas)
        orders = {"period": observed_order(tab.kappa, tab.period_gap_s),
                  "step_length": observed_order(tab.kappa, tab.step_gap_m)}
        summary = {"kappa": tab.kappa.tolist(), "period_gap_s": tab.period_gap_s.tolist(),
                   "step_gap_m": tab.step_gap_m.tolist(),
                   "observed_order_period": orders["period"].tolist(),
                   "observed_order_step_length": orders["step_length"].tolist(),
                   "expected_order": expected_order(walker.contact.e)}

        def writer(f):
            f.attrs["family"] = ("walkerlab.contact.rigid_limit: k*kappa, cmax*kappa^(1/(e+1)), "
                                 "dmax and latch height*kappa^(-1/(e+1)), vs, vd*kappa^(-1/2), "
                                 "knee stop along the same family")
            f.attrs["expected_order"] = summary["expected_order"]
            coordinate(f, "kappa", tab.kappa, "-", "stiffness factor on the scene's contact")
            k = ("kappa",)
            put(f, "period", tab.period_s, "s", "step period of the contact periodic gait",
                dims=k)
            put(f, "step_length", tab.step_length_m, "m",
                "step length of the contact periodic gait", dims=k)
            put(f, "converged", tab.converged.astype(np.int8), "-", "1: fixed point found",
                dims=k)
            put(f, "multipliers/real", tab.multipliers.real, "-",
                "slow Floquet multipliers, column j matched to rigid/multipliers j",
                dims=("kappa", "multiplier"))
            put(f, "multipliers/imag", tab.multipliers.imag, "-", "imaginary parts",
                dims=("kappa", "multiplier"))
            put(f, "rigid/period", tab.rigid_period_s, "s", "rigid gait's step period")
            put(f, "rigid/step_length", tab.rigid_step_length_m, "m", "rigid step length")
            put(f, "rigid/multipliers/real", tab.rigid_multipliers.real, "-",
                "rigid gait's nonzero Floquet multipliers", dims=("multiplier",))
            put(f, "rigid/multipliers/imag", tab.rigid_multipliers.imag, "-", "imaginary parts",
                dims=("multiplier",))
            for name, o in orders.items():
                put(f, f"observed_order/{name}", o, "-",
                    "log(gap_i / gap_i+1) / log(kappa_i+1 / kappa_i)", dims=("interval",))
        return writer, summary

    return run_cached("rigid-limit", scene, runs_root, SECTIONS, (), compute, force,
                      extra_key=repr(kappas))


def load(path: Path) -> dict:
    """The artifact as arrays: ``kappa``, ``period``, ``step_length``, ``multipliers``
    (complex (n, r)), ``rigid_period``, ``rigid_step_length``, ``rigid_multipliers`` (r,)."""
    from walkerlab.io.artifacts import open_artifact

    with open_artifact(path, "rigid-limit") as f:
        return {"kappa": f["kappa"][()], "period": f["period"][()],
                "step_length": f["step_length"][()],
                "multipliers": f["multipliers/real"][()] + 1j * f["multipliers/imag"][()],
                "rigid_period": float(f["rigid/period"][()]),
                "rigid_step_length": float(f["rigid/step_length"][()]),
                "rigid_multipliers": (f["rigid/multipliers/real"][()]
                                      + 1j * f["rigid/multipliers/imag"][()])}


def table_lines(path: Path) -> list[str]:
    """The convergence table (kappa, period gap, step gap, each multiplier, observed order)."""
    from walkerlab.analysis.rigid_limit import observed_order

    d = load(path)
    gT = d["period"] - d["rigid_period"]
    gL = d["step_length"] - d["rigid_step_length"]
    oT, oL = observed_order(d["kappa"], gT), observed_order(d["kappa"], gL)
    lam = d["multipliers"]
    head = (f"{'kappa':>8} {'period gap [ms]':>16} {'order':>6} {'step gap [mm]':>14} "
            f"{'order':>6}  multipliers (rigid: "
            + ", ".join(f"{x:.4f}" for x in d["rigid_multipliers"]) + ")")
    out = [head]
    for i, k in enumerate(d["kappa"]):
        o1 = f"{oT[i - 1]:6.3f}" if i else " " * 6
        o2 = f"{oL[i - 1]:6.3f}" if i else " " * 6
        out.append(f"{k:8.3g} {gT[i] * 1e3:+16.4f} {o1} {gL[i] * 1e3:+14.4f} {o2}  "
                   + ", ".join(f"{x:.4f}" for x in lam[i]))
    return out


def draw(scene: Scene, runs_root: Path | str, path: Path) -> list[Path]:
    """Draw ``rigid_limit.png/svg`` into the scene's figures folder from the artifact."""
    from walkerlab.io.runpaths import figures_dir
    from walkerlab.plotting.figures import save
    from walkerlab.plotting.rigid_limit_figure import rigid_limit_figure

    return save(rigid_limit_figure(load(path), scene.name or "walker"),
                figures_dir(scene, runs_root, claim=True), "rigid_limit")
