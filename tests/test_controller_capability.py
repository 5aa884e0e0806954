"""A controller kind reaches a vessel by the capability the vessel declares, not by a per-vessel
hook: the ``course`` controller is the heading autopilot on a vessel with a rudder state (every
catalogue vessel) and document 003's law on CyberShip II, and a controller kind registered with a
builder for ``rudder-state`` steers every catalogue vessel with no change to the vessel's code."""

from __future__ import annotations

import copy
import math
from dataclasses import fields
from typing import Literal

import numpy as np
import pytest

from shipgnc.errors import ConfigError
from shipgnc.scenarios import components as C
from shipgnc.scenarios import schema
from shipgnc.scenarios import sections as S
from shipgnc.scenarios.registry import load_scenario
from shipgnc.scenarios.runner import build, run_scenario


class RudderHoldConfig(S.Navigated):
    """A throwaway controller section: hold the rudder at ``delta_deg`` from the start."""

    type: Literal["rudder-hold"]
    delta_deg: float = 10.0
    Ts: float | None = None


class RudderHold:
    """Commands a constant rudder angle; the vessel's other inputs are held at their straight-run
    values (the catalogue's steady straight run, ``straight_state``)."""

    continuous = False
    reference_names: tuple[str, ...] = ()
    signals = ()

    def __init__(self, delta: float, hold: tuple[float, ...], Ts: float):
        self.delta, self.hold, self.Ts = delta, hold, Ts

    def reset(self, batch_shape) -> None:
        pass

    def step(self, t, measurement, reference):
        shape = measurement.shape[:-1]
        return np.stack([np.full(shape, self.delta)] + [np.full(shape, h) for h in self.hold],
                        axis=-1)

    def signal_values(self) -> dict:
        return {}


def rudder_hold(cfg, model, scenario):
    """The builder of the throwaway kind, living beside its test (nowhere in ``vessels/``)."""
    x0 = model.straight_state()
    state_names = [s.name for s in model.states]
    hold = tuple(float(x0[state_names.index(s.name.removesuffix("_c"))]) for s in model.inputs[1:])
    return RudderHold(math.radians(cfg.delta_deg), hold, cfg.Ts)


@pytest.fixture
def rudder_hold_kind(monkeypatch):
    """The registry with a ``rudder-hold`` controller kind for vessels with a rudder state, and
    the scenario schema's controller sections rebuilt from it (as a package registered before the
    schema is imported would have it); both restored afterwards."""
    kind = C.ControllerKind("rudder-hold", RudderHoldConfig,
                            by_capability=((C.RUDDER_STATE, f"{__name__}:rudder_hold"),))
    monkeypatch.setitem(C.CONTROLLERS, kind.type, kind)
    union = schema._union_by_type(C.CONTROLLERS)
    model_fields = schema.Scenario.__pydantic_fields__
    for name, annotation in (("controller", union | None),
                             ("controllers", dict[str, union] | None)):
        field = copy.copy(model_fields[name])
        field.annotation = annotation
        monkeypatch.setitem(model_fields, name, field)
    schema.Scenario.model_rebuild(force=True)
    yield kind
    monkeypatch.undo()
    schema.Scenario.model_rebuild(force=True)


def test_no_vessel_carries_its_own_controller_builder():
    assert "controller" not in {f.name for f in fields(C.VesselKind)}
    import shipgnc.vessels.scenario as catalogue_scenarios

    assert not hasattr(catalogue_scenarios, "controller")
    for name in C.CATALOGUE_VESSELS:
        assert C.RUDDER_STATE in C.VESSEL_KINDS[name].capabilities
        assert C.controller_builder("course", C.VESSEL_KINDS[name]).endswith(":course_autopilot")
    assert C.controller_builder("course", C.VESSEL_KINDS["cybership2"]).endswith(
        "runner:course_controller")


def test_a_registered_controller_kind_steers_a_catalogue_vessel(rudder_hold_kind):
    """A Nomoto ship (K = 0.05 1/s, T = 20 s) under the throwaway kind's constant 10° rudder
    settles at the first-order Nomoto model's steady yaw rate r = K δ (Nomoto et al. 1957;
    Fossen 2021 eq. 7.43): after 15 T the transient e^(−t/T) is below 1e-6."""
    K, T, delta = 0.05, 20.0, math.radians(10.0)
    scenario = load_scenario("mariner-cst-heading", [
        f"vessel={{model: nomoto, K: {K}, T: {T}, speed_mps: 6.0}}", "metrics=none",
        "controller={type: rudder-hold, delta_deg: 10.0}", "guidance=null",
        f"simulation.t_end={15 * T}", "simulation.backend=numpy"])
    assert isinstance(build(scenario).controller, RudderHold)
    run = run_scenario(scenario)
    r = run.result["r"].values
    np.testing.assert_allclose(r[-1], K * delta, rtol=1e-6)
    np.testing.assert_allclose(run.result["delta"].values[-1], delta, rtol=1e-12)


def test_the_registered_kind_fits_every_vessel_with_a_rudder_state_and_no_other(rudder_hold_kind):
    """The KVLCC2 (a propeller state too: its command held at the straight run) takes the new
    kind with no edit of its entry; CyberShip II, declaring no rudder state, refuses it naming
    the types that fit it."""
    scenario = load_scenario("mariner-cst-heading", [
        "vessel={model: kvlcc2}", "metrics=none", "controller={type: rudder-hold, delta_deg: 5}",
        "guidance=null"])
    controller = build(scenario).controller
    assert isinstance(controller, RudderHold) and len(controller.hold) == 1
    assert "rudder-hold" in C.controller_types(C.VESSEL_KINDS["kvlcc2"])
    with pytest.raises(ConfigError, match=r"type 'rudder-hold' does not fit vessel model "
                                          r"'cybership2' \(allowed: course\)"):
        load_scenario("cybership-calm", ["controllers=null", "controller={type: rudder-hold}"])


def test_the_course_laws_stay_with_the_vessels_they_are_designed_on():
    """Document 003's sliding-mode variants need CyberShip II's model; ``design: auto`` designs a
    rudder-state vessel's PD: each elsewhere is a one-line error naming what is allowed."""
    with pytest.raises(ConfigError, match=r"controller.variant = 'smc_tuned'.* variant 'pd'") as err:
        build(load_scenario("mariner-cst-heading", [
            "controller={type: course, variant: smc_tuned}"]))
    assert "\n" not in str(err.value)
    with pytest.raises(ConfigError, match=r"design = 'auto': designs the heading autopilot of a "
                                          r"vessel with a rudder state"):
        build(load_scenario("cybership-calm", ["controllers=null",
                                               "controller={type: course, design: auto}"]))
