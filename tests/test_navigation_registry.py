"""Sensors and estimators are registry records declared beside their classes
(:mod:`shipgnc.navigation.records`): the scenario schema's unions and the runner's navigation
set-up come from the records, and a sensor without a kernel takes the numpy loop rather than
running wrong in the compiled one."""

from __future__ import annotations

import importlib
import math
import typing

import numpy as np
import pytest

from shipgnc.errors import ConfigError
from shipgnc.navigation import GNSS, Compass, Navigation, Sensor
from shipgnc.navigation.records import EstimatorKind, SensorKind
from shipgnc.scenarios import components as C
from shipgnc.scenarios import runner
from shipgnc.scenarios.registry import load_scenario


@pytest.mark.parametrize("table, kind, cls_field", [(C.SENSORS, SensorKind, "sensor"),
                                                    (C.ESTIMATORS, EstimatorKind, "estimator")])
def test_each_record_is_declared_in_its_component_s_module(table, kind, cls_field):
    assert table, "no records collected"
    for name, record in table.items():
        assert isinstance(record, kind)
        module = importlib.import_module(getattr(record, cls_field).__module__)
        assert module.__name__ in C.NAVIGATION_MODULES
        assert record in vars(module).values(), f"{name}: not declared beside its class"
        assert record.config.__module__ == module.__name__
        # the section's discriminator is the record's name
        assert typing.get_args(record.config.model_fields["type"].annotation) == (name,)
        assert record.compiled  # every built-in sensor and estimator has its kernel


def test_the_schema_s_unions_are_the_records():
    from shipgnc.scenarios.schema import EstimatorConfig, SensorConfig

    assert set(typing.get_args(typing.get_args(SensorConfig)[0])) == {
        r.config for r in C.SENSORS.values()}
    assert set(typing.get_args(typing.get_args(EstimatorConfig)[0])) == {
        r.config for r in C.ESTIMATORS.values()}
    with pytest.raises(ConfigError, match=r"sensors\.0.*'sonar'.*'gnss', 'compass', 'gyro', 'log'"):
        load_scenario("boat-los-gnss", ["sensors=[{type: sonar}]"])


def test_the_runner_builds_navigation_through_the_records():
    """Scenario files give degrees, the sensors take radians (the record's builder converts)."""
    scenario = load_scenario("boat-los-gnss", [
        "sensors=[{type: gnss, noise_m: 2.0}, {type: compass, noise_deg: 0.5, bias_deg: 1.0}]",
        "estimator={type: ekf}"])
    nav = runner.navigation(scenario, scenario.controller)
    gnss, compass = nav.sensors
    assert isinstance(gnss, GNSS) and gnss.noise_std == 2.0
    assert isinstance(compass, Compass)
    assert compass.noise_std == pytest.approx(math.radians(0.5), rel=1e-15)
    assert compass.bias == pytest.approx(math.radians(1.0), rel=1e-15)
    assert type(nav.estimator) is C.ESTIMATORS["ekf"].estimator


class _Sonar(Sensor):
    """A depth-free test sensor: the surge speed with no error, and no kernel kind."""

    kind = "sonar"
    measures = ("u",)
    units = ("m/s",)
    noise_std = 0.0

    def _measure(self, u):
        return u

    def variances(self):
        return np.zeros(1)


def test_a_sensor_without_a_kernel_takes_the_numpy_loop():
    from shipgnc.sim.simulator import simulate

    scenario = load_scenario("boat-los-gnss", ["simulation.t_end=20"])
    setup, dt = runner.build(scenario), scenario.simulation.dt
    nav = Navigation([_Sonar()])
    assert nav.kernel_reason() == "sensor sonar (_Sonar) has no kernel"
    result = simulate(setup.model, setup.x0, t_end=20.0, dt=dt, actuator=setup.actuator,
                      controller=setup.controller, guidance=setup.guidance, navigation=nav,
                      u0=setup.u0)
    assert result.attrs["backend"] == "numpy"
    # an error-free sensor sampled at every control sample holds the true state of that sample
    hold = round(setup.controller.Ts / dt)
    np.testing.assert_array_equal(result.u_meas.values[::hold], result.u.values[::hold])
    with pytest.raises(ConfigError, match=r"sensor sonar \(_Sonar\) has no kernel"):
        simulate(setup.model, setup.x0, t_end=20.0, dt=dt, actuator=setup.actuator,
                 controller=setup.controller, guidance=setup.guidance, navigation=Navigation([_Sonar()]),
                 u0=setup.u0, backend="compiled")
