"""Fitting steering and manoeuvring models to a logged run, with confidence intervals.

Models (``shipgnc identify --model``):

``nomoto1``
    r/δ = K/(1 + Ts) (Nomoto et al. 1957; Fossen 2021 eq. 7.42). The fit is
    :func:`shipgnc.analysis.identification.fit_nomoto` (output error: the model's yaw rate
    simulated exactly between samples from the logged rudder and the logged r(0), least squares
    with ``scipy.optimize.least_squares``), from several starts when the first does not explain
    the log, then polished with the initial yaw rate as a nuisance parameter (a noisy logged r(0)
    would bias K and T). A course-unstable equation-error estimate switches to prediction windows
    (``horizon``; a free-running unstable model diverges from the log).
``nomoto2``
    r/δ = K(1 + T₃s)/((1 + T₁s)(1 + T₂s)) (Fossen 2021 eq. 7.50), fitted by
    :func:`~shipgnc.analysis.identification.fit_nomoto2` (output error as above), polished and
    given intervals in the denominator's coefficients T₁ + T₂ and T₁T₂ (smooth where T₁ = T₂).
``linear-3dof``
    The linear manoeuvring model M ν̇ + N ν = B δ with ν = [u − U, v, r] (Fossen 2021 §7.2, the
    catalogue's ``linear-3dof``). Written as ν̇ = A ν + b δ, A = −M⁻¹N, b = M⁻¹B, with the
    surge decoupled from sway–yaw (the linear model of a port–starboard symmetric ship)::

        u̇ = a_uu (u − U),   [v̇, ṙ]ᵀ = [[a_vv, a_vr], [a_rv, a_rr]] [v, r]ᵀ + [b_v, b_r]ᵀ δ

    Output error: the sway–yaw state is simulated exactly for a rudder linear between samples
    (first-order hold through the matrix exponential of the augmented system) from an initial
    (v, r) fitted as nuisance parameters, and the six parameters minimise the residuals of v and
    r, each channel weighted by
    the inverse of its residual RMS (a second pass re-weights with the first pass's residuals:
    the channels' noise levels). The start values are the equation-error least squares
    v̇, ṙ ≈ [v, r, δ]θ on numerically differentiated signals (``numpy.gradient``). Surge: when the
    speed changes by at least :data:`SURGE_MIN_CHANGE` of its mean, u(t) = U + (u₀ − U)e^{a_uu t}
    is fitted for (a_uu, U, nuisance u₀); otherwise the surge is not identified, a_uu = 0 (the written model
    keeps u constant) and U is the mean speed. Only M⁻¹N and M⁻¹B are identifiable from motions
    (any invertible matrix multiplying the equation gives the same response), so the vessel YAML
    has M = I, N = −A, B = b: the equation per unit inertia. A course-unstable start estimate
    switches to prediction windows of ``horizon`` seconds (each restarted from the logged state).

Every fit is on the first part of the log; the last ``holdout`` fraction (default 30 %) is kept
out of the fit and scores the model. The model is re-simulated over the whole log from the logged
initial state with the logged rudder, and on the held-out part

    NRMSE = ‖ŷ − y‖ / ‖y − ȳ‖      (0 = perfect, 1 = no better than the mean; fit % = 100(1 − NRMSE))

for each fitted output y (r; or u, v, r).

Confidence intervals (95 %, two-sided): θ̂ ± t₀.₉₇₅(n − p) · SE, with the covariance
s² (JᵀJ)⁻¹, J the Jacobian of the (weighted) residuals at the optimum (central differences),
s² = RSS/(n − p), n the residuals and p the parameters (Seber & Wild 1989, Nonlinear Regression,
§5.1; Ljung 1999, System Identification, §9.2), when the residuals are white. Residuals are
rarely white (wind, waves and unmodelled dynamics act through the ship's slow yaw response): an
autoregressive model of the residuals is fitted (order by BIC) and the covariance is the
least-squares estimator's under those autocorrelated errors, (JᵀJ)⁻¹ Jᵀ Cov(ε) J (JᵀJ)⁻¹
(:mod:`shipgnc.identify.noise`; Seber & Wild 1989, §6.1–6.2). The lag-1 autocorrelation of the
residuals is reported, and a note says when it exceeds 0.5 (coloured noise or a model error; a
model error is a bias the intervals do not hold).

A fit the log does not support is refused (one line, no vessel file): undetermined parameters,
no significant rudder effect, a time constant of undecided sign, no better than the mean, a yaw
rate that leads the rudder (:mod:`shipgnc.identify.verdict`); so is a ``--horizon`` not shorter
than the fitted part of the log.

Too little excitation is refused before fitting: the rudder must span at least
:data:`MIN_RUDDER_SPAN` over the fitted part, and the equation-error regressor ([r, δ] for the
Nomoto models, [v, r, δ] for sway–yaw) scaled to unit-norm columns must have a condition number
≤ :data:`CONDITION_LIMIT` (collinear columns, e.g. a steady turn r = Kδ, cannot separate the
parameters).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from scipy import linalg, optimize, signal, stats

from shipgnc.analysis.identification import (
    _foh_first_order,
    _segments,
    _simulate_segments,
    fit_nomoto,
    fit_nomoto2,
)
from shipgnc.errors import ConfigError
from shipgnc.identify.noise import ARNoise
from shipgnc.identify.verdict import check_time_scale, refuse_unidentified

MODELS = ("nomoto1", "nomoto2", "linear-3dof")
LEVEL = 0.95
#: largest condition number of the unit-column regressor accepted
CONDITION_LIMIT = 1.0e3
#: smallest rudder span [rad] over the fitted part
MIN_RUDDER_SPAN = math.radians(1.0)
#: relative speed change above which the surge is identified
SURGE_MIN_CHANGE = 0.02
#: fewest samples in the fitted part
MIN_FIT_SAMPLES = 20
COVARIANCE_WHITE = "s^2 (J^T J)^-1 at the optimum, s^2 = RSS/(n - p)"
COVARIANCE = ("least squares under AR residuals: (J^T J)^-1 J^T Cov(res) J (J^T J)^-1, Cov(res) of "
              "the AR model A(q) res = e fitted to the residuals, s_e^2 = |e|^2/(n_e - p - AR orders)")


@dataclass(frozen=True)
class Parameter:
    """A fitted parameter with its standard error and 95 % interval (``dof`` residual d.o.f.)."""

    name: str
    value: float
    std_error: float
    ci95: tuple[float, float]
    unit: str
    meaning: str
    dof: int

    def to_json(self) -> dict:
        return {"value": self.value, "ci95": list(self.ci95), "std_error": self.std_error,
                "unit": self.unit, "meaning": self.meaning}


@dataclass
class Identification:
    """The result of :func:`identify_nomoto1` and siblings (see :meth:`to_json`)."""

    model: str
    parameters: dict[str, Parameter]
    t: np.ndarray
    rudder: np.ndarray
    measured: dict[str, np.ndarray]
    simulated: dict[str, np.ndarray]
    split: int
    holdout: float
    nrmse_holdout: dict[str, float | None]
    nrmse_fit: dict[str, float]
    residual_rms: dict[str, float]
    residual_lag1: float
    condition_number: float
    regressor: str
    vessel: dict
    method: str
    heading: np.ndarray | None = None
    notes: list[str] = field(default_factory=list)
    noise: dict | None = None

    @property
    def holdout_start(self) -> float:
        return float(self.t[self.split]) if self.split < self.t.size else float(self.t[-1])

    def value(self, name: str) -> float:
        return self.parameters[name].value

    def to_json(self) -> dict:
        dofs = sorted({p.dof for p in self.parameters.values()})
        return {
            "model": self.model,
            "method": self.method,
            "samples": int(self.t.size),
            "dt_s": float(self.t[1] - self.t[0]),
            "duration_s": float(self.t[-1] - self.t[0]),
            "split": {"fit_samples": int(self.split), "holdout_samples": int(self.t.size - self.split),
                      "holdout_fraction": self.holdout, "holdout_start_s": self.holdout_start},
            "parameters": {k: p.to_json() for k, p in self.parameters.items()},
            "confidence": {"level": LEVEL, "distribution": "student-t", "dof": dofs,
                           "covariance": COVARIANCE if self.noise else COVARIANCE_WHITE,
                           "noise_model": self.noise},
            "nrmse_holdout": self.nrmse_holdout,
            "nrmse_fit": self.nrmse_fit,
            "residual_rms": self.residual_rms,
            "residual_lag1_autocorrelation": self.residual_lag1,
            "excitation": {"condition_number": self.condition_number, "limit": CONDITION_LIMIT,
                           "regressor": self.regressor},
            "vessel": self.vessel,
            "notes": list(self.notes),
        }


# --------------------------------------------------------------------------- shared pieces

def split_index(n: int, holdout: float) -> int:
    """Number of samples fitted: the first round((1 − holdout) n)."""
    if not (isinstance(holdout, (int, float)) and math.isfinite(holdout) and 0 <= holdout <= 0.8):
        raise ConfigError(f"--holdout {holdout!r}: the held-out fraction must be in [0, 0.8]")
    k = round((1.0 - holdout) * n)
    if k < MIN_FIT_SAMPLES:
        raise ConfigError(f"--holdout {holdout!r}: leaves {k} samples to fit; need at least "
                          f"{MIN_FIT_SAMPLES} (a longer log or a smaller --holdout)")
    return k


def condition_number(columns) -> float:
    """Condition number of the regressor with its columns scaled to unit 2-norm (inf if one is 0)."""
    X = np.column_stack([np.asarray(c, dtype=float) for c in columns])
    norms = np.linalg.norm(X, axis=0)
    if np.any(norms == 0) or not np.all(np.isfinite(norms)):
        return math.inf
    return float(np.linalg.cond(X / norms))


def check_excitation(columns, labels: str, rudder: np.ndarray) -> float:
    """The regressor's condition number, or a ConfigError when the log excites too little."""
    span = float(np.ptp(rudder))
    if span < MIN_RUDDER_SPAN:
        raise ConfigError(f"too little excitation: the rudder spans {math.degrees(span):.3g}° over "
                          f"the fitted part (need >= {math.degrees(MIN_RUDDER_SPAN):g}°); log a "
                          "manoeuvre with rudder changes, e.g. a zig-zag")
    cond = condition_number(columns)
    if not cond <= CONDITION_LIMIT:
        raise ConfigError(f"too little excitation: the regressor {labels} has condition number "
                          f"{cond:.3g} (columns scaled to unit norm; allowed <= {CONDITION_LIMIT:.0e}): "
                          "its columns are nearly collinear; log a manoeuvre with rudder changes, "
                          "e.g. a zig-zag")
    return cond


