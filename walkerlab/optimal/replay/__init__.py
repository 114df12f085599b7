"""Optimised steps replayed on the rigid and contact views."""
