"""The per-walk slope streams of the Monte Carlo walks for many walks at once: the numbers of
:func:`walkerlab.analysis.robustness.mfpt.draw_slopes` bit for bit, without a NumPy
``SeedSequence`` per walk (its construction was most of the per-walk cost outside the
compiled walks: ``scripts/bench_mfpt.py``).

Walk ``w`` of seed ``s`` draws from ``Generator(PCG64(SeedSequence(s, spawn_key=(w,))))``.
Here the ``SeedSequence`` hashing is done for all walks together on NumPy arrays: the entropy
``s`` (32-bit words, little-endian, padded with zeros to the pool size 4 because there is a
spawn key) then ``w``, mixed into a pool of 4 words by O'Neill's ``hashmix``/``mix`` and
expanded by ``generate_state(4, uint64)`` (NumPy's ``numpy/random/bit_generator.pyx``).
PCG64's state follows from those words by ``pcg_setseq_128_srandom_r`` (two steps of the
128-bit LCG, in Python integers; NumPy's ``numpy/random/src/pcg64/pcg64.h``) and is set on
one reused ``PCG64``, whose ``Generator`` draws the walk's numbers: the draws themselves are
NumPy's (ziggurat normal, uniform).

The tests compare :func:`slope_rows` with ``draw_slopes`` bit for bit (several seeds, walks,
both distributions).
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["slope_rows", "pcg64_states", "seed_words"]

_M32 = 0xFFFFFFFF
_INIT_A, _MULT_A = 0x43B0D7E5, 0x931E8875
_INIT_B, _MULT_B = 0x8B51F9DD, 0x58F38DED
_MIX_L, _MIX_R = 0xCA01F9DD, 0x4973F715
_PCG_MULT = 0x2360ED051FC65DA44385DF649FCCF645
_M128 = (1 << 128) - 1


def seed_words(value: int) -> list[int]:
    """The 32-bit words (little-endian, ``[0]`` for zero) NumPy's ``SeedSequence`` makes of
    a non-negative integer; raises ValueError for a negative one."""
    value = int(value)
    if value < 0:
        raise ValueError(f"seed {value}: a random seed must be a non-negative integer")
    out = [0] if value == 0 else []
    while value > 0:
        out.append(value & _M32)
        value >>= 32
    return out


def _hash(values: np.ndarray, hc: int) -> tuple[np.ndarray, int]:
    """``hashmix`` of the words ``values`` (uint64 holding 32-bit words) with the hash
    constant ``hc``; the next constant."""
    v = values ^ np.uint64(hc)
    hc = (hc * _MULT_A) & _M32
    v = (v * np.uint64(hc)) & np.uint64(_M32)
    return v ^ (v >> np.uint64(16)), hc


def _mix(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    r = (np.uint64(_MIX_L) * x - np.uint64(_MIX_R) * y) & np.uint64(_M32)
    return r ^ (r >> np.uint64(16))


def _generate_state(seed: int, walks: np.ndarray) -> np.ndarray:
    """``SeedSequence(seed, spawn_key=(w,)).generate_state(4, uint64)`` of every walk ``w``
    as 32-bit words: (W, 8) uint64."""
    run = seed_words(seed)
    run += [0] * (4 - len(run))
    ent = [np.full(walks.size, v, dtype=np.uint64) for v in run] + [walks.astype(np.uint64)]
    pool, hc = [], _INIT_A
    for i in range(4):
        h, hc = _hash(ent[i], hc)
        pool.append(h)
    for i_src in range(len(ent)):
        for i_dst in range(4):
            if i_src == i_dst:
                continue
            h, hc = _hash(pool[i_src] if i_src < 4 else ent[i_src], hc)
            pool[i_dst] = _mix(pool[i_dst], h)
    words, hc = np.empty((walks.size, 8), dtype=np.uint64), _INIT_B
    for i in range(8):
        v = pool[i % 4] ^ np.uint64(hc)
        hc = (hc * _MULT_B) & _M32
        v = (v * np.uint64(hc)) & np.uint64(_M32)
        words[:, i] = v ^ (v >> np.uint64(16))
    return words


def pcg64_states(seed: int, walks) -> list[tuple[int, int]]:
    """``(state, inc)`` of ``PCG64(SeedSequence(seed, spawn_key=(w,)))`` for every walk
    ``w`` in ``walks`` (128-bit integers, as ``PCG64.state["state"]``).

    Raises
    ------
    ValueError
        A negative seed, a walk number outside ``[0, 2**32)``.
    """
    w = np.asarray(list(walks), dtype=np.int64).reshape(-1)
    if w.size and (w.min() < 0 or w.max() >= 2**32):
        raise ValueError("walk numbers must be in [0, 2**32)")
    out = []
    for r in _generate_state(seed, w).tolist():
        u = [r[2 * k] | (r[2 * k + 1] << 32) for k in range(4)]  # little-endian uint64
        init_state, init_seq = (u[0] << 64) | u[1], (u[2] << 64) | u[3]
        inc = ((init_seq << 1) | 1) & _M128
        state = (((inc + init_state) & _M128) * _PCG_MULT + inc) & _M128
        out.append((state, inc))
    return out


def slope_rows(seed: int, walks, start: int, n: int, mean: float, sd: float,
               distribution: str = "normal") -> np.ndarray:
    """Slopes [rad] of steps ``start`` to ``start + n - 1`` of each walk in ``walks``: row ``i``
    is ``draw_slopes(seed, walks[i], start + n, mean, sd, distribution)[start:]`` bit for bit
    (:func:`walkerlab.analysis.robustness.mfpt.draw_slopes`).

    Parameters
    ----------
    seed : int
        Non-negative.
    walks : sequence of int
        Walk numbers, each in ``[0, 2**32)``.
    start, n : int
        First step and number of steps.
    mean, sd : float
        Mean and standard deviation of the slope [rad].
    distribution : {"normal", "uniform"}
        Uniform on ``mean -/+ sqrt(3) sd``; any other value: normal (as ``draw_slopes``).

    Returns
    -------
    ndarray, shape (len(walks), n)

    Raises
    ------
    ValueError
        A negative seed, a walk number outside ``[0, 2**32)``.
    """
    states = pcg64_states(seed, walks)
    total, start = int(start) + int(n), int(start)
    z = np.empty((len(states), total))
    bg = np.random.PCG64(0)
    gen = np.random.Generator(bg)
    half = math.sqrt(3.0) * sd
    for i, (state, inc) in enumerate(states):
        bg.state = {"bit_generator": "PCG64", "state": {"state": state, "inc": inc},
                    "has_uint32": 0, "uinteger": 0}
        if distribution == "uniform":
            z[i] = gen.uniform(mean - half, mean + half, total)
        else:
            gen.standard_normal(out=z[i])
    if distribution == "uniform":
        return z[:, start:].copy()
    return mean + sd * z[:, start:]
