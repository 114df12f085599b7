"""Exchange formats: the walker as URDF and MJCF (and the MuJoCo scene it walks in), and
the helpers that walk it in MuJoCo; the walker as an MSC Adams Solver dataset and command file
(:mod:`walkerlab.export.adams`) and the reader of that subset
(:mod:`walkerlab.export.adams_reader`)."""
