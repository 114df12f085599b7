"""The printed inverse of a walker's mass (and impact) matrix (:func:`walkerlab.codegen.printers.
_solve_lines`): the adjugate over the determinant up to 3 x 3, LU factors above, checked
against numpy's LAPACK inverse; and the round-off of a six-coordinate walker's printed flow
(the stabilised 3D kneed walker, whose expanded 6 x 6 determinant cancelled to 1e-10)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from walkerlab.codegen.printers import ADJUGATE_MAX_N, _solve_lines

ROOT = Path(__file__).resolve().parents[1]


def _printed_inverse(A: np.ndarray, zero: np.ndarray) -> tuple[np.ndarray, list[list[str]]]:
    """Run the printed lines on ``A``'s entries (``zero``: the entries named ``"0"``, known
    to vanish); returns the inverse they compute and the inverse's entry names."""
    n = A.shape[0]
    names = [["0" if zero[i, j] else f"_M{i}{j}" for j in range(n)] for i in range(n)]
    lines, inv = _solve_lines(n, names, "_i")
    ns = {f"_M{i}{j}": float(A[i, j]) for i in range(n) for j in range(n) if not zero[i, j]}
    exec("\n".join(ln.strip() for ln in lines), {}, ns)  # noqa: S102 - our own printed code
    out = np.array([[0.0 if inv[i][j] == "0" else ns[inv[i][j]] for j in range(n)]
                    for i in range(n)])
    return out, inv


def _spd(n: int, cond: float, rng) -> np.ndarray:
    """A symmetric positive definite matrix of condition number ``cond``."""
    Q = np.linalg.qr(rng.standard_normal((n, n)))[0]
    return Q @ np.diag(np.geomspace(1.0, cond, n)) @ Q.T


@pytest.mark.parametrize("n", [2, 3, 4, 5, 6, 7])
def test_the_printed_inverse_of_a_mass_matrix_equals_lapacks_to_its_condition(n):
    """A mass matrix of condition 1.5e3 (the stabilised 3D kneed walker's): the printed
    inverse, adjugate (n <= 3) or LU factors (n > 3), equals numpy's within cond * 50 eps
    relative (a backward-stable inverse's forward error is O(cond eps); the expanded 6 x 6
    determinant's was 1e-10, 3e2 times that)."""
    rng = np.random.default_rng(n)
    A = _spd(n, 1.5e3, rng)
    got, _ = _printed_inverse(A, np.zeros((n, n), bool))
    ref = np.linalg.inv(A)
    assert np.abs(got - ref).max() / np.abs(ref).max() < 1.5e3 * 50 * np.finfo(float).eps


@pytest.mark.parametrize("n", [4, 6])
def test_entries_known_to_vanish_stay_out_of_the_printed_lu_inverse(n):
    """A block-diagonal matrix whose off-block entries are named ``"0"`` (the planar blocks of
    a walker whose roll decouples): the inverse's off-block entries are printed as ``"0"``
    (no line computes them), and the blocks equal numpy's inverse."""
    assert n > ADJUGATE_MAX_N
    rng = np.random.default_rng(7)
    k = n // 2
    A = np.zeros((n, n))
    A[:k, :k], A[k:, k:] = _spd(k, 10.0, rng), _spd(n - k, 10.0, rng)
    zero = A == 0.0
    got, inv = _printed_inverse(A, zero)
    assert all(inv[i][j] == "0" for i in range(n) for j in range(n) if zero[i, j])
    assert np.allclose(got, np.linalg.inv(A), rtol=0, atol=1e-13)


@pytest.mark.slow  # derives the stabilised 3D kneed walker (minutes on an empty cache)
def test_the_six_coordinate_kneed_walkers_flow_has_the_round_off_of_its_arithmetic():
    """The stabilised 3D kneed walker's swing flow (six coordinates, cond(M) about 1.5e3)
    along a line of 21 states 1e-12 apart: its accelerations less a quadratic fit scatter by
    less than 1e-14 of their size (measured 5e-16; the expanded determinant's inverse
    scattered by 1.3e-10, so the gait search's stride map repeated only to 1e-9)."""
    from walkerlab.config import load_scene
    from walkerlab.models.registry import build_walker
    from walkerlab.walker.plant import Plant

    sc = load_scene(ROOT / "configs" / "kneed_3d_stabilised.yaml")
    w = build_walker(Plant.from_scene(sc))
    g = sc.fixedpoint.initial_guess.model_extra
    x0 = np.array([g[s + ("_rad" if s.endswith("_angle") else "_rad_per_s")]
                   for s in w.state_names()])
    n = x0.size // 2
    assert n == 6
    v = np.random.default_rng(0).standard_normal(x0.size)
    ks = np.arange(-10, 11)
    F = np.array([w.phases[0].flow(0.0, x0 + k * 1e-12 * v) for k in ks])[:, n:]
    for j in range(n):
        scatter = np.std(F[:, j] - np.polyval(np.polyfit(ks, F[:, j], 2), ks))
        assert scatter < 1e-14 * np.abs(F[:, j]).max(), j
