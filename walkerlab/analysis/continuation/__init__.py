"""Continuation of gaits: the map a continuation follows, pseudo-arclength branches, special
points and their validity, two-parameter curves and homotopy between walkers."""
