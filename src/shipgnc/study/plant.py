"""A Monte Carlo over the plant: each member's own draw of the perturbed vessel parameters
(``--perturb vessel.params.NAME=...``).

Member *i* draws its parameters from its third stream (:meth:`Study.member_streams`), in the
order the perturbations are given; its plant is the scenario's model with those parameters
(validated by the parameter class's own ``with_``), and a chunk runs its members' plants as one
:class:`~shipgnc.models.per_ship.PerShipModel`. Only the plant changes: the controller, the
guidance and the actuator are built from the nominal model (a controller designed on the nominal
model meets the uncertain plant, which is the point of such a study). So a parameter that does
not enter the model's equations of motion (an actuator limit such as ``T_max``, ``delta_max``,
``delta_rate``, which a batch shares) is refused rather than silently ignored.
"""

from __future__ import annotations

import math

import numpy as np

from shipgnc.errors import ConfigError
from shipgnc.kernels import NotCompiled
from shipgnc.models.per_ship import PerShipModel, plant_params, with_params
from shipgnc.study.spec import PARAM_PREFIX, Perturbation, Study


def _numeric(value) -> bool:
    return isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool)


def _signature(model):
    """What the parameters change in the equations: the kernel's parameters (the numpy form's
    numbers, combined as it combines them) and the input limits."""
    lower, upper = model.input_limits()
    kernel = None
    if callable(getattr(model, "kernel", None)):
        try:
            kernel = np.asarray(model.kernel().params, dtype=float)
        except (NotCompiled, ConfigError):  # no kernel for this setting: the limits only
            kernel = None
    return kernel, np.asarray(lower, dtype=float), np.asarray(upper, dtype=float)


def _enters_equations(model, name: str, value: float) -> bool | None:
    """Whether a small change of ``name`` changes the model's equations (True), only its input
    limits or nothing (False); None when neither direction of the change is valid."""
    if name in getattr(getattr(model, "params", None), "inactive", ()):
        return False  # the model says so (e.g. the catamaran's lag constants without the lag)
    kernel0, lower0, upper0 = _signature(model)
    step = 1e-3 * abs(value) if value != 0 else 1e-3
    for changed in (value + step, value - step):
        try:
            kernel, lower, upper = _signature(with_params(model, **{name: changed}))
        except ConfigError:
            continue
        if not (np.array_equal(lower, lower0) and np.array_equal(upper, upper0)):
            return False
        if kernel is None or kernel0 is None:
            return True  # no kernel to tell: a parameter that keeps the limits is taken as a plant's
        return not (kernel.shape == kernel0.shape and np.array_equal(kernel, kernel0))
    return None


def perturbable_params(model) -> list[str]:
    """The numeric parameters of ``model`` that enter its equations of motion (sorted)."""
    out = []
    for name, value in plant_params(model).items():
        if _numeric(value) and math.isfinite(value) and _enters_equations(model, name, float(value)):
            out.append(name)
    return sorted(out)


def check_plant(perturb, model, flag: str = "--perturb") -> None:
    """Every perturbed parameter must be a numeric parameter of ``model`` that enters its
    equations of motion; a relative spread needs a non-zero nominal value; a uniform spread's
    bounds must be valid values (checked before any work)."""
    plant = [p for p in perturb if p.param is not None]
    if not plant:
        return
    kind = type(model).__name__
    nominal = plant_params(model)
    allowed = perturbable_params(model)
    for p in plant:
        if p.param not in allowed:
            if p.param not in nominal:
                why = _missing(model, p.param)
            elif not _numeric(nominal[p.param]):
                why = f"{PARAM_PREFIX}{p.param} of the {kind} is not a number"
            elif p.param in getattr(model.params, "inactive", ()):
                why = (f"{PARAM_PREFIX}{p.param} does not enter the {kind}'s equations as set up "
                       "(the catamaran's T_t, k_t act only with vessel.thruster)")
            else:
                why = (f"{PARAM_PREFIX}{p.param} does not enter the {kind}'s equations of motion "
                       "(an actuator limit or a drawing size, one per batch)")
            raise ConfigError(f"{flag} {p}: {why}; perturbable: {', '.join(allowed)}")
        value = float(nominal[p.param])
        if p.relative and value == 0:
            raise ConfigError(f"{flag} {p}: the nominal {p.param} is 0, so a % spread is none; "
                              "give an absolute one")
        if p.kind == "uniform":
            for bound in (p.low, p.high):
                drawn = p.apply(value, bound)
                try:
                    with_params(model, **{p.param: drawn})
                except ConfigError as exc:
                    raise ConfigError(f"{flag} {p}: members would draw {p.param} = {drawn:g}, "
                                      f"outside the model's range ({exc}); narrow the "
                                      "distribution") from None


def _missing(model, name: str) -> str:
    """Why ``model`` has no parameter ``name`` to perturb: a catalogue vessel's section may take
    it but not give it (a default the builder works out, e.g. ``R66``; an alternative, e.g.
    ``Cb`` beside the matrices), or give it as a matrix; else the model has none."""
    config = getattr(model, "vessel_config", None)
    if config is None:
        return f"the {type(model).__name__} has no parameter {name!r}"
    from shipgnc.vessels.catalogue import get_vessel

    given = config.params()
    if name in given:
        return f"vessel.{name} of the {config.model} vessel section is not a number (a matrix)"
    if name in config.optional_fields():
        return (f"the {config.model} vessel section does not set {name} (give it there, "
                f"vessel.{name}: VALUE, to perturb it about that value)")
    if name in get_vessel(config.model).param_names:
        return (f"the {config.model} vessel section with {', '.join(given)} does not take "
                f"{name}")
    return f"the {config.model} vessel has no parameter {name!r}"


def member_params(study: Study, model, start: int, stop: int) -> dict[str, np.ndarray]:
    """Each perturbed parameter's value [SI] for members ``start .. stop-1`` (nominal of
    ``model`` plus the member's own draw, from its plant stream); empty without a plant
    perturbation."""
    plant = study.plant
    if not plant:
        return {}
    nominal = plant_params(model)
    values = {p.param: np.empty(stop - start) for p in plant}
    for row, member in enumerate(range(start, stop)):
        rng = np.random.default_rng(study.member_stream(member, 2))
        for p in plant:
            values[p.param][row] = p.apply(float(nominal[p.param]), p.draw(rng))
    return values


def member_plant(study: Study, model, start: int, stop: int,
                 values: dict[str, np.ndarray]) -> PerShipModel:
    """The members' plants as one model; a member whose draw leaves the model's valid range is a
    one-line ConfigError naming the member, its values and the ``--perturb`` items."""
    models = []
    for row, member in enumerate(range(start, stop)):
        draw = {name: float(v[row]) for name, v in values.items()}
        try:
            models.append(with_params(model, **draw))
        except ConfigError as exc:
            items = ", ".join(str(p) for p in study.plant)
            drawn = ", ".join(f"{name} = {v:g}" for name, v in draw.items())
            raise ConfigError(f"--perturb {items}: member {member} draws {drawn}, outside the "
                              f"model's range ({exc}); narrow the distribution") from None
    return PerShipModel(tuple(models), model)


def param_variables(study: Study, values: dict[str, np.ndarray]) -> dict:
    """The draws as Dataset variables ``param_<NAME>`` over ``member`` (SI)."""
    by_name: dict[str, Perturbation] = {p.param: p for p in study.plant}
    return {f"param_{name}": ("member", np.asarray(v, dtype=float),
                              {"long_name": f"{PARAM_PREFIX}{name} of the member's plant (SI)",
                               "perturb": str(by_name[name])})
            for name, v in values.items()}
