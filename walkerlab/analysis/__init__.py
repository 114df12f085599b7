"""Analysis on top of the models and the solver layer: Poincaré map, fixed points, metrics."""
