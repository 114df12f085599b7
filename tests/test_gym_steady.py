"""The native vector environment's steady control period (:mod:`walkerlab.gym.rows_steady`):
a common period after one whose every walker settled at its piece's end reuses what that
period wrote instead of reading the walkers again; it must give ``gymnasium.make_vec(...,
"sync")``'s numbers bit for bit, and fall back on the common period whenever a walker may
have changed (a heel strike, a fall, a reset, ``set_attr``); and the rewards and flags it
returns uncopied stay the caller's.

Compared exactly (no tolerance): ``gym.make``'s environment advances its walker with the
same kernel as a batch of one (tests/test_gym_vector.py), so sync's numbers are the native
form's bit for bit.
"""

import numpy as np
import pytest

gym = pytest.importorskip("gymnasium")

from tests.test_gym_vector import _native, _run, _same, _vec  # noqa: E402


def _count_steady(monkeypatch) -> dict:
    """Count the steady periods run (``ran``), those that fell back (``back``) and those
    whose rows did not all settle (``slow``: a guard crossing taken from the steady
    period)."""
    from walkerlab.gym import rows_steady

    counts = {"ran": 0, "back": 0, "slow": 0}
    period, slow_period = rows_steady._Steady.period, rows_steady.slow_period

    def counted(self, *args):
        out = period(self, *args)
        counts["ran" if out is not None else "back"] += 1
        return out

    def slow(*args):
        counts["slow"] += 1
        return slow_period(*args)

    monkeypatch.setattr(rows_steady._Steady, "period", counted)
    monkeypatch.setattr(rows_steady, "slow_period", slow)
    return counts


@pytest.mark.parametrize("policy, scale", [("scene", 0.3), (None, 0.0)],
                         ids=["controller_random_actions", "zero_actions"])
def test_steady_periods_equal_sync_through_heel_strikes_falls_and_resets(
        monkeypatch, policy, scale):
    """8 three-link walkers: the scene's controller under random actions (torques on in
    every row; one row held at zero for a stretch: on in the others only), or no
    controller and zero actions (no torque: the benchmark's case), walker 0 pushed for 10
    periods twice (without the controller it falls: autoresets of one walker), the time
    limit 70 (truncations, resets of every walker at once).  Over 260 periods a third or more
    steady (guard crossings among them: their rows taken as the common period takes them),
    every output (observations, rewards, flags, infos) is sync's exactly, heel strikes,
    truncations (and falls) met; a ``set_attr`` half-way is read by the next period (the
    steady one falls back)."""
    counts = _count_steady(monkeypatch)
    n, steps = 8, 260
    kw = dict(start_noise=0.05, max_episode_steps=70, policy=policy)
    sync = _vec("sync", n, "threelink_hzd", **kw)
    native = _native(n, "threelink_hzd", **kw)
    rng = np.random.default_rng(21)
    actions = (scale * rng.uniform(-1.0, 1.0, (steps, n, 2))).astype(np.float32)
    actions[40:60, 3] = 0.0  # (with random actions: torques on in the other rows only)
    actions[100:110, 0] = actions[200:210, 0] = 1.0  # (walker 0 pushed)
    half = steps // 2
    a = _run(sync, actions[:half], 5)
    b = _run(native, actions[:half], 5)
    for env in (sync, native):
        env.set_attr("weights", [(1.0, 0.5, 1e-3, 0.0)] * n)
    a += [sync.step(act) for act in actions[half:]]
    b += [native.step(act) for act in actions[half:]]
    assert len(a) == len(b)
    for k, (x, y) in enumerate(zip(a, b, strict=True)):
        for j, (u, v) in enumerate(zip(x, y, strict=True)):
            _same(u, v, f"output {k}, item {j}")
    outs = b[1:]
    terms = np.array([o[2] for o in outs])
    assert np.array([o[3] for o in outs]).any() and (terms.any() or policy == "scene")
    assert sum(int(o[4]["heel_strike"].sum()) for o in outs) > n
    assert counts["ran"] > steps // 3 and counts["back"] > 0 and counts["slow"] > 0
    sync.close()
    native.close()


def test_a_steps_arrays_stay_as_returned_through_later_steps_and_resets():
    """The rewards and flags a step returns are the caller's (not copied again: the vector
    env copies them before it writes, ``_own``): through later steps, a walker's fall and
    its reset on the next step (rows written in place), the time limit and a partial
    ``reset``, every array returned stays as it was returned."""
    env = _native(3, "threelink_hzd", max_episode_steps=40, policy=None)
    env.reset(seed=2)
    actions = np.zeros((90, 3, 2), np.float32)
    actions[:, 0] = 1.0  # (walker 0 pushed over: it falls, the others walk on)
    kept = []
    for t, a in enumerate(actions):
        out = env.step(a)
        kept.append((out[:4], [x.copy() for x in out[:4]]))
        if t == 60:
            env.reset(options={"reset_mask": np.array([False, True, False])})
        for got, copy in kept:
            for x, y in zip(got, copy, strict=True):
                np.testing.assert_array_equal(x, y)
    steps = [o for o, _ in kept]
    terms = np.array([o[2] for o in steps])
    assert terms[:, 0].any() and not terms[:, 1:].any() and np.array([o[3] for o in steps]).any()
    env.close()
