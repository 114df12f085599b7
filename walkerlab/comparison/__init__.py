"""Comparisons of stored results, the paper's Section 5: the gait metrics of Table 3 from
sampled trajectories (``tables``), the errors of the contact model against the rigid one,
time- and phase-aligned (``errors``), and the numbers the report prints beside the published
ones (``report_numbers``).  Above ``analysis/`` (it uses its checks), below the stages."""
