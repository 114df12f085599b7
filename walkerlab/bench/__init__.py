"""Benchmarks and the work-precision study: what ``walkerlab bench`` and
``walkerlab workprecision`` time (run by :mod:`walkerlab.cli.bench` and the stages)."""
