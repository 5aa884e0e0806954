"""The component registry is the one place that says which components exist and what fits what:
the schema's unions, its compatibility checks and the runner's dispatch follow its tables."""

from __future__ import annotations

import copy

import pytest

from shipgnc.errors import ConfigError
from shipgnc.scenarios import components as C
from shipgnc.scenarios import schema
from shipgnc.scenarios.registry import raw_scenario, validate

#: a built-in scenario of each controlled vessel kind (validated, then changed one field at a time)
BY_VESSEL = {"vectored-thrust-boat": "boat-los", "cybership2": "cybership-calm",
             "mariner": "mariner-lqr", "mariner-cst": "mariner-cst-heading"}


def _hooks():
    for table in (C.VESSEL_KINDS, C.CONTROLLERS, C.GUIDANCE, C.DISTURBANCES):
        for key, kind in table.items():
            for hook in ("build", "setup", "run", "initial_state", "check"):
                target = getattr(kind, hook, None)
                if target is not None:
                    yield f"{key}.{hook}", target
            for capability, target in getattr(kind, "by_capability", ()):
                yield f"{key}.by_capability[{capability}]", target


@pytest.mark.parametrize(("where", "target"), list(_hooks()))
def test_every_hook_names_a_function(where, target):
    assert callable(C.resolve(target)), where


def test_every_fit_names_a_registered_component():
    for kind in C.VESSEL_KINDS.values():
        assert set(kind.controllers) <= set(C.CONTROLLERS), kind.model
        assert C.controller_types(kind), f"{kind.model}: no controller fits it"
        assert set(kind.disturbances) <= set(C.DISTURBANCES), kind.model
    for kind in C.CONTROLLERS.values():
        assert set(kind.guidance) <= set(C.GUIDANCE), kind.type
    for kind in C.METRICS.values():
        assert kind.guidance is None or kind.guidance in C.GUIDANCE
    for kind in C.GUIDANCE.values():
        assert kind.vessels is None or set(kind.vessels) <= set(C.VESSEL_KINDS)


def test_capability_lists_are_the_registry_s():
    assert set(schema.CURRENT_VESSELS) == {n for n, k in C.VESSEL_KINDS.items() if k.current}
    assert set(schema.NAVIGATION_VESSELS) == {n for n, k in C.VESSEL_KINDS.items() if k.navigation}


def test_unknown_vessel_model_lists_every_registered_one():
    data, source = raw_scenario("boat-los")
    data["vessel"] = {"model": "hovercraft"}
    with pytest.raises(ConfigError) as err:
        validate(data, source)
    for name in C.VESSEL_KINDS:
        assert name in str(err.value)


@pytest.mark.parametrize("vessel", list(BY_VESSEL))
def test_a_controller_that_does_not_fit_is_refused_with_the_registry_s_list(vessel):
    data, source = raw_scenario(BY_VESSEL[vessel])
    validate(data, source)  # the scenario as built in
    kind = C.VESSEL_KINDS[vessel]
    fitting = C.controller_types(kind)
    foreign = next(t for t in C.CONTROLLERS if t not in fitting)
    changed = copy.deepcopy(data)
    changed.pop("controllers", None)
    minimal = {"open-loop": {"schedule": [{"t": 0, "T": 0, "alpha_deg": 0}]},
               "course": {"variant": "pd"}}.get(foreign, {})
    changed["controller"] = {"type": foreign, **minimal}
    with pytest.raises(ConfigError, match=rf"type '{foreign}' does not fit vessel model '{vessel}' "
                                          rf"\(allowed: {', '.join(fitting)}\)"):
        validate(changed, source)


@pytest.mark.parametrize("vessel", list(BY_VESSEL))
def test_a_disturbance_that_does_not_fit_is_refused(vessel):
    data, source = raw_scenario(BY_VESSEL[vessel])
    kind = C.VESSEL_KINDS[vessel]
    foreign = next(t for t in ("waves", "mariner", "constant") if t not in kind.disturbances)
    values = {"waves": {}, "mariner": {}, "constant": {"values": [0, 0, 0]}}[foreign]
    data["disturbance"] = {"type": foreign, **values}
    with pytest.raises(ConfigError, match=rf"disturbance type '{foreign}' does not fit vessel "
                                          rf"model '{vessel}'"):
        validate(data, source)


def test_a_controller_without_the_guidance_it_needs_is_refused():
    data, source = raw_scenario("cybership-calm")
    data["guidance"] = {"type": "schedule", "schedule": [{"t": 0, "psi_deg": 0, "u": 0.3}]}
    needs = C.CONTROLLERS["course"].guidance
    with pytest.raises(ConfigError, match=rf"needs a guidance section of type {' or '.join(needs)}"):
        validate(data, source)


def test_a_section_the_vessel_does_not_read_is_refused():
    data, source = raw_scenario("cybership-calm")
    data["montecarlo"] = {"runs": 4}
    with pytest.raises(ConfigError, match=r"montecarlo: applies to vessel model mariner"):
        validate(data, source)
    data, source = raw_scenario("mariner-lqr")
    data["actuator"] = {"thrust_time_constant": 1.0}
    with pytest.raises(ConfigError, match=r"actuator: applies to vessel model vectored-thrust-boat"):
        validate(data, source)


def test_a_metric_set_of_another_shape_is_refused():
    data, source = raw_scenario("boat-los")
    data["metrics"] = "catamaran"
    with pytest.raises(ConfigError, match=r"metrics = 'catamaran': scores vessel model 'catamaran', "
                                          r"not 'vectored-thrust-boat'"):
        validate(data, source)