def check_horizon(horizon: float, t_fit: np.ndarray) -> None:
    """A prediction window [s] must be a time > 0 shorter than the fitted part of the log
    (a window as long as the log is one free run: no --horizon)."""
    if not (isinstance(horizon, (int, float)) and math.isfinite(horizon) and horizon > 0):
        raise ConfigError(f"--horizon {horizon!r}: must be a time > 0 s")
    span = float(t_fit[-1] - t_fit[0])
    if horizon >= span:
        raise ConfigError(f"--horizon {horizon:g}: the prediction window is not shorter than the "
                          f"fitted part of the log ({span:.4g} s); use a shorter window, or no "
                          "--horizon for one free run over the log")


def jacobian(fun: Callable, theta, rel_step: float = 1e-6) -> np.ndarray:
    """Central-difference Jacobian of ``fun`` at ``theta`` (steps relative to each parameter)."""
    theta = np.asarray(theta, dtype=float)
    scale = max(float(np.max(np.abs(theta))), 1e-12)
    cols = []
    for i, th in enumerate(theta):
        step = rel_step * max(abs(th), 1e-3 * scale)
        up, down = theta.copy(), theta.copy()
        up[i] += step
        down[i] -= step
        cols.append((np.asarray(fun(up)) - np.asarray(fun(down))) / (2.0 * step))
    return np.column_stack(cols)


