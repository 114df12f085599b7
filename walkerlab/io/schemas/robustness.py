"""``robustness.h5``: robustness of the gait beyond |lambda|, writer and reader side by side.

Layout (every value a scalar dataset with its unit)::

    max_abs_multiplier/{absolute,relative}            -      |lambda|max in two coordinates
    gsn/<disturbance>                                 1/unit GSN, linearised step-to-step map
    gsn_nonlinear/<disturbance>                       1/unit GSN, small nonlinear impulse
    state_norm/{absolute,relative}/<disturbance>      1/unit state-indicator norm (Jin et al.)
    step_down_m/{lo,hi}, step_up_m/{lo,hi}            m      bisection bracket (lo survives)
    contact_step_{down,up}_m/{lo,hi}                  m      the same, contact model (NaN:
                                                             not asked for)
    push_{forward,backward}_m_per_s/{lo,hi}           m/s    mid-stance push bracket
    sigma_rad                                         rad    per-step slope sigma of the MFPT
    mfpt_steps, mfpt_steps_stderr                     steps  Monte Carlo MFPT (censored MLE)
    montecarlo_walks, montecarlo_falls                -
    push_lateral_{out,in}_m_per_s/{lo,hi}             m/s    sideways push at the section
                                                             (a walker in 3D only)
    push_lateral_kg                                   kg     its impulse per unit hip
                                                             velocity change [N s/(m/s)]

attributes: ``disturbances`` (names), ``units`` (unit of each disturbance), ``state_names``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from walkerlab.io.artifacts import artifact_loader
from walkerlab.io.schemas.mfpt import VARIABLES as MFPT_VARIABLES

STAGE = "robustness"
COORDINATES = ("absolute", "relative")


def per_unit(unit: str) -> str:
    """Unit of a sensitivity per unit disturbance (``m/s`` -> ``s/m``)."""
    return "s/m" if unit == "m/s" else f"1/{unit}"


def _bracket(name: str, unit: str, lo: str, hi: str) -> dict[str, tuple[str, str]]:
    """The ``{name}/lo`` and ``{name}/hi`` rows of a bisection bracket (lo survives, hi
    falls), both in ``unit``, described by ``lo`` and ``hi``."""
    return {f"{name}/lo": (unit, lo), f"{name}/hi": (unit, hi)}


#: scalar dataset -> (unit, description), in the artifact's order
SCALARS = {
    **_bracket("step_down_m", "m", "largest step-down survived (bisection bracket, lower end)",
               "smallest step-down that falls (upper end; inf: none up to the search cap)"),
    **_bracket("step_up_m", "m", "largest step-up survived (lower end)",
               "smallest step-up that falls (upper end)"),
    **_bracket("push_forward_m_per_s", "m/s", "largest forward mid-stance push survived (hip "
               "velocity change; lower end)", "smallest forward push that falls (upper end)"),
    **_bracket("push_backward_m_per_s", "m/s", "largest backward mid-stance push survived",
               "smallest backward push that falls"),
    "sigma_rad": ("rad", "per-step slope standard deviation of the MFPT"),
    "mfpt_steps": ("steps", "Monte Carlo MFPT: heel strikes before the fall"),
    "mfpt_steps_stderr": ("steps", "standard error of mfpt_steps"),
    # the same Monte Carlo walks as mfpt.h5's: described there
    **{k: MFPT_VARIABLES[k] for k in ("montecarlo_walks", "montecarlo_falls")},
    **_bracket("contact_step_down_m", "m", "contact model: largest step-down survived (lower "
               "end; NaN: robustness.contact not asked for)",
               "contact model: smallest step-down that falls"),
    **_bracket("contact_step_up_m", "m", "contact model: largest step-up survived (lower end)",
               "contact model: smallest step-up that falls"),
}


#: the scalars of a walker with a lateral axis (a walker in 3D), written only when the study
#: computed them (a planar walker's artifact has none of them)
LATERAL_SCALARS = {
    **_bracket("push_lateral_out_m_per_s", "m/s", "largest sideways push at the section "
               "survived, toward the swing leg's side (hip lateral velocity change; lower "
               "end)", "smallest sideways push toward the swing leg's side that falls"),
    **_bracket("push_lateral_in_m_per_s", "m/s", "largest sideways push at the section "
               "survived, toward the stance leg's side (lower end)",
               "smallest sideways push toward the stance leg's side that falls"),
    "push_lateral_kg": ("kg", "impulse of a sideways push at the hip per unit of the hip's "
                        "lateral velocity change, at the gait's section [N s per m/s]"),
}


@dataclass
class RobustnessData:
    """The contents of ``robustness.h5``.

    Attributes
    ----------
    disturbances : list of str
    units : dict[str, str]
        Unit of each disturbance (``rad``, ``m``).
    max_abs_multiplier : dict[str, float]
        By coordinate choice (:data:`COORDINATES`).
    gsn, gsn_nonlinear : dict[str, float]
        By disturbance [1/unit].
    state_norm : dict[str, dict[str, float]]
        By coordinate choice, then disturbance.
    scalars : dict[str, float]
        Every name of :data:`SCALARS`; a walker in 3D also :data:`LATERAL_SCALARS`.
    state_names : list of str
    """

    disturbances: list
    units: dict
    max_abs_multiplier: dict
    gsn: dict
    gsn_nonlinear: dict
    state_norm: dict
    scalars: dict
    state_names: list = field(default_factory=list)

    def __getitem__(self, name: str) -> float:
        return self.scalars[name]


def write(f, d: RobustnessData) -> None:
    """Fill an open artifact (``write_artifact``'s writer) with ``d``."""
    from walkerlab.io.artifacts import put

    for c in COORDINATES:
        put(f, f"max_abs_multiplier/{c}", float(d.max_abs_multiplier[c]), "-",
            f"largest |Floquet multiplier|, {c} leg angles")
    for dist in d.disturbances:
        u = per_unit(d.units[dist])
        put(f, f"gsn/{dist}", float(d.gsn[dist]), u, "gait sensitivity norm (linearised)")
        put(f, f"gsn_nonlinear/{dist}", float(d.gsn_nonlinear[dist]), u,
            "gait sensitivity norm (nonlinear response to a small impulse)")
        for c in COORDINATES:
            put(f, f"state_norm/{c}/{dist}", float(d.state_norm[c][dist]), u,
                f"sensitivity norm with the post-impact state as indicator, {c} angles")
    for name, (unit, desc) in SCALARS.items():
        put(f, name, float(d.scalars[name]), unit, desc)
    for name, (unit, desc) in LATERAL_SCALARS.items():
        if name in d.scalars:
            put(f, name, float(d.scalars[name]), unit, desc)
    f.attrs["disturbances"] = list(d.disturbances)
    f.attrs["disturbance_units"] = [d.units[k] for k in d.disturbances]
    f.attrs["state_names"] = list(d.state_names)


@artifact_loader(STAGE)
def load(f, path: Path) -> RobustnessData:
    """Read ``robustness.h5``."""
    dists = [str(s) for s in f.attrs["disturbances"]]
    units = dict(zip(dists, (str(s) for s in f.attrs["disturbance_units"])))
    return RobustnessData(
        dists, units,
        {c: float(f[f"max_abs_multiplier/{c}"][()]) for c in COORDINATES},
        {k: float(f[f"gsn/{k}"][()]) for k in dists},
        {k: float(f[f"gsn_nonlinear/{k}"][()]) for k in dists},
        {c: {k: float(f[f"state_norm/{c}/{k}"][()]) for k in dists} for c in COORDINATES},
        {**{k: float(f[k][()]) if k in f else float("nan") for k in SCALARS},
         **{k: float(f[k][()]) for k in LATERAL_SCALARS if k in f}},
        [str(s) for s in f.attrs["state_names"]])
