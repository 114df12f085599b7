"""The heel strike of a virtual-constraint controller, rigid and in MuJoCo: is the rigid
impact's impulse inside the friction cone, and what does MuJoCo's soft contact do there?

Rigid (the scene's closed loop from its zero dynamics' fixed point, one step):

- the heel strike's impulse ``Lambda`` on the new stance foot [N s] from the walker's
  generated extended impact (``De``, ``E``: ``De (q'e+ - q'e-) = E^T Lambda``, ``E q'e+ =
  0``; Y. Hurmuzlu & D. B. Marghitu 1994, Int. J. Robotics Research 13(1):82-92;
  Westervelt et al. 2007, ch. 3), checked against an
  independent computation, the whole walker's linear momentum change ``m (v_com+ -
  v_com-)`` with ``q'+`` from the generated pinned impact (``Mi q'+ = B q'-``) and the
  centre of mass from the bodies' mass points; ``|Lambda_t / Lambda_n|`` against the
  design's friction coefficient;
- the trailing foot's velocity just after the impact (it must lift off: normal > 0);
- the stance foot's force ratio ``|F_t / F_n|`` along the step (``m (a_com + g)``).

MuJoCo (``walkerlab export`` MJCF, the export's stepping loop with the scene's feedback,
optionally with the file's numbers replaced): per heel strike, the new stance foot's
travel along the ground (the first 30 ms, then the rest of the step), the zero dynamics'
momentum ``sigma = b^T M q'`` (the angular momentum about the stance foot) just before the
strike, and 3 ms after it in MuJoCo and in the rigid closed loop from the rigid impact of the
same pre-impact state; the step period against the rigid one.

Usage: ``python scripts/hzd_heel_strike.py SCENE.yaml [OUTDIR] [--mujoco]
[--sub REGEX::REPLACEMENT ...]`` (e.g. ``--sub 'friction="0.9 ::friction="2.0 '``).
"""

from __future__ import annotations

import argparse
import re
from pathlib import Path

import numpy as np

from walkerlab.walker.plant import Plant


def rigid(scene) -> dict:
    """The rigid heel strike's numbers (module docstring): ``impulse_n``, ``impulse_t``
    [N s] (``De``, ``E``), ``impulse_momentum`` (2,) [N s] (the momentum balance, the
    ground's x, y), ``impulse_world`` (2,) [N s] (``De``, ``E``), ``rate_gap`` [rad/s] (``q'+``
    of the two impacts), ``trailing_normal``, ``trailing_tangential`` [m/s], ``stance_ratio``
    (401,) ``|F_t / F_n|`` along the step, ``min_normal`` [N], ``step_period_s``."""
    import sympy as sp

    from walkerlab.analysis.gait.zero_dynamics import zero_dynamics
    from walkerlab.codegen.virtual_constraints import derive_equations
    from walkerlab.integrate.rigid import integrate_step
    from walkerlab.integrate.solver import Solver
    from walkerlab.models.registry import build_walker
    from walkerlab.walker.description import walker_data

    walker = build_walker(Plant.from_scene(scene))
    ctrl = walker.actuators.controller
    zd = zero_dynamics(ctrl)
    seg = integrate_step(walker, zd.x_plus, Solver.from_settings(scene.solver),
                         max_step_time=3 * zd.step_period_s)
    t = np.linspace(seg.t_start, seg.t_end, 401)
    X = seg.sample(t).T
    xm = X[-1]
    data = walker_data(scene.walker, scene.slope.phi_rad)
    st = data.structure
    eq = derive_equations(st)
    n = len(eq.q)
    par = dict(zip(eq.params, (float(v) for v in data.params)))
    q, dq = xm[:n], xm[n:]

    def num(expr):
        return np.array(sp.lambdify(eq.q, sp.Matrix(expr).subs(par), "numpy")(*q), float)
    De, E = num(eq.De), num(eq.E)
    K = np.block([[De, -E.T], [E, np.zeros((2, 2))]])
    dqe = np.concatenate([dq, [0.0, 0.0]])
    sol = np.linalg.solve(K, np.concatenate([De @ dqe, [0.0, 0.0]]))
    lam = sol[n + 2:]
    # independent: m (v_com+ - v_com-), q'+ from the pinned impact, the new stance foot at rest
    dqp = np.linalg.solve(num(eq.Mi), num(eq.B) @ dq)
    names = dict(zip(st.param_names, (float(v) for v in data.params)))
    pts = [(names["M_hip"], "hip")] if st.hip_mass and "M_hip" in names else []
    for body in st.bodies:
        if not body.massless:
            pts += [(names[f"m_{body.name}"], f"{r}_{body.name}") for r in ("stance", "swing")]
    for body in st.torso or ():
        if not body.massless and f"torso_{body.name}" in eq.points:
            pts.append((names[f"m_torso_{body.name}"], f"torso_{body.name}"))
    mtot = sum(m for m, _ in pts)
    com = sum((m * sp.Matrix(eq.points[p]) for m, p in pts), sp.zeros(2, 1)) / mtot
    Jc = num(com.jacobian(sp.Matrix(eq.q)))
    Jf = num(sp.Matrix(eq.points["swing_foot"]).jacobian(sp.Matrix(eq.q)))
    lam_mom = mtot * ((Jc - Jf) @ dqp - Jc @ dq)
    gam = data.slope_rad
    nrm, tan = np.array([np.sin(gam), np.cos(gam)]), np.array([np.cos(gam), -np.sin(gam)])
    ln, lt = lam @ nrm, lam @ tan
    from walkerlab.optimal.transcription.virtual_constraints import hzd_functions

    fns = hzd_functions(data, scene.walker.actuation.virtual_constraints)
    u = np.array([np.real(ctrl.torques(x)) for x in X])
    g = np.array([np.asarray(fns.grf(x, ui), float).ravel() for x, ui in zip(X, u)])
    r = np.abs(g[:, 1] / g[:, 0])
    return {"impulse_n": float(ln), "impulse_t": float(lt), "impulse_world": lam,
            "impulse_momentum": lam_mom, "rate_gap": float(np.max(np.abs(sol[:n] - dqp))),
            "trailing_normal": float(sol[n:n + 2] @ nrm),
            "trailing_tangential": float(sol[n:n + 2] @ tan), "stance_ratio": r,
            "min_normal": float(g[:, 0].min()), "step_period_s": float(zd.step_period_s)}


