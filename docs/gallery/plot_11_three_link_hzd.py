"""
The three-link walker's hybrid zero dynamics
============================================

``configs/threelink_hzd.yaml`` drives the book's three-link walker (Grizzle, Abba & Plestan
2001; Westervelt et al. 2007) by virtual constraints: the swing leg's and the torso's
absolute angles follow Bezier polynomials of degree 4 of the stance leg's angle ``theta``,
enforced at the two hips by computed torque and made exactly invariant under the heel
strike. The closed loop then lives on a two-dimensional surface, the hybrid zero dynamics,
whose Poincare map ``rho(zeta) = delta^2 zeta - V(theta-)`` (``zeta`` half the squared
angular momentum about the stance foot) is computed by quadrature
(:doc:`../user_guide/virtual_constraints`). Below: the numbers, the zero dynamics' phase
portrait with the full walker converging onto its orbit, and ``delta^2`` and the step period
over one Bezier coefficient.
"""

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import walkerlab as wl
from walkerlab.analysis.gait.zero_dynamics import zero_dynamics
from walkerlab.models.hybrid.virtual_constraints import annihilator

ROOT = Path(wl.__file__).resolve().parents[1]  # configs/ beside the package
walker = wl.Walker.from_scene(ROOT / "configs" / "threelink_hzd.yaml")
ctrl = walker.model.actuators.controller
hzd = zero_dynamics(ctrl)
print(f"delta^2 = {hzd.delta2:.10f}, V(theta-) = {hzd.v_minus:.4f}, V_max = {hzd.v_max:.4f}")
print(f"existence: delta^2/(1-delta^2) V(theta-) + V_max = {hzd.existence_margin:.3f} < 0")
print(f"zeta* = {hzd.zeta_star:.4f}, phase rate at impact {hzd.phase_rate_minus:.8f} rad/s, "
      f"step period {hzd.step_period_s:.8f} s")
print("Bezier coefficients in force (c0, c1 from the impact map):")
for name, c in zip(hzd.output_names, ctrl.design.alpha):
    print(f"  {name:15s}", np.round(c, 6))

# %%
# The full-order fixed point (the scene's LSODA, rtol 1e-11) has the zero dynamics' orbit:
# one step of the full walker from the orbit's post-impact state returns to it with the
# quadrature's period, and its Floquet multipliers are ``delta^2`` and the feedback's (~0).

x1 = walker.step(hzd.x_plus)
print(f"|P(x*) - x*| = {np.max(np.abs(x1.x_next - hzd.x_plus)):.1e}, "
      f"period {x1.period:.10f} s (quadrature {hzd.step_period_s:.10f} s)")
print("full-order multipliers", np.round(np.abs(walker.floquet(hzd.x_plus)), 8))

# %%
# The zero dynamics' phase portrait. On the surface the state is ``(theta, theta')``; with
# ``sigma = I(theta) theta'`` and ``b = (1, 1, 1)`` the rotation no actuator drives,
# ``zeta = sigma^2 / 2 = zeta+ - V(theta)``, ``V(theta) = int I b^T G``. Each grey curve is
# one step at another ``zeta+``; the heel strike maps ``zeta-`` to ``delta^2 zeta-`` and
# the step restarts at ``theta+``. The full walker started 25 % faster than the orbit
# (black), on the surface, converges onto it step by step (dark to light: ``zeta``'s
# distance to ``zeta*`` shrinks by ``delta^2`` = 0.89 per step).

d = ctrl.design
b = annihilator(ctrl.B)
s = np.linspace(0.0, 1.0, 201)
qs, tangents = ctrl.path(s)
theta = d.theta_plus + s * (d.theta_minus - d.theta_plus)
I_ = np.empty_like(s)
bG = np.empty_like(s)
for j, (q, qp) in enumerate(zip(qs, tangents)):
    M, _C, G = ctrl.fns["matrices"](np.concatenate([q, qp]))
    I_[j], bG[j] = b @ np.real(M) @ qp, b @ np.real(np.ravel(G))
f = I_ * bG  # dV/dtheta
V = np.concatenate([[0.0], np.cumsum((f[1:] + f[:-1]) / 2 * np.diff(theta))])

zeta_plus = hzd.delta2 * hzd.zeta_star
fig, (ax_v, ax_p) = plt.subplots(1, 2, figsize=(9.0, 3.6), layout="constrained")
ax_v.plot(theta, V, color="C0")
ax_v.axhline(hzd.v_max, color="0.6", ls=":", lw=0.8)
ax_v.annotate("V_max", (theta[np.argmax(V)], hzd.v_max), textcoords="offset points",
              xytext=(0, 4), ha="center", fontsize=8)
ax_v.plot([d.theta_minus], [hzd.v_minus], "o", color="C3")
ax_v.annotate("V(theta-)", (d.theta_minus, hzd.v_minus), textcoords="offset points",
              xytext=(-4, 6), ha="right", fontsize=8)
