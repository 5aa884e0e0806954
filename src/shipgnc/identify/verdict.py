"""Refusing what a log cannot identify: checks on a finished fit, each a one-line ConfigError.

A least-squares optimiser always returns numbers; whether the log determines them is a separate
question (Ljung 1999, *System Identification*, §13.2 on informative experiments and §16.6 on model
validation). ``shipgnc identify`` refuses (exit 2, no vessel file) when any of these fails, in
this order, naming the first that fails:

1. **Determined parameters** — every reported parameter has a finite value and a finite standard
   error, i.e. the Fisher information JᵀJ of the fit (J the Jacobian of the prediction errors) is
   invertible (``confidence`` sets the errors to ∞ when its condition number exceeds 10¹⁴).
   A log that moves along one direction of the parameter space only (a closed-loop heading hold,
   a rescaled time axis) fails here.
2. **A rudder effect** — the parameter carrying the rudder's effect on the yaw rate (K of the
   Nomoto models, b_r = (M⁻¹B)_r of the linear model) differs from 0 at the 95 % level: its
   interval excludes 0 (a Wald test). A yaw rate that does not respond to the rudder fails here.
3. **A time constant of known sign** — the Nomoto time constant T (T₁ + T₂ of the second-order
   model) has a 95 % interval of one sign: the log decides whether the ship is course-stable.
   An interval reaching across 0 means a time constant far longer than the log (K and T
   separately undetermined, only K/T) or none at all.
4. **Better than the null model** — the re-simulated yaw rate explains more than the mean does
   (NRMSE < 1, i.e. R² = 1 − NRMSE² > 0) on the fitted part and on the held-out part.
5. **The yaw rate follows the rudder** — the cross-correlation of the sample-to-sample changes
   Δδ(t) and Δr(t + ℓ) over lags |ℓ| ≤ :data:`MAX_LAG_S` (or a quarter of the log) is largest in
   magnitude at a lag ℓ ≥ 0: the yaw rate responds to the rudder, not the other way round
   (cross-correlation analysis of cause and effect; Ljung 1999, §16.6 and Box & Jenkins 1976,
   §11.1). Swapped rudder and yaw-rate columns fail here.

:func:`check_time_scale` refuses a log too short to hold a steering response (a time column in
another unit than seconds).
"""

from __future__ import annotations

import math

import numpy as np
from scipy import signal

from shipgnc.errors import ConfigError

#: shortest log [s]: a ship's (even a model ship's) yaw response takes seconds
MIN_DURATION = 1.0
#: largest lag [s] of the rudder / yaw-rate cross-correlation (check 5)
MAX_LAG_S = 60.0
#: the parameter carrying the rudder's effect on the yaw rate, per model
RUDDER_PARAMETER = {"nomoto1": "K", "nomoto2": "K", "linear-3dof": "b_r"}
#: the time constant whose sign decides course stability, per model
TIME_PARAMETER = {"nomoto1": "T", "nomoto2": "T1+T2"}
#: parameters whose intervals may be unbounded while the model is determined (T₁ = T₂)
_MAY_BE_UNBOUNDED = {"nomoto2": ("T1", "T2")}


def check_time_scale(t: np.ndarray, name: str = "time") -> None:
    """Refuse a log lasting less than :data:`MIN_DURATION` (a time column not in seconds)."""
    span = float(t[-1] - t[0])
    if span < MIN_DURATION:
        raise ConfigError(f"time column {name!r}: the log lasts {span:.3g} s (need >= "
                          f"{MIN_DURATION:g} s for a steering response); is the time in seconds?")


def _interval(p) -> str:
    return f"[{p.ci95[0]:.4g}, {p.ci95[1]:.4g}]"


def refuse_unidentified(ident) -> None:
    """Raise a ConfigError naming the first check of the module docstring ``ident`` fails."""
    model = ident.model
    skip = _MAY_BE_UNBOUNDED.get(model, ())
    bad = [n for n, p in ident.parameters.items()
           if n not in skip and not (math.isfinite(p.value) and math.isfinite(p.std_error))]
    if bad:
        raise ConfigError(f"{model}: the log does not determine {', '.join(bad)} (the Fisher "
                          "information of the fit is singular: unbounded intervals); log an "
                          "open-loop manoeuvre with rudder changes, e.g. a zig-zag")
    name = RUDDER_PARAMETER[model]
    p = ident.parameters[name]
    if p.ci95[0] <= 0.0 <= p.ci95[1]:
        raise ConfigError(f"{model}: the yaw rate does not respond to the rudder: {name} = "
                          f"{p.value:.4g} {p.unit}, 95 % interval {_interval(p)} contains 0; check "
                          "the rudder and yaw-rate columns (--columns) and their units")
    name = TIME_PARAMETER.get(model)
    if name is not None:
        p = ident.parameters[name]
        if p.ci95[0] <= 0.0 <= p.ci95[1]:
            raise ConfigError(f"{model}: the log does not determine the time constant: {name} = "
                              f"{p.value:.4g} s, 95 % interval {_interval(p)} spans both signs "
                              "(stable or unstable undecided; only K/T is determined); log a "
                              "longer manoeuvre with more rudder changes")
    for part, scores in (("fitted", ident.nrmse_fit), ("held-out", ident.nrmse_holdout)):
        score = scores.get("r")
        if score is not None and not score < 1.0:
            raise ConfigError(f"{model}: the model explains the {part} yaw rate no better than "
                              f"its mean (NRMSE {score:.3g} >= 1, R^2 <= 0); the log does not "
                              "follow a linear steering model (closed loop, swapped columns?)")
    lag = leading_lag(ident.t, ident.rudder, ident.measured["r"])
    if lag < 0:
        raise ConfigError(f"{model}: the yaw rate leads the rudder (their changes correlate most "
                          f"with the yaw rate {-lag:.3g} s ahead): are the rudder and yaw-rate "
                          "columns swapped (--columns)?")


def leading_lag(t: np.ndarray, rudder: np.ndarray, r: np.ndarray) -> float:
    """The lag ℓ [s] maximising |corr(Δδ(t), Δr(t + ℓ))| over |ℓ| ≤ min(MAX_LAG_S, duration/4)
    (check 5 of the module docstring; ℓ > 0: the yaw rate after the rudder)."""
    h = float(t[1] - t[0])
    du, dy = np.diff(np.asarray(rudder, dtype=float)), np.diff(np.asarray(r, dtype=float))
    if not (np.std(du) > 0 and np.std(dy) > 0):
        return 0.0
    du = (du - du.mean()) / du.std()
    dy = (dy - dy.mean()) / dy.std()
    n = du.size
    m = max(1, min(round(MAX_LAG_S / h), n // 4))
    corr = signal.correlate(dy, du, mode="full", method="fft")  # index n-1+l: sum du_t dy_{t+l}
    lags = np.arange(-m, m + 1)
    best = lags[int(np.argmax(np.abs(corr[n - 1 + lags])))]
    return float(best * h)
