"""The one executor protocol (walkerlab.execution): chains keep their order and carry, every
executor gives the same results, an error in a job reaches the caller."""

from __future__ import annotations

import pytest

from walkerlab.execution.executor import InlineExecutor, make_executor, run_chains, run_each


def _add(job, carry):
    """Job of a chain: the running sum of the chain's numbers so far."""
    total = (carry or 0) + job
    return total, total


def _square(x):
    return x * x


def _fail(x):
    raise ValueError(f"bad job {x}")


CHAINS = [[1, 2, 3], [], [10, 20], [5]]


def test_inline_runs_each_chain_to_its_end_before_the_next():
    """In this process a chain's next job goes before another chain's first (as the sweep's
    in-process runner always did), each job starting from its predecessor's carry."""
    with InlineExecutor() as ex:
        got = list(run_chains(ex, _add, CHAINS, [100, None, None, None]))
    assert [(c, k) for c, k, _, _ in got] == [(0, 0), (0, 1), (0, 2), (2, 0), (2, 1), (3, 0)]
    assert [out for _, _, out, _ in got] == [101, 103, 106, 10, 30, 5]


def test_inline_runs_its_initializer_once_in_this_process():
    seen = []
    with InlineExecutor(seen.append, ("warm",)) as ex:
        assert list(run_each(ex, _square, [(2,), (3,)])) == [(0, 4), (1, 9)]
    assert seen == ["warm"]


def test_process_pool_gives_the_inline_results():
    """Same chains on two worker processes: the same outputs per (chain, position), in
    whatever order they finish."""
    with make_executor(2) as ex:
        pooled = {(c, k): out for c, k, out, _ in run_chains(ex, _add, CHAINS)}
    with make_executor(1) as ex:
        inline = {(c, k): out for c, k, out, _ in run_chains(ex, _add, CHAINS)}
    assert pooled == inline and len(inline) == 6


@pytest.mark.parametrize("workers", [1, 2])
def test_a_failing_job_raises_in_the_caller(workers):
    with make_executor(workers) as ex, pytest.raises(ValueError, match="bad job 3"):
        list(run_each(ex, _fail, [(3,)]))
