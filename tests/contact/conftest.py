"""Make the repository root importable when walkerlab is not installed."""

import sys
from pathlib import Path

_ROOT = str(Path(__file__).resolve().parents[2])
_TESTS = str(Path(__file__).resolve().parents[1])  # tests/independent (reference walkers)
for _p in (_ROOT, _TESTS):
    if _p not in sys.path:
        sys.path.insert(0, _p)

# approx. ideal fixed point of the paper walker (leg1 swing, rad and rad/s) and its step
# length [m]: starting states and patch placement of the contact tests
FP = (-0.2042, 0.1694, -0.6058, -0.8610)
STEP_LENGTH = 0.372
