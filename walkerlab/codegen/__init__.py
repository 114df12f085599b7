"""Generated code of a walker: symbolic derivation (sympy) of the rigid and floating views,
python / numba source, and the one importer and disk cache of generated modules
(:mod:`walkerlab.codegen.cache`).  Built on :mod:`walkerlab.walker`; no module-level state
besides the cache's memo."""