def covariance(fun: Callable, theta, noise: ARNoise | None = None
               ) -> tuple[np.ndarray, np.ndarray, int]:
    """(Cov θ̂, prediction errors, d.o.f.) of the least-squares optimum ``theta`` of the residual
    function ``fun`` (module docstring). White residuals (``noise`` None or of order 0):
    s²(JᵀJ)⁻¹, s² = RSS/(n − p). AR residuals (:mod:`shipgnc.identify.noise`): the least-squares
    estimator's covariance under autocorrelated errors, (JᵀJ)⁻¹ Jᵀ Cov(ε) J (JᵀJ)⁻¹ with
    Cov(ε) = s_e² F Fᵀ of the fitted AR model, s_e² = ‖e‖²/(n_e − p − Σ orders), e = A(q)ε.
    A singular JᵀJ (condition number > 10¹⁴) gives an infinite covariance."""
    theta = np.asarray(theta, dtype=float)
    res = np.asarray(fun(theta), dtype=float)
    J = jacobian(fun, theta)
    p = J.shape[1]
    coloured = noise is not None and not noise.white
    e = noise.whiten(res) if coloured else res
    dof = max(e.size - p - (noise.n_params if coloured else 0), 1)
    s2 = float(e @ e) / dof
    JTJ = J.T @ J
    try:
        if np.linalg.cond(JTJ) > 1e14:
            raise np.linalg.LinAlgError("singular")
        inv = np.linalg.inv(JTJ)
        if coloured:
            G = noise.colour_transpose(J)
            cov = s2 * inv @ (G.T @ G) @ inv
        else:
            cov = s2 * inv
    except np.linalg.LinAlgError:
        cov = np.full((p, p), math.inf)
    return cov, e, dof


def confidence(fun: Callable, theta, specs, noise: ARNoise | None = None
               ) -> tuple[dict[str, Parameter], np.ndarray]:
    """Parameters with standard errors and 95 % t intervals (module docstring) for the residual
    function ``fun`` at its optimum ``theta``; ``specs`` = [(name, unit, meaning), ...] (a name
    starting with ``_`` is a nuisance parameter: in the covariance, not in the result). With a
    ``noise`` model the covariance allows for autocorrelated residuals (:func:`covariance`)."""
    theta = np.asarray(theta, dtype=float)
    cov, _, dof = covariance(fun, theta, noise)
    res = np.asarray(fun(theta), dtype=float)
    se = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    q = float(stats.t.ppf(0.5 + LEVEL / 2.0, dof))
    out = {}
    for (name, unit, meaning), value, e in zip(specs, theta, se, strict=True):
        if name.startswith("_"):
            continue  # a nuisance parameter (an initial state): in J, not reported
        out[name] = Parameter(name, float(value), float(e), (float(value - q * e), float(value + q * e)),
                              unit, meaning, dof)
    return out, res


def nrmse(y_hat: np.ndarray, y: np.ndarray) -> float | None:
    """‖ŷ − y‖/‖y − ȳ‖ (None for an empty or constant record)."""
    if y.size < 2:
        return None
    spread = float(np.linalg.norm(y - np.mean(y)))
    if spread == 0:
        return None
    return float(np.linalg.norm(y_hat - y)) / spread


def lag1(res: np.ndarray) -> float:
    res = np.asarray(res, dtype=float) - np.mean(res)
    den = float(res @ res)
    return float(res[1:] @ res[:-1]) / den if den > 0 else 0.0


def _scores(ident_measured, ident_simulated, split) -> tuple[dict, dict, dict]:
    hold, fit, rms = {}, {}, {}
    for key, y in ident_measured.items():
        y_hat = ident_simulated[key]
        hold[key] = nrmse(y_hat[split:], y[split:]) if split < y.size - 1 else None
        fit[key] = nrmse(y_hat[:split], y[:split])
        rms[key] = float(np.sqrt(np.mean((y_hat - y) ** 2)))
    return hold, fit, rms


