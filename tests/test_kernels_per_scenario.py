"""Each built-in scenario's component kernels: the compiled batch over ships that
:func:`shipgnc.derive.per_ship` derives from a kernel equals the kernel's own plain-Python form
(``py_func``, :func:`shipgnc.derive.plain_python`) on a few ships near the scenario's initial
state — the compiled code computes what its source says.

Tolerance: 1e-12 relative to the output's largest magnitude (and exact equality of a guidance's
"finished" flag). The two are not bit-identical by design: the compiled kernel contracts
``a*b + c`` into one fused multiply-add and may compute ``x/c`` as ``x*(1/c)``
(:data:`shipgnc.kernels.JIT_OPTIONS`), and numba's libm may differ from CPython's ``math`` by an
ulp; each is at most one rounding (≈ 1.1e-16 relative) per operation, and a kernel's output is a
few dozen operations deep, so 1e-12 leaves two orders of margin for cancellation while any wrong
term (a sign, a swapped index, a missing factor) shows at 1e-3 or more.

A scenario without component kernels says why in its test id (a routing problem that simulates
nothing), and one whose component has no kernel asserts that its runs take the numpy loop.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from shipgnc.derive import per_ship, plain_python
from shipgnc.errors import ConfigError
from shipgnc.kernels import NotCompiled
from shipgnc.scenarios.registry import builtin_names, load_scenario
from shipgnc.scenarios.runner import build, simulation_of
from shipgnc.sim import compose
from shipgnc.sim.simulator import _validate, reset_components

#: a kernel's arguments in the order of the composed loop's calls (shipgnc.derive's letters)
SPECS = {"model": "i i i p o", "controller": "t i i z p o o", "guidance": "t i z p o o -> r",
         "disturbance": "t i z p i o", "current": "t i z p i o"}
RTOL = 1e-12
#: ships of a scenario that runs one
SHIPS = 3


def _case(name):
    scenario = load_scenario(name)
    if scenario.route is not None and scenario.sail is None:
        return pytest.param(name, id=f"{name}-routing-only-nothing-simulated")
    return pytest.param(name, id=name)


def _setup(name):
    """The scenario's first run as a SimSetup of a few ships (a batch scenario: its own ships),
    states drawn near its initial state, components reset as a run resets them."""
    scenario = load_scenario(name)
    built = build(scenario)
    sim = simulation_of(scenario, built)
    x0 = np.asarray(built.x0, dtype=float)
    rng = np.random.default_rng(7)
    if x0.ndim == 1:
        x0 = np.tile(x0, (SHIPS, 1))
    x0 = x0 + rng.normal(scale=0.01, size=x0.shape) * (1.0 + np.abs(x0))
    setup = _validate(built.model, x0, t_end=10 * sim.dt, dt=sim.dt, controller=built.controller,
                      actuator=built.actuator, guidance=built.guidance,
                      disturbance=built.disturbance, u0=built.u0, integrator="rk4",
                      method="RK45", rtol=1e-3, atol=1e-6, seed=1, on_divergence="raise",
                      observer=None, progress=None, log_every=1,
                      navigation=getattr(built, "navigation", None))
    reset_components(setup)
    return setup


def _kernels(setup):
    """role → Kernel of each component that has one; role → why for the others."""
    batch, dt = setup.batch_shape, setup.dt
    makers = {
        "model": (setup.model, lambda c: c.kernel()),
        "guidance": (setup.guidance, lambda c: c.kernel(batch)),  # its references feed the
        "controller": (setup.controller, lambda c: c.kernel(batch)),  # controller's
        "disturbance": (setup.disturbance, lambda c: c.kernel(batch, dt=dt)),
        "current": (setup.disturbance, lambda c: c.kernel_current(batch, dt=dt)),
    }
    kernels, missing = {}, {}
    for role, (component, make) in makers.items():
        attribute = "kernel_current" if role == "current" else "kernel"
        if component is None or (role == "current" and not hasattr(component, attribute)):
            continue
        why = getattr(component, "kernel_reason", None)
        reason = why() if callable(why) and role != "current" else None
        if not callable(getattr(component, attribute, None)) or reason:
            missing[role] = reason or f"{type(component).__name__} has no kernel"
            continue
        try:
            kernels[role] = make(component)
        except NotCompiled as exc:
            missing[role] = str(exc)
    return kernels, missing


def _arguments(role, kernel, setup, n, ref):
    """The kernel's arguments for ``n`` ships (states as fresh copies: each form updates its own)."""
    model = setup.model
    rng = np.random.default_rng(11)
    x = setup.x0.reshape(n, -1)
    p = np.atleast_2d(kernel.params)
    z = kernel.state_for(n)
    if role == "model":
        u = np.broadcast_to(setup.u0, (n, setup.actuator.n)) * (1 + 0.01 * rng.normal(size=(n, 1)))
        d = 0.01 * rng.normal(size=(n, len(model.disturbances)))
        return (x, u, d, p, len(model.states))
    if role == "controller":
        return (0.3, x, ref, z, p, setup.actuator.n, len(getattr(setup.controller, "signals", ())))
    if role == "guidance":
        return (0.3, x, z, p, len(setup.guidance.references), len(setup.guidance.outputs))
    table = kernel.table(0, 1)[0] if kernel.table is not None else np.zeros((n, 0))
    return (0.3, x, z, p, np.ascontiguousarray(table), len(model.disturbances))


@pytest.mark.parametrize("name", [_case(name) for name in builtin_names()])
def test_each_kernel_of_the_scenario_is_its_plain_python_form(name):
    scenario = load_scenario(name)
    if scenario.route is not None and scenario.sail is None:
        with pytest.raises(ConfigError, match="nothing is simulated"):
            build(scenario)
        return
    setup = _setup(name)
    n = math.prod(setup.batch_shape)
    kernels, missing = _kernels(setup)
    if missing:  # a component without a kernel: the run takes the numpy loop, and says why
        assert compose.unsupported_reason(setup) is not None, missing
    assert "model" in kernels or "model" in missing
    ref = np.zeros((n, 0))
    checked = []
    for role, kernel in kernels.items():
        batch = per_ship(kernel.function, SPECS[role])
        args = _arguments(role, kernel, setup, n, ref)
        fresh = tuple(a.copy() if isinstance(a, np.ndarray) else a for a in args)  # each form
        compiled = _as_list(batch(*args))  # updates its own component state
        with plain_python():
            plain = _as_list(batch(*fresh))
        if role in ("controller", "guidance"):
            compiled.append(args[3 if role == "controller" else 2])
            plain.append(fresh[3 if role == "controller" else 2])
        for got, want in zip(compiled, plain, strict=True):
            scale = max(1.0, float(np.max(np.abs(want)))) if want.size else 1.0
            np.testing.assert_allclose(got, want, rtol=0, atol=RTOL * scale,
                                       err_msg=f"{name}: {role} kernel {kernel.function}")
        if role == "guidance":
            np.testing.assert_array_equal(compiled[2], plain[2])  # finished flags
            ref = np.ascontiguousarray(plain[0].reshape(n, -1))  # the controller's references
        checked.append(role)
    assert checked or missing


def _as_list(result):
    return [np.asarray(r) for r in (result if isinstance(result, tuple) else (result,))]
