"""The ``continuation`` artifact (``runs/<scene>/continuation_<field>.h5``): writer and
loader side by side.

Layout
------
- root attributes ``parameter_path``, ``parameter_unit``, ``state_names``,
  ``parameter_start`` (the scene's own value, where the continuation started),
  ``steps_per_map`` (steps of the one Poincaré map ``P`` of every branch: 1 a step, 2 a
  stride; absent in artifacts written before it was recorded);
- ``branches/<i>/`` for each branch ``i`` (attribute ``branch_period``: 1, 2, 4 maps):
  ``param`` [field unit] (points,), ``state/<name>`` [rad or rad/s] (points,) just after
  heel strike, ``orbit/<name>`` (points, k) after each of the orbit's maps,
  ``period`` [s] (duration of the branch's ``k`` maps), ``multipliers/real``
  and ``multipliers/imag`` (points, 2n) of ``D(P^k)``, ``stable`` (points,) 0/1;
- ``special_points/``: ``kind`` (strings ``fold`` (a multiplier through +1, the branch
  turning back), ``branch_point`` (through +1, the branch passing through: transcritical
  or pitchfork), ``period_doubling``, ``neimark_sacker``, ``branch_end``), ``param``
  [field unit], ``period`` (1, 2, 4: the branch it lies on), ``branch`` (index into
  ``branches``), ``cause`` (why a branch ends; else empty), ``state/<name>``,
  ``multipliers/real``/``imag`` (specials, 2n);
- ``two_parameter/<j>/`` (optional): ``param`` [field unit], ``param2`` [second field's
  unit] of a fold or period-doubling curve (attributes ``kind``, ``period``, ``path2``,
  ``unit2``), ``critical_multiplier/real``/``imag``;
- ``stats/``: ``maps``, ``variational_maps``, ``wall_time`` [s].
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from walkerlab.io.artifacts import artifact_loader, read_named

__all__ = ["continuation_writer", "load_continuation", "initial_state", "ContinuationData", "STAGE"]

STAGE = "continuation"
#: the gait measures stored at each branch point (``branches/<i>/gait/``): unit, meaning
GAIT_MEASURES = {
    "step_length": ("m", "mean step length of the gait (stance foot to swing foot)"),
    "speed": ("m/s", "distance along the ground over the period's time"),
    "cost_of_transport": ("-", "mean cost of transport of the gait's steps "
                               "(walkerlab.analysis.gait.energy)"),
}


def continuation_writer(res, curves=()):
    """``writer(h5file)`` for a :class:`walkerlab.analysis.continuation.branch.ContinuationResult`
    and optional :class:`~walkerlab.analysis.continuation.two_parameter.TwoParameterCurve` s."""
    from walkerlab.io.artifacts import put
    from walkerlab.units import map_name

    names, units = list(res.state_names), list(res.state_units)
    per = map_name(getattr(res, "steps_per_map", 1))

    def states(g, X, what):
        X = np.asarray(X, float).reshape(-1, len(names))
        for k, (n, u) in enumerate(zip(names, units)):
            put(g, f"state/{n}", X[:, k], u, f"{n} just after heel strike, {what}")

    def mults(g, M, what):
        M = np.asarray(M, complex).reshape(-1, len(names))
        put(g, "multipliers/real", M.real, "-", f"Floquet multipliers of {what}, real part")
        put(g, "multipliers/imag", M.imag, "-", f"Floquet multipliers of {what}, imag part")

    def writer(f):
        f.attrs["parameter_path"] = res.path
        f.attrs["parameter_unit"] = res.unit
        f.attrs["state_names"] = names
        f.attrs["parameter_start"] = float(res.start)
        f.attrs["steps_per_map"] = int(getattr(res, "steps_per_map", 1))
        for i, br in enumerate(res.branches):
            g = f.create_group(f"branches/{i}")
            g.attrs["branch_period"] = int(br.period)
            put(g, "param", br.params(), res.unit, f"{res.path} along the branch")
            states(g, [q.x for q in br.points], f"period-{br.period} fixed point")
            orb = np.array([q.orbit for q in br.points], float)  # (points, k, 2n)
            for k, (n, u) in enumerate(zip(names, units)):
                put(g, f"orbit/{n}", orb[:, :, k], u, f"{n} at the start of each of the "
                    f"orbit's {br.period} map(s) of a {per} (points, map)")
            put(g, "period", [q.period_s for q in br.points], "s",
                f"duration of the {br.period} {per}(s) of the gait")
            mults(g, [q.multipliers for q in br.points],
                  f"{br.period} composed map(s) of a {per} (per {per} for period 1)")
            put(g, "stable", [int(q.stable) for q in br.points], "-",
                "1 if every multiplier is inside the unit circle")
            for k, (u, what) in GAIT_MEASURES.items():
                if k in br.measures:
                    put(g, f"gait/{k}", br.measures[k], u, what)
        sp = res.specials
        g = f.create_group("special_points")
        put(g, "kind", [s.kind for s in sp] or np.zeros(0, "S1"), "-",
            "fold, branch_point, period_doubling, neimark_sacker or branch_end")
        put(g, "param", np.array([s.p for s in sp], float), res.unit,
            f"located value of {res.path}")
        put(g, "period", np.array([s.period for s in sp], int), "steps",
            "period of the branch the point lies on")
        put(g, "branch", np.array([s.branch for s in sp], int), "-", "index of the branch")
        put(g, "cause", [s.cause or "-" for s in sp] or np.zeros(0, "S1"), "-",
            "why a branch ends ('-' for the other kinds)")
        states(g, np.array([s.x for s in sp], float), "at the special point")
        mults(g, np.array([s.multipliers for s in sp], complex), "the branch's map there")
        for j, c in enumerate(curves):
            h = f.create_group(f"two_parameter/{j}")
            h.attrs.update(kind=c.kind, period=int(c.period), path2=c.path2, unit2=c.unit2)
            put(h, "param", c.p, res.unit, f"{res.path} at the {c.kind}")
            put(h, "param2", c.p2, c.unit2, f"{c.path2}")
            put(h, "critical_multiplier/real", np.real(c.multiplier), "-",
                "the multiplier at +1 (fold) or -1 (period doubling), real part")
            put(h, "critical_multiplier/imag", np.imag(c.multiplier), "-", "imag part")
        put(f, "stats/maps", int(res.maps), "-", "step maps integrated (plain)")
        put(f, "stats/variational_maps", int(res.variational_maps), "-",
            "step maps with the variational equations")
        put(f, "stats/wall_time", float(res.wall_time_s), "s", "continuation wall time")

    return writer


@dataclass
class ContinuationData:
    """A loaded continuation artifact (see the module docstring for the meaning).

    ``branches``: list of dicts with ``period`` (int), ``param`` (N,), ``states`` (name ->
    (N,)), ``orbit`` (name -> (N, k)), ``step_period`` (N,) [s], ``multipliers`` (N, 2n)
    complex, ``stable`` (N,) bool, ``gait`` (name -> (N,): ``step_length`` [m], ``speed``
    [m/s], ``cost_of_transport`` [-]; empty in artifacts written before).
    ``special``: dict of arrays ``kind``, ``param``, ``period``, ``branch``, ``cause``,
    ``states`` (name -> (S,)), ``multipliers`` (S, 2n).  ``curves``: list of dicts ``kind``,
    ``period``, ``param``, ``param2``, ``path2``, ``unit2``, ``multiplier``.
    ``steps_per_map``: steps of the one Poincaré map of every branch (1 a step, 2 a
    stride; 0: not recorded, an artifact written before).
    """

    path: str
    unit: str
    state_names: list
    start: float
    branches: list = field(default_factory=list)
    special: dict = field(default_factory=dict)
    curves: list = field(default_factory=list)
    steps_per_map: int = 0

    def state_at(self, value: float, branch: int = 0) -> np.ndarray:
        """The state (2n,) [rad, rad/s] of branch ``branch`` at the parameter ``value`` (in
        :attr:`unit`; linear
        interpolation between the two nearest points along the branch; a guess for a root
        finder).

        Raises
        ------
        ValueError
            ``value`` outside the branch's range.
        """
        b = self.branches[branch]
        p = b["param"]
        X = np.column_stack([b["states"][n] for n in self.state_names])
        best = None
        for i in range(len(p) - 1):
            lo, hi = sorted((p[i], p[i + 1]))
            if lo <= value <= hi:
                lam = 0.0 if hi == lo else (value - p[i]) / (p[i + 1] - p[i])
                cand = (1 - lam) * X[i] + lam * X[i + 1]
                best = cand if best is None else best
        if best is None:
            if len(p) == 1 and p[0] == value:
                return X[0]
            raise ValueError(f"{value:g} {self.unit} is outside the branch's range "
                             f"{float(np.min(p)):g}..{float(np.max(p)):g}")
        return best


def _s(v) -> str:
    return v.decode() if isinstance(v, bytes) else str(v)


@artifact_loader(STAGE)
def load_continuation(f, path: Path) -> ContinuationData:
    """Read a ``continuation`` artifact."""
    names = [_s(n) for n in f.attrs["state_names"]]
    out = ContinuationData(_s(f.attrs["parameter_path"]), _s(f.attrs["parameter_unit"]),
                           names, float(f.attrs["parameter_start"]),
                           steps_per_map=int(f.attrs.get("steps_per_map", 0)))

    def mult(g):
        return np.asarray(g["multipliers/real"][()]) + 1j * np.asarray(
            g["multipliers/imag"][()])

    for key in sorted(f["branches"], key=int):
        g = f["branches"][key]
        out.branches.append({
            "period": int(g.attrs["branch_period"]), "param": g["param"][()],
            "states": {n: g[f"state/{n}"][()] for n in names},
            "orbit": {n: g[f"orbit/{n}"][()] for n in names},
            "step_period": g["period"][()], "multipliers": mult(g),
            "stable": g["stable"][()].astype(bool),
            "gait": {k: g[f"gait/{k}"][()] for k in GAIT_MEASURES
                     if f"gait/{k}" in g}})
    g = f["special_points"]
    out.special = {k: np.asarray(read_named(g, k)) for k in
                   ("kind", "param", "period", "branch", "cause")}
    out.special["kind"] = np.array([_s(k) for k in np.atleast_1d(out.special["kind"])])
    out.special["cause"] = np.array([_s(k) for k in np.atleast_1d(out.special["cause"])])
    out.special["states"] = {n: g[f"state/{n}"][()] for n in names}
    out.special["multipliers"] = mult(g)
    for key in sorted(f.get("two_parameter", {}), key=int):
        h = f["two_parameter"][key]
        out.curves.append({
            "kind": _s(h.attrs["kind"]), "period": int(h.attrs["period"]),
            "path2": _s(h.attrs["path2"]), "unit2": _s(h.attrs["unit2"]),
            "param": h["param"][()], "param2": h["param2"][()],
            "multiplier": h["critical_multiplier/real"][()]
            + 1j * h["critical_multiplier/imag"][()]})
    return out


def initial_state(spec, state_names: list[str] | None = None):
    """The state (2n,) a scene's ``StateSpec`` names, in the order of ``state_names``: by
    name, or read from a continuation artifact (``{from: runs/x/continuation_<field>.h5,
    at: 0.27, branch: 0}``, :class:`walkerlab.config.studies.GuessFromArtifact`).

    Parameters
    ----------
    spec : walkerlab.config.studies.StateSpec
    state_names : list of str, optional
        The walker's ``state_names()``.

    Returns
    -------
    ndarray, shape (2n,)
        [rad, rad/s].

    Raises
    ------
    ValueError
        Artifact missing or damaged, ``at`` off the branch, or other state names (one line).
    """
    from walkerlab.io.artifacts import ArtifactError

    source = spec.artifact
    if source is None:
        return spec.as_array(state_names)
    try:
        data = load_continuation(Path(source.from_))
    except ArtifactError as exc:
        raise ValueError(str(exc)) from None
    return source.pick(data, state_names)