def _lag_note(rho: float) -> list[str]:
    if rho > 0.5:
        return [f"the residuals are correlated (lag-1 autocorrelation {rho:.2f}): coloured noise or "
                "a model error; the intervals allow for the correlation (an AR model of the "
                "residuals), not for a model error (a bias)"]
    return []


# --------------------------------------------------------------------------- Nomoto

def _nomoto1_best(tf, df, rf, horizon: float | None) -> tuple[object, float | None, list[str]]:
    """fit_nomoto from the equation-error estimate and (one free run only), unless that explains
    the fitted part (fit > 0.9 with T > 0), from a grid of time constants of either sign of K; the
    lowest cost wins. A course-unstable equation-error estimate
    (T < 0) switches to prediction windows of |T|/2 (a free-running unstable model diverges)."""
    h = float(tf[1] - tf[0])
    (a, b), *_ = np.linalg.lstsq(np.column_stack([rf, df]), np.gradient(rf, h), rcond=None)
    notes = []
    if horizon is not None:
        check_horizon(horizon, tf)
    elif a > 0:
        horizon = max(10 * h, 0.5 / a)
        notes.append(f"the equation-error estimate is course-unstable (T = {-1 / a:.3g} s): fitted "
                     f"as {horizon:.3g} s prediction windows restarted from the logged r (and so "
                     "re-simulated); --horizon sets the window")
    k_static = float(df @ rf) / max(float(df @ df), 1e-300)
    k_static = k_static if k_static != 0 else (-b / a if a else 1.0)
    dur = float(tf[-1] - tf[0])
    starts = [None]
    if horizon is None:  # (prediction windows start from the logged r: the first start serves)
        starts += [(s * abs(k_static), f * dur) for f in (0.02, 0.1, 0.3) for s in (1.0, -1.0)]
    best = None
    for g in starts:
        if best is not None and g is not None and best.fit > 0.9 and best.T > 0:
            break  # the equation-error start explains the log: no other starts needed
        try:
            cand = fit_nomoto(tf, df, rf, guess=g, horizon=horizon)
        except ConfigError:
            continue
        if not (math.isfinite(cand.K) and math.isfinite(cand.T)) or cand.T == 0:
            continue
        if best is None or cand.cost < best.cost:
            best = cand
    if best is None:
        raise ConfigError("nomoto1: the least-squares fit found no finite K, T for this log")
    return best, horizon, notes


def identify_nomoto1(t, delta, r, *, holdout: float = 0.3, speed: float | None = None,
                     heading=None, horizon: float | None = None) -> Identification:
    """First-order Nomoto K, T from the log (module docstring); ``speed`` [m/s] goes to the
    vessel YAML, ``heading`` [rad] (optional) to the figure, ``horizon`` [s] fits prediction
    windows (default: one free run, unless the equation-error estimate is course-unstable)."""
    t, delta, r = (np.asarray(a, dtype=float) for a in (t, delta, r))
    h = float(t[1] - t[0])
    k = split_index(t.size, holdout)
    tf, df, rf = t[:k], delta[:k], r[:k]
    cond = check_excitation([rf, df], "[r, delta] of r_dot = a r + b delta", df)
    fit, horizon, notes = _nomoto1_best(tf, df, rf, horizon)
    steps = None if horizon is None else max(1, round(horizon / h))
    specs = [("K", "1/s", "yaw-rate gain r/delta in a steady turn"),
             ("T", "s", "time constant (T < 0: course-unstable)")]
    if steps is None:
        # one free run: the initial yaw rate is a nuisance parameter (a noisy logged r(0) would
        # bias K, T), polished from fit_nomoto's optimum
        def fun(theta):
            return _foh_first_order(theta[0], theta[1], h, df, theta[2]) - rf

        sol = optimize.least_squares(fun, [fit.K, fit.T, rf[0]], x_scale="jac", method="lm",
                                     xtol=1e-14, ftol=1e-14, gtol=1e-14, max_nfev=2000)
        theta = sol.x if np.all(np.isfinite(sol.x)) and sol.cost <= fit.cost * (1 + 1e-9) + 1e-300 \
            else np.array([fit.K, fit.T, rf[0]])
        specs.append(("_r0", "rad/s", "initial yaw rate"))
    else:
        seg_fit = _segments(k, steps)

        def fun(theta):
            return _simulate_segments(theta[0], theta[1], h, df, rf, seg_fit)[1:] - rf[1:]

        theta = [fit.K, fit.T]
    noise = ARNoise.fit(fun(theta))
    params, res = confidence(fun, theta, specs, noise)
    K, T = params["K"].value, params["T"].value
    if steps is None:
        r_sim = _foh_first_order(K, T, h, delta, float(theta[2]))
    else:
        r_sim = _simulate_segments(K, T, h, delta, r, _segments(t.size, steps))
    vessel = {"model": "nomoto", "K": K, "T": T}
    method = "output error (fit_nomoto: exact first-order hold, least squares"
    method += f", {horizon:.3g} s prediction windows)" if horizon is not None else ")"
    ident = _finish("nomoto1", params, t, delta, {"r": r}, {"r": r_sim}, k, holdout, res, cond,
                    "[r, delta]", vessel, speed, heading, method)
    ident.noise = noise.to_json(("r",))
    if abs(T) < 2 * h:
        notes.append(f"|T| = {abs(T):.3g} s is below two sampling steps: the time constant is not "
                     "resolved (the log looks like a static gain r = K delta)")
    ident.notes = notes + ident.notes
    refuse_unidentified(ident)
    return ident


