"""What a rigid walker's actuators ask of its legs' masses
(:func:`walkerlab.models.hybrid.actuated.actuate`): Kuo's (2002) limit of massless legs on
a point hip mass, where a torque is given per foot mass and acts at the hip alone and the
push-off is a point foot's (:func:`massless_limit`), and, for legs with some massless
bodies, a push-off's extended impact that needs every link to carry mass
(:func:`check_impact_masses`).
"""

from __future__ import annotations

import numpy as np

__all__ = ["check_impact_masses", "massless_limit"]


def massless_limit(data, spec) -> bool:
    """Whether the walker's legs are massless on a point hip mass (Kuo's limit), refusing
    what is physically impossible there (one line).  A joint the walker does not have is
    refused by :func:`walkerlab.models.hybrid.actuators.joint_links` (naming the joints it
    has), an ankle push-off by the kind (:func:`walkerlab.models.hybrid.actuated.actuate`).

    Parameters
    ----------
    data : walkerlab.walker.description.WalkerData
    spec : walkerlab.config.actuation.Actuation

    Returns
    -------
    bool
        True for massless legs on a hip mass without a torso.

    Raises
    ------
    ValueError
        Massless legs without a hip mass, a push-off on massless arc-footed legs, a torque
        scaling that does not fit the legs, a torque per foot mass away from the hip.
    """
    st = data.structure
    massless = [b.massless for b in st.bodies]
    # Kuo's limit: massless legs on a point hip mass.  Legs with some massless bodies, or
    # massless legs under a torso (which the legs' angles move): the force in the massless
    # limit's rows (Actuators.link_rows, which refuses a torque across a link whose
    # bodies are all massless)
    limit = bool(massless) and all(massless) and not st.torso
    if limit and not st.hip_mass:
        raise ValueError("walker.actuation: massless legs without a hip mass or a torso "
                         "have no mass at all (no equations of motion to drive): give "
                         "walker.hip_mass_kg > 0")
    if limit and st.foot != "point" and spec.push_off is not None:
        raise ValueError("walker.actuation.push_off: on massless legs the push-off's limit "
                         "m -> 0 is Kuo's point foot; an arc's depends on where its mass "
                         "sits: give the legs mass")
    for i, t in enumerate(spec.torques):
        if limit and t.scaled_by != "foot_mass":
            raise ValueError(f"walker.actuation.torques.{i}.scaled_by: the legs are massless "
                             "(a torque on them needs infinite acceleration): give the torque "
                             "per foot mass, scaled_by: foot_mass (Kuo 2002)")
        if limit and t.joint != "hip":
            raise ValueError(f"walker.actuation.torques.{i}.joint: the legs are massless: a "
                             "torque per foot mass acts at the hip only (joint: hip)")
        if not limit and t.scaled_by != "none":
            raise ValueError(f"walker.actuation.torques.{i}.scaled_by: foot_mass is for "
                             "massless legs on a hip mass (Kuo 2002; no torso), where the "
                             "legs' rows are divided by the vanishing mass")
    return limit


def check_impact_masses(acts) -> None:
    """Legs with some massless bodies and a push-off: the extended impact needs every
    link to carry mass (``De`` regular).  A leg link that moves no mass (its bodies
    massless or at the hip; massless legs under a torso) takes any velocity at no cost:
    the impulses leave it undetermined, and only a limiting rule fixes it (Kuo 2002's
    point hip: the trailing foot keeps no velocity across its leg).

    Raises
    ------
    ValueError
        A leg link that moves no mass (one line, naming ``walker.actuation.push_off``).
    """
    q = np.linspace(0.1, 0.3, acts.n)
    w = np.linalg.eigvalsh(np.real(np.asarray(acts.fns["impact_matrices"](q)[0], float)))
    if w[0] <= 1e-10 * w[-1]:
        raise ValueError("walker.actuation.push_off: a leg link moves no mass (its bodies "
                         "are massless or at the hip), so the impulses leave its velocity "
                         "undetermined; give the leg mass, or describe the walker as "
                         "massless legs on a hip mass without a torso (Kuo's point-hip "
                         "push-off)")
