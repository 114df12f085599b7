"""Design optimisation over a scene's numeric fields."""
