"""Figures drawn from loaded artifacts only (never from live simulation objects)."""
