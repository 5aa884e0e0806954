"""Actuators between the controller's command and the model's input.

Per input channel: saturation to ``[lower, upper]``, an optional rate limit ``rate`` [unit/s]
and an optional first-order lag ``tau`` [s]. The controller's command is held over each step
(zero-order hold); the applied input may move within the step:

* no lag, no rate limit: u = sat(cmd), constant over the step (document 001's ``np.clip``);
* rate limit, no lag: the applied value slews towards sat(cmd) at most ``rate·h`` per step,
  moving linearly within the step (``rate_mode="ramp"``, the motion of a slewing servo), or
  jumping to the slewed value at the step's start and holding it (``rate_mode="hold"``, a
  discrete rate limiter, as many published simulations do);
* lag (τ > 0): ȧ = clip((sat(cmd) − a)/τ, −rate, rate), integrated in the same RK4 stages as the
  plant (document 004 eq. (22)); u = a.

Logged values: the command and the applied input at each sample instant.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from shipgnc.derive import per_ship
from shipgnc.errors import ConfigError, require
from shipgnc.kernels import clip, kernel_function


def _per_channel(value, n: int, field: str, default: float) -> np.ndarray:
    if value is None:
        return np.full(n, default, dtype=float)
    arr = np.broadcast_to(np.asarray(value, dtype=float), (n,)).copy()
    return arr


@dataclass(frozen=True, eq=False)
class Actuator:
    """Saturation + rate limit + first-order lag, vectorised over channels and ships.

    Parameters are per channel (scalars broadcast): ``lower``/``upper`` bounds, ``rate``
    (``inf`` = none) and ``tau`` (0 = no lag). ``names`` label the channels in errors.
    """

    lower: np.ndarray
    upper: np.ndarray
    rate: np.ndarray | None = None
    tau: np.ndarray | None = None
    names: tuple[str, ...] = ()
    rate_mode: str = "ramp"

    def __post_init__(self) -> None:
        require(self.rate_mode in ("ramp", "hold"), "actuator.rate_mode", self.rate_mode,
                "allowed: ramp (linear within the step), hold (slewed value held over the step)")
        lower = np.atleast_1d(np.asarray(self.lower, dtype=float))
        n = lower.size
        names = self.names or tuple(f"input[{i}]" for i in range(n))
        upper = _per_channel(self.upper, n, "upper", np.inf)
        rate = _per_channel(self.rate, n, "rate", np.inf)
        tau = _per_channel(self.tau, n, "tau", 0.0)
        for i, name in enumerate(names):
            require(not np.isnan(lower[i]) and not np.isnan(upper[i]), f"actuator.{name}.limits",
                    (lower[i], upper[i]), "limits must be numbers")
            require(lower[i] < upper[i], f"actuator.{name}.limits", (lower[i], upper[i]),
                    "lower limit must be below upper limit")
            require(rate[i] > 0, f"actuator.{name}.rate", rate[i], "rate limit must be > 0")
            require(np.isfinite(tau[i]) and tau[i] >= 0, f"actuator.{name}.tau", tau[i],
                    "time constant must be >= 0 s (0 = no lag)")
        object.__setattr__(self, "lower", lower)
        object.__setattr__(self, "upper", upper)
        object.__setattr__(self, "rate", rate)
        object.__setattr__(self, "tau", tau)
        object.__setattr__(self, "names", names)

    @classmethod
    def for_model(cls, model, *, rate=None, tau=None, rate_mode: str = "ramp") -> Actuator:
        """The actuator with the model's own hardware limits (``model.input_limits()``)."""
        lower, upper = model.input_limits()
        return cls(lower, upper, rate=rate, tau=tau, names=tuple(s.name for s in model.inputs),
                   rate_mode=rate_mode)

    @property
    def n(self) -> int:
        return self.lower.size

    @property
    def has_lag(self) -> bool:
        return bool(np.any(self.tau > 0))

    @property
    def has_rate_limit(self) -> bool:
        return bool(np.any(np.isfinite(self.rate)))

    @property
    def is_static(self) -> bool:
        """Saturation only: the applied input is a memoryless function of the command."""
        return not (self.has_lag or self.has_rate_limit)

    def saturate(self, command: np.ndarray) -> np.ndarray:
        """Clip each channel to its limits (NaN passes through, for the divergence guard)."""
        return np.clip(command, self.lower, self.upper)

    def check_command_shape(self, command: np.ndarray) -> None:
        if command.shape[-1:] != (self.n,):
            raise ConfigError(f"controller command has shape {command.shape}; the actuator "
                              f"expects (..., {self.n}) for channels {', '.join(self.names)}")

    def initial(self, command0: np.ndarray) -> np.ndarray:
        """Applied input at t = 0: the saturated initial command."""
        return self.saturate(command0)

    def begin_step(self, applied: np.ndarray, command: np.ndarray, h: float):
        """Plan one step of length ``h``: returns ``(start, end)`` of the non-lag channels (the
        batch of :func:`plan_kernel`)."""
        return per_ship(plan_kernel, "i i p t t t o o")(
            applied, command, self._params, h, self.has_rate_limit, self.rate_mode == "hold",
            self.n, self.n)

    def input_at(self, plan, theta: float, lag_state: np.ndarray | None) -> np.ndarray:
        """Applied input at fraction ``theta`` ∈ [0, 1] of the step (lag channels: ``lag_state``;
        the batch of :func:`input_at_kernel`)."""
        start, end = plan
        lag = np.zeros(self.n) if lag_state is None else lag_state
        return per_ship(input_at_kernel, "i i t i p t t o")(
            start, end, theta, lag, self._params, lag_state is not None, self.has_rate_limit,
            self.n)

    def lag_derivative(self, command: np.ndarray, lag_state: np.ndarray) -> np.ndarray:
        """ȧ of the lag channels, 0 elsewhere (the batch of :func:`lag_rate_kernel`)."""
        return per_ship(lag_rate_kernel, "i i p o")(command, lag_state, self._params, self.n)

    @cached_property
    def _params(self) -> np.ndarray:
        return self.kernel_params()

    def kernel_params(self) -> np.ndarray:
        """``[lower, upper, rate, tau]`` (n each): the parameters of the kernels below."""
        return np.concatenate([self.lower, self.upper, self.rate, self.tau]).astype(np.float64)


