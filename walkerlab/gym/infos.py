"""The native vector environment's infos (:class:`walkerlab.gym.vector.WalkerVectorEnv`):
the sub-environments' info dicts, or their columns, batched as
:meth:`gymnasium.vector.VectorEnv._add_info` batches them one by one (:func:`batch_infos`,
:func:`batch_columns`), a step's infos batched on first use (:class:`LazyInfos`), and the
views' solver words they hold (:func:`view_messages`)."""

from __future__ import annotations

import numpy as np

__all__ = ["LazyInfos", "batch_columns", "batch_infos", "view_messages"]


def batch_infos(each: list[dict]) -> dict | None:
    """The sub-environments' infos ``each[i]`` (flat dicts of numbers, text, lists or None)
    batched as :meth:`gymnasium.vector.VectorEnv._add_info` batches them one by one: per key
    an array of ``len(each)`` whose type is the first value's (a number's dtype, else
    objects) and its mask ``_key``, keys in the order met; None where a value is a dict
    (gymnasium's own recursion then)."""
    n = len(each)
    out: dict = {}
    for i, info in enumerate(each):
        for key, value in info.items():
            t = type(value)
            if t is dict:
                return None
            arr = out.get(key)
            if arr is None:
                if t in (int, float, bool) or issubclass(t, np.number):
                    arr = np.zeros(n, dtype=t)
                elif isinstance(value, np.ndarray):
                    arr = np.zeros((n, *value.shape), dtype=value.dtype)
                else:
                    arr = np.full(n, None, dtype=object)
                out[key] = arr
                out[f"_{key}"] = np.zeros(n, dtype=np.bool_)
            arr[i] = value
            out[f"_{key}"][i] = True
    return out


def batch_columns(columns: dict, n: int) -> dict | None:
    """Infos given by key, ``columns[key]`` the N sub-environments' values (a list, or an
    array of numbers), batched as :func:`batch_infos` batches the same infos given one
    dict per sub-environment (every sub-environment holding every key): per key an array
    (N,) whose type is sub-environment 0's value's (a number's dtype: a float array holds
    NaN for None; else objects) and its mask ``_key`` (all True); None where a value is a
    dict."""
    out: dict = {}
    masks = np.ones((len(columns), n), dtype=np.bool_)
    for j, (key, vals) in enumerate(columns.items()):
        if isinstance(vals, np.ndarray) and vals.dtype.kind in "fi":
            arr = vals  # numbers of one dtype: the first one's
        else:
            v0 = vals[0]
            t = type(v0)
            if t is dict:
                return None
            if t in (int, float, bool) or issubclass(t, np.number):
                arr = np.array(vals, dtype=t)
            elif isinstance(v0, np.ndarray):
                arr = np.zeros((n, *v0.shape), dtype=v0.dtype)
                arr[:] = vals
            else:
                arr = np.empty(n, dtype=object)
                for i, v in enumerate(vals):
                    arr[i] = v
        out[key] = arr
        out[f"_{key}"] = masks[j]
    return out


class LazyInfos(dict):
    """A step's infos, batched on first use: a ``dict`` whose entries are ``make()``'s,
    made (once) by the first thing that reads or changes it - a key, its length, its keys,
    a copy, a comparison, ``repr``, pickling - so a training loop that does not read the
    infos of a step does not pay for their batching (about a tenth of the 8-walker call).
    ``make`` takes only what the step has already copied out of the walkers (their
    columns, the reset walkers' infos), so the entries are the step's, whenever made."""

    __slots__ = ("_make",)

    def __init__(self, make):
        super().__init__()
        self._make = make

    def _filled(self) -> LazyInfos:
        make = self._make
        if make is not None:
            self._make = None
            dict.update(self, make())
        return self

    def __reduce_ex__(self, protocol):  # a copy or a pickle: the plain dict of entries
        return (dict, (dict.copy(self._filled()),))


def _filling(name: str):
    method = getattr(dict, name)

    def read(self, *args, **kwargs):
        return method(self._filled(), *args, **kwargs)
    read.__name__ = name
    read.__doc__ = f"``dict.{name}`` of the entries (made first)."
    return read


for _name in ("__getitem__", "__iter__", "__len__", "__contains__", "__eq__", "__ne__",
              "__repr__", "__reversed__", "__or__", "__ror__", "__ior__", "__setitem__",
              "__delitem__", "__sizeof__", "keys", "values", "items",
              "get", "pop", "popitem", "setdefault", "update", "copy", "clear"):
    setattr(LazyInfos, _name, _filling(_name))
del _name


def view_messages(views) -> list:
    """Each view's solver words (its ``failure``, "" without one: the rigid view's are its
    instance's, when it has them), as :func:`walkerlab.gym.batch.end_periods`' infos read
    them (``solver_message``)."""
    if not any(map(_class_failure, set(map(type, views)))):
        return [v.__dict__.get("failure", "") for v in views]
    return [getattr(v, "failure", "") for v in views]


_CLASS_FAILURE: dict = {}  # a view's class -> whether it has an attribute ``failure``


def _class_failure(cls) -> bool:
    """Whether the class ``cls`` has an attribute ``failure`` (kept per class)."""
    out = _CLASS_FAILURE.get(cls)
    if out is None:
        out = _CLASS_FAILURE[cls] = hasattr(cls, "failure")
    return out