def _lsim2_sp(K, S, P, T3, t, delta, r0):
    """The second-order Nomoto response in the denominator's coefficients S = T₁ + T₂, P = T₁T₂
    (P r̈ + S ṙ + r = K(δ + T₃δ̇)): smooth where T₁ = T₂ (and for complex poles), as
    :func:`~shipgnc.analysis.identification._lsim2` (same realisation and start)."""
    A = np.array([[0.0, 1.0], [-1.0 / P, -S / P]])
    C = np.array([[K / P, K * T3 / P]])
    x0 = np.array([r0 / C[0, 0] if C[0, 0] != 0 else 0.0, 0.0])
    sys = signal.StateSpace(A, np.array([[0.0], [1.0]]), C, np.zeros((1, 1)))
    with np.errstate(all="ignore"):  # a trial point with T₁T₂ → 0 overflows: a large residual, not a message
        _, y, _ = signal.lsim(sys, delta, t - t[0], X0=x0, interp=True)
    return np.asarray(y, dtype=float).reshape(-1)


def identify_nomoto2(t, delta, r, *, holdout: float = 0.3, speed: float | None = None,
                     heading=None) -> Identification:
    """Second-order Nomoto K, T₁, T₂, T₃ from the log (module docstring).

    The intervals come from the covariance in (K, S = T₁ + T₂, P = T₁T₂, T₃), which the data
    determine even when T₁ = T₂ (there T₁, T₂ separately are not: their intervals are unbounded);
    S and P are reported beside them, T₁ and T₂ by the delta method (Seber & Wild 1989, §5.1).
    """
    t, delta, r = (np.asarray(a, dtype=float) for a in (t, delta, r))
    k = split_index(t.size, holdout)
    tf, df, rf = t[:k], delta[:k], r[:k]
    cond = check_excitation([rf, df], "[r, delta] of r_dot = a r + b delta", df)
    fit = fit_nomoto2(tf, df, rf)

    def fun(phi):
        return _lsim2_sp(*phi, tf, df, rf[0])[1:] - rf[1:]

    phi = [fit.K, fit.T1 + fit.T2, fit.T1 * fit.T2, fit.T3]
    complex_note = None
    try:  # polish in (K, S, P, T3): reaches a distinct real pair fit_nomoto2 stopped short of
        sol = optimize.least_squares(fun, phi, x_scale="jac", method="lm", max_nfev=400)
        S_, P_ = sol.x[1], sol.x[2]
        if np.all(np.isfinite(sol.x)) and sol.cost < 0.5 * float(np.sum(fun(phi) ** 2)):
            if S_ * S_ - 4 * P_ >= 0 and P_ > 0:
                phi = list(sol.x)
            elif P_ > 0:
                complex_note = (f"the log fits better with complex poles (T1+T2 = {S_:.4g} s, "
                                f"T1*T2 = {P_:.4g} s^2, residual RMS "
                                f"{math.sqrt(2 * sol.cost / (k - 1)):.3g} vs "
                                f"{math.sqrt(float(np.mean(fun(phi) ** 2))):.3g}): an oscillatory "
                                "yaw mode that real T1, T2 cannot express; linear-3dof can")
    except (ValueError, np.linalg.LinAlgError):
        pass
    noise = ARNoise.fit(fun(phi))
    sp, res = confidence(fun, phi, [
        ("K", "1/s", "yaw-rate gain r/delta in a steady turn"),
        ("T1+T2", "s", "sum of the time constants (denominator's s coefficient)"),
        ("T1*T2", "s^2", "product of the time constants (denominator's s^2 coefficient)"),
        ("T3", "s", "zero's time constant")])
    S, P = sp["T1+T2"].value, sp["T1*T2"].value
    D = S * S - 4.0 * P
    root = math.sqrt(D) if D > 0 else 0.0
    T1, T2 = 0.5 * (S + root), 0.5 * (S - root)
    # delta method for T1, T2 from the (S, P) block of the covariance
    cov, _, dof = covariance(fun, phi, noise)
    q = float(stats.t.ppf(0.5 + LEVEL / 2.0, dof))
    params = {"K": sp["K"]}
    for name, value, sign, meaning in (("T1", T1, 1.0, "first (larger) time constant"),
                                       ("T2", T2, -1.0, "second time constant")):
        if root > 1e-9 * max(abs(S), 1e-12):
            g = np.array([0.5 + sign * 0.5 * S / root, -sign / root])
            se = float(math.sqrt(max(g @ cov[1:3, 1:3] @ g, 0.0)))
        else:
            se = math.inf
        params[name] = Parameter(name, value, se, (value - q * se, value + q * se), "s", meaning, dof)
    params["T3"] = sp["T3"]
    params["T1+T2"], params["T1*T2"] = sp["T1+T2"], sp["T1*T2"]
    r_sim = _lsim2_sp(sp["K"].value, S, P, sp["T3"].value, t, delta, r[0])
    vessel = {"model": "nomoto2", "K": sp["K"].value, "T1": T1, "T2": T2, "T3": sp["T3"].value}
    ident = _finish("nomoto2", params, t, delta, {"r": r}, {"r": r_sim}, k, holdout, res, cond,
                    "[r, delta]", vessel, speed, heading,
                    "output error (fit_nomoto2: scipy.signal.lsim, least squares)")
    ident.noise = noise.to_json(("r",))
    if D <= 0 or not math.isfinite(params["T1"].std_error):
        ident.notes.append(f"T1 = T2 = {T1:.4g} s (a double pole; the best real pair for a response "
                           "that may have complex poles): T1 and T2 separately are undetermined, "
                           "their sum and product are (T1+T2, T1*T2)")
    if complex_note:
        ident.notes.append(complex_note)
    wide = [n for n, p in params.items() if n in ("K", "T3", "T1+T2", "T1*T2")
            and (not math.isfinite(p.std_error) or p.std_error > abs(p.value))]
    if wide:
        ident.notes.append(f"{', '.join(wide)} poorly determined (standard error > |value|): the "
                           "log does not separate the second-order model's time constants "
                           "(pole-zero near cancellation); nomoto1 may serve better")
    refuse_unidentified(ident)
    return ident


