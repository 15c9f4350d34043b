"""Static verification: mechanical equilibrium of a scene in each input state."""
