"""The suite's ``xdist_group`` marks take effect (timing tests alone, shared references once).

pytest-xdist's ``--dist loadgroup`` sends tests of one group to one worker by suffixing their
node ids with ``@group``; pytest 9.2 moved the node id out of the attribute pytest-xdist 3.8
writes, and the marks were silently ignored (pyproject pins ``pytest<9.2``).
"""

import os

import pytest


@pytest.mark.xdist_group("probe")
def test_grouped_node_id_carries_its_group(request):
    # on a worker, pytest-xdist sets ``option.loadgroup`` (and ``dist`` to "no")
    on_grouped_worker = getattr(request.config.option, "loadgroup", False)
    if "PYTEST_XDIST_WORKER" not in os.environ or not on_grouped_worker:
        pytest.skip("only meaningful on pytest-xdist workers with --dist loadgroup")
    assert request.node.nodeid.endswith("@probe"), request.node.nodeid
