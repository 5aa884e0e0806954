"""
A gymnasium loop with a scripted policy
=======================================

The scenarios double as `gymnasium <https://gymnasium.farama.org>`_ environments
(:doc:`/rl`): ``shipgnc/BoatHeading-v0`` rewards holding the heading reference of
``boat-autopilot``. A reinforcement-learning agent would replace the scripted policy below — a PD on
the named observations with a constant thrust — and its training loop is exactly this loop.
Sign: ``psi_error`` is ψ − ψ_ref and a thruster angle α > 0 turns the boat to port, so the PD's
α has the sign of the error (the opposite sign spins the boat).
"""

import gymnasium as gym
import matplotlib.pyplot as plt
import numpy as np

import shipgnc.rl  # noqa: F401  (registers the environment ids)
from shipgnc.viz.style import show_example

env = gym.make("shipgnc/BoatHeading-v0")
obs, info = env.reset(seed=0)
names = env.unwrapped.observation_names
psi_error, rewards = [], []
for _ in range(400):
    o = env.unwrapped.named(obs)                     # {"psi_error": ..., "r": ..., ...}
    # psi_error = ψ − ψ_ref; a thruster angle α > 0 (to starboard) turns the bow to port
    # (yaw moment −L_m T sin α), so the PD turns α the same sign as the error and the yaw rate
    action = np.array([120.0, np.clip(1.5 * o["psi_error"] + 1.0 * o["r"], -0.78, 0.78)])   # [N, rad]
    obs, reward, terminated, truncated, info = env.step(action)
    psi_error.append(np.degrees(o["psi_error"]))
    rewards.append(reward)
    if terminated or truncated:
        break
print("observations:", names)
print(f"{len(rewards)} steps, return {sum(rewards):.3f}")

fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(7, 4.5), sharex=True)
ax1.plot(psi_error)
ax1.set(ylabel="heading error [deg]", title="scripted policy on shipgnc/BoatHeading-v0")
ax2.plot(np.cumsum(rewards))
ax2.set(xlabel="step", ylabel="cumulative reward")
fig.tight_layout()
show_example()   # run as a script: saves the figure (and shows it where there is a display)
