"""The words of a gait search that found nothing
(:func:`walkerlab.analysis.gait.search.find_gaits`): the solver's message in one line, and
the one-line failure with its advice."""

from __future__ import annotations

import math
import re

from walkerlab.models.hybrid.base import HybridWalker

__all__ = ["failure_message", "solver_words"]


#: MINPACK's (``scipy.optimize.root``, hybrd/hybrj) stop messages in walkerlab's words
_MINPACK_WORDS = (
    ("The iteration is not making good progress, as measured by the improvement from the "
     "last five Jacobian evaluations.", "the root finder stalled: its last five Jacobians "
     "brought no progress"),
    ("The iteration is not making good progress, as measured by the improvement from the "
     "last ten iterations.", "the root finder stalled: its last ten steps brought no "
     "progress"),
    ("The number of calls to function has reached maxfev", "the root finder ran out of "
     "map evaluations"),
)


def solver_words(msg: str) -> str:
    """The root finder's message, one line, without the prefix and the residual (given
    apart); MINPACK's stop messages in walkerlab's words, MINPACK's own after them in
    brackets (:data:`_MINPACK_WORDS`)."""
    text = " ".join(str(msg).removeprefix("no fixed point found: ").split())
    text = re.sub(r" \(residual [^)]*\)$", "", text)
    for head, words in _MINPACK_WORDS:
        at = text.find(head)
        if at >= 0 and words not in text:  # not said already
            end = text.find(".", at + len(head) - 1) + 1 or len(text)
            return f"{text[:at]}{words} [MINPACK: {text[at:end].strip()}]{text[end:]}"
    return text


def no_energy_reason(walker: HybridWalker) -> str:
    """Why a passive walker can have no gait here ("" when it may): no actuators and no
    drop to pay the heel strikes' loss - level or uphill ground, stairs up (each step up
    takes energy only actuators give).  No start of the root finder can find what is not
    there: the gait search says so instead of carrying gaits to it."""
    if walker.actuators is not None:
        return ""
    drop = walker.params.get("landing_drop_m", 0.0)
    if drop < 0 and walker.slope_rad <= 0:
        # every step lands higher: gravity cannot pay the climb (nor the heel strikes' loss)
        return ("a passive walker cannot climb stairs or step up (each step up takes energy "
                "only actuators give: walker.actuation; passive, walk stairs down)")
    if not (walker.slope_rad > 0 or drop > 0):
        return ("a passive walker needs a downhill slope (slope > 0), stairs down or "
                "walker.actuation")
    return ""


def failure_message(walker: HybridWalker, tried: list[str], best: float, last: str,
                    had_guess: bool) -> str:
    """The one line of a gait search that found nothing: why (the walker's slope, stairs,
    actuators), what to try next (a continuation from a known gait, an initial guess, a
    scene to start from), then what was tried and the solver's last word.

    Parameters
    ----------
    walker : HybridWalker
    tried : list of str
        The starts tried, in words (``"the initial guess"``, ``"0 of 45 scale-free seeds"``).
    best : float
        The smallest residual reached [state units] (NaN: none).
    last : str
        The root finder's last message.
    had_guess : bool
        Whether the scene gave ``fixedpoint.initial_guess``.

    Returns
    -------
    str
        One line: the advice first, the solver's detail last (a display that shortens it
        cuts the detail, never the advice).
    """
    res = f", best residual {best:.2g}" if math.isfinite(best) else ""
    last = solver_words(last)
    if last and "standing" not in last:
        last = "scipy: " + last[:1].lower() + last[1:].rstrip(".")
    if walker.actuators is not None:
        why = ("the initial guess did not converge and the seeds are a passive walker's: "
               "the walker may have no period-1 gait here" if had_guess else
               "the seeds are a passive walker's, and a powered gait may lie far from them")
    else:
        why = no_energy_reason(walker) or "the walker may have no period-1 gait here"
    if "standing" in last:  # walkerlab's own diagnosis, not a solver's detail: in the text
        why, last = f"{why}; {last}", ""
    # the advice first, the solver's detail last: a one-line display that must shorten the
    # message cuts the detail, never the advice; with a guess given, the advice is not to
    # give one
    nearer = ("start from a gait known nearby (walkerlab fixedpoint --from KNOWN_SCENE, or "
              "its gait as fixedpoint.initial_guess)" if had_guess
              else "give fixedpoint.initial_guess (a gait at a nearby push-off or slope, or "
              "walkerlab fixedpoint --from KNOWN_SCENE)"
              if walker.actuators is not None else "give fixedpoint.initial_guess (or start "
              "from a gait known nearby: walkerlab fixedpoint --from KNOWN_SCENE)")
    return (f"no period-1 gait found; {why}; to see where the gait ends, try a continuation "
            "from a walker whose gait is known (walkerlab continuation SCENE --param "
            f"FIELD=KNOWN:THIS, e.g. slope.angle_deg), or {nearer}"
            + f" [tried {' and '.join(tried)}{res}"
            + (f"; last: {last}]" if last else "]" if "standing" in why
               else "; last: every start fell]"))
