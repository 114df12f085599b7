"""The rigid walker's gait: the Poincaré map and its Jacobian, the gait search and its
starts, one-step kernels, gait metrics, tables and checks."""
