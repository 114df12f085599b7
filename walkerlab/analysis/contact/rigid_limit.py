"""The contact walker's periodic gait along the rigid-limit family, against the rigid gait.

For each stiffness factor ``kappa`` the contact is scaled along the one family
(:mod:`walkerlab.models.contact.rigid_limit`), the contact walker's own periodic gait is found
(:func:`walkerlab.analysis.contact.periodic.find_contact_periodic_gait`, warm-started from
the previous ``kappa``'s fixed point) and its step period, step length and slow Floquet
multipliers are set beside the rigid walker's.  The observed order of convergence between
successive factors is ``log(gap_i / gap_{i+1}) / log(kappa_{i+1} / kappa_i)`` (as PyBaMM's
convergence tests take log2 of successive error ratios); the family's expected order is
:func:`walkerlab.models.contact.rigid_limit.expected_order` (``1/(e+1)``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import linear_sum_assignment

from walkerlab.models.contact.parts import contact_part
from walkerlab.models.contact.rigid_limit import scale_walker
from walkerlab.models.contact.scene import ideal_step_length
from walkerlab.numerics import sort_multipliers

__all__ = ["RigidLimitTable", "convergence", "match_multipliers", "observed_order"]


@dataclass
class RigidLimitTable:
    """The contact periodic gait along the rigid-limit family.

    Attributes
    ----------
    kappa : ndarray (n,)
        Stiffness factors [-] (1 = the scene's contact).
    period_s, step_length_m : ndarray (n,)
        Step period [s] and step length [m] of the contact walker's periodic gait.
    multipliers : ndarray (n, r) complex
        Its slow Floquet multipliers [-], column j matched to ``rigid_multipliers[j]``.
    rigid_period_s, rigid_step_length_m : float
        The rigid gait's step period [s] and step length [m].
    rigid_multipliers : ndarray (r,) complex
        The rigid gait's nonzero Floquet multipliers [-], by decreasing modulus.
    converged : ndarray (n,) bool
    """

    kappa: np.ndarray
    period_s: np.ndarray
    step_length_m: np.ndarray
    multipliers: np.ndarray
    rigid_period_s: float
    rigid_step_length_m: float
    rigid_multipliers: np.ndarray
    converged: np.ndarray

    @property
    def period_gap_s(self) -> np.ndarray:
        """Contact - rigid step period [s], (n,)."""
        return self.period_s - self.rigid_period_s

    @property
    def step_gap_m(self) -> np.ndarray:
        """Contact - rigid step length [m], (n,)."""
        return self.step_length_m - self.rigid_step_length_m

    @property
    def multiplier_gap(self) -> np.ndarray:
        """``|lambda_contact - lambda_rigid|`` per matched pair [-], (n, r)."""
        return np.abs(self.multipliers - self.rigid_multipliers[None, :])


def observed_order(kappa, gap) -> np.ndarray:
    """Observed order between successive factors, ``log(|g_i| / |g_i+1|) / log(k_i+1 / k_i)``.

    Parameters
    ----------
    kappa, gap : array_like (n,)

    Returns
    -------
    ndarray (n - 1,)
    """
    k, g = np.asarray(kappa, float), np.abs(np.asarray(gap, float))
    return np.log(g[:-1] / g[1:]) / np.log(k[1:] / k[:-1])


def match_multipliers(contact, rigid, free_modes: int = 0) -> np.ndarray:
    """The contact multipliers matched to their rigid partners.

    Parameters
    ----------
    contact : array_like (m,) complex
        All Floquet multipliers of the contact gait (its fast contact modes ~ 0 included).
    rigid : array_like (r,) complex
        The rigid gait's nonzero multipliers (r + free_modes <= m).
    free_modes : int
        Slow contact multipliers with no rigid partner (a walker in 3D: the heading, which
        the rigid stance foot holds; :attr:`walkerlab.models.contact.parts.ContactPart.
        free_modes`), left unmatched.

    Returns
    -------
    ndarray (r,) complex
        Entry j is the contact multiplier nearest ``rigid[j]`` among the ``r + free_modes``
        largest in modulus (assignment minimising the summed distance,
        ``scipy.optimize.linear_sum_assignment``).
    """
    c = np.asarray(contact, complex)
    r = np.asarray(rigid, complex)
    slow = sort_multipliers(c)[:r.size + free_modes]
    rows, cols = linear_sum_assignment(np.abs(slow[:, None] - r[None, :]))
    out = np.empty(r.size, complex)
    out[cols] = slow[rows]
    return out


def convergence(walker, ideal, kappas, *, min_multiplier: float = 1e-6,
                **search) -> RigidLimitTable:
    """The contact walker's periodic gait at each ``kappa`` along the rigid-limit family.

    Parameters
    ----------
    walker : ContactWalker
        The scene's contact walker (``kappa = 1``).
    ideal : fixed-point result of the rigid walker
        With ``x`` (post-impact state, role order), ``period_s`` (its map's: a stride's
        when ``step_periods_s`` has two steps) and ``multipliers_variational`` (as
        :func:`walkerlab.analysis.gait.scene.solve_variant`); its multipliers are put on the
        contact map's steps (``walker.steps_per_map``: squared for a stride of a step
        map's) and its period on one step.
    kappas : array_like (n,)
        Increasing stiffness factors [-].
    min_multiplier : float
        Rigid multipliers below this modulus are the structural zeros (the map lands on the
        guard) and have no contact partner.
    **search
        Passed to :func:`~walkerlab.analysis.contact.periodic.find_contact_periodic_gait`.

    Returns
    -------
    RigidLimitTable
    """
    from walkerlab.analysis.contact.periodic import find_contact_periodic_gait  # light

    rigid_steps = max(1, len(getattr(ideal, "step_periods_s", ()) or ()))
    lam_r = np.asarray(ideal.multipliers_variational, complex)
    lam_r = lam_r[np.abs(lam_r) > min_multiplier]
    if walker.steps_per_map % rigid_steps == 0:  # the rigid map's multipliers, on the
        lam_r = lam_r ** (walker.steps_per_map // rigid_steps)  # contact map's steps
    lam_r = sort_multipliers(lam_r)
    # a held heading is no free mode (contact.hold_heading)
    free = 0 if walker.hold_heading else contact_part(walker.structure).free_modes
    search.setdefault("check_fd", False)
    rows, guess = [], ideal.x
    for kappa in kappas:
        g = find_contact_periodic_gait(scale_walker(walker, float(kappa)), guess, **search)
        rows.append((g.period_s, g.step_length_m,
                     match_multipliers(g.multipliers, lam_r, free), g.converged))
        guess = g.z if g.converged else guess
    period, step, lam, ok = zip(*rows)
    return RigidLimitTable(np.asarray(kappas, float), np.array(period), np.array(step),
                           np.array(lam), float(ideal.period_s) / rigid_steps,
                           ideal_step_length(walker, ideal.x),
                           lam_r, np.array(ok))
