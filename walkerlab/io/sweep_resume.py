"""Resume bookkeeping of a partial sweep file (:mod:`walkerlab.io.sweep_store`): the rows'
and the chain checkpoints' hashes, and which rows a resumed sweep keeps.

Resume bookkeeping of the partial file::

    /points/row_hash       (n,) str, SHA-256 of the row's columns and the input hash
    /plan/index            (n_points,) int64, grid indices in chain order (the chunk plan
                           fixed when the sweep started: it does not depend on what is done)
    /plan/chain_start      (n_chains + 1,) int64, offsets of each chain in plan/index
    /plan/done             (n_chains,) int64, points of each chain whose rows are written
    /plan/guess            (n_chains,) str, JSON of the continuation after them
    /plan/check            (n_chains,) str, SHA-256 of chain, done, guess and input hash

A resumed sweep recomputes the hashes: a row that does not match (edited, damaged) and every
row of a chain whose checkpoint does not match are dropped, and that chain is computed again
from its start; an intact chain continues from its checkpoint with the stored continuation,
so a resumed sweep writes the same rows, bit for bit, as an uninterrupted one.
"""

from __future__ import annotations

import hashlib
from pathlib import Path

import h5py
import numpy as np

__all__ = ["BOOKKEEPING", "STR", "chain_check", "datasets", "keep_intact", "read_rows",
           "row_hashes", "write_plan"]

#: Variable-length UTF-8 string dtype of the string columns.
STR = h5py.string_dtype()

#: Columns that are bookkeeping, not a row's content (not hashed).
BOOKKEEPING = ("row_hash",)


def datasets(g: h5py.Group) -> dict[str, h5py.Dataset]:
    """Every dataset under ``g`` by relative name (``param/<path>`` included)."""
    out: dict[str, h5py.Dataset] = {}
    g.visititems(lambda name, obj: out.__setitem__(name, obj)
                 if isinstance(obj, h5py.Dataset) else None)
    return out


def row_hashes(columns: dict[str, np.ndarray], key: str) -> list[str]:
    """SHA-256 (hex) of each row: every column's value by name, and the input hash ``key``.

    Parameters
    ----------
    columns : dict
        Column name -> (n,) array (numbers or strings), as stored under ``/points``.
    key : str
        The sweep's input hash (a row of another sweep does not match).
    """
    names = sorted(c for c in columns if c not in BOOKKEEPING)
    n = len(columns[names[0]]) if names else 0
    cols = []
    for c in names:
        a = np.asarray(columns[c])
        if a.dtype.kind in "OSU":
            cols.append([(x.decode() if isinstance(x, bytes) else str(x)).encode() for x in a])
        else:
            a = np.ascontiguousarray(a, dtype=a.dtype.newbyteorder("<"))
            cols.append([v.tobytes() for v in a])
    out = []
    for i in range(n):
        h = hashlib.sha256(key.encode())
        for c, col in zip(names, cols):
            b = col[i]
            h.update(f"{c}:{len(b)}:".encode())
            h.update(b)
        out.append(h.hexdigest())
    return out


def chain_check(chain: int, done: int, guess: str, key: str) -> str:
    """SHA-256 (hex) of a chain's checkpoint: the input hash ``key``, the chain number, the
    points done and the continuation's JSON ``guess``."""
    return hashlib.sha256(f"{key}|{chain}|{done}|{guess}".encode()).hexdigest()


def read_checkpoints(f: h5py.File, n_chains: int) -> tuple[np.ndarray, list[str], list[str]]:
    """Points done, continuation JSON and check of each chain of an open partial file
    (rewritten as chains advance); unreadable ones are replaced: every chain restarts.

    Returns
    -------
    (done, guesses, checks) : ndarray of int64 shape (n_chains,), list of str, list of str
        Empty lists (and zeros) when the checkpoints are missing or unreadable.
    """
    try:
        return (f["plan/done"][()],
                [x.decode() if isinstance(x, bytes) else str(x) for x in f["plan/guess"][()]],
                [x.decode() if isinstance(x, bytes) else str(x) for x in f["plan/check"][()]])
    except (KeyError, ValueError, OSError):
        for name in ("plan/done", "plan/guess", "plan/check"):
            if name in f:
                del f[name]
        f.create_dataset("plan/done", data=np.zeros(n_chains, np.int64))
        f.create_dataset("plan/guess", data=np.array(["null"] * n_chains, dtype=object),
                         dtype=STR)
        f.create_dataset("plan/check", data=np.array(["?"] * n_chains, dtype=object),
                         dtype=STR)
        return np.zeros(n_chains, np.int64), [], []


