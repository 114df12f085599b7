"""Drop test of the IMPACT contact: coefficient of restitution against stiffness.

A point mass ``m`` moving down at ``v_in`` meets flat ground governed by the IMPACT law
(:func:`walkerlab.models.contact.laws.impact_normal_force`, the law the walker's kernel compiles)
under gravity; the coefficient of restitution is ``e = v_out / v_in`` with ``v_out`` the upward
speed at separation (force back to zero).  A plastic impact (the rigid model's heel strike)
has ``e = 0``.  :func:`restitution_curve` sweeps the stiffness in the paper's family (damping
fixed) and in the rigid-limit family (:mod:`walkerlab.models.contact.rigid_limit`).

Each drop integrates on CyRK's Radau (``CyRK.pysolve_ivp``: scipy's Radau IIA ported to
C++, the separation located as an event) with a plain-Python right-hand side
(:func:`walkerlab.models.contact.laws.impact_normal_force_scalar`), its restitutions within
~1e-11 relative of scipy's Radau (rtol 1e-10).  A drop is computed once per contact law,
mass, speed, gravity and tolerance and kept in the private user cache (``drop/<key>.json``;
the key also hashes the sources that decide the numbers and the installed CyRK); a damaged
or foreign entry is a miss.
"""

from __future__ import annotations

from functools import lru_cache
from pathlib import Path

import numpy as np

from walkerlab.config.contact import ContactSettings
from walkerlab.integrate.events import Event, run_to_event
from walkerlab.integrate.solver import Solver
from walkerlab.models.contact.laws import impact_normal_force_scalar
from walkerlab.models.contact.rigid_limit import contact_si

__all__ = ["FAMILIES", "drop_restitution", "restitution_curve"]

FAMILIES = ("paper", "rigid_limit")


def drop_restitution(contact: ContactSettings, mass_kg: float = 20.0, v_in_m_per_s: float = 0.3,
                     g: float = 0.0, rtol: float = 1e-10) -> dict:
    """Coefficient of restitution of one drop.

    Parameters
    ----------
    contact : ContactSettings
        Contact law (its ``stiffness_family`` applies).
    mass_kg : float
        Dropped mass [kg] (default 20 kg = the paper walker's total mass).
    v_in_m_per_s : float
        Downward speed at first contact [m/s].
    g : float
        Gravity [m/s^2] during the impact (default 0: the impact alone, as in the issue's
        numbers; with g the static weight holds a soft contact down).
    rtol : float
        Integrator tolerance (CyRK's Radau with events).

    Returns
    -------
    dict
        ``restitution`` [-] (0 if the mass comes to rest in contact within 50 contact
        times), ``max_penetration_m`` [m], ``contact_time_s`` [s].
    """
    c = contact_si(contact)[0]
    key = _cache_key(c, mass_kg, v_in_m_per_s, g, rtol)
    cached = _cached(key)
    if cached is not None:
        return cached
    out = _drop(c, float(mass_kg), float(v_in_m_per_s), float(g), float(rtol))
    _store(key, out)
    return out


#: the sources whose code decides a drop's numbers (part of the cache key)
_SOURCES = ("analysis/contact/drop.py", "models/contact/laws.py", "integrate/events.py",
            "integrate/solver.py")


@lru_cache(maxsize=1)
def _code_version() -> bytes:
    """The installed CyRK integrator (its compiled solver module's name, size and time: a
    stat, where CyRK's version string reads the package metadata and
    ``CyRK.__version__`` imports numba) and the deciding sources (read once per process)."""
    import importlib.util

    spec = importlib.util.find_spec("CyRK")
    where = Path(spec.origin).parent / "cy" if spec and spec.origin else None
    libs = sorted(where.glob("pysolver.*")) if where and where.is_dir() else []
    stamp = [(p.name, p.stat().st_size, p.stat().st_mtime_ns) for p in libs]
    root = Path(__file__).resolve().parents[2]
    return repr(("CyRK", stamp)).encode() + b"".join(
        (root / rel).read_bytes() for rel in _SOURCES)


def _cache_key(c, mass_kg, v_in, g, rtol) -> str:
    """sha256 of the drop's numbers (exact reprs), the deciding sources and CyRK's build."""
    import hashlib

    h = hashlib.sha256(repr((float(c.k), float(c.e), float(c.cmax), float(c.dmax),
                             float(mass_kg), float(v_in), float(g), float(rtol))).encode())
    h.update(_code_version())
    return h.hexdigest()[:32]


def _cached(key: str) -> dict | None:
    """A drop computed before with the same key, from the private user cache (``drop/``)."""
    import json

    from walkerlab.usercache import private_dir, read_private

    d = private_dir("drop")
    text = None if d is None else read_private(d / f"{key}.json")
    if text is None:
        return None
    try:
        out = json.loads(text)
    except ValueError:
        return None
    return out if isinstance(out, dict) and set(out) == set(_KEYS) else None


def _store(key: str, out: dict) -> None:
    import json

    from walkerlab.usercache import private_dir, write_private

    d = private_dir("drop", writable=True)
    if d is not None:  # a cache that cannot be written: computed again next time
        write_private(d / f"{key}.json", json.dumps(out))


_KEYS = ("restitution", "max_penetration_m", "contact_time_s")


def _drop(c, mass_kg: float, vin: float, g: float, rtol: float) -> dict:
    """One drop of the point mass on the SI law ``c`` (:func:`drop_restitution`)."""
    dstar = ((c.e + 1) * mass_kg * vin**2 / (2 * c.k)) ** (1 / (c.e + 1))
    tc = dstar / vin

    k, e, cmax, dmax = float(c.k), float(c.e), float(c.cmax), float(c.dmax)

    def f(t, y):
        d, dd = y.tolist()
        return np.array((dd, g - impact_normal_force_scalar(d, dd, k, e, cmax, dmax) / mass_kg))

    separation = Event("separation", lambda t, y: y[0] if t > 0 else 1.0, -1)
    solver = Solver("Radau", rtol, [1e-6 * dstar, 1e-6 * vin], max_step_s=tc / 10,
                    backend="cyrk")
    run = run_to_event(f, [0.0, vin], 50 * tc, solver, [separation])
    penetration, _rate = run.y  # the point mass's state [delta (m), d delta/dt (m/s)]
    dmax = float(np.max(penetration))
    if run.event == "separation":
        vout = -float(run.y_event[1])
        return {"restitution": max(vout, 0.0) / vin, "max_penetration_m": dmax,
                "contact_time_s": run.t_event}
    return {"restitution": 0.0, "max_penetration_m": dmax, "contact_time_s": float("nan")}


def restitution_curve(base: ContactSettings, stiffness, families=FAMILIES, **kw) -> dict:
    """Restitution of the drop test for each stiffness in each family, the stiffnesses in
    the unit ``base`` writes its stiffness in (``N/mm^e`` or ``N/m^e``).

    Returns
    -------
    dict
        ``stiffness`` (n,) and per family ``{family: {"restitution": (n,),
        "max_penetration_m": (n,), "contact_time_s": (n,)}}``.
    """
    ks = np.asarray(stiffness, float)
    out: dict = {"stiffness": ks}
    unit = base.written("stiffness")[1]
    for fam in families:
        family = base.model_copy(update={"stiffness_family": fam})
        rows = [drop_restitution(family.with_written("stiffness", float(k), unit), **kw)
                for k in ks]
        out[fam] = {key: np.array([r[key] for r in rows]) for key in rows[0]}
    return out
