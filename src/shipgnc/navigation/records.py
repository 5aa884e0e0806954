"""Registry records of the sensors and the estimators: what a scenario file's ``sensors[].type``
and ``estimator.type`` may name.

Each record is declared in the module of the component it describes, beside its class (e.g.
:data:`shipgnc.navigation.sensors.GNSS_SENSOR`), and collected by the component registry
(:mod:`shipgnc.scenarios.components`: the built-in modules, and third-party packages' through the
``shipgnc.components`` entry-point group). The scenario schema's unions of sensor and estimator
sections and the runner's navigation set-up are derived from the records, so a new sensor or
estimator is its module (class, configuration section, record) and its test.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass


@dataclass(frozen=True)
class SensorKind:
    """A ``sensors[].type``.

    ``config``: its configuration section (a :class:`~shipgnc.config_types.Strict` model with a
    ``type: Literal[...]`` field, usually a subclass of
    :class:`~shipgnc.navigation.sensors.SensorConfigBase`); ``sensor``: its class (a
    :class:`~shipgnc.navigation.sensors.Sensor`); ``build(cfg) -> Sensor``: the sensor of a
    section, scenario units (degrees) converted to SI here; ``measures``: the model states it
    measures by default (capability, shown in the docs). The compiled loop's sensor kernel
    computes it when its class's errors are that kernel's model (:attr:`compiled`)."""

    type: str
    config: type
    sensor: type
    build: Callable
    measures: tuple[str, ...] = ()

    @property
    def compiled(self) -> bool:
        """The composed compiled loop computes this sensor (its class's ``kernel_errors``: its
        errors are the model of :func:`shipgnc.navigation.kernels.sensors_observe`); otherwise
        a run with it takes the numpy loop."""
        return bool(getattr(self.sensor, "kernel_errors", False))


@dataclass(frozen=True)
class EstimatorKind:
    """An ``estimator.type``.

    ``config``: its configuration section (``type: Literal[...]``); ``estimator``: its class (an
    :class:`~shipgnc.navigation.estimator.Estimator`); ``build(cfg) -> Estimator``: the estimator
    of a section; ``needs``: model states the sensors must measure (capability; the estimator's
    ``prepare`` refuses a run without them in one line). Its kernel for the compiled loop is the
    class's ``kernel_block`` (:attr:`compiled`)."""

    type: str
    config: type
    estimator: type
    build: Callable
    needs: tuple[str, ...] = ()

    @property
    def compiled(self) -> bool:
        """The composed compiled loop computes this estimator (its class has ``kernel_block``);
        otherwise a run with it takes the numpy loop."""
        return callable(getattr(self.estimator, "kernel_block", None))
