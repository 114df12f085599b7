"""Advancing the models in time: integration backends, chunks and event location.

Above the models (:mod:`walkerlab.models`, :mod:`walkerlab.contact`), below the analyses.
:mod:`walkerlab.integrate.contact` integrates the compliant-contact walker (odeint, CyRK's
BDF over a compiled RHS, numbalsoda, solve_ivp; trips, falls and flights located on the
Hermite interpolant); :mod:`walkerlab.integrate.ends` names how a run ends, for the rigid
and the contact model alike.  Importing this package loads nothing heavy.
"""
