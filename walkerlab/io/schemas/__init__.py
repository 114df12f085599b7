"""Artifact schemas: one module per artifact, its writer and its loader side by side.

``write_<stage>(f, result)`` fills the (in-memory) HDF5 file a stage hands to
:func:`walkerlab.io.artifacts.write_artifact`; ``load_<stage>(path)`` returns a typed,
fully loaded result (a dataclass holding numpy arrays and strings, no open file).  Stages,
the report and the plots work on loaded objects, never on h5py.
"""
