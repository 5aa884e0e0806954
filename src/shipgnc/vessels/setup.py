"""A catalogue vessel made ready to sail: the one way a vessel section (a scenario's ``vessel:``, a
vessel file of ``shipgnc trial --vessel FILE``, the YAML ``shipgnc identify`` writes) or a
catalogue name becomes model + actuator + straight-run inputs + limits + name, for ``shipgnc run``
and ``shipgnc trial`` alike."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True, eq=False)
class VesselSetup:
    """A built catalogue vessel: ``model`` at its speed, ``actuator`` (the model's input saturation;
    the steering machine is inside the model), ``u0`` the inputs that hold the straight run (trim
    rudder, propeller at its straight-run state), the rudder's limit ``max_rudder`` [rad] and rate
    ``rudder_rate`` [rad/s] (the model's steering machine), ``length_m`` (the entry's, else the
    length a ship from main dimensions is built with; None: the model has none), the catalogue
    ``entry`` and the ``name`` it is shown by."""

    name: str
    entry: object
    model: object
    actuator: object
    u0: np.ndarray
    length_m: float | None
    max_rudder: float
    rudder_rate: float
    config: object | None = None

    @property
    def can_reverse(self) -> bool:
        return bool(self.entry.can_reverse)

    @property
    def source(self) -> str:
        return self.entry.source


def vessel_setup(vessel, speed_mps: float | None = None, *, name: str | None = None,
                 **params) -> VesselSetup:
    """``vessel``: a validated vessel section (:class:`~shipgnc.vessels.config.CatalogueVesselConfig`,
    from a scenario or a file: its speed and parameters) or a catalogue name (``params``: the
    entry's parameters, e.g. K, T of ``nomoto``). ``speed_mps`` and ``params`` given with a
    section override its own (a trial's test speed, the SOLAS steering gear's rate); null values
    are left out. A one-line ConfigError for a bad parameter or a speed outside the valid range."""
    from shipgnc.actuators import Actuator
    from shipgnc.vessels.catalogue import get_vessel
    from shipgnc.vessels.scenario import straight_inputs

    params = {k: v for k, v in params.items() if v is not None}
    config = None if isinstance(vessel, str) else vessel
    entry = get_vessel(vessel if config is None else config.model)
    if config is not None and speed_mps is None and not params:
        model = config.build()  # (keeps the section: a study may rebuild it, vessel.params.X)
    else:
        if config is not None:
            params = {**config.params(), **params}
            speed_mps = config.speed_mps if speed_mps is None else speed_mps
        model = entry.build(speed_mps, **params)
    length = entry.length_m
    if length is None:
        length = getattr(model, "length", None)
    length = None if length is None else float(length)
    return VesselSetup(name=name or entry.name, entry=entry, model=model,
                       actuator=Actuator.for_model(model), u0=straight_inputs(model),
                       length_m=length, max_rudder=float(model.delta_max),
                       rudder_rate=float(model.delta_rate), config=config)

