"""Exchange formats: the walker as URDF and MJCF (and the MuJoCo scene it walks in), and
the helpers that walk it in MuJoCo."""
