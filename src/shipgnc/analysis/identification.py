"""Steering-model identification from a simulated manoeuvre (notes 003-3.3–003-3.4).

Document 003 designs its sliding-mode autopilot on the first-order Nomoto model (18),
ṙ = a₂₂ r + b₂ δ, reduced from the linear model (17): a₂₂ = 0.1057 s⁻¹, b₂ = −0.0040 s⁻². That
model is course-unstable and its rudder gain b₂ is 23 × smaller than the plant's instantaneous
rudder-to-yaw-acceleration gain (M⁻¹b)_r = −0.0918 s⁻² (note 003-3.3). Here the model is instead
**identified from the plant**, as one identifies a ship from its trials (``docs/trials.md``):

1. :func:`zigzag_trial` runs the zig-zag δ/ψ manoeuvre (rudder to +δ, reversed each time the
   heading has changed ±ψ from the original course; :class:`ZigZag`) on any model through the
   normal :func:`~shipgnc.sim.simulator.simulate`, with the model's own steering machine;
2. :func:`fit_nomoto` fits Nomoto's first-order model r/δ = K/(1 + Ts) (Nomoto 1957; Fossen 2021
   eq. 7.42) to the logged yaw rate by least squares (``scipy.optimize.least_squares``) on the
   simulated response, the *output error* r_model(t; K, T) − r(t) driven by the applied rudder;
   :func:`fit_nomoto2` does the same for the second-order model
   r/δ = K(1 + T₃s)/((1 + T₁s)(1 + T₂s)) (the linear sway–yaw model's transfer function);
3. :func:`identify_cybership2` does both steps for CyberShip II at the scenario's propeller speed
   (20°/20° zig-zag by default, the IMO manoeuvre) and returns the fit with its residual.

The response of the first-order model to a rudder that is linear between samples (the steering
machine slews linearly, ``rate_mode="ramp"``) is computed exactly (first-order hold):

    r_{k+1} = α r_k + b₂ [δ_k (φ₁ − φ₂) + δ_{k+1} φ₂],   α = e^{a h},  a = −1/T,  b₂ = K/T,
    φ₁ = (e^{ah} − 1)/a,   φ₂ = (e^{ah} − 1 − ah)/(a²h),

so a synthetic Nomoto plant is recovered to the integrator's accuracy (a test: within 1 %).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np

from shipgnc.errors import require

__all__ = ["NomotoFit", "NomotoFit2", "ZigZag", "fit_nomoto", "fit_nomoto2",
           "identify_cybership2", "zigzag_trial"]


# the zig-zag manoeuvre as a controller lives with the trials (one rule for both); re-exported here
from shipgnc.trials.zigzag import ZigZag


def zigzag_trial(model, actuator, x0, *, delta_deg: float = 20.0, psi_deg: float = 20.0,
                 t_end: float = 120.0, dt: float = 0.1, held=(), rudder_sign: float = -1.0,
                 rudder_index: int = -1, disturbance=None, seed=None):
    """Run the zig-zag ``delta_deg``/``psi_deg`` on ``model`` with ``simulate`` (numpy loop, RK4,
    the actuator's rate limit); returns the result Dataset (``psi``, ``r``, the applied rudder)."""
    from shipgnc.sim.simulator import simulate

    ctrl = ZigZag(math.radians(delta_deg), math.radians(psi_deg), rudder_sign=rudder_sign,
                  held=held, rudder_index=rudder_index)
    return simulate(model, np.asarray(x0, dtype=float), t_end=t_end, dt=dt, controller=ctrl,
                    actuator=actuator, disturbance=disturbance, seed=seed, backend="numpy")


def _foh_first_order(K: float, T: float, h: float, delta: np.ndarray, r0: float) -> np.ndarray:
    """Exact response of ṙ = (Kδ − r)/T to δ linear between samples h apart (module docstring)."""
    from scipy import signal

    a = -1.0 / T
    ah = a * h
    alpha = math.exp(ah)
    if abs(ah) < 1e-6:  # series of φ₁, φ₂ (a → 0: the integrator)
        phi1 = h * (1.0 + ah / 2.0 + ah * ah / 6.0)
        phi2 = h * (0.5 + ah / 6.0 + ah * ah / 24.0)
    else:
        phi1 = math.expm1(ah) / a
        phi2 = (math.expm1(ah) - ah) / (a * a * h)
    b2 = K / T
    forcing = b2 * (delta[:-1] * (phi1 - phi2) + delta[1:] * phi2)
    # r_{k+1} − α r_k = forcing_k, with r_0 given
    out, _ = signal.lfilter([1.0], [1.0, -alpha], forcing, zi=[alpha * r0])
    return np.concatenate([[r0], out])


def _series(t, delta, r) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    t, delta, r = (np.asarray(a, dtype=float).reshape(-1) for a in (t, delta, r))
    require(t.size == delta.size == r.size and t.size >= 10, "identification.data",
            (t.size, delta.size, r.size), "need t, delta, r of the same length >= 10")
    steps = np.diff(t)
    h = float(np.mean(steps))
    require(h > 0 and np.allclose(steps, h, rtol=1e-6, atol=1e-12), "identification.t", h,
            "samples must be equally spaced")
    require(bool(np.all(np.isfinite(delta)) and np.all(np.isfinite(r))), "identification.data",
            "non-finite", "delta and r must be finite")
    return t, delta, r, h


@dataclass(frozen=True, eq=False)
class NomotoFit:
    """A first-order Nomoto model fitted to a manoeuvre: r/δ = K/(1 + Ts), ṙ = a₂₂ r + b₂ δ.

    ``residual_rms`` = RMS(r_model − r) [rad/s] over the fitted record, ``r_rms`` = RMS(r) of the
    record, ``fit`` = 1 − ‖r_model − r‖/‖r − mean r‖ (NRMSE fit, 1 = perfect); ``cost`` as
    ``least_squares`` returns it; ``label`` says which manoeuvre it came from.
    """

    K: float
    T: float
    residual_rms: float
    r_rms: float
    fit: float
    cost: float
    label: str = ""
    extra: dict = field(default_factory=dict)

    @property
    def a22(self) -> float:
        """−1/T [1/s]."""
        return -1.0 / self.T

    @property
    def b2(self) -> float:
        """K/T [1/s²]: the model's rudder-to-yaw-acceleration gain."""
        return self.K / self.T

    @property
    def design_model(self) -> tuple[float, float]:
        """(a₂₂, b₂) for :func:`shipgnc.control.course.design_smc`."""
        return self.a22, self.b2

    def predict(self, t, delta, r0: float = 0.0) -> np.ndarray:
        """The model's yaw rate for the rudder record ``delta`` at the equally spaced times ``t``."""
        t, delta, _, h = _series(t, delta, np.zeros(np.size(t)))
        return _foh_first_order(self.K, self.T, h, delta, float(r0))

    def residual(self, t, delta, r) -> dict:
        """How well the model predicts another record: residual RMS [rad/s], r RMS and the fit."""
        t, delta, r, _ = _series(t, delta, r)
        return _scores(self.predict(t, delta, r[0]) - r, r)


def _scores(res: np.ndarray, r: np.ndarray) -> dict:
    spread = float(np.linalg.norm(r - np.mean(r)))
    return {"residual_rms": float(np.sqrt(np.mean(res**2))), "r_rms": float(np.sqrt(np.mean(r**2))),
            "fit": 1.0 - float(np.linalg.norm(res)) / spread if spread > 0 else float("nan")}


def _segments(n: int, horizon_steps: int | None) -> list[tuple[int, int]]:
    """Index ranges [i0, i1] (inclusive) of consecutive prediction windows (one if no horizon)."""
    if horizon_steps is None or horizon_steps >= n - 1:
        return [(0, n - 1)]
    starts = range(0, n - 1, horizon_steps)
    return [(i, min(i + horizon_steps, n - 1)) for i in starts]


def _simulate_segments(K, T, h, delta, r, segments) -> np.ndarray:
    out = np.empty_like(r)
    out[0] = r[0]
    for i0, i1 in segments:
        out[i0 + 1:i1 + 1] = _foh_first_order(K, T, h, delta[i0:i1 + 1], r[i0])[1:]
    return out


def fit_nomoto(t, delta, r, *, guess: tuple[float, float] | None = None, label: str = "",
               horizon: float | None = None) -> NomotoFit:
    """Least-squares fit of r/δ = K/(1 + Ts) to the record (t [s], applied δ [rad], r [rad/s]).

    The start value comes from an equation-error regression ṙ ≈ a r + b δ (finite differences),
    unless ``guess`` = (K, T) is given; the output error is then minimised over (K, 1/T) with
    ``scipy.optimize.least_squares`` (the inverse time constant keeps course-unstable fits,
    T < 0, reachable without crossing T = 0). The record starts from the logged r(0).

    ``horizon`` [s]: fit the model's predictions over consecutive windows of this length, each
    started from the logged r (a multi-step prediction error; None = the whole record as one
    simulation, the pure output error).
    """
    t, delta, r, h = _series(t, delta, r)
    segments = _segments(t.size, None if horizon is None else max(1, round(horizon / h)))
    if guess is None:
        rdot = np.gradient(r, h)
        A = np.column_stack([r, delta])
        (a, b), *_ = np.linalg.lstsq(A, rdot, rcond=None)
        a = a if abs(a) > 1e-6 else -1e-3
        guess = (-b / a, -1.0 / a)
    K0, T0 = (float(v) for v in guess)
    require(T0 != 0 and math.isfinite(K0) and math.isfinite(T0), "identification.guess", guess,
            "need finite K and T != 0")

    def residuals(theta):
        K, inv_T = theta
        if inv_T == 0.0:
            inv_T = 1e-12
        return _simulate_segments(K, 1.0 / inv_T, h, delta, r, segments) - r

    from scipy import optimize

    sol = optimize.least_squares(residuals, [K0, 1.0 / T0], x_scale="jac", method="lm",
                                 xtol=1e-14, ftol=1e-14, gtol=1e-14, max_nfev=2000)
    K, inv_T = sol.x
    res = sol.fun
    return NomotoFit(K=float(K), T=float(1.0 / inv_T), cost=float(sol.cost), label=label,
                     **_scores(res, r))


@dataclass(frozen=True, eq=False)
class NomotoFit2:
    """A second-order Nomoto model r/δ = K(1 + T₃s)/((1 + T₁s)(1 + T₂s)) fitted to a record."""

    K: float
    T1: float
    T2: float
    T3: float
    residual_rms: float
    r_rms: float
    fit: float
    cost: float
    label: str = ""

    def _system(self):
        return _second_order_system(self.K, self.T1, self.T2, self.T3)

    @property
    def yaw_acceleration_gain(self) -> float:
        """The instantaneous rudder-to-yaw-acceleration gain K T₃/(T₁T₂) [1/s²]."""
        return self.K * self.T3 / (self.T1 * self.T2)

    def first_order(self) -> tuple[float, float]:
        """Nomoto's reduction (K, T = T₁ + T₂ − T₃) (eq. (18)'s rule)."""
        return self.K, self.T1 + self.T2 - self.T3

    def predict(self, t, delta, r0: float = 0.0) -> np.ndarray:
        t, delta, _, _ = _series(t, delta, np.zeros(np.size(t)))
        return _lsim2(self.K, self.T1, self.T2, self.T3, t, delta, r0)

    def residual(self, t, delta, r) -> dict:
        t, delta, r, _ = _series(t, delta, r)
        return _scores(self.predict(t, delta, r[0]) - r, r)


def _second_order_system(K, T1, T2, T3):
    # (T₁T₂) r̈ + (T₁+T₂) ṙ + r = K(δ + T₃ δ̇) in controllable canonical form
    a2, a1 = T1 * T2, T1 + T2
    A = np.array([[0.0, 1.0], [-1.0 / a2, -a1 / a2]])
    B = np.array([[0.0], [1.0]])
    C = np.array([[K / a2, K * T3 / a2]])
    return A, B, C


def _lsim2(K, T1, T2, T3, t, delta, r0):
    A, B, C = _second_order_system(K, T1, T2, T3)
    # start on the output r0 with the state's derivative part at zero
    x0 = np.array([r0 / C[0, 0] if C[0, 0] != 0 else 0.0, 0.0])
    from scipy import signal

    sys = signal.StateSpace(A, B, C, np.zeros((1, 1)))
    _, y, _ = signal.lsim(sys, delta, t - t[0], X0=x0, interp=True)
    return np.asarray(y, dtype=float).reshape(-1)


def fit_nomoto2(t, delta, r, *, guess: tuple[float, float, float, float] | None = None,
                label: str = "") -> NomotoFit2:
    """Least-squares fit of the second-order Nomoto model to the record (as :func:`fit_nomoto`).

    Start: the first-order fit (K, T) split as T₁ = T, T₂ = T₃ = T/10 unless ``guess`` =
    (K, T₁, T₂, T₃) is given.
    """
    t, delta, r, _ = _series(t, delta, r)
    if guess is None:
        first = fit_nomoto(t, delta, r)
        guess = (first.K, first.T, 0.1 * abs(first.T), 0.1 * abs(first.T))

    def residuals(theta):
        K, T1, T2, T3 = theta
        if abs(T1 * T2) < 1e-9:
            return np.full(r.size, 1e3)
        return _lsim2(K, T1, T2, T3, t, delta, r[0]) - r

    from scipy import optimize

    sol = optimize.least_squares(residuals, np.asarray(guess, dtype=float), x_scale="jac",
                                 max_nfev=400)
    K, T1, T2, T3 = (float(v) for v in sol.x)
    if T2 > T1:
        T1, T2 = T2, T1
    return NomotoFit2(K=K, T1=T1, T2=T2, T3=T3, cost=float(sol.cost), label=label,
                      **_scores(sol.fun, r))


def cybership2_zigzag(params=None, *, delta_deg: float = 20.0, psi_deg: float = 20.0,
                      propeller_rps: float | None = None, t_end: float = 120.0, dt: float = 0.1):
    """The zig-zag ``delta_deg``/``psi_deg`` of CyberShip II from its surge equilibrium at
    ``propeller_rps`` (default 8.13 rps), with its steering machine (note 003-B8); a Dataset."""
    from shipgnc.models.cybership2 import (
        CRUISE_RPS,
        CyberShip2,
        CyberShip2Params,
        steering_machine,
        surge_equilibrium,
    )

    p = params if params is not None else CyberShip2Params()
    n = CRUISE_RPS if propeller_rps is None else float(propeller_rps)
    u0 = surge_equilibrium(p, n)
    return zigzag_trial(CyberShip2(p), steering_machine(p), [0.0, 0.0, 0.0, u0, 0.0, 0.0],
                        delta_deg=delta_deg, psi_deg=psi_deg, t_end=t_end, dt=dt, held=[n],
                        rudder_sign=-1.0, rudder_index=1)


def _record(ds):
    return ds["time"].values, ds["delta"].values, ds["r"].values


#: the form of a kept identification (:func:`shipgnc.derived_cache.stored`)
_KEPT = {"fit": dict.fromkeys(("K", "T", "residual_rms", "r_rms", "fit", "cost"), float),
         "extra": {"min_surge_mps": float, "mean_surge_mps": float}}


@lru_cache(maxsize=16)
def _identify_cached(params, delta_deg, psi_deg, propeller_rps, t_end, dt):
    from shipgnc.derived_cache import stored

    inputs = {"params": params.as_dict(), "delta_deg": delta_deg, "psi_deg": psi_deg,
              "propeller_rps": propeller_rps, "t_end": t_end, "dt": dt}
    kept = stored("cybership2-nomoto", inputs, (__name__, "shipgnc.models.cybership2"),
                  lambda: _identify(params, delta_deg, psi_deg, propeller_rps, t_end, dt),
                  shape=_KEPT)
    label = f"CyberShip II zig-zag {delta_deg:g}/{psi_deg:g}, {t_end:g} s"
    return NomotoFit(**kept["fit"], label=label, extra=kept["extra"])


def _identify(params, delta_deg, psi_deg, propeller_rps, t_end, dt) -> dict:
    """:func:`identify_cybership2` computed: the zig-zag simulated and the model fitted to it."""
    ds = cybership2_zigzag(params, delta_deg=delta_deg, psi_deg=psi_deg,
                           propeller_rps=propeller_rps, t_end=t_end, dt=dt)
    fit = fit_nomoto(*_record(ds))
    return {"fit": {"K": fit.K, "T": fit.T, "residual_rms": fit.residual_rms, "r_rms": fit.r_rms,
                    "fit": fit.fit, "cost": fit.cost},
            "extra": {"min_surge_mps": float(ds["u"].min()), "mean_surge_mps": float(ds["u"].mean())}}


def identify_cybership2(params=None, *, delta_deg: float = 20.0, psi_deg: float = 20.0,
                        propeller_rps: float | None = None, t_end: float = 120.0,
                        dt: float = 0.1) -> NomotoFit:
    """First-order Nomoto model of CyberShip II identified from its zig-zag (module docstring).

    ``params``: the plant (:class:`~shipgnc.models.cybership2.CyberShip2Params`, default the
    published one with the ``table1`` rudder, 35° and 19.4105°/s). Kept per argument set, in the
    process and on disk (:func:`shipgnc.derived_cache.stored`, keyed by the arguments and by the
    code that simulates and fits: a later process reads back the same numbers).
    """
    from shipgnc.models.cybership2 import CRUISE_RPS, CyberShip2Params

    p = params if params is not None else CyberShip2Params()
    n = CRUISE_RPS if propeller_rps is None else float(propeller_rps)
    return _identify_cached(p, float(delta_deg), float(psi_deg), n, float(t_end), float(dt))