# ----------------------------------------------------------------------------------------------
# kernels of the composed loop (shipgnc.sim.compose): one ship, p = Actuator.kernel_params()
# ----------------------------------------------------------------------------------------------

@kernel_function
def plan_kernel(applied, cmd, pa, h, rate_limited, hold_mode, start, end):
    """One step of length ``h`` for one ship (:meth:`Actuator.begin_step`): the input runs from
    ``start`` to ``end``. Without a rate limit start = end = sat(cmd); with one,
    end = applied + clip(sat(cmd) − applied, ±rate·h) and the input ramps linearly from
    start = applied to end (``hold_mode``, or a channel without a limit: start = end)."""
    n = cmd.shape[0]
    for j in range(n):
        target = clip(cmd[j], pa[j], pa[n + j])
        if not rate_limited:
            start[j] = target
            end[j] = target
            continue
        rate = pa[2 * n + j]
        e = applied[j] + clip(target - applied[j], -rate * h, rate * h)
        end[j] = e
        start[j] = e if (hold_mode or not math.isfinite(rate)) else applied[j]


@kernel_function
def input_at_kernel(start, end, theta, lag, pa, has_lag, rate_limited, u):
    """The applied input at fraction ``theta`` ∈ [0, 1] of the step for one ship
    (:meth:`Actuator.input_at`): u = start + θ (end − start), the lag state ``lag`` on lag
    channels (``has_lag``)."""
    n = u.shape[0]
    for j in range(n):
        if has_lag and pa[3 * n + j] > 0:
            u[j] = lag[j]
        elif theta == 1.0 or not rate_limited:
            u[j] = end[j]
        else:
            u[j] = start[j] + theta * (end[j] - start[j])


@kernel_function
def lag_rate_kernel(cmd, lag, pa, out):
    """ȧ = clip((sat(cmd) − a)/τ, −rate, rate) on lag channels, 0 elsewhere, for one ship
    (document 004 eq. (22); :meth:`Actuator.lag_derivative`)."""
    n = cmd.shape[0]
    for j in range(n):
        tau = pa[3 * n + j]
        if tau > 0:
            target = clip(cmd[j], pa[j], pa[n + j])
            rate = pa[2 * n + j]
            out[j] = clip((target - lag[j]) / tau, -rate, rate)
        else:
            out[j] = 0.0
