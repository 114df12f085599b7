"""A mid-episode :class:`~walkerlab.gym.env.WalkerEnv`'s episode as plain data: what
``copy.deepcopy`` and ``pickle`` carry, so that a copy continues the episode bit for bit
(as MuJoCo's environments' copies do).

The environment itself is rebuilt from the arguments it was built from (its compiled flows,
the scene's generated code and compiled segments are not copied: the copy builds its own,
from the same cache), then :func:`restore` puts the episode in it: the control periods
counted, the reset's random generator (``np_random``; the copy's ``np_random_seed`` reads
-1, gymnasium's value for a generator set directly), and the view's state.

- Rigid view (:class:`walkerlab.gym.rigid_view.RigidView`): the state, time, stance leg,
  phase, stance foot, the step's start and its control periods, the ledger; the step's walker
  is chosen again as the view chooses it (:func:`walkerlab.integrate.rigid.walker_of_step`,
  or a profile's segment), its actuators' clock at the step's start.  On a height profile
  the step's dense output (read by the swing foot's check at the heel strike) is made again
  by walking the step from its start with its periods' actions, as the view walks a step
  again on another segment (:meth:`RigidView._again`), and checked to end on the state copied
  bit for bit.
- Contact view (:class:`walkerlab.gym.contact_view.ContactView`): its patches (the layout's
  size, the footfalls' lanes, the terrain's roughness and seed) and the powered run's state
  (state and work integrals, stance leg, the step's start, the push-off's and the resumed
  segment's bookkeeping) carried into a new run's hook, as the view carries them when it
  lays its patches out again.

Every solver call starts afresh from the state at a control period's boundary (no step size
or order is carried from one period to the next), so the copy's next period is the
original's, bit for bit.
"""

from __future__ import annotations

import copy
import dataclasses

import numpy as np

__all__ = ["capture", "restore"]

#: the rigid view's plain episode attributes (copied as they are)
_RIGID = ("t", "t_step", "leg", "x", "foot", "advance_x", "ended", "trip", "ledger", "steps",
          "_period", "k", "_step_start", "_log")
#: the contact run's hook's attributes besides its state, time and what ``_start`` carries
_HOOK = ("t_strike", "resume", "pulse_end", "pushed", "term", "msg", "event", "nfev", "njev")


def capture(env) -> dict | None:
    """The episode of ``env`` (a :class:`~walkerlab.gym.env.WalkerEnv`) as plain data
    (numbers, arrays, text, tuples, dicts, the reset's ``numpy.random.Generator``); an
    empty dict before its first reset."""
    if not env._has_reset:  # (its generator, made on first use, is drawn afresh)
        return {}
    # the reset's generator (gymnasium's public property: made by the reset, read as it is)
    out = {"np_random": env.np_random}
    s = env.sim
    out.update(elapsed=env._elapsed, terrain_seed=env.terrain_seed, hip_x=env._hip_x,
               checked_start=env._checked_start)
    if env.view == "rigid":
        out["rigid"] = {k: copy.deepcopy(getattr(s, k)) for k in _RIGID}
        if s.ground is not None:
            out["rigid"].update(j=s.j, tried=set(s.tried))
    else:
        h = s.hook
        out["contact"] = {
            "roughness": s._roughness, "seed": s._seed, "laid": s._laid,
            "lanes": tuple(a.copy() for a in s._lanes),
            "track": copy.deepcopy(s._track), "ended": s.ended, "failure": s.failure,
            "ledger": dict(s.ledger), "steps": s.steps, "t": float(h.t), "y": h.y.copy(),
            "keep": (h.stance, h.t_origin, h.ankle_on, h.step_s),
            "hook": {k: copy.deepcopy(getattr(h, k)) for k in _HOOK}}
    return out


def restore(env, state: dict) -> None:
    """Put the episode ``state`` (:func:`capture`'s) in ``env``, a
    :class:`~walkerlab.gym.env.WalkerEnv` built from the same arguments as the one it was
    captured from.

    Raises
    ------
    RuntimeError
        On a height profile, the step walked again from its start does not end on the
        state copied (one line; not met on the shipped scenes).
    """
    if not state:  # never reset: it still asks for a reset
        return
    env.np_random = state["np_random"]  # (gymnasium's setter: np_random_seed reads -1)
    env._elapsed, env.terrain_seed = state["elapsed"], state["terrain_seed"]
    env._hip_x, env._checked_start = state["hip_x"], state["checked_start"]
    if env.view == "rigid":
        _restore_rigid(env.sim, state["rigid"])
    else:
        _restore_contact(env.sim, state["contact"])
    env._has_reset = True


def _restore_rigid(v, st: dict) -> None:
    for k in _RIGID:
        setattr(v, k, copy.deepcopy(st[k]))
    v._pieces = []
    if v.ground is None:
        v._choose_walker()  # the step's walker (of the steps made and the stance leg)
    else:
        v.j, v.tried = st["j"], set(st["tried"])
        v.walker = v.ground.walker(v.j, v.foot)
    if v.walker.actuators is not None:  # their clock: the step's start
        v.walker.actuators.begin_step(v._step_start[0])
    if v.ground is None or v.ended:
        return
    # a profile: the step's dense output (the swing foot's check at the heel strike reads
    # it), made again by walking the step from its start with its periods' actions
    u, t_end = v._period
    strikes = v._again(v.j)
    strikes += v._run(u, t_end)
    same = (not strikes and not v.ended and v.t == st["t"] and v.k == st["k"]
            and v.x.tobytes() == np.asarray(st["x"]).tobytes() and v.ledger == st["ledger"])
    if not same:
        raise RuntimeError("walkerlab.gym: the copied episode's step, walked again on the "
                           "profile from its start, does not end on the state copied: "
                           "reset the copy")
    for k in _RIGID:  # (the very values copied, the counters too)
        setattr(v, k, copy.deepcopy(st[k]))
    v.tried = set(st["tried"])


def _restore_contact(v, st: dict) -> None:
    v._roughness, v._seed, v._track = st["roughness"], st["seed"], None
    v._lay_out(st["laid"])  # the scene's patches for the steps laid out (v._at_rigid)
    v._track = copy.deepcopy(st["track"])
    lane1, lane2 = st["lanes"]  # the episode's footfalls' lanes; roughness on them
    v._use(dataclasses.replace(v._at_rigid, lane1=lane1.copy(), lane2=lane2.copy()))
    v.ended, v.failure, v.ledger, v.steps = (st["ended"], st["failure"], dict(st["ledger"]),
                                             st["steps"])
    y = np.asarray(st["y"], float)
    n = 2 * v.nq
    v._start(y[:n].copy(), st["t"], (*st["keep"], y[n:].copy()))
    for k, value in st["hook"].items():
        setattr(v.hook, k, copy.deepcopy(value))
