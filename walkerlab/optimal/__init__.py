"""Optimal gaits: periodic hybrid gaits by direct collocation (CasADi + IPOPT).

A package of its own above :mod:`walkerlab.analysis` (it reads the walker's symbolic
equations, the rigid model and the gait analysis); design optimisation will live here too.
"""
