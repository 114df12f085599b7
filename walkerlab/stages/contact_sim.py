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

from walkerlab.config import ContactSolverSettings, Scene
from walkerlab.contact.config import ContactSimSettings, TerrainSettings
from walkerlab.io.artifacts import put
from walkerlab.io.trajectory import NamedTrajectory, write_samples
from walkerlab.stages import fixedpoint as fixedpoint_stage
from walkerlab.stages.common import StageOutcome, artifact_path, require, run_cached

SECTIONS = ("walker", "slope", "contact", "terrain", "contact_sim", "contact_solver")
LEGS = ["leg1", "leg2"]


def settings(scene: Scene):
    """Contact sections with defaults for the optional ones."""
    contact = require(scene, "contact", "contact-sim")
    return (contact, scene.terrain or TerrainSettings(), scene.contact_sim or ContactSimSettings(),
            scene.contact_solver or ContactSolverSettings())


def build(scene: Scene, x_fp: np.ndarray, n_steps: int):
    """ContactWalker of the scene with checkerboard patches from the ideal step length."""
    from walkerlab.contact.model import ContactWalker

    contact, terrain, _, _ = settings(scene)
    w = scene.walker
    step_length = 2 * w.leg_length_m * np.sin((x_fp[1] - x_fp[0]) / 2)
    return ContactWalker.from_settings(
        contact, terrain, step_length=step_length, n_steps=n_steps + 4, L=w.leg_length_m,
        m=w.leg_mass_kg, MH=w.hip_mass_kg, a=w.leg_mass_from_foot_m, g=w.gravity_m_per_s2,
        phi=scene.slope.phi_rad), step_length


def simulate_from(scene: Scene, x_fp: np.ndarray, period: float, rate_scale=None,
                  solver: ContactSolverSettings | None = None, strides: int | None = None):
    """Run the contact walker from the ideal fixed point ``x_fp`` (role-ordered, leg2 stance)."""
    from walkerlab.contact.simulate import initial_state_from_ideal, simulate_contact

    _, _, cs, sv = settings(scene)
    sv = solver or sv
    n_strides = strides or cs.n_strides
    walker, step_length = build(scene, x_fp, 2 * n_strides)
    scale = cs.initial_rate_scale if rate_scale is None else rate_scale
    x0 = initial_state_from_ideal(walker, *x_fp, rate_scale=tuple(scale))
    t_final = cs.t_final_s or (2 * n_strides + 0.5) * period
    res = simulate_contact(
        walker, x0, t_final, method=sv.method, rtol=sv.rtol, atol=sv.atol,
        max_step=sv.max_step_s or np.inf, sample_rate_hz=cs.sample_rate_hz,
        pin_stance_until=cs.pin_stance_until, pin_time_s=cs.pin_time_s,
        fall_hip_height_m=cs.fall_hip_height_m)
    return walker, res, x0, step_length