def intact_chains(plan: list[list[int]], checkpoints: tuple, valid: set[int],
                   present: set[int], input_hash: str, parse_guess):
    """The chains that continue from their checkpoint: ``(start, keep, restarted)`` with
    ``start`` chain -> (points done, continuation), ``keep`` the grid indices of their rows
    and ``restarted`` the number of chains with rows that start again."""
    ndone, guesses, checks = checkpoints
    start: dict = {}
    keep_idx: set[int] = set()
    restarted = 0
    for c, chain in enumerate(plan):
        n = int(ndone[c]) if c < len(ndone) else 0
        ok = (c < len(checks) and 0 <= n <= len(chain)
              and checks[c] == chain_check(c, n, guesses[c], input_hash)
              and all(i in valid for i in chain[:n]))
        if ok and n > 0:
            try:
                start[c] = (n, parse_guess(guesses[c]))
            except (ValueError, KeyError, TypeError):
                ok = False
        if ok:
            keep_idx.update(chain[:n])
        elif any(i in present for i in chain):
            restarted += 1
    return start, keep_idx, restarted


def drop_rows(f: h5py.File, dsets: dict, cols: dict, keep: np.ndarray, restart: list[int],
               input_hash: str) -> None:
    """Keep only the rows ``keep`` of every column and reset the checkpoints of the chains
    ``restart`` (they are computed again from their start).

    ``keep``: bool mask of shape (n,) over the rows of the columns ``cols`` (each (n,));
    ``restart``: chain numbers.
    """
    for name, ds in dsets.items():
        v = cols[name][keep]
        ds.resize((int(keep.sum()),))
        ds[...] = v
    for c in restart:
        f["plan/done"][c] = 0
        f["plan/guess"][c] = "null"
        f["plan/check"][c] = chain_check(c, 0, "null", input_hash)
    f.flush()


def write_plan(f: h5py.File, plan: list[list[int]], input_hash: str) -> None:
    """Store the chunk plan (``plan``: the chains of grid indices, in evaluation order) in a
    new partial file, every chain's checkpoint at its start."""
    idx = np.array([i for c in plan for i in c], np.int64)
    f.create_dataset("plan/index", data=idx)
    f.create_dataset("plan/chain_start",
                     data=np.cumsum([0] + [len(c) for c in plan]).astype(np.int64))
    f.create_dataset("plan/done", data=np.zeros(len(plan), np.int64))
    f.create_dataset("plan/guess", data=np.array(["null"] * len(plan), dtype=object),
                     dtype=STR)
    f.create_dataset("plan/check", data=np.array(
        [chain_check(c, 0, "null", input_hash) for c in range(len(plan))], dtype=object),
        dtype=STR)


def read_rows(f: h5py.File) -> tuple[dict, dict, np.ndarray, list[list[int]]]:
    """The rows of an open partial file and its plan: ``(datasets, columns, index, plan)``
    (``datasets``: name -> h5py dataset under ``/points``; ``columns``: name -> (n,) array;
    ``index``: (n,) grid indices; ``plan``: the chains of grid indices as planned).

    Raises
    ------
    KeyError, ValueError, OSError
        A damaged file.
    """
    g = f["points"]
    dsets = datasets(g)
    cols = {name: ds[()] for name, ds in dsets.items()}
    idx = np.asarray(cols["index"], np.int64)
    starts = f["plan/chain_start"][()]
    order = f["plan/index"][()]
    plan = [[int(i) for i in order[a:b]] for a, b in zip(starts[:-1], starts[1:])]
    return dsets, cols, idx, plan


def keep_intact(f: h5py.File, dsets: dict, cols: dict, idx: np.ndarray,
                plan: list[list[int]], input_hash: str, parse_guess, part: Path,
                tell=None) -> dict:
    """Check every row's and chain checkpoint's hash of the open partial file ``part`` and
    drop the rows that do not continue (a damaged row, the rows of a chain whose checkpoint
    does not match, a row past its chain's checkpoint); ``tell`` receives a one-line note
    of dropped rows.

    Returns
    -------
    dict
        Chain number -> ``(points done, continuation)`` for every chain that continues from
        its checkpoint (``parse_guess`` reads the continuation's JSON); the other chains
        start again.
    """
    ndone, guesses, checks = read_checkpoints(f, len(plan))
    stored = [x.decode() if isinstance(x, bytes) else str(x) for x in cols["row_hash"]]
    good_row = np.array([a == b for a, b in zip(row_hashes(cols, input_hash), stored)],
                        bool)
    valid = {int(i) for i, ok in zip(idx, good_row) if ok}
    start, keep_idx, restarted = intact_chains(
        plan, (ndone, guesses, checks), valid, set(idx.tolist()), input_hash, parse_guess)
    keep = np.array([int(i) in keep_idx for i in idx], bool)
    # one row per index: a chain's rows past its checkpoint are computed again
    _, first = np.unique(idx, return_index=True)
    once = np.zeros(idx.size, bool)
    once[first] = True
    keep &= once
    bad = int(np.sum(~good_row))
    if bad or restarted:
        msg = (f"{part}: {bad} row(s) failed their integrity check; " if bad
               else f"{part}: ")
        msg += (f"{restarted} chain(s) of points will be computed again from their start "
                f"({int(np.sum(~keep))} row(s) dropped)")
        if tell is not None:
            tell(msg)
    if not keep.all():
        drop_rows(f, dsets, cols, keep, [c for c in range(len(plan)) if c not in start],
                  input_hash)
    return start