def _finish(model, params, t, delta, measured, simulated, k, holdout, res, cond, regressor,
            vessel, speed, heading, method) -> Identification:
    hold, fitq, rms = _scores(measured, simulated, k)
    rho = lag1(res)
    notes = _lag_note(rho)
    if speed is not None:
        vessel["speed_mps"] = float(speed)
    else:
        notes.append("no surge speed in the log and no --speed: the vessel YAML has no "
                     "speed_mps (the scenario's vessel section must give it)")
    if "K" in params and params["K"].value < 0:
        notes.append("K < 0: in this log a positive rudder turns the bow to port (e.g. CyberShip "
                     "II's convention); the written model keeps the log's sign")
    poor = {key: v for key, v in hold.items() if v is not None and v > 0.5}
    if poor:
        notes.append("the model explains the held-out part poorly (NRMSE "
                     + ", ".join(f"{key} {v:.3g}" for key, v in poor.items())
                     + "): a nonlinear or closed-loop log, or a model too simple for it; a "
                     "zig-zag log of larger amplitude identifies better")
    psi = None
    if heading is not None:
        psi = np.asarray(heading, dtype=float)
    return Identification(model=model, parameters=params, t=t, rudder=delta, measured=measured,
                          simulated=simulated, split=k, holdout=float(holdout), nrmse_holdout=hold,
                          nrmse_fit=fitq, residual_rms=rms, residual_lag1=rho,
                          condition_number=cond, regressor=regressor, vessel=vessel, method=method,
                          heading=psi, notes=notes)


# --------------------------------------------------------------------------- linear 3-DOF

def foh_lti(A: np.ndarray, b: np.ndarray, h: float, u: np.ndarray, x0: np.ndarray) -> np.ndarray:
    """Exact response (n_samples, n) of ẋ = A x + b u to ``u`` linear between samples ``h``
    apart (first-order hold): expm([[A, b, 0], [0, 0, 1], [0, 0, 0]] h) = [[Φ, Γ₁, Γ₂], ...],
    x_{k+1} = Φ x_k + Γ₁ u_k + Γ₂ (u_{k+1} − u_k)/h. Recursion per mode of Φ (``lfilter``)."""
    A = np.asarray(A, dtype=float)
    n = A.shape[0]
    aug = np.zeros((n + 2, n + 2))
    aug[:n, :n] = A
    aug[:n, n] = b
    aug[n, n + 1] = 1.0
    E = linalg.expm(aug * h)
    Phi, G1, G2 = E[:n, :n], E[:n, n], E[:n, n + 1]
    u = np.asarray(u, dtype=float)
    g = np.outer(u[:-1], G1) + np.outer(np.diff(u) / h, G2)     # (N-1, n)
    out = np.empty((u.size, n))
    out[0] = x0
    lam, V = np.linalg.eig(Phi)
    if np.linalg.cond(V) < 1e8:
        z0 = np.linalg.solve(V, np.asarray(x0, dtype=complex))
        gz = np.linalg.solve(V, g.T.astype(complex))
        z = np.empty((n, u.size - 1), dtype=complex)
        for i in range(n):
            z[i], _ = signal.lfilter([1.0], [1.0, -lam[i]], gz[i], zi=[lam[i] * z0[i]])
        out[1:] = np.real(V @ z).T
        return out
    x = np.asarray(x0, dtype=float)
    for j in range(u.size - 1):  # defective Φ (repeated pole): the plain recursion
        x = Phi @ x + g[j]
        out[j + 1] = x
    return out


def _windows(n: int, steps: int | None) -> list[tuple[int, int]]:
    if steps is None or steps >= n - 1:
        return [(0, n - 1)]
    return [(i, min(i + steps, n - 1)) for i in range(0, n - 1, steps)]


