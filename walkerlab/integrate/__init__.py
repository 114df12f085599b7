"""Advancing the models in time: the one solver layer of the rigid and the contact model.

Above the models (:mod:`walkerlab.models`, :mod:`walkerlab.models.contact`), below the analyses.
:mod:`walkerlab.integrate.solver` holds the one settings object (:class:`Solver`: method,
tolerances, largest step, backend) and :func:`available_backends`;
:mod:`walkerlab.integrate.rigid` integrates the rigid hybrid walker step by step (scipy,
CyRK, CyRK over a numba-compiled flow: :mod:`walkerlab.integrate._compiled`; CyRK loaded
without numba by :mod:`walkerlab.integrate.cyrk_loader`), guards located as events;
:mod:`walkerlab.integrate.contact` integrates the compliant-contact walker (odeint, CyRK's
BDF over a compiled RHS, numbalsoda, solve_ivp; trips, falls and flights located on the
Hermite interpolant); :mod:`walkerlab.integrate.contact_grid` runs it on a time grid
(CyRK's BDF over the compiled RHS: the contact step map's flow);
:mod:`walkerlab.integrate.ends` names how a run ends
(:class:`RunEnd`), for the rigid and the contact model alike.  Importing this package loads
nothing heavy.
"""
