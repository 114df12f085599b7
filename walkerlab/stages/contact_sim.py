"""Stage ``contact-sim``: the compliant-contact (MSC ADAMS style) walker -> ``contact_sim.h5``.

The walker of the scene as free bodies on the scene's terrain, started from the ideal fixed
point (``fixedpoint.h5``; paper Table 2, MATLAB column) with the stance foot at its static
penetration, initial rates scaled by ``contact_sim.initial_rate_scale``.  The artifact has
the same named ``samples/`` as ``simulate.h5`` (see :mod:`walkerlab.io.trajectory`) plus
per-foot contact histories, events and per-step slip, bounces and penetration.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from walkerlab.analysis import contact_sim as contact_run
from walkerlab.config import Scene
from walkerlab.contact import scene as contact_scene
from walkerlab.io.artifacts import put
from walkerlab.io.netcdf import coordinate
from walkerlab.io.trajectory import NamedTrajectory, write_samples  # noqa: F401
from walkerlab.stages import fixedpoint as fixedpoint_stage
from walkerlab.stages.common import StageOutcome, artifact_path, require, run_cached

SECTIONS = ("walker", "slope", "contact", "terrain", "contact_sim", "contact_solver")
#: stiffness values of the drop test stored with every contact run, relative to the scene's
#: own stiffness (the paper's k = 1e5 N/mm^2.2: 1e4 ... 1e9 N/mm^2.2)
DROP_STIFFNESS_RATIO = (0.1, 0.3, 1.0, 3.0, 1e1, 3e1, 1e2, 3e2, 1e3, 3e3, 1e4)
#: downward speed of the drop test at first contact [m/s, or the scene's speed unit]
DROP_SPEED = 0.3


def drop_test(scene: Scene, mass_kg: float) -> dict:
    """The drop test of the scene's contact law (:func:`walkerlab.analysis.contact_drop.
    restitution_curve`): the walker's total mass ``mass_kg`` [kg] meeting flat ground at
    :data:`DROP_SPEED`, at the stiffnesses :data:`DROP_STIFFNESS_RATIO` x the scene's.

    The rigid-limit family starts from the scene's own contact (its stiffness is the
    reference) when the scene follows the paper family, so both curves pass through the
    scene's contact whatever its unit system (``reference_stiffness`` defaults to the
    paper's 1e5 N/mm^2.2, which means nothing in SI units, e.g. round_feet.yaml's 4e9 N/m^2.2).
    """
    from walkerlab.analysis.contact_drop import restitution_curve

    base = settings(scene)[0]
    if base.stiffness_family == "paper":
        base = base.model_copy(update={"reference_stiffness": base.stiffness})
    ks = [base.stiffness * r for r in DROP_STIFFNESS_RATIO]
    return restitution_curve(base, ks, mass_kg=float(mass_kg), v_in_m_per_s=DROP_SPEED)
LEGS = ["leg1", "leg2"]


def settings(scene: Scene):
    """Contact sections with defaults for the optional ones (StageError if no ``contact``)."""
    require(scene, "contact", "contact-sim")
    return contact_scene.settings(scene)


build = contact_scene.build
simulate_from = contact_run.simulate_from


def named_trajectory(walker, res) -> NamedTrajectory:
    """Map a ContactResult onto the shared named layout (see
    :func:`walkerlab.analysis.contact_sim.named_trajectory`)."""
    return contact_run.named_trajectory(walker, res, LEGS)


def rate_states(walker, leg: str) -> list[str]:
    """Names of the rate states of ``leg``'s links (what one entry of
    ``initial_rate_scale`` multiplies): ``dtheta1``; kneed ``dtheta1_thigh dtheta1_shank``."""
    idx = walker.state_names()
    n = walker.nq
    return [idx[idx.index(s) + n] for s in walker.leg_angle_states(leg)]


def run(scene: Scene, runs_root: Path | str = "runs", force: bool = False,
        adjust: bool = False, periodic: bool = False) -> StageOutcome:
    """Simulate the contact walker (optionally after ``--adjust``) and write the artifact.

    Raises
    ------
    StageError
        The scene has no ``contact`` section.
    """
    periodic = periodic or settings(scene)[2].periodic_gait
    fixedpoint_stage.run(scene, runs_root)
    up = (artifact_path(scene, runs_root, "fixedpoint"),)
    sections = SECTIONS + (("adjust",) if adjust else ()) + (("periodic",) if periodic else ())

    def compute():
        x_fp, meta = fixedpoint_stage.load_fixed_point(up[0])
        adj = None
        scale = None
        if adjust:
            from walkerlab.analysis.contact_adjust import adjust_rates, better_start

            adj = adjust_rates(scene, x_fp, meta["step_period_s"])
            scale = adj["scale"]
        run = simulate_from(scene, x_fp, meta["step_period_s"], scale)
        if adjust:  # the adjusted start must walk at least as well as the scene's own
            plain = simulate_from(scene, x_fp, meta["step_period_s"], None)
            adj["kept"], adj["kept_reason"] = better_start(plain[1], run[1])
            if adj["kept"] == "scene":
                run, scale = plain, None
        walker, res, x0, step_length = run
        tr = named_trajectory(walker, res)
        gait = gait_error = None
        cs = settings(scene)[2]
        if periodic:
            from walkerlab.analysis.contact_periodic import (
                PeriodicGaitError,
                find_contact_periodic_gait,
            )

            try:
                gait = find_contact_periodic_gait(walker, x_fp,
                                                  time_limit_s=cs.periodic_time_limit_s)
            except PeriodicGaitError as exc:
                gait_error = exc
        drop = drop_test(scene, walker.total_mass)
        c = walker.contact
        steps = res.steps
        slips = np.array([s.stance_slip_mm for s in steps])
        creep = np.array([s.double_support_creep_mm for s in steps])
        summary = {
            "termination": res.termination,
            "outcome": res.outcome.kind,
            "heel_strikes": int(res.walked_steps),
            "strides_completed": int(res.walked_steps // 2),
            "mean_abs_stance_slip_mm": float(np.nanmean(np.abs(slips)))
            if np.isfinite(slips).any() else np.nan,
            "max_abs_stance_slip_mm": float(res.max_stance_slip_mm),
            "total_double_support_creep_mm": float(np.sum(creep)) if creep.size else 0.0,
            "peak_penetration_mm": float(max((s.peak_penetration_m for s in steps),
                                             default=np.nan) * 1e3),
            "total_bounces": int(sum(s.bounce_count for s in steps)),
            "total_scuffs": int(sum(s.scuff_count for s in steps)),
            "nfev": int(res.nfev), "njev": int(res.njev), "wall_time_s": float(res.wall_time_s),
        }
        units = {"mean_abs_stance_slip_mm": "mm", "peak_penetration_mm": "mm",
                 "max_abs_stance_slip_mm": "mm", "total_double_support_creep_mm": "mm",
                 "wall_time_s": "s"}

        def writer(f):
            f.attrs["model"] = ("compass_gait_contact" if walker.nq == 4
                                and walker.structure.foot == "point" else "biped_contact")
            f.attrs["legs"] = LEGS
            f.attrs["termination"] = res.termination
            f.attrs["method"] = res.method
            f.attrs["outcome"] = res.outcome.kind
            f.attrs["outcome_message"] = res.outcome.message
            f.attrs["stiffness_family"] = settings(scene)[0].stiffness_family
            if res.fall_time is not None:
                f.attrs["fall_time_s"] = res.fall_time
            o = res.outcome
            g = f.create_group("outcome")
            g.attrs["kind"] = o.kind
            g.attrs["foot"] = o.foot
            g.attrs["message"] = o.message
            put(g, "time", o.time_s, "s", "time of the event that set the outcome (NaN: none)")
            put(g, "patch_edge", o.patch_edge_m, "m", "along-slope position of the patch side "
                "hit by a trip (NaN: no trip)")
            put(g, "hip_height", o.hip_height_m, "m", "hip height above the ground line at "
                "the outcome time")
            g = f.create_group("drop_test")
            g.attrs["method"] = (f"point mass {walker.total_mass:.6g} kg (the walker's) meeting "
                                 f"flat ground at {DROP_SPEED} m/s, no gravity "
                                 "(walkerlab.analysis.contact_drop); restitution = v_out / v_in")
            g.attrs["mass_kg"] = float(walker.total_mass)
            lu = "mm" if settings(scene)[0].unit_system == "mm-kg-s" else "m"
            coordinate(g, "stiffness", drop["stiffness"], f"N/{lu}^e",
                       "IMPACT stiffness in the scene's unit system")
            k = ("stiffness",)
            for fam in ("paper", "rigid_limit"):
                put(g, f"{fam}/restitution", drop[fam]["restitution"], "-",
                    f"coefficient of restitution, {fam} family", dims=k)
                put(g, f"{fam}/max_penetration", drop[fam]["max_penetration_m"], "m",
                    "largest penetration in the drop", dims=k)
                put(g, f"{fam}/contact_time", drop[fam]["contact_time_s"], "s",
                    "duration of the contact (NaN: comes to rest)", dims=k)
            write_samples(f, tr)
            for name, val, unit in (("stiffness", c.k, "N/m^e"), ("exponent", c.e, "-"),
                                    ("max_damping", c.cmax, "N s/m"),
                                    ("penetration_at_max_damping", c.dmax, "m"),
                                    ("mu_static", c.mu_s, "-"), ("mu_dynamic", c.mu_d, "-"),
                                    ("stiction_velocity", c.v_s, "m/s"),
                                    ("friction_velocity", c.v_d, "m/s")):
                put(f, f"contact_params_si/{name}", val, unit, f"{name} in SI")
            put(f, "terrain/step_length", step_length, "m", "ideal step length used for patches")
            for leg, lane in (("leg1", walker.lane1), ("leg2", walker.lane2)):
                coordinate(f.require_group("terrain"), f"patch_{leg}", np.arange(len(lane)),
                           "-", f"patch number on {leg}'s lane")
                put(f, f"terrain/lane_{leg}", lane, "m", "patch centres, along-slope s",
                    dims=(f"patch_{leg}",))
            put(f, "terrain/patch_half_width", walker.patch_half_width, "m", "")
            put(f, "terrain/continuous", bool(walker.continuous), "-", "")
            coordinate(f, "contact_state", list(walker.state_names()), "-",
                       "state component of the floating contact walker")
            put(f, "initial_state", x0, ", ".join(walker.state_units()),
                "initial state, named by state_names", names=list(walker.state_names()),
                dims=("contact_state",))
            for name, val, unit in zip(walker.state_names(), x0, walker.state_units()):
                put(f, f"initial_state_named/{name}", float(val), unit, f"initial {name}")
            coordinate(f, "state", list(meta["state_names"]), "-",
                       "state component of the rigid walker (role-ordered)")
            put(f, "initial_state_ideal", x_fp, "rad, rad/s", "ideal fixed point (Table 2 MATLAB)",
                dims=("state",))
            scaled = [" ".join(rate_states(walker, leg)) for leg in LEGS]
            coordinate(f, "rate", scaled, "-", "rates scaled (leg1 swing, leg2 stance)")
            put(f, "initial_rate_scale", np.asarray(scale if scale is not None else
                                                    settings(scene)[2].initial_rate_scale),
                "-", f"multipliers on ({'; '.join(scaled)})", dims=("rate",))
            for leg, ft in res.feet.items():
                g = f.create_group(f"feet/{leg}")
                coordinate(g, "time", tr.time, "s", "sample time")
                t = ("time",)
                put(g, "normal_force", ft.normal_force, "N", "IMPACT normal force", dims=t)
                put(g, "friction_force", ft.friction_force, "N", "Coulomb friction, down-slope",
                    dims=t)
                put(g, "penetration", ft.penetration, "m", "signed penetration (<0: above)",
                    dims=t)
                put(g, "slip_velocity", ft.slip_velocity, "m/s", "tangential foot velocity",
                    dims=t)
                for ev in ("touchdown", "liftoff"):
                    times = getattr(ft, f"{ev}_times")
                    coordinate(g, ev, np.arange(len(times)), "-", f"{ev} number")
                    put(g, f"{ev}_times", times, "s", f"{ev} times of {leg}'s foot", dims=(ev,))
            g = f.create_group("events")
            legs = list(res.heel_strike_legs) or [""]
            coordinate(g, "heel_strike", np.arange(len(legs)), "-", "heel strike number")
            put(g, "heel_strike_times", res.heel_strike_times, "s", "heel-strike times",
                dims=("heel_strike",) if len(res.heel_strike_times) == len(legs) else None)
            put(g, "heel_strike_legs", legs, "-", "leg striking", dims=("heel_strike",))
            g = f.create_group("steps")
            coordinate(g, "step", np.arange(len(steps) or 1), "-", "step number")
            s_dim = ("step",)
            for fld, unit in (("t_start", "s"), ("t_end", "s"), ("period", "s"),
                              ("stance_slip_mm", "mm"), ("double_support_creep_mm", "mm"),
                              ("bounce_count", "-"), ("scuff_count", "-"),
                              ("peak_penetration_m", "m"), ("liftoff_time", "s")):
                put(g, fld, np.array([getattr(s, fld) for s in steps], dtype=float), unit, fld,
                    dims=s_dim if steps else None)
            put(g, "stance_leg", [s.stance_leg for s in steps] or [""], "-", "stance leg",
                dims=s_dim)
            for k, v in summary.items():
                if k not in ("termination", "outcome"):
                    put(f, f"summary/{k}", v, units.get(k, "-"), k)
            if gait_error is not None:
                g = f.create_group("periodic_gait")
                g.attrs["outcome"] = gait_error.kind
                g.attrs["message"] = str(gait_error)
            if gait is not None:
                g = f.create_group("periodic_gait")
                g.attrs["section"] = "mid-stance (proximal links aligned), stance foot loaded only"
                g.attrs["outcome"] = "ok"
                for k, v in gait.fixed_point.items():
                    g.attrs[f"fixed_point_{k}"] = float(v)
                put(g, "step_period", gait.period_s, "s", "period of the contact gait")
                put(g, "step_length", gait.step_length_m, "m", "")
                put(g, "residual", gait.residual, "-", "scaled map residual")
                coordinate(g, "multiplier", np.arange(len(gait.multipliers)), "-",
                           "Floquet multiplier number")
                m = ("multiplier",)
                put(g, "multipliers/real", gait.multipliers.real, "-",
                    "Floquet multipliers, real part", dims=m)
                put(g, "multipliers/imag", gait.multipliers.imag, "-",
                    "Floquet multipliers, imag part", dims=m)
                put(g, "multiplier_fd_spread", gait.multiplier_fd_spread, "-",
                    "change of the multipliers for FD steps x3 and /3")
                put(g, "stable", bool(gait.stable), "-", "all |multipliers| < 1")
                put(g, "converged", bool(gait.converged), "-", "residual below tolerance")
            if adj is not None:
                for k, v in adj.items():
                    if isinstance(v, (int, float, np.ndarray, list, tuple)):
                        v = np.asarray(v, dtype=float)
                        put(f, f"adjust/{k}", v, "-", k,
                            dims=("rate",) if k == "scale" and v.shape == (2,) else None)
                # which start the run is from, and why (both runs' outcomes)
                f["adjust"].attrs["kept"] = adj["kept"]
                f["adjust"].attrs["kept_reason"] = adj["kept_reason"]
        return writer, summary

    return run_cached("contact-sim", scene, runs_root, sections, up, compute, force)

