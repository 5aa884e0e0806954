"""The one simulation loop (``simulate``), its integrators and its result format."""
