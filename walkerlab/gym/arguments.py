""":class:`walkerlab.gym.env.WalkerEnv`'s arguments: checked (:func:`check_arguments`; an
action, :func:`checked_action`, refused as :class:`InvalidAction`), and what it builds of
its scene besides the walker: the rigid view's ground beyond its walker's own
(:func:`rigid_ground`) and the walker it steps when the scene's feedback controller is the
policy (:func:`plant_scene`)."""

from __future__ import annotations

import math

import gymnasium as gym
import numpy as np

__all__ = ["MAX_START_NOISE", "InvalidAction", "check_arguments", "checked_action", "plant_scene",
           "rigid_ground", "whole_number"]

#: the largest ``start_noise``: the start's rates times ``1 + U(-1, 1)`` (from rest to twice
#: the gait's rates; beyond, rates change sign)
MAX_START_NOISE = 1.0


def rigid_ground(scene, plant):
    """The rigid view's ground beyond its walker's own
    (:func:`walkerlab.integrate.rigid.walker_of_step`: a slope, stairs, footholds of one or
    several heights or slopes, as ``walkerlab simulate`` steps them): a height profile's steps
    (:func:`walkerlab.analysis.gait.rigid_run.profile_ground` of ``plant``, the scene's
    :class:`~walkerlab.walker.plant.Plant`), else None.

    Raises
    ------
    ValueError
        A per-step random ground (``terrain.per_step``), or a profile the rigid walk does
        not read (one line).
    """
    t = scene.terrain
    if t is None:
        return None
    if getattr(t, "per_step", None) is not None:
        raise ValueError("walkerlab.gym: terrain.per_step: the rigid view walks the scene's "
                         "own ground, not one drawn per step (walkerlab simulate "
                         "--terrain-seed draws it); leave terrain.per_step out")
    if t.kind != "profile":
        return None
    from walkerlab.analysis.gait.rigid_run import profile_ground

    try:
        return profile_ground(scene, plant)
    except ValueError as exc:
        raise ValueError(f"walkerlab.gym: {exc}") from None


def plant_scene(scene):
    """``scene`` without its feedback controller (``walker.actuation: None``): the walker
    the environment steps when the controller is the policy
    (:meth:`walkerlab.gym.env.WalkerEnv.scene_policy`)."""
    return scene.model_copy(update={"walker": scene.walker.model_copy(
        update={"actuation": None})})


def check_arguments(view, control_period_s, max_episode_steps, render_mode, start_noise,
                     terrain_roughness_m) -> None:
    """Refuse :class:`walkerlab.gym.env.WalkerEnv`'s arguments out of their ranges (one
    line naming the argument)."""
    if view not in ("rigid", "contact"):
        raise ValueError(f"view={view!r}: give 'rigid' or 'contact'")
    if not (isinstance(control_period_s, (int, float)) and not isinstance(
            control_period_s, bool) and 0 < control_period_s <= 1.0
            and math.isfinite(control_period_s)):
        raise ValueError(f"control_period_s={control_period_s!r}: give a positive number "
                         "of seconds, at most 1")
    if max_episode_steps is not None and (
            isinstance(max_episode_steps, bool) or not isinstance(max_episode_steps, int)
            or max_episode_steps < 1):
        raise ValueError(f"max_episode_steps={max_episode_steps!r}: give a whole number "
                         ">= 1")
    if render_mode not in (None, "rgb_array"):
        raise ValueError(f"render_mode={render_mode!r}: give None or 'rgb_array'")
    for name, v in (("start_noise", start_noise),
                    ("terrain_roughness_m", terrain_roughness_m)):
        if not (isinstance(v, (int, float)) and not isinstance(v, bool)
                and math.isfinite(v) and v >= 0):
            raise ValueError(f"{name}={v!r}: give a number >= 0")
    if start_noise > MAX_START_NOISE:
        raise ValueError(f"start_noise={start_noise!r}: give a relative noise in [0, "
                         f"{MAX_START_NOISE:g}] (the start's rates times 1 + U(-s, s))")


def whole_number(value, name: str, low: int, allow_none: bool = False) -> int | None:
    """``value`` as a whole number >= ``low`` (or None when ``allow_none``).

    Raises
    ------
    ValueError
        Not a whole number >= ``low`` (a bool, a float, text) or None where not allowed
        (one line naming ``name``).
    """
    if value is None and allow_none:
        return None
    if isinstance(value, bool) or not isinstance(value, int | np.integer) or value < low:
        raise ValueError(f"{name}={value!r}: give a whole number >= {low}"
                         + (" or None" if allow_none else ""))
    return int(value)


class InvalidAction(ValueError, gym.error.InvalidAction):
    """An action that is not the environment's ``k`` finite real torques of shape ``(k,)``
    (a ``ValueError`` and gymnasium's ``InvalidAction``)."""


def checked_action(action, k: int, joints: list[str], action_space) -> np.ndarray:
    """``action`` as finite float64 torques (k,) (not yet scaled or clipped), or refused:
    the checks of :meth:`walkerlab.gym.env.WalkerEnv.step` behind its common case (an
    array of ``k`` finite floats), whose message names the action's ``joints`` and
    ``action_space``.

    Raises
    ------
    InvalidAction
        None, not real numbers (complex, text, objects), not of shape (k,), or NaN/inf
        entries (one line naming the action space).
    """
    want = (f"give {k} finite real number{'s' if k > 1 else ''} "
            f"({', '.join(joints)}), shape ({k},), in {action_space}")
    if action is None:
        raise InvalidAction(f"action is None: {want}")
    try:
        a = np.asarray(action)
    except (ValueError, TypeError):  # ragged nesting
        raise InvalidAction(f"action of type {type(action).__name__} is not an array of "
                            f"numbers: {want}") from None
    if a.dtype.kind not in "iuf":
        what = "complex" if a.dtype.kind == "c" else f"of dtype {a.dtype}"
        raise InvalidAction(f"action is {what}: {want}")
    if a.shape != (k,):
        raise InvalidAction(f"action has shape {a.shape}: {want}")
    a = a.astype(np.float64)
    bad = np.flatnonzero(~np.isfinite(a))
    if bad.size:
        raise InvalidAction(f"action[{int(bad[0])}] is {a[bad[0]]}: {want}")
    return a
