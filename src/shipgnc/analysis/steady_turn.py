"""The catamaran's steady turns live in :mod:`shipgnc.models.steady_turn` (a model's analysis:
the models' layer, used by the finite-state law's feasibility check); this module keeps the old
import path working."""

from shipgnc.models.steady_turn import (
    SteadyTurn,
    omega_max,
    steady_state_at_angle,
    steady_turn,
    turning_characteristic,
)

__all__ = ["SteadyTurn", "omega_max", "steady_state_at_angle", "steady_turn", "turning_characteristic"]
