"""Transcriptions of a periodic gait into a nonlinear program (CasADi + IPOPT)."""
