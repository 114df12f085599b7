"""Analysis on top of the models: hybrid integration, Poincaré map, fixed points, metrics."""
