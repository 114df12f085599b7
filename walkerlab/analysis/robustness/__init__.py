"""Robustness beyond ``|λ|``: local sensitivity measures, pushes, mean first-passage time and
the basin's area."""
