"""A reader of exactly the Adams Solver subset :mod:`walkerlab.export.adams` writes.

Not a general Adams parser: it reads the statements and arguments of :data:`ADM_SUBSET`
(and the commands of :data:`ACF_SUBSET`) and refuses anything else in one line.

Syntax read (Adams Solver statement reference): the dataset's first line is its title; ``!``
starts a comment; a line starting with ``,`` continues the statement above; a statement is
``NAME/id, ARG=value, ..., FLAG, ...`` (or ``NAME/ARG=value, ...`` for ``UNITS``,
``ACCGRAV``, ``OUTPUT``); a value is one or more comma-separated numbers (``QP=1, 2, 3``),
a function expression (commas inside parentheses belong to it; ``\\`` ends one in
``REQUEST``) or a word; a number followed by ``D`` is in degrees.  Keywords are read
case-insensitively.

Semantics (what :class:`AdmModel` computes, in SI):

- ``UNITS``: FORCE NEWTON, MASS KILOGRAM or GRAM, LENGTH MILLIMETER, CENTIMETER or METER,
  TIME SECOND (others refused);
- ``PART`` ``QG`` is its frame's origin in ground, ``REULER = a, b, c`` body-fixed 3-1-3
  angles: ``R = Rz(a) Rx(b) Rz(c)`` (columns: the part's axes in ground);
- ``MARKER`` ``QP``/``REULER`` are in its part's frame (ground markers: in ground);
- ``IP = xx, yy, zz[, xy, xz, yz]`` is the inertia about the CM marker's origin in the CM
  marker's axes (products as positive integrals: the tensor holds ``-xy``);
- ``VX``, ``VY``, ``VZ``: the CM marker's velocity along ground axes; ``WX``, ``WY``,
  ``WZ``: the angular velocity along the CM marker's axes.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field

import numpy as np

__all__ = ["ACF_SUBSET", "ADM_SUBSET", "AdmModel", "AdmReadError", "Statement", "parse_acf",
           "parse_adm", "read_adm", "reuler_matrix"]

#: Statements the reader knows, with their arguments and flags (Adams Solver statement
#: reference names).
ADM_SUBSET = {
    "UNITS": {"FORCE", "MASS", "LENGTH", "TIME"},
    "PART": {"GROUND", "MASS", "CM", "IP", "QG", "REULER", "VX", "VY", "VZ", "WX", "WY",
             "WZ"},
    "MARKER": {"PART", "QP", "REULER", "FLOATING"},
    "JOINT": {"REVOLUTE", "FIXED", "PLANAR", "SPHERICAL", "UNIVERSAL", "I", "J"},
    "JPRIM": {"PARALLEL_AXES", "PERPENDICULAR", "I", "J"},
    "ACCGRAV": {"IGRAVITY", "JGRAVITY", "KGRAVITY"},
    "GRAPHICS": {"ELLIPSOID", "CYLINDER", "LENGTH", "RADIUS", "CM", "XSCALE", "YSCALE",
                 "ZSCALE", "BOX", "CORNER", "X", "Y",
                 "Z"},
    "CONTACT": {"IGEOM", "JGEOM", "IMPACT", "STIFFNESS", "DAMPING", "DMAX", "EXPONENT",
                "COULOMB_FRICTION", "MU_STATIC", "MU_DYNAMIC",
                "STICTION_TRANSITION_VELOCITY", "FRICTION_TRANSITION_VELOCITY"},
    "SPRINGDAMPER": {"ROTATIONAL", "I", "J", "KT", "CT", "ANGLE"},
    "SFORCE": {"ROTATION", "I", "J", "FUNCTION"},
    "COUPLER": {"JOINTS", "TYPE", "SCALES"},
    "GFORCE": {"I", "JFLOAT", "RM", "FX", "FY", "FZ", "TX", "TY", "TZ"},
    "VARIABLE": {"FUNCTION"},
    "REQUEST": {"F2", "F3", "F4", "F6", "F7", "F8"},
    "OUTPUT": {"REQSAVE", "GRSAVE"},
    "END": set(),
}
#: Commands of the .acf the reader knows.
ACF_SUBSET = {"SIMULATE": {"INITIAL_CONDITIONS", "DYNAMICS", "END", "STEPS"},
              "DEACTIVATE": {"JOINT", "ID"}, "STOP": set()}

_LENGTH = {"MILLIMETER": 1e-3, "CENTIMETER": 1e-2, "METER": 1.0}
_MASS = {"KILOGRAM": 1.0, "GRAM": 1e-3}


class AdmReadError(ValueError):
    """A dataset outside the subset, or inconsistent (one line: statement and argument)."""


@dataclass(frozen=True)
class Statement:
    """One statement: ``name`` (``PART``), ``id`` (None for ``UNITS`` etc.), ``args``
    (keyword -> raw value strings) and ``flags`` (bare words: ``GROUND``, ``REVOLUTE``)."""

    name: str
    id: int | None
    args: dict = field(default_factory=dict)
    flags: tuple = ()

    def numbers(self, key: str, default=None) -> tuple[float, ...]:
        """The numbers of ``key`` (degrees with ``D`` in radians)."""
        if key not in self.args:
            if default is None:
                raise AdmReadError(f"{self.name}/{self.id}: {key} missing")
            return tuple(default)
        try:
            return tuple(_number(v) for v in self.args[key])
        except ValueError:
            raise AdmReadError(f"{self.name}/{self.id}: {key}={','.join(self.args[key])} "
                               "is not a number") from None

    def number(self, key: str, default: float | None = None) -> float:
        """The first number of ``key`` (``default`` if absent; none: :class:`AdmReadError`)."""
        return self.numbers(key, None if default is None else (default,))[0]

    def integer(self, key: str) -> int:
        """An id argument (``CM=301``) as an int."""
        return int(self.number(key))


def _number(tok: str) -> float:
    tok = tok.strip().upper()
    if tok.endswith("D"):
        return math.radians(float(tok[:-1]))
    return float(tok)


def _split(body: str, seps: str = ",\\") -> list[str]:
    """Split at separators outside parentheses."""
    out, depth, cur = [], 0, []
    for ch in body:
        depth += (ch == "(") - (ch == ")")
        if ch in seps and depth == 0:
            out.append("".join(cur).strip())
            cur = []
        else:
            cur.append(ch)
    out.append("".join(cur).strip())
    return [t for t in out if t]


def _statements(lines) -> list[str]:
    """Whole statements: comments dropped, continuation lines joined."""
    out: list[str] = []
    for raw in lines:
        line = raw.split("!", 1)[0].rstrip()
        if not line.strip():
            continue
        if line.lstrip().startswith(","):
            if not out:
                raise AdmReadError("a continuation line (',') before any statement")
            out[-1] += line.lstrip()
        else:
            out.append(line.strip())
    return out


_NUMERIC = re.compile(r"^[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?[dD]?$")


def _statement(text: str, subset: dict) -> Statement:
    head, _, rest = text.partition("/")
    name = head.strip().upper()
    if name not in subset:
        raise AdmReadError(f"{name}: not a statement walkerlab's Adams reader knows "
                           f"({', '.join(subset)})")
    toks = _split(rest)
    sid = None
    if toks and re.fullmatch(r"\d+", toks[0]):
        sid = int(toks.pop(0))
    args: dict[str, list[str]] = {}
    flags, last = [], None
    for tok in toks:
        key, eq, val = tok.partition("=")
        key = key.strip().upper()
        if eq:
            if key not in subset[name]:
                raise AdmReadError(f"{name}/{sid}: argument {key} is not in the subset read")
            args[key] = [val.strip()]
            last = key
        elif _NUMERIC.match(tok) and last is not None:
            args[last].append(tok)  # QP=1, 2, 3: the further numbers of the last argument
        else:
            if key not in subset[name]:
                raise AdmReadError(f"{name}/{sid}: {tok} is not in the subset read")
            flags.append(key)
            last = None
    return Statement(name, sid, {k: tuple(v) for k, v in args.items()}, tuple(flags))


def parse_adm(text: str) -> tuple[str, list[Statement]]:
    """The title and the statements of a dataset (through ``END``).

    Raises
    ------
    AdmReadError
        A statement or argument outside :data:`ADM_SUBSET`, no ``END`` (one line).
    """
    lines = text.splitlines()
    if not lines:
        raise AdmReadError("empty dataset (the first line is its title)")
    stmts = [_statement(s, ADM_SUBSET) for s in _statements(lines[1:])]
    if not stmts or stmts[-1].name != "END":
        raise AdmReadError("the dataset does not end with END")
    return lines[0], stmts[:-1]


def parse_acf(text: str) -> list[Statement]:
    """The commands of a command file (its first two lines name the dataset and the output
    files); the last is ``STOP``.

    Raises
    ------
    AdmReadError
        A command outside :data:`ACF_SUBSET`, no ``STOP``.
    """
    cmds = [_statement(s, ACF_SUBSET) for s in _statements(text.splitlines()[2:])]
    if not cmds or cmds[-1].name != "STOP":
        raise AdmReadError("the command file does not end with STOP")
    return cmds[:-1]


def reuler_matrix(a: float, b: float, c: float) -> np.ndarray:
    """Body-fixed 3-1-3 rotation ``Rz(a) Rx(b) Rz(c)`` [rad]; columns are the rotated
    frame's axes in the reference frame."""
    def rz(t):
        return np.array([[math.cos(t), -math.sin(t), 0], [math.sin(t), math.cos(t), 0],
                         [0, 0, 1.0]])
    rx = np.array([[1.0, 0, 0], [0, math.cos(b), -math.sin(b)], [0, math.sin(b), math.cos(b)]])
    return rz(a) @ rx @ rz(c)