def test_a_catamaran_case_refuses_what_its_builder_sets_naming_where_it_goes():
    for section, value, message in (  # the older spelling: a case builder's runs
            ("actuator", {"thrust_time_constant": 1.0}, r"runs\.ideal\.actuator: applies to vessel "
                                                         r"model vectored-thrust-boat"),
            ("montecarlo", {"runs": 3}, r"montecarlo: a scenario with a case section takes its runs "
                                        r"from the case builder \(set them in case\.options\)"),
            ("guidance", {"type": "yaw-rate"}, r"guidance: a scenario with a case section")):
        data, source = raw_scenario("catamaran-actuator")
        data.pop("runs", None), data.pop("guidance", None)
        data["case"] = {"builder": "actuator"}
        data[section] = value
        with pytest.raises(ConfigError, match=message):
            validate(data, source)
    for section, value, message in (  # the same sections on a scenario of controllers and guidance
            ("actuator", {"thrust_time_constant": 1.0}, r"actuator: applies to vessel model "
                                                         r"vectored-thrust-boat in this release, not "
                                                         r"'catamaran'$"),
            ("montecarlo", {"runs": 3}, r"montecarlo: applies to vessel model mariner"),
            ("disturbance", {"type": "constant", "values": [1, 0, 0]},
             r"does not fit vessel model 'catamaran' \(it takes none; an earth-fixed current is the "
             r"current section\)")):
        data, source = raw_scenario("catamaran-turn")
        data[section] = value
        with pytest.raises(ConfigError, match=message):
            validate(data, source)
    data, source = raw_scenario("catamaran-turn")  # in the file, or a --set of the whole section
    data["simulation"]["initial_state"] = {"u": 5.0}
    with pytest.raises(ConfigError, match=r"simulation\.initial_state: vessel model 'catamaran' does "
                                          r"not read it"):
        validate(data, source)


def test_a_config_class_name_is_not_a_vessel_model():
    data, source = raw_scenario("boat-los")
    data["vessel"] = {"model": "MarinerVesselConfig"}
    with pytest.raises(ConfigError, match="unknown vessel model; allowed: vectored-thrust-boat"):
        validate(data, source)


def test_the_runner_dispatches_by_the_registry():
    from shipgnc.guidance.los import LOSGuidance
    from shipgnc.scenarios.registry import load_scenario
    from shipgnc.scenarios.runner import build
    from shipgnc.vessels.autopilot import HeadingAutopilot

    assert C.GUIDANCE["los"].build.endswith(":los_guidance")
    assert isinstance(build(load_scenario("boat-los")).guidance, LOSGuidance)
    # a ``course`` controller on a vessel with a rudder state is the heading autopilot (the
    # builder for the capability the catalogue declares), on CyberShip II document 003's law
    assert isinstance(build(load_scenario("mariner-cst-heading")).controller, HeadingAutopilot)
    assert not isinstance(build(load_scenario("cybership-calm")).controller, HeadingAutopilot)


def test_show_of_a_catamaran_scenario_lists_what_a_set_can_change():
    """``shipgnc show`` prints the fields that act on the run: a scenario's runs as given; a
    scenario of controllers and guidance its sections' fields; neither the initial state and
    integrator the runs do not read; a ``--set`` into one of those is refused instead of being
    ignored."""
    import yaml

    from shipgnc.cases.catamaran import ACTUATOR_RUNS
    from shipgnc.scenarios.registry import load_scenario, scenario_yaml

    shown = yaml.safe_load(scenario_yaml(load_scenario("catamaran-actuator")))
    assert "initial_state" not in shown["simulation"] and "integrator" not in shown["simulation"]
    assert "sensors" not in shown and "actuator" not in shown and "controllers" not in shown
    assert list(shown["runs"]) == ["ideal", *ACTUATOR_RUNS]  # S8's runs (note 004-4.7)
    for key, (T_t, k_t) in ACTUATOR_RUNS.items():
        assert shown["runs"][key]["vessel"]["thruster"] == {"T_t": T_t, "k_t": k_t}
        assert shown["runs"][key]["controller"]["T_a"] == 2.0  # the law assumes T_a = 2 s, k_a = 1
    assert "case" not in shown
    shown = yaml.safe_load(scenario_yaml(load_scenario("catamaran-heading")))
    assert "initial_state" not in shown["simulation"] and "case" not in shown
    assert shown["guidance"] == {"type": "heading-capture", "psi_target_rad": 0.8, "omega_c": 0.0022,
                                 "ramp_s": 0.0}  # document 004, S7: K* = 0.8 rad, ω_c = 0.0022 rad/s
    assert shown["controller"] == {"type": "yaw-rate-fsm", "law": 21}
    for key in ("simulation.initial_state.u=3", "simulation.integrator=solve_ivp"):
        with pytest.raises(ConfigError, match=r"does not read simulation\.\w+ .*would be ignored"):
            load_scenario("catamaran-turn", [key])


def test_show_reads_back_as_the_same_scenario_for_every_built_in():
    """What ``shipgnc show`` prints is a scenario file: validated again it is the same scenario
    (a null that is not a field's default, e.g. a GNSS ``rate_hz: null``, is kept)."""
    import yaml

    from shipgnc.scenarios.registry import builtin_names, load_scenario, scenario_yaml

    for name in builtin_names():
        scenario = load_scenario(name)
        text = scenario_yaml(scenario)
        again = validate(yaml.safe_load(text), f"shown {name}")
        # the same sections (a file in the older case spelling is shown as the runs it makes)
        assert again.model_dump() == scenario.model_dump(), name
        assert scenario_yaml(again) == text, name
    shown = yaml.safe_load(scenario_yaml(load_scenario("cybership-waves-observer")))
    assert any(s["type"] == "gnss" and s["rate_hz"] is None for s in shown["sensors"])
