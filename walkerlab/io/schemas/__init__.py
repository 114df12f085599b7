"""Artifact schemas: one module per artifact, its writer and its loader side by side.

``write_<stage>(f, result)`` fills the (in-memory) HDF5 file a stage hands to
:func:`walkerlab.io.artifacts.write_artifact`; ``load_<stage>(path)`` returns a typed,
fully loaded result (a dataclass holding numpy arrays and strings, no open file): it is
written as the reading of the open file, ``load_<stage>(f, path)``, made into the loader
by :func:`walkerlab.io.artifacts.artifact_loader` (which opens and checks the file and
turns what it lacks into one line).  Stages, the report and the plots work on loaded
objects, never on h5py.
"""
