"""The walker as data: the description (a scene's ``walker`` section -> structure and
parameters), its state layout (names, units, slices, legs; the rigid -> floating map) and its
tree of links.  Imports nothing but settings; everything else builds on it."""
