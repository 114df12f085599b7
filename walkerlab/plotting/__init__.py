"""Figures drawn from loaded artifacts only (never from live simulation objects)."""

#: legend labels of the two models (rigid hybrid walker, compliant-contact walker)
IDEAL_LABEL = "ideal (rigid, plastic impact)"
CONTACT_LABEL = "contact (IMPACT + Coulomb)"
