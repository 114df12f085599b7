"""What a rigid gait asks of the ground, in words (printed by the CLI and the report): whether
its contact is unilateral (:func:`ground_contact_text`, the stored check of
:class:`~walkerlab.io.schemas.fixedpoint.GroundContactRecord`), the twist a 3D gait's stance
foot carries (:func:`twist_text`), a stair gait's footholds (:func:`footholds_text`) and
the word on each gait found (:func:`ground_word`).
"""

from __future__ import annotations

__all__ = ["TWIST_NONE_N_M", "footholds_text", "ground_contact_problems",
           "ground_contact_text", "ground_word", "twist_text"]


def ground_contact_problems(g, u) -> list[str]:
    """Why a gait's ground contact is not unilateral (``g``: the stored check,
    :class:`~walkerlab.io.schemas.fixedpoint.GroundContactRecord`; ``u``: the units)."""
    v, out = g.values, []
    if v.get("min_normal_force_n", 0.0) < 0:
        out.append(f"the stance foot would lift: its normal force falls to "
                   f"{v['min_normal_force_n']:.4g} {u('N')} at t = "
                   f"{v['min_normal_time_s']:.4g} {u.time} (the ground would have to pull)")
    for key, what in (("heel_strike_normal_impulse_n_s", "heel strike"),
                      ("push_off_normal_impulse_n_s", "push-off")):
        if v.get(key, 0.0) < 0:
            out.append(f"the {what}'s normal impulse is {v[key]:.4g} {u('N s')} (a pull)")
    if v.get("trailing_foot_normal_velocity_m_per_s", 0.0) < 0:
        out.append(f"the trailing foot moves into the ground after the transition "
                   f"({v['trailing_foot_normal_velocity_m_per_s']:.4g} {u.speed})")
    return out


def ground_contact_text(g, u) -> str:
    """One line on whether the gait needs only a ground that pushes (``g``: the stored
    check; ``u``: the units)."""
    if g.ok is None:
        return f"ground contact: not checked ({g.not_checked})"
    if not g.ok:
        return "ground contact: NOT a gait on real ground: " + "; ".join(
            ground_contact_problems(g, u))
    v = g.values
    po = v.get("push_off_normal_impulse_n_s", 0.0)
    return (f"ground contact: unilateral (stance normal force >= "
            f"{v['min_normal_force_n']:.4g} {u('N')}, heel-strike normal impulse "
            f"{v['heel_strike_normal_impulse_n_s']:.4g} {u('N s')}"
            + (f", push-off {po:.4g} {u('N s')}" if po > 0 else "")
            + f"; friction coefficient needed {v['max_friction_ratio']:.3g})")


#: a twist at most this [N m] is none (round-off of a gait that needs none)
TWIST_NONE_N_M = 1e-9


def twist_text(g, u) -> str | None:
    """One line on the moment about the slope's normal a 3D gait's stance foot carries (``g``:
    the stored check, ``u``: the units), or None (a planar gait, or not checked)."""
    v = g.values
    if "max_twist_n_m" not in v:
        return None
    r = v.get("twist_patch_radius_m", float("nan"))
    if v["max_twist_n_m"] <= TWIST_NONE_N_M:  # e.g. a walker of zero hip width, upright
        return (f"stance foot twist: none (at most {v['max_twist_n_m']:.2g} {u('N m')} about "
                "the slope's normal: a point foot holds this gait)")
    hold = ("" if r != r else f", a round foot patch of radius >= "
            f"{r * u.small_scale:.3g} {u.small_length} could by friction with the ground's mu")
    return (f"stance foot twist: up to {v['max_twist_n_m']:.4g} {u('N m')} about the slope's "
            f"normal at t = {v['max_twist_time_s']:.4g} {u.time}, carried by the rigid "
            f"model's stance joint (it lets the foot roll and pitch, not turn); a point foot "
            f"cannot hold it{hold}")


def footholds_text(fh: dict) -> str:
    """Lines on a stair gait's footholds (``fixedpoint.h5``'s ``footholds/``, SI): step
    advance, tread drift, the footfall that would miss a tread, the swing foot's clearances
    over the tread behind, the stance tread and the riser edge ahead."""
    miss = int(fh["steps_until_miss"])
    edge = float(fh["riser_clearance_m"])
    mid, back = float(fh["midstance_clearance_m"]), float(fh["back_clearance_m"])
    if edge != edge and mid != mid and back != back and not fh["riser_scuff"]:
        # a spoked wheel: its next spoke lands on the tread ahead from above, never over
        # the stance tread, the tread behind or the riser edge between
        return "\n".join(_footholds_head(fh, miss) + [
            "  swing-foot clearance: the landing spoke stays ahead of the riser edge (it "
            "lands on the tread ahead from above; no foot swings over the treads)"])
    return "\n".join(_footholds_head(fh, miss) + [
        f"  swing-foot clearance: riser edge ahead {1e3 * edge:.4g} mm"
        + (" (SCUFFS the riser: not modelled)" if fh["riser_scuff"] else "")
        + f", stance tread {1e3 * mid:.4g} mm (mid-stance "
        f"foot-through as on a slope), tread behind {1e3 * back:.4g} mm"])


def _footholds_head(fh: dict, miss: int) -> list[str]:
    """:func:`footholds_text`'s first two lines: the stairs, the step advance and drift,
    the footfall that would miss its tread."""
    return [
        f"stairs ({fh['direction']}, riser {1e3 * fh['riser_m']:.4g} mm, tread "
        f"{1e3 * fh['tread_m']:.4g} mm): step advance {1e3 * fh['step_advance_m']:.4f} mm, "
        f"the foot drifts {1e3 * fh['drift_per_step_m']:+.4f} mm per tread",
        f"  from {1e3 * fh['first_foothold_m']:.4g} mm on the first tread: "
        + ("never misses a tread" if miss < 0 else f"footfall {miss} misses its tread")]


def ground_word(g, u) -> str:
    """``, on real ground`` / ``, NEEDS THE GROUND TO PULL (min normal force -31.4 N)`` for
    a gait that carries its ground check, else ``""`` (``g``: one of the stored gaits,
    :class:`~walkerlab.io.schemas.fixedpoint.GaitResult`; ``u``: the units); a gait
    outside the friction cone says so too."""
    gc = g.ground_contact
    fr = getattr(gc, "friction", None)
    slips = ("" if fr is None or fr.inside is not False else
             f", OUTSIDE THE FRICTION CONE (needs {fr.needed()}, the ground's mu is "
             f"{fr.mu:.3g})")
    if gc is None or gc.ok is None:
        return slips
    if gc.ok:
        return ", on real ground" + slips
    n = gc.values.get("min_normal_force_n", 0.0)
    return (", NEEDS THE GROUND TO PULL" + (f" (stance normal force down to {n:.4g} {u('N')})"
                                              if n < 0 else " (a pulling impulse)"))