class AdmModel:
    """A parsed dataset and its geometry, masses and start in SI units.

    Parameters
    ----------
    statements : list of Statement
        From :func:`parse_adm`.
    """

    def __init__(self, statements: list[Statement]):
        self.statements = statements
        self.by_kind: dict[str, dict] = {}
        for s in statements:
            self.by_kind.setdefault(s.name, {})[s.id] = s
        units = self.by_kind.get("UNITS", {}).get(None)
        if units is None:
            raise AdmReadError("UNITS: missing (the reader needs the dataset's units)")
        u = {k: v[0].upper() for k, v in units.args.items()}
        if u.get("FORCE") != "NEWTON" or u.get("TIME") != "SECOND" or \
                u.get("LENGTH") not in _LENGTH or u.get("MASS") not in _MASS:
            raise AdmReadError(f"UNITS: {u} outside the subset read (NEWTON, SECOND, "
                               f"{'/'.join(_LENGTH)}, {'/'.join(_MASS)})")
        self.length = _LENGTH[u["LENGTH"]]  # metres per file length unit
        self.mass = _MASS[u["MASS"]]

    def get(self, kind: str, sid: int) -> Statement:
        """The ``kind`` statement with id ``sid``.

        Raises
        ------
        AdmReadError
            No such statement.
        """
        try:
            return self.by_kind[kind][sid]
        except KeyError:
            raise AdmReadError(f"{kind}/{sid}: referenced but not defined") from None

    def part_pose(self, pid: int) -> tuple[np.ndarray, np.ndarray]:
        """A part frame's origin [m] (3,) and rotation (3, 3) in ground."""
        p = self.get("PART", pid)
        if "GROUND" in p.flags:
            return np.zeros(3), np.eye(3)
        return (np.array(p.numbers("QG", (0, 0, 0))) * self.length,
                reuler_matrix(*p.numbers("REULER", (0, 0, 0))))

    def marker_pose(self, mid: int) -> tuple[np.ndarray, np.ndarray]:
        """A marker's origin [m] (3,) and rotation (3, 3) in ground."""
        m = self.get("MARKER", mid)
        origin, rot = self.part_pose(m.integer("PART"))
        qp = np.array(m.numbers("QP", (0, 0, 0))) * self.length
        return origin + rot @ qp, rot @ reuler_matrix(*m.numbers("REULER", (0, 0, 0)))

    def part_mass(self, pid: int) -> float:
        """[kg]."""
        return self.get("PART", pid).number("MASS", 0.0) * self.mass

    def part_inertia(self, pid: int) -> np.ndarray:
        """The inertia tensor (3, 3) about the CM [kg m^2], in ground axes."""
        p = self.get("PART", pid)
        ip = p.numbers("IP", (0, 0, 0)) + (0.0,) * 3
        xx, yy, zz, xy, xz, yz = ip[:6]
        tensor = np.array([[xx, -xy, -xz], [-xy, yy, -yz], [-xz, -yz, zz]])
        _, rot = self.marker_pose(p.integer("CM"))
        return rot @ tensor @ rot.T * self.mass * self.length ** 2

    def part_velocity(self, pid: int) -> tuple[np.ndarray, np.ndarray]:
        """The CM's velocity [m/s] (3,) and the angular velocity [rad/s] (3,) in ground."""
        p = self.get("PART", pid)
        v = np.array([p.number(k, 0.0) for k in ("VX", "VY", "VZ")]) * self.length
        w = np.array([p.number(k, 0.0) for k in ("WX", "WY", "WZ")])
        _, rot = self.marker_pose(p.integer("CM"))
        return v, rot @ w

    def gravity(self) -> np.ndarray:
        """[m/s^2] (3,)."""
        g = self.by_kind.get("ACCGRAV", {}).get(None)
        if g is None:
            raise AdmReadError("ACCGRAV: missing")
        return np.array([g.number(k, 0.0) for k in ("IGRAVITY", "JGRAVITY", "KGRAVITY")]
                        ) * self.length

    def joints(self) -> dict[int, tuple[str, int, int]]:
        """``{id: (type, I marker, J marker)}``."""
        return {j.id: (j.flags[0], j.integer("I"), j.integer("J"))
                for j in self.by_kind.get("JOINT", {}).values()}

    def functions(self, kind: str = "VARIABLE") -> dict[int, str]:
        """``{id: FUNCTION expression}`` of the ``kind`` statements that have one
        (``VARIABLE``, ``SFORCE``), the expressions as written (Adams Solver function
        syntax: ``VARVAL``, ``AZ``, ``WZ``, ``IF(e: a, b, c)``, ...)."""
        return {sid: st.args["FUNCTION"][0] for sid, st in self.by_kind.get(kind, {}).items()
                if "FUNCTION" in st.args}

    def gforce(self, gid: int) -> dict[str, str]:
        """A GFORCE's markers (``I``, ``JFLOAT``, ``RM``: ids as strings) and its six
        component expressions (``FX`` .. ``TZ``)."""
        g = self.get("GFORCE", gid)
        return {k: v[0] for k, v in g.args.items()}

    def contact_si(self, cid: int) -> dict[str, float]:
        """A CONTACT's IMPACT law and Coulomb friction in SI: ``k`` [N/m^e], ``e``, ``cmax``
        [N s/m], ``dmax`` [m], ``mu_s``, ``mu_d``, ``v_s``, ``v_d`` [m/s]."""
        c = self.get("CONTACT", cid)
        e, L = c.number("EXPONENT"), self.length
        return {"k": c.number("STIFFNESS") / L ** e, "e": e,
                "cmax": c.number("DAMPING") / L, "dmax": c.number("DMAX") * L,
                "mu_s": c.number("MU_STATIC"), "mu_d": c.number("MU_DYNAMIC"),
                "v_s": c.number("STICTION_TRANSITION_VELOCITY") * L,
                "v_d": c.number("FRICTION_TRANSITION_VELOCITY") * L}


def read_adm(text: str) -> AdmModel:
    """Parse a dataset of the subset (:func:`parse_adm`) into an :class:`AdmModel`.

    Raises
    ------
    AdmReadError
        Outside the subset, or ``UNITS`` missing / not read (one line).
    """
    return AdmModel(parse_adm(text)[1])