ax_v.set(xlabel="theta (stance leg) [rad]", ylabel="V [(kg m^2/s)^2]",
         title="the zero dynamics' potential")
ax_v.invert_xaxis()  # theta decreases through a step

for zp in np.linspace(0.6, 1.6, 6) * zeta_plus:
    ok = zp - V > 0
    ax_p.plot(theta[ok], -np.sqrt(2 * (zp - V[ok])) / np.abs(I_[ok]), color="0.75", lw=0.8)
ax_p.plot(theta, -np.sqrt(2 * (zeta_plus - V)) / np.abs(I_), color="k", lw=2,
          label="periodic orbit")
x0 = hzd.x_plus.copy()
x0[3:] *= 1.25  # the same direction on the surface, a faster start
walk = walker.simulate(x0, 8, sample_rate_hz=200)
names = walker.state_names()
th_w, dth_w = walk.x[:, names.index("stance_angle")], walk.x[:, names.index("stance_rate")]
cuts = np.flatnonzero(np.diff(th_w) > 0) + 1  # each heel strike: theta jumps back to theta+
pieces = np.split(np.arange(th_w.size), cuts)
for k, idx in enumerate(pieces):
    ax_p.plot(th_w[idx], dth_w[idx], color=plt.cm.Oranges(0.9 - 0.6 * k / len(pieces)), lw=1,
              label="full walker, 16 steps" if k == 0 else None)
ax_p.set(xlabel="theta [rad]", ylabel="theta' [rad/s]", title="phase portrait on the surface")
ax_p.invert_xaxis()
ax_p.legend(loc="lower left", fontsize=8)
plt.show()

# %%
# ``delta^2`` and the step period over the torso's last coefficient ``c_4`` (the torso's
# lean at the heel strike; invariance sets ``c_0`` to the same lean after it). ``delta^2``
# depends only on the ends of the design and moves little (0.86-0.89); the step's duration
# changes threefold: leaning back, the walker spends its momentum lifting the torso over
# mid-stance, until from ``c_4`` ~ -0.055 rad ``V_max`` exceeds what the heel strike leaves
# (the existence margin ``delta^2/(1-delta^2) V(theta-) + V_max`` turns positive) and the
# walker falls back before ``theta-``: no gait. Each point is one zero-dynamics quadrature (a
# few milliseconds); at three of them one full-order step from the orbit (circles) returns
# the same period. The same study from the command line (the full-order fixed point at each
# point, the zero dynamics' columns beside it)::
#
#     walkerlab sweep configs/threelink_hzd.yaml \
#         --param walker.actuation.virtual_constraints.outputs.1.bezier_rad.4=-0.2:-0.06:0.02

key = "walker.actuation.virtual_constraints.outputs.1.bezier_rad.4"
c4 = np.round(np.arange(-0.20, -0.015, 0.01), 3)
rows, full = [], []
for v in c4:
    w = walker.with_changes({key: float(v)})
    z = zero_dynamics(w.model.actuators.controller)
    rows.append((z.delta2, z.step_period_s, z.existence_margin))
    if v in (-0.18, -0.12, -0.06):
        full.append((v, w.step(z.x_plus).period))
rows = np.array(rows)
print("torso c_4 [rad]   delta^2   period [s]   existence margin")
for v, (d2, T, m) in zip(c4, rows):
    print(f"  {v:+.2f}        {d2:.4f}    {T:8.4f}     {m:9.1f}")

fig, (ax1, ax3) = plt.subplots(1, 2, figsize=(9.0, 3.6), layout="constrained")
ax1.plot(c4, rows[:, 0], "o-", color="C0", ms=3)
ax1.set(xlabel="torso c_4 [rad]", ylabel="delta^2 (restricted map)",
        title="stability and period")
ax1.set_ylabel("delta^2 (restricted map)", color="C0")
ax2 = ax1.twinx()
ax2.plot(c4, rows[:, 1], "s-", color="C1", ms=3)
ax2.plot(*np.array(full).T, "o", color="k", ms=7, mfc="none", label="full-order step")
ax2.set_ylabel("step period [s]", color="C1")
ax2.legend(loc="upper left", fontsize=8)
ax3.plot(c4, rows[:, 2], "o-", color="C2", ms=3)
ax3.axhline(0.0, color="k", lw=0.8)
ax3.axvspan(c4[rows[:, 2] > 0].min() - 0.005, c4.max() + 0.005, color="C3", alpha=0.1,
            label="no gait")
ax3.set(xlabel="torso c_4 [rad]", ylabel="existence margin [(kg m^2/s)^2]",
        title="delta^2/(1-delta^2) V(theta-) + V_max")
ax3.legend(loc="upper left", fontsize=8)
for ax in (ax1, ax3):
    ax.axvline(ctrl.design.alpha[1, -1], color="0.8", lw=0.8, zorder=0)  # the scene's
plt.show()
