"""
Navigation: an EKF between the sensors and the autopilot
========================================================

With ``navigation=`` the controller and the guidance act on an estimate instead of the truth
(:doc:`/navigation`): here GNSS at 1 Hz with a 10 s dropout, a compass and a rate gyro feed an
extended Kalman filter on the boat's own model, started 20 m off in north (the first fix, at
t = 0, pulls it in). The LOS guidance
steers the boat on the estimate; the figure shows the estimate converging on the truth and
bridging the dropout on the model and the gyro.
"""

import math

import matplotlib.pyplot as plt
import numpy as np

from shipgnc import HeadingSpeedAutopilot, LOSGuidance, VectoredThrustBoat, WaypointPath, simulate
from shipgnc.navigation import GNSS, Compass, ExtendedKalmanFilter, Navigation, RateGyro
from shipgnc.viz.style import show_example

boat = VectoredThrustBoat()
path = WaypointPath(np.array([[0.0, 0.0], [60.0, 0.0], [60.0, 60.0]]))
nav = Navigation(
    sensors=[GNSS(1.5, rate_hz=1.0, dropouts=[(20.0, 30.0)]), Compass(math.radians(1.0)),
             RateGyro(math.radians(0.2))],
    estimator=ExtendedKalmanFilter(process_psd={"u": 1e-3, "v": 1e-3, "r": 1e-4},
                                   P0_std={"north": 20.0, "east": 20.0}, x0_offset={"north": 20.0}))
result = simulate(boat, np.array([0.0, -10.0, 0.0, 0.0, 0.0, 0.0]), t_end=60.0, dt=0.05,
                  controller=HeadingSpeedAutopilot(boat.params, Ts=0.1),
                  guidance=LOSGuidance(path, lookahead=8.0, speed=1.5), navigation=nav, seed=1)
error = np.hypot(result.north - result.north_hat, result.east - result.east_hat)
print("logged:", [name for name in result.data_vars if name.endswith(("_meas", "_hat"))])
print(f"position error: {float(error[0]):.1f} m at t = 0, {float(error[-1]):.2f} m at the end")

fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4))
ax1.plot(result.east, result.north, label="truth")
ax1.plot(result.east_hat, result.north_hat, ls="--", label="EKF estimate")
ax1.plot(result.east_meas, result.north_meas, ".", ms=3, label="GNSS fixes")
ax1.set(xlabel="east [m]", ylabel="north [m]", aspect="equal", title="track")
ax1.legend()
ax2.plot(result.time, error)
ax2.axvspan(20, 30, color="0.9", label="GNSS dropout")
ax2.set(xlabel="time [s]", ylabel="|position error| [m]", yscale="log", title="estimate vs truth")
ax2.legend()
fig.tight_layout()
show_example()   # run as a script: saves the figure (and shows it where there is a display)
