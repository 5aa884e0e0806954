"""Navigation, the N in GNC: sensor models and state estimators between the true state and the
controller (docs/navigation.md).

    true state x ──▶ sensors (GNSS, compass, rate gyro, speed log) ──▶ estimator (KF | EKF |
    passive observer) ──▶ x̂ ──▶ guidance and controller

The interface the simulation loop calls (:func:`shipgnc.sim.simulator.simulate`, ``navigation=``):

``Navigation(sensors=[...], estimator=None | KalmanFilter | ExtendedKalmanFilter | PassiveObserver)``

* ``signals: tuple[Signal, ...]`` — what the loop logs (complete after ``reset``):
  ``<state>_meas`` (held measurement, NaN while not valid) and ``<sensor>_valid`` (1/0) per
  sensor; with an estimator ``<state>_hat`` for every estimated quantity, and for the Kalman
  filters ``<state>_std`` (√ of the covariance diagonal) and ``nees``
  ((x − x̂)ᵀP⁻¹(x − x̂) against the true state, over the estimated model states).
* ``reset(batch_shape, rng, model, Ts) -> None`` — validates against the model (measured states
  found by name in ``model.states``) and the control period ``Ts`` (every sensor period a whole
  multiple of it), draws the initial error states. Random numbers come from child streams
  ``rng.spawn(...)`` of the run's generator (one per sensor and one for the estimator; per ship
  when ``rng`` is a :class:`~shipgnc.streams.MemberStreams`): the run's disturbance draws are
  the same with or without navigation, and the same seed gives the same run.
* ``observe(t, x, u) -> x_seen`` — at every control sample, with the TRUE state ``x``
  (*batch, n_states) and the input ``u`` (*batch, n_inputs) applied over the last sample. Returns
  the state the guidance and the controller see (*batch, n_states): with an estimator its estimate
  for the states it estimates; every other state measured by a valid sensor is replaced by the
  held measurement; a state nobody measures or estimates (and a measured one before its sensor's
  first valid sample) stays the true value.
* ``signal_values() -> dict[str, np.ndarray]`` — the last values of ``signals`` for the log.

No navigation (``navigation=None``) is today's loop unchanged: the controller reads the truth.

Both loops run navigation, and its arithmetic is written once: each sensor's and estimator's
per-ship step is a scalar kernel of :mod:`shipgnc.navigation.kernels`, whose batch over ships
(:func:`shipgnc.derive.per_ship`) the numpy classes call, and which the composed compiled loop
calls ship by ship (:mod:`shipgnc.sim.nav_template`; :meth:`Navigation.kernel` packs the blocks,
declared by named fields in :mod:`shipgnc.navigation.layout`), with the sensors' draws taken from
the same child streams, so a seed gives the same run in both. Sensors and estimators are slots
of that loop: the sensor kernel computes every sensor whose errors are its model
(``Sensor.kernel_errors``), an estimator's ``kernel_block`` names its slot's function; a sensor or
an estimator without them runs in the numpy loop (``unsupported_reason`` names it).

Each sensor and estimator module declares its registry record beside its class
(:mod:`shipgnc.navigation.records`; e.g. :data:`~shipgnc.navigation.sensors.GNSS_SENSOR`), which
the scenario registry collects. The names below are imported when first used, so that reading a
scenario file (the records and their sections) does not import the compiled kernels.
"""

from importlib import import_module

_HOMES = {
    "Navigation": "core", "spawn_streams": "core",
    "ExtendedKalmanFilter": "ekf", "force_psd_to_state_psd": "ekf",
    "Estimator": "estimator", "GaussianFilter": "estimator",
    "KalmanFilter": "kalman", "heading_wave_kf": "kalman", "van_loan": "kalman",
    "PassiveObserver": "passive_observer",
    "GNSS": "sensors", "SENSOR_TYPES": "sensors", "Compass": "sensors", "RateGyro": "sensors",
    "Sensor": "sensors", "SpeedLog": "sensors",
    "EstimatorKind": "records", "SensorKind": "records",
}


def __getattr__(name: str):
    home = _HOMES.get(name)
    if home is None:
        raise AttributeError(f"module 'shipgnc.navigation' has no attribute {name!r}")
    value = getattr(import_module(f"shipgnc.navigation.{home}"), name)
    globals()[name] = value
    return value


def __dir__():
    return sorted([*globals(), *_HOMES])


__all__ = ["GNSS", "SENSOR_TYPES", "Compass", "Estimator", "EstimatorKind", "ExtendedKalmanFilter",
           "GaussianFilter", "KalmanFilter", "Navigation", "PassiveObserver", "RateGyro", "Sensor",
           "SensorKind", "SpeedLog", "force_psd_to_state_psd", "heading_wave_kf", "spawn_streams",
           "van_loan"]
