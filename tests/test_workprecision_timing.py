"""Work-precision timing (issue 25, item 7): CPU time of the integration alone, the Pareto
front and the fastest setting only beyond the spread of the repeats."""

import time

import numpy as np
import pytest

from walkerlab.bench.workprecision import time_case
from walkerlab.bench.workprecision_results import pareto_front


@pytest.mark.xdist_group("timing")  # CPU and wall-clock bounds
def test_time_case_ranks_by_the_integrations_cpu_time_not_wall_time():
    """A runner that waits 50 ms (wall, no CPU) outside its timed integration and spins
    ~20 ms of CPU inside: the stored CPU times are the inner ones, the wall times include
    the wait.  Bounds: thread_time's resolution is < 1 ms on Linux; the spin is >= 20 ms."""
    def runner(method, rtol, atol):
        time.sleep(0.05)  # set-up / another process's turn: not the integration
        c0 = time.thread_time()
        while time.thread_time() - c0 < 0.02:
            pass
        return np.zeros(2), 7, time.thread_time() - c0

    res = time_case(runner, "X", 1e-6, 1e-8, repeats=3)
    assert len(res["cpu_times"]) == len(res["times"]) == 3
    assert all(0.02 <= c < 0.04 for c in res["cpu_times"])
    assert all(w >= 0.07 for w in res["times"])  # 50 ms sleep + 20 ms spin
    assert res["clock"] == "thread_cpu_integration" and res["nfev"] == 7


def test_pareto_front_keeps_only_differences_beyond_the_spread():
    """Three settings: A (1.0-1.2 s, error 1e-6), B (1.1-1.3 s, error 1e-8: times overlap
    A's, more accurate) and C (3-3.1 s, error 1e-10).  By medians alone A, B and C are all
    on the front; with the spread A is indistinguishable in time from B and less accurate,
    so it is dominated: the front is B, C.  D (0.1-0.2 s, error 1e-4) is clearly faster
    than all and stays."""
    t = np.array([1.1, 1.2, 3.05, 0.15])
    lo = np.array([1.0, 1.1, 3.0, 0.1])
    hi = np.array([1.2, 1.3, 3.1, 0.2])
    e = np.array([1e-6, 1e-8, 1e-10, 1e-4])
    assert list(pareto_front(t, e)) == [3, 0, 1, 2]
    front = list(pareto_front(t, e, lo, hi))
    assert front == [3, 1, 2]
    # no two front points have overlapping time ranges
    for i, a in enumerate(front):
        for b in front[i + 1:]:
            assert hi[a] < lo[b] or hi[b] < lo[a]
    # a failed run (inf error) is never on the front
    assert 0 not in pareto_front(t, np.array([np.inf, 1e-8, 1e-10, 1e-4]), lo, hi)


def test_work_precision_labels_cover_no_label_legend_or_other_marker():
    """Seven methods x ten tolerances crowded into one decade of time (as the paper's
    ideal study is): every tolerance label that is drawn covers no other label, not the
    legend and not another setting's marker (4 px half-width)."""
    from walkerlab.plotting import figures as F

    rng = np.random.default_rng(0)
    rows = {}
    for k in range(7):
        rt = 10.0 ** -np.arange(3, 13)
        t = 0.01 * (1 + 0.3 * k) * (1 + 0.2 * np.arange(10)) * rng.uniform(0.95, 1.05, 10)
        rows[f"M{k}"] = {"rtol": rt, "time": t, "time_min": 0.9 * t, "time_max": 1.1 * t,
                         "error": rt * (1 + k), "wall_time": 2 * t}
    fig = F.work_precision(rows, "t")
    ax = fig.axes[0]
    r = fig.canvas.get_renderer()
    boxes = [t.get_window_extent(r) for t in ax.texts]
    legend = ax.get_legend().get_window_extent(r)
    assert 10 <= len(boxes) < 70  # crowded: some labels had to go
    assert not any(a.overlaps(b) for i, a in enumerate(boxes) for b in boxes[i + 1:])
    assert not any(b.overlaps(legend) for b in boxes)
    pts = ax.transData.transform(np.concatenate(
        [np.c_[d["time"], d["error"]] for d in rows.values()]))
    for t, b in zip(ax.texts, boxes):
        own = ax.transData.transform(np.asarray(t.xy, float)[None])[0]
        for px, py in pts:
            if np.hypot(px - own[0], py - own[1]) > 1e-6:  # another setting's marker
                assert not (b.x0 - 4 < px < b.x1 + 4 and b.y0 - 4 < py < b.y1 + 4)
    assert "CPU time of the integration" in ax.get_xlabel()
    F.plt.close(fig)