def report(r: dict) -> None:
    """Print :func:`rigid`'s numbers."""
    ln, lt, sr = r["impulse_n"], r["impulse_t"], r["stance_ratio"]
    print(f"  heel strike impulse (De, E): Lambda_n {ln:.6g} N s, Lambda_t {lt:.6g} N s, "
          f"|Lambda_t / Lambda_n| = {abs(lt / ln):.4f}")
    print(f"  momentum balance m (v_com+ - v_com-): differs by "
          f"{np.max(np.abs(r['impulse_momentum'] - r['impulse_world'])):.2e} N s; q'+ "
          f"(De, E) vs (Mi, B): {r['rate_gap']:.2e} rad/s")
    print(f"  trailing foot after the impact: normal {r['trailing_normal']:.4f} m/s, "
          f"tangential {r['trailing_tangential']:.4f} m/s")
    s = np.linspace(0.0, 1.0, len(sr))
    print(f"  stance |F_t / F_n|: {sr[0]:.3f} at s = 0, {sr[len(sr) // 2]:.3f} at 0.5, max "
          f"{sr.max():.4f} at s = {s[sr.argmax()]:.2f}; min F_n {r['min_normal']:.1f} N; step "
          f"period {r['step_period_s']:.6g} s")


def mujoco(scene, outdir: Path, subs, period: float, steps: float = 21.5) -> None:
    """Print MuJoCo's heel strikes (module docstring)."""
    import mujoco as mj

    from walkerlab.export import mujoco_walk as mw
    from walkerlab.integrate.rigid import integrate_step
    from walkerlab.integrate.solver import Solver
    from walkerlab.models.registry import build_walker
    from walkerlab.models.virtual_constraints import annihilator
    from walkerlab.stages import export as export_stage

    out = export_stage.write(scene, outdir, "mjcf")
    path = Path(out.path)
    if subs:
        text = path.read_text()
        for a, b in subs:
            text, k = re.subn(a, b, text)
            if not k:
                raise SystemExit(f"--sub {a!r}: not in {path}")
        path = path.with_name("walker_sub.xml")
        path.write_text(text)
    plant = Plant.from_scene(scene)
    fb = mw.virtual_constraint_feedback(scene, plant.data)
    ctrl, n = fb.controller, fb.controller.n
    b = annihilator(ctrl.B)

    def sigma(x):
        return float(b @ np.real(ctrl.fns["matrices"](x)[0]) @ x[n:])
    _, model, data = mw._at_gait_keyframe(path, "diagnosing the heel strike")
    site = [mj.mj_name2id(model, mj.mjtObj.mjOBJ_SITE, f"{g}_foot") for g in mw.LEGS]
    geom = [mj.mj_name2id(model, mj.mjtObj.mjOBJ_GEOM, f"{g}_foot") for g in mw.LEGS]
    loop = mw.powered_loop(model, fb)
    loop.bind(model, site)
    mj.mj_forward(model, data)

    def role(stance):
        q = {c: data.qpos[a] for c, a in loop.q_of.items()}
        v = {c: data.qvel[a] for c, a in loop.v_of.items()}
        return fb.role_state(q, v, stance)
    last, strikes, pending, rows, feet = [data.time] * 2, [], None, [], []
    while data.time < steps * period:
        before = role(loop.stance)
        loop.control(data)
        mj.mj_step(model, data, 1)
        feet.append((data.time, data.site_xpos[site[0]][0], data.site_xpos[site[1]][0]))
        if pending is not None and data.time >= pending[0]:
            rows.append((*pending[1:], sigma(role(loop.stance))))
            pending = None
        if data.ncon:
            hit = data.contact.geom[:data.ncon]
            for k in range(2):
                if (hit == geom[k]).any():
                    if data.time - last[k] > 0.1:
                        strikes.append((data.time, k))
                        xr = np.real(ctrl.fns["reset"](before))
                        pending = (data.time + 0.003, sigma(before), xr)
                        loop.heel_strike(data, k)
                    last[k] = data.time
    F = np.array(feet)
    ts = np.array([s[0] for s in strikes])
    per = np.diff(ts)[1:]
    print(f"  MuJoCo: {len(ts)} heel strikes, mean step period {per.mean():.5f} s "
          f"({per.mean() / period - 1:+.2%} from the rigid)")
    slip = []
    for (t0, k), (t1, _) in zip(strikes[:-1], strikes[1:]):
        m = (F[:, 0] >= t0) & (F[:, 0] < t1)
        x, tt = F[m, 1 + k], F[m, 0]
        a = x[np.searchsorted(tt, t0 + 0.03)]
        slip.append((a - x[0], x[-1] - a))
    slip = 1e3 * np.array(slip[1:])
    walker, solver = build_walker(plant), Solver.from_settings(scene.solver)

    def rigid_after(xr):  # the rigid closed loop 3 ms after its impact
        seg = integrate_step(walker, xr, solver, max_step_time=0.003)
        return sigma(seg.sample(np.array([seg.t_end])).T[-1])
    sm = np.array([r[0] for r in rows[1:]])
    sr = np.array([rigid_after(r[1]) for r in rows[1:]])
    sa = np.array([r[2] for r in rows[1:]])
    print(f"  new stance foot's travel per step: {slip[:, 0].mean():.3f} mm in its first 30 ms, "
          f"{slip[:, 1].mean():.3f} mm after (mean of {len(slip)} steps)")
    print(f"  sigma 3 ms after the strike / sigma before it: the rigid impact and closed loop "
          f"{np.mean(sr / sm):.4f}, MuJoCo {np.mean(sa / sm):.4f} (mean of {len(sm)} strikes)")


def main() -> None:
    from walkerlab.config import load_scene

    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("scene", type=Path)
    ap.add_argument("outdir", type=Path, nargs="?", default=Path("/tmp/hzd_heel_strike"))
    ap.add_argument("--mujoco", action="store_true")
    ap.add_argument("--sub", action="append", default=[], metavar="REGEX::REPLACEMENT")
    a = ap.parse_args()
    scene = load_scene(a.scene)
    print(f"{a.scene.name}:")
    r = rigid(scene)
    report(r)
    if a.mujoco:
        mujoco(scene, a.outdir, [s.split("::", 1) for s in a.sub], r["step_period_s"])


if __name__ == "__main__":
    main()