def named_trajectory(walker, res) -> NamedTrajectory:
    """Map a ContactResult onto the shared named layout (stance leg from heel strikes)."""
    t = res.t
    stance = np.full(t.size, LEGS.index("leg2"))
    step = np.zeros(t.size, dtype=int)
    for k, (ths, leg) in enumerate(zip(res.heel_strike_times, res.heel_strike_legs)):
        m = t >= ths
        stance[m] = LEGS.index(leg)
        step[m] = k + 1
    X = res.x
    en = walker.energies(X)
    feet = walker.foot_positions(X)  # (n, 2, 2): foot, xy
    b = walker.b
    hip = X[:, :2].T
    pts = {"hip": hip}
    for i, leg in enumerate(LEGS):
        th = X[:, 2 + i]
        pts[f"{leg}_foot"] = np.asarray(feet)[:, i, :].T
        pts[f"{leg}_mass"] = hip + b * np.vstack([np.sin(th), -np.cos(th)])
    return NamedTrajectory(
        time=t, legs=LEGS,
        coordinates={"leg1_angle": X[:, 2], "leg2_angle": X[:, 3], "leg1_rate": X[:, 6],
                     "leg2_rate": X[:, 7]},
        units={"leg1_angle": "rad", "leg2_angle": "rad", "leg1_rate": "rad/s",
               "leg2_rate": "rad/s"}, stance_leg=stance, step_index=step,
        kinetic=en["kinetic"], potential=en["potential"], points=pts)


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
            from walkerlab.contact.adjust import adjust_rates

            adj = adjust_rates(scene, x_fp, meta["step_period_s"])
            scale = adj["scale"]
        walker, res, x0, step_length = simulate_from(scene, x_fp, meta["step_period_s"], scale)
        tr = named_trajectory(walker, res)
        gait = None
        if periodic:
            from walkerlab.contact.periodic import find_contact_periodic_gait

            gait = find_contact_periodic_gait(walker, x_fp)
        c = walker.contact
        steps = res.steps
        slips = np.array([s.stance_slip_mm for s in steps])
        summary = {
            "termination": res.termination,
            "heel_strikes": int(res.walked_steps),
            "strides_completed": int(res.walked_steps // 2),
            "mean_abs_stance_slip_mm": float(np.nanmean(np.abs(slips))) if slips.size else np.nan,
            "peak_penetration_mm": float(max((s.peak_penetration_m for s in steps),
                                             default=np.nan) * 1e3),
            "total_bounces": int(sum(s.bounce_count for s in steps)),
            "nfev": int(res.nfev), "njev": int(res.njev), "wall_time_s": float(res.wall_time_s),
        }
        units = {"mean_abs_stance_slip_mm": "mm", "peak_penetration_mm": "mm",
                 "wall_time_s": "s"}

        def writer(f):
            f.attrs["model"] = "compass_gait_contact"
            f.attrs["legs"] = LEGS
            f.attrs["termination"] = res.termination
            f.attrs["method"] = res.method
            if res.fall_time is not None:
                f.attrs["fall_time_s"] = res.fall_time
                f.attrs["fall_reason"] = str(res.fall_reason)
            write_samples(f, tr)
            for name, val, unit in (("stiffness", c.k, "N/m^e"), ("exponent", c.e, "-"),
                                    ("max_damping", c.cmax, "N s/m"),
                                    ("penetration_at_max_damping", c.dmax, "m"),
                                    ("mu_static", c.mu_s, "-"), ("mu_dynamic", c.mu_d, "-"),
                                    ("stiction_velocity", c.v_s, "m/s"),
                                    ("friction_velocity", c.v_d, "m/s")):
                put(f, f"contact_params_si/{name}", val, unit, f"{name} in SI")
            put(f, "terrain/step_length", step_length, "m", "ideal step length used for patches")
            put(f, "terrain/lane_leg1", walker.lane1, "m", "patch centres, along-slope s")
            put(f, "terrain/lane_leg2", walker.lane2, "m", "patch centres, along-slope s")
            put(f, "terrain/patch_half_width", walker.patch_half_width, "m", "")
            put(f, "terrain/continuous", bool(walker.continuous), "-", "")
            put(f, "initial_state", x0, "m, rad, m/s, rad/s",
                "[hip_x, hip_y, theta1, theta2] and rates", )
            put(f, "initial_state_ideal", x_fp, "rad, rad/s", "ideal fixed point (Table 2 MATLAB)")
            put(f, "initial_rate_scale", np.asarray(scale if scale is not None else
                                                    settings(scene)[2].initial_rate_scale),
                "-", "multipliers on (dtheta1, dtheta2)")
            for leg, ft in res.feet.items():
                g = f.create_group(f"feet/{leg}")
                put(g, "normal_force", ft.normal_force, "N", "IMPACT normal force")
                put(g, "friction_force", ft.friction_force, "N", "Coulomb friction, down-slope")
                put(g, "penetration", ft.penetration, "m", "signed penetration (<0: above)")
                put(g, "slip_velocity", ft.slip_velocity, "m/s", "tangential foot velocity")
                put(g, "touchdown_times", ft.touchdown_times, "s", "")
                put(g, "liftoff_times", ft.liftoff_times, "s", "")
            put(f, "events/heel_strike_times", res.heel_strike_times, "s", "")
            put(f, "events/heel_strike_legs", list(res.heel_strike_legs) or [""], "-", "")
            g = f.create_group("steps")
            for fld, unit in (("t_start", "s"), ("t_end", "s"), ("period", "s"),
                              ("stance_slip_mm", "mm"), ("bounce_count", "-"),
                              ("peak_penetration_m", "m")):
                put(g, fld, np.array([getattr(s, fld) for s in steps], dtype=float), unit, fld)
            put(g, "stance_leg", [s.stance_leg for s in steps] or [""], "-", "")
            for k, v in summary.items():
                if k != "termination":
                    put(f, f"summary/{k}", v, units.get(k, "-"), k)
            if gait is not None:
                g = f.create_group("periodic_gait")
                g.attrs["section"] = "mid-stance (legs aligned), stance foot loaded only"
                for k, v in gait.fixed_point.items():
                    g.attrs[f"fixed_point_{k}"] = float(v)
                put(g, "step_period", gait.period_s, "s", "period of the contact gait")
                put(g, "step_length", gait.step_length_m, "m", "")
                put(g, "residual", gait.residual, "-", "scaled map residual")
                put(g, "multipliers/real", gait.multipliers.real, "-", "Floquet multipliers")
                put(g, "multipliers/imag", gait.multipliers.imag, "-", "")
                put(g, "multiplier_fd_spread", gait.multiplier_fd_spread, "-",
                    "change of the multipliers for FD steps x3 and /3")
                put(g, "stable", bool(gait.stable), "-", "all |multipliers| < 1")
                put(g, "converged", bool(gait.converged), "-", "residual below tolerance")
            if adj is not None:
                for k, v in adj.items():
                    if isinstance(v, (int, float, np.ndarray, list, tuple)):
                        put(f, f"adjust/{k}", np.asarray(v, dtype=float), "-", k)
        return writer, summary

    return run_cached("contact-sim", scene, runs_root, sections, up, compute, force)


def workprecision_runner(scene: Scene, runs_root, x_fp: np.ndarray, strides: int):
    """``run(method, rtol, atol) -> (final [angles, rates], nfev)`` for the contact walker."""
    _, meta = fixedpoint_stage.load_fixed_point(artifact_path(scene, runs_root, "fixedpoint"))

    def run(method, rtol, atol):
        sv = ContactSolverSettings(method=method, rtol=rtol, atol=atol)
        _, res, _, _ = simulate_from(scene, x_fp, meta["step_period_s"], solver=sv,
                                     strides=strides)
        if res.termination != "t_final":
            return None, res.nfev
        return np.concatenate([res.q[-1, 2:], res.qdot[-1, 2:]]), res.nfev
    return run
