"""Stages: each reads a scene and upstream artifacts and writes exactly one HDF5 artifact.

``fixedpoint -> simulate -> (contact-sim) -> compare -> plot``; ``report`` runs what the
scene needs.  A stage is skipped when its input hash (config sections it reads, upstream
artifacts' hashes, walkerlab version and source code) matches the stored one.
"""
