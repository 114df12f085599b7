"""HDF5 artifacts: atomic writes, self-describing datasets, content hashes."""

from walkerlab.io.artifacts import (
    ArtifactError,
    code_hash,
    open_artifact,
    put,
    read_named,
    write_artifact,
)

__all__ = ["ArtifactError", "code_hash", "open_artifact", "put", "read_named", "write_artifact"]
