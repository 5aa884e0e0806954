"""Analysis of vessel models: equilibria, stability, linearised transfer functions, energy."""
