"""``rigid_limit.h5``: the contact walker's periodic gait along the rigid-limit family
(writer and loader side by side).

Layout: root attributes ``family`` (how the contact is scaled with ``kappa``) and
``expected_order``; dimension ``kappa`` (stiffness factor on the scene's contact [-]);
``period`` [s], ``step_length`` [m], ``converged`` on ``kappa``;
``multipliers/{real,imag}`` (kappa, multiplier): the slow Floquet multipliers, column j
matched to the rigid gait's j; ``rigid/period`` [s], ``rigid/step_length`` [m],
``rigid/multipliers/{real,imag}``; ``observed_order/{period,step_length}`` on dimension
``interval``: log(gap_i / gap_i+1) / log(kappa_i+1 / kappa_i).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from walkerlab.io.artifacts import artifact_loader, put
from walkerlab.io.netcdf import coordinate

STAGE = "rigid-limit"
FAMILY = ("walkerlab.models.contact.rigid_limit: k*kappa, cmax*kappa^(1/(e+1)), dmax and latch "
          "height*kappa^(-1/(e+1)), vs, vd*kappa^(-1/2), knee stop along the same family")


@dataclass
class RigidLimitRun:
    """What the rigid-limit stage computed (the writer's input): ``table``
    (:func:`walkerlab.analysis.contact.rigid_limit.convergence`), the observed ``orders``
    ({"period", "step_length"}: ndarray (n - 1,)) and the ``expected_order``."""

    table: object
    orders: dict
    expected_order: float


def write_rigid_limit(f, run: RigidLimitRun) -> None:
    """Fill an open (in-memory) artifact with ``run`` (layout in the module docstring)."""
    tab = run.table
    f.attrs["family"] = FAMILY
    f.attrs["expected_order"] = run.expected_order
    coordinate(f, "kappa", tab.kappa, "-", "stiffness factor on the scene's contact")
    k = ("kappa",)
    put(f, "period", tab.period_s, "s", "step period of the contact periodic gait", dims=k)
    put(f, "step_length", tab.step_length_m, "m", "step length of the contact periodic gait",
        dims=k)
    put(f, "converged", tab.converged.astype(np.int8), "-", "1: fixed point found", dims=k)
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
    for name, o in run.orders.items():
        put(f, f"observed_order/{name}", o, "-",
            "log(gap_i / gap_i+1) / log(kappa_i+1 / kappa_i)", dims=("interval",))


@artifact_loader(STAGE)
def load_rigid_limit(f, path: Path) -> dict:
    """The artifact as arrays: ``kappa`` (n,), ``period`` [s], ``step_length`` [m],
    ``multipliers`` (complex (n, r)), ``rigid_period`` [s], ``rigid_step_length`` [m],
    ``rigid_multipliers`` (r,), ``observed_order`` ({"period", "step_length"}: (n - 1,))."""
    return {"kappa": f["kappa"][()], "period": f["period"][()],
            "step_length": f["step_length"][()],
            "multipliers": f["multipliers/real"][()] + 1j * f["multipliers/imag"][()],
            "rigid_period": float(f["rigid/period"][()]),
            "rigid_step_length": float(f["rigid/step_length"][()]),
            "rigid_multipliers": (f["rigid/multipliers/real"][()]
                                  + 1j * f["rigid/multipliers/imag"][()]),
            "observed_order": {k: f["observed_order"][k][()]
                               for k in f["observed_order"]}}
