"""The continuation state a sweep chunk carries from point to point: the last fixed points and
their Poincaré-map Jacobians, a secant predictor of the next (:class:`Continuation`), and its
JSON form as a sweep's partial file stores it per chain (:func:`guess_to_json`,
:func:`guess_from_json`).
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass

import numpy as np

__all__ = ["Continuation", "guess_to_json", "guess_from_json"]


@dataclass(frozen=True)
class Continuation:
    """What a chunk's next point takes from the fixed points before it (picklable, small).

    Attributes
    ----------
    values : tuple of float or None
        Continuation-axis value of each kept fixed point, oldest first (at most two; ``None``
        when the axis is not numeric, and then no extrapolation is done).
    states : tuple of ndarray (2n,)
        The fixed points (role-ordered state just after heel strike, ``state_names()``;
        [rad], [rad/s]).
    jacobians : tuple of ndarray (2n, 2n)
        ``DP`` at each fixed point (Poincaré-map Jacobian from the variational equations
        with saltation matrices; [state unit / state unit]).
    target : float or None
        Continuation-axis value of the point to predict (set by :meth:`aimed`).
    """

    values: tuple = ()
    states: tuple = ()
    jacobians: tuple = ()
    target: float | None = None

    def aimed(self, value) -> Continuation:
        """This continuation, set to predict the point at ``value`` (``target``)."""
        return Continuation(self.values, self.states, self.jacobians, _real(value))

    @property
    def x(self) -> np.ndarray:
        """The last fixed point (2n,) (``state_names()``, [rad, rad/s])."""
        return self.states[-1]

    def then(self, value, res) -> Continuation:
        """This continuation with the fixed point ``res`` (a FixedPointResult) at ``value``
        appended (only the last two are kept)."""
        v = _real(value)
        keep = slice(-1, None) if self.values and self.values[-1] is not None \
            and v is not None else slice(0, 0)
        return Continuation(self.values[keep] + (v,), self.states[keep] + (np.asarray(res.x),),
                            self.jacobians[keep] + (np.asarray(res.jacobian_variational),))

    def predict(self) -> tuple[np.ndarray, np.ndarray]:
        """Guess of the fixed point and of ``DP`` at ``target``: secant (linear)
        extrapolation from the last two fixed points of the chunk, or the last one.

        Returns
        -------
        x : ndarray (2n,)
            Post-impact state (``state_names()``, [rad, rad/s]).
        DP : ndarray (2n, 2n)
            Poincaré-map Jacobian [state unit / state unit].
        """
        v = self.target
        if len(self.values) < 2 or v is None or self.values[0] == self.values[1]:
            return self.states[-1], self.jacobians[-1]
        (v0, v1), (x0, x1), (J0, J1) = self.values, self.states, self.jacobians
        s = (v - v1) / (v1 - v0)
        return x1 + s * (x1 - x0), J1 + s * (J1 - J0)


def guess_to_json(guess) -> str:
    """JSON of a continuation state (:class:`Continuation` or None), as a sweep's partial
    file stores it per chain; floats are written with ``repr`` precision, so it reads back
    bit for bit."""
    if guess is None:
        return "null"
    if isinstance(guess, np.ndarray):  # a bare state (the continuation of a state guess)
        return json.dumps({"array": guess.tolist(), "dtype": guess.dtype.str})
    return json.dumps({"values": list(guess.values),
                       "states": [np.asarray(x, float).tolist() for x in guess.states],
                       "jacobians": [np.asarray(j, float).tolist() for j in guess.jacobians],
                       "target": guess.target})


def guess_from_json(text: str):
    """Inverse of :func:`guess_to_json` (data only: nothing in the file is executed)."""
    d = json.loads(text)
    if d is None:
        return None
    if "array" in d:
        return np.asarray(d["array"], dtype=np.dtype(str(d["dtype"])))
    return Continuation(tuple(d["values"]), tuple(np.asarray(x, float) for x in d["states"]),
                        tuple(np.asarray(j, float) for j in d["jacobians"]), d["target"])


def _real(value) -> float | None:
    if isinstance(value, bool) or not isinstance(value, (int, float, np.floating, np.integer)):
        return None
    v = float(value)
    return v if math.isfinite(v) else None
