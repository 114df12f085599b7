"""walkerlab: a command-line lab for passive-dynamic biped walkers.

The package is split by role (see ``STYLE.md`` of the project):

- :mod:`walkerlab.config`   typed YAML scenes (pydantic, ``extra="forbid"``)
- :mod:`walkerlab.models`   walker models (flow, guard, reset as pure functions)
- :mod:`walkerlab.contact`  the compliant-contact (MSC ADAMS style) walker
- :mod:`walkerlab.analysis` hybrid integration, Poincaré map, fixed points, gait metrics
- :mod:`walkerlab.io`       HDF5 artifacts (atomic writes, content hashes)
- :mod:`walkerlab.stages`   one function per stage: config + upstream artifacts -> one artifact
- :mod:`walkerlab.plotting` figures drawn from loaded artifacts only
- :mod:`walkerlab.cli`      thin typer front end

Importing the package has no side effects and loads no heavy optional package.
"""

__version__ = "0.1.0"