def _sim_sway_yaw(theta, h, delta, x_meas, windows) -> np.ndarray:
    A = np.array([[theta[0], theta[1]], [theta[2], theta[3]]])
    b = np.array([theta[4], theta[5]])
    out = np.empty_like(x_meas)
    out[0] = x_meas[0]
    for i0, i1 in windows:
        out[i0 + 1:i1 + 1] = foh_lti(A, b, h, delta[i0:i1 + 1], x_meas[i0])[1:]
    return out


SWAY_YAW = [("a_vv", "1/s", "sway damping per unit inertia, (-M^-1 N)_vv"),
            ("a_vr", "m/s", "sway from yaw rate, (-M^-1 N)_vr"),
            ("a_rv", "1/(m s)", "yaw from sway, (-M^-1 N)_rv"),
            ("a_rr", "1/s", "yaw damping per unit inertia, (-M^-1 N)_rr"),
            ("b_v", "m/s^2/rad", "sway acceleration per rudder angle, (M^-1 B)_v"),
            ("b_r", "1/s^2", "yaw acceleration per rudder angle, (M^-1 B)_r")]


def identify_linear3dof(t, delta, u, v, r, *, holdout: float = 0.3, horizon: float | None = None,
                        speed: float | None = None, heading=None) -> Identification:
    """The linear 3-DOF model's A = −M⁻¹N and b = M⁻¹B from the log (module docstring).

    ``horizon`` [s]: fit predictions over windows of this length, each restarted from the logged
    state (None: one simulation over the fitted part, unless the start estimate is unstable).
    ``speed`` [m/s] overrides U when the surge is not identified.
    """
    t, delta, u, v, r = (np.asarray(a, dtype=float) for a in (t, delta, u, v, r))
    h = float(t[1] - t[0])
    k = split_index(t.size, holdout)
    df, vf, rf, uf = delta[:k], v[:k], r[:k], u[:k]
    cond = check_excitation([vf, rf, df], "[v, r, delta] of v_dot, r_dot = A [v, r] + b delta", df)
    notes: list[str] = []
    # equation-error start on differentiated signals
    X = np.column_stack([vf, rf, df])
    cv, *_ = np.linalg.lstsq(X, np.gradient(vf, h), rcond=None)
    cr, *_ = np.linalg.lstsq(X, np.gradient(rf, h), rcond=None)
    theta0 = np.array([cv[0], cv[1], cr[0], cr[1], cv[2], cr[2]])
    steps = None
    if horizon is not None:
        check_horizon(horizon, t[:k])
        steps = max(1, round(horizon / h))
    else:
        lam = np.linalg.eigvals(theta0[:4].reshape(2, 2))
        if np.max(lam.real) > 0:
            steps = max(10, round(2.0 / float(np.max(lam.real)) / h))
            notes.append(f"the start estimate is course-unstable: fitted as {steps * h:.4g} s "
                         "prediction windows restarted from the logged state (and so simulated)")
    windows = _windows(k, steps)
    xm = np.column_stack([vf, rf])
    w = np.array([1.0 / max(np.std(vf), 1e-12), 1.0 / max(np.std(rf), 1e-12)])
    free_x0 = steps is None  # one free run: the initial (v, r) are nuisance parameters

    def simulate(theta, dl, x_meas, wins):
        if free_x0:
            x_meas = x_meas.copy()
            x_meas[0] = theta[6:8]
        return _sim_sway_yaw(theta, h, dl, x_meas, wins)

    def fun(theta):
        return ((simulate(theta, df, xm, windows) - xm) * w).T.reshape(-1)

    theta = np.concatenate([theta0, xm[0]]) if free_x0 else theta0
    for _ in range(2):  # second pass: weights = 1/residual RMS per channel (noise levels)
        sol = optimize.least_squares(fun, theta, x_scale="jac", method="lm", xtol=1e-12,
                                     ftol=1e-12, gtol=1e-12, max_nfev=4000)
        theta = sol.x
        resid = simulate(theta, df, xm, windows) - xm
        w = 1.0 / np.maximum(np.sqrt(np.mean(resid**2, axis=0)), 1e-15)
    specs = SWAY_YAW + ([("_v0", "m/s", ""), ("_r0", "rad/s", "")] if free_x0 else [])
    noise = ARNoise.fit(fun(theta), channels=2)
    params, res = confidence(fun, theta, specs, noise)
    rho = lag1(res[: res.size // 2]) * 0.5 + lag1(res[res.size // 2:]) * 0.5
    # surge
    mean_u = float(np.mean(uf))
    surge_params: dict[str, Parameter] = {}
    if np.ptp(uf) >= SURGE_MIN_CHANGE * max(abs(mean_u), 1e-9):
        tau = t[:k] - t[0]
        u0 = uf[0]
        tail = uf[-max(3, k // 10):]
        Xu = np.column_stack([uf, np.ones(k)])
        (au, cu), *_ = np.linalg.lstsq(Xu, np.gradient(uf, h), rcond=None)
        U0 = -cu / au if au < 0 else float(np.mean(tail))
        au = au if au < 0 else -1.0 / max(tau[-1], h)

        def fun_u(th):  # th = (a_uu, U, u(0)): the initial speed is a nuisance parameter
            return th[1] + (th[2] - th[1]) * np.exp(th[0] * tau) - uf

        sol = optimize.least_squares(fun_u, [au, U0, u0], x_scale="jac", method="lm",
                                     max_nfev=2000)
        surge_params, _ = confidence(fun_u, sol.x, [
            ("a_uu", "1/s", "surge damping per unit inertia, (-M^-1 N)_uu"),
            ("U", "m/s", "speed the surge settles to (linearisation speed)"),
            ("_u0", "m/s", "initial surge speed")])
        a_uu, U = surge_params["a_uu"].value, surge_params["U"].value
        u_sim = U + (sol.x[2] - U) * np.exp(a_uu * (t - t[0]))
    else:
        a_uu = 0.0
        U = float(speed) if speed is not None else mean_u
        u_sim = np.full_like(u, U)  # as the vessel YAML below sails it
        notes.append(f"surge not identified: the speed changes by {np.ptp(uf):.3g} m/s "
                     f"(< {100 * SURGE_MIN_CHANGE:g} % of its mean {mean_u:.4g} m/s); the vessel "
                     "YAML keeps u constant (N_uu = 0) at U = "
                     f"{U:.4g} m/s")
    all_params = {**surge_params, **params}
    th = [params[n].value for n, _, _ in SWAY_YAW]
    x_all = np.column_stack([v, r])
    if free_x0:
        x_all[0] = theta[6:8]
    sim = _sim_sway_yaw(th, h, delta, x_all, _windows(t.size, steps))
    A = np.array([[a_uu, 0.0, 0.0], [0.0, th[0], th[1]], [0.0, th[2], th[3]]])
    vessel = {"model": "linear-3dof", "speed_mps": float(U),
              "M": np.eye(3).tolist(), "N": (-A).tolist(), "B": [[0.0], [th[4]], [th[5]]]}
    measured = {"v": v, "r": r}
    simulated = {"v": sim[:, 0], "r": sim[:, 1]}
    if surge_params:
        measured = {"u": u, **measured}
        simulated = {"u": u_sim, **simulated}
    hold, fitq, rms = _scores(measured, simulated, k)
    if not surge_params:
        measured = {"u": u, **measured}
        simulated = {"u": u_sim, **simulated}
    notes = _lag_note(rho) + notes
    notes.append("M is not identifiable from motions (only M^-1 N and M^-1 B are): the vessel "
                 "YAML has M = I, N = -A, B = b (the equations per unit inertia)")
    ident = Identification(model="linear-3dof", parameters=all_params, t=t, rudder=delta,
                          measured=measured, simulated=simulated, split=k, holdout=float(holdout),
                          nrmse_holdout=hold, nrmse_fit=fitq, residual_rms=rms, residual_lag1=rho,
                          condition_number=cond, regressor="[v, r, delta]", vessel=vessel,
                          method="output error (exact first-order hold, least squares; start: "
                                 "equation error on numerically differentiated v, r)",
                          heading=None if heading is None else np.asarray(heading, dtype=float),
                          notes=notes, noise=noise.to_json(("v", "r")))
    refuse_unidentified(ident)
    return ident


# --------------------------------------------------------------------------- from a log

def identify_log(log, model: str = "nomoto1", *, holdout: float = 0.3, speed: float | None = None,
                 horizon: float | None = None) -> Identification:
    """Fit ``model`` to a checked :class:`~shipgnc.identify.logs.Log` (yaw rate from the
    differentiated heading when the log has none)."""
    if model not in MODELS:
        raise ConfigError(f"--model {model!r}: allowed: {', '.join(MODELS)}")
    if speed is not None and not (math.isfinite(speed) and speed > 0):
        raise ConfigError(f"--speed {speed!r}: must be a speed > 0 m/s")
    if horizon is not None and model == "nomoto2":
        raise ConfigError(f"--horizon {horizon!r}: prediction windows are fitted for nomoto1 and "
                          "linear-3dof only (nomoto2 fits one free run)")
    check_time_scale(log.t, log.names.get("time", "time"))
    notes = list(log.notes)
    if log.has("yaw_rate"):
        r = log.data["yaw_rate"]
    else:
        r = np.gradient(log.data["heading"], log.t)
        notes.append(f"no yaw-rate column: r from the differentiated heading {log.names['heading']!r}")
    heading = log.data.get("heading")
    if model == "linear-3dof":
        for role in ("u", "v"):
            if not log.has(role):
                from shipgnc.identify.logs import DEFAULT_COLUMNS

                raise ConfigError(f"LOG {log.path!r}: linear-3dof needs the {role} column (looked for "
                                  f"{' or '.join(map(repr, DEFAULT_COLUMNS[role]))}); columns present: "
                                  f"{', '.join(log.present)}; name it with --columns {role}=NAME")
        ident = identify_linear3dof(log.t, log.data["rudder"], log.data["u"], log.data["v"], r,
                                    holdout=holdout, horizon=horizon, speed=speed, heading=heading)
    else:
        if speed is None and log.has("u"):
            speed = float(np.mean(log.data["u"]))
            notes.append(f"speed_mps = {speed:.4g} m/s: the mean of the surge column {log.names['u']!r}")
        if model == "nomoto1":
            ident = identify_nomoto1(log.t, log.data["rudder"], r, holdout=holdout, speed=speed,
                                     heading=heading, horizon=horizon)
        else:
            ident = identify_nomoto2(log.t, log.data["rudder"], r, holdout=holdout, speed=speed,
                                     heading=heading)
    ident.notes = notes + ident.notes
    return ident
