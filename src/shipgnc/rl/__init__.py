"""Reinforcement-learning environments (``pip install "shipgnc[rl]"``): shipgnc scenarios as
``gymnasium`` environments, registered under ``shipgnc/...`` ids when this module is imported::

    import gymnasium as gym
    import shipgnc.rl  # registers the ids

    env = gym.make("shipgnc/BoatHeading-v0")
    envs = gym.make_vec("shipgnc/BoatHeading-v0", num_envs=1000,
                        vectorization_mode="vector_entry_point")

Registered ids (scenario; initial offsets drawn at each reset):

* ``shipgnc/BoatHeading-v0``: ``boat-autopilot`` (document 001, heading steps); heading ±30°;
* ``shipgnc/BoatLOS-v0``: ``boat-los`` (waypoints with LOS references);
* ``shipgnc/CyberShipCourse-v0``: ``cybership-calm`` (document 003; the return is −J);
* ``shipgnc/CyberShipWaves-v0``: ``cybership-waves`` (a seeded sea per episode);
* ``shipgnc/CatamaranTurn-v0``: ``catamaran-turn`` (document 004, S3: yaw rate ω* = 0.08 rad/s;
  reward −(r − ω*)², action δ̇);
* ``shipgnc/CatamaranHeading-v0``: ``catamaran-heading`` (S7: heading K* = 0.8 rad; reward
  −wrap(ψ − K*)²); heading ±30° at reset;
* ``shipgnc/Ship-v0``: ``gym.make("shipgnc/Ship-v0", scenario=..., perturb=[...])`` for a boat or
  CyberShip II scenario with guidance and metric set ``heading-steps``, ``waypoints`` or
  ``course-quality``, or a catamaran scenario of a ``yaw-rate-fsm`` law with guidance
  ``yaw-rate``, ``yaw-rate-sine`` or ``heading-capture`` (or case builder ``turn``, ``sine`` or
  ``heading``; the other builders have no per-sample reward: ConfigError).
"""

from __future__ import annotations

try:
    import gymnasium as gym
except ImportError as exc:  # pragma: no cover - the [rl] extra is missing
    raise ImportError("shipgnc.rl needs gymnasium: pip install 'shipgnc[rl]'") from exc

from shipgnc.rl.env import ShipEnv, ShipVectorEnv, named

ENVIRONMENTS = {
    "shipgnc/BoatHeading-v0": {"scenario": "boat-autopilot", "perturb": ("psi_deg=uniform:-30,30",)},
    "shipgnc/BoatLOS-v0": {"scenario": "boat-los"},
    "shipgnc/CyberShipCourse-v0": {"scenario": "cybership-calm"},
    "shipgnc/CyberShipWaves-v0": {"scenario": "cybership-waves"},
    "shipgnc/CatamaranTurn-v0": {"scenario": "catamaran-turn"},
    "shipgnc/CatamaranHeading-v0": {"scenario": "catamaran-heading", "perturb": ("psi_deg=uniform:-30,30",)},
    "shipgnc/Ship-v0": {},
}


def register() -> None:
    """Register every id of :data:`ENVIRONMENTS` (again: a no-op)."""
    for env_id, kwargs in ENVIRONMENTS.items():
        if env_id not in gym.registry:
            gym.register(env_id, entry_point="shipgnc.rl.env:ShipEnv",
                         vector_entry_point="shipgnc.rl.env:ShipVectorEnv", kwargs=dict(kwargs))


register()

__all__ = ["ENVIRONMENTS", "ShipEnv", "ShipVectorEnv", "named", "register"]
