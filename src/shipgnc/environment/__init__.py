"""Environment: disturbances acting on a vessel (forces, currents, waves)."""
