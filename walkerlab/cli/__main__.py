"""``python -m walkerlab.cli``: the ``walkerlab`` command."""

import sys

from walkerlab.cli import app

if __name__ == "__main__":  # pragma: no cover
    sys.exit(app())
