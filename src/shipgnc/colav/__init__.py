"""Ships that meet ships: target tracks, encounter geometry, COLREG situations and collision-avoidance
algorithms (velocity obstacles, simulation-based MPC) for the own ship's guidance."""
