"""Published reference numbers, one module per source (as PyBaMM keeps one file per parameter set).

Every number is stored once, next to its citation and the place in the source where it is
printed (equation, table, figure).  Tables, tests and the report read them from here; no other
module writes a published value literally.

Modules
-------
Each module defines ``CITATION`` (str) and its values as module-level constants with the unit
in the name or in a comment, e.g. ``walkerlab.published.garcia1998``.
"""
