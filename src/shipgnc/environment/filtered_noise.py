"""Narrow-band noise from white noise through a second-order filter (note 000-A11).

The wave disturbance of document 000 is "suitably filtered white noise"; note 000-A11 fixes it as
the output w = ẋ₁ of the linear wave-response filter (Fossen's linear wave model)::

    ẋ₁ = x₂,   ẋ₂ = −ω₀² x₁ − 2ζω₀ x₂ + q ξ(t),   w = x₂,                        (A11)

ξ white with unit intensity, ω₀ = 2π/T₀, q chosen so that the stationary RMS of w is σ:
var(x₂) = q²/(4ζω₀), so q = σ √(4ζω₀). The filter starts in its stationary distribution.

**What is held over a step.** The simulator samples a disturbance at each step's start and holds
it over the step. Holding the *point* value w(t_k) would alias the narrow band: the held sequence
then has a white floor ≈ q²h²/(12π) at low frequencies, far above the filter's own spectrum, and
the yaw rate it drives random-walks. The value held over [t_k, t_k + h] is therefore
the **exact step average** w̄_k = (1/h)∫ w dt of the filtered process over that step: the
filter is augmented with y' = w and propagated exactly in distribution over each step::

    [x(t+h); y] = Φₐ [x(t); 0] + Lₐ n,   Φₐ = exp(Aₐ h),   Lₐ Lₐᵀ = ∫₀ʰ e^{Aₐs} b bᵀ e^{Aₐᵀs} ds,

n ~ N(0, I₃) per ship, b = (0, q, 0), w̄ = y/h; the covariance from Van Loan's matrix exponential.
The held sequence is then an exact sample of the step averages of the continuous process: its
spectrum is S_w(ω)·sinc²(ωh/2) folded at the Nyquist frequency (the low-frequency floor gone), and
its statistics do not depend on the step beyond that average.

The step h of the call at t_k is t_k − t_{k−1} (the toolkit's loops call at t_k = k·dt). The
first call after :meth:`SecondOrderNoise.reset` does not know its step: it uses ``step`` when
given, else it holds the point value w(t₀) (the average over a vanishing step; its variance σ²
instead of the average's, e.g. 0.5 % more at dt = 0.3 s, T₀ = 8 s), and every later value is an
exact step average. A call earlier than the end of the step drawn before it (an irregular call
sequence; no loop of the toolkit does this) restarts from the state at that step's start.
Draws come from the simulator's seeded generator, shape (*batch, 3) per step: same seed, same
sea; each ship of a batch gets its own realisation.
"""

from __future__ import annotations

import math

import numba
import numpy as np
import scipy.linalg

from shipgnc.batchmath import matvec
from shipgnc.errors import require
from shipgnc.streams import normal_steps


class SecondOrderNoise:
    """Seeded narrow-band noise w(t) of RMS ``sigma`` around ω₀ = 2π/``period`` (eq. A11).

    ``sigma`` in the unit of the channel it drives (e.g. rad/s² for a yaw acceleration),
    ``period`` T₀ [s], ``zeta`` the filter's damping ratio, ``step`` the loop's step [s] when
    known (only the first call needs it; see the module notes). ``__call__(t, x)`` returns the
    exact average of w (...,) over the step starting at t (held over the step, ``per_stage =
    False``); ``at_times(times)`` the values of a run of calls at once (one draw, one compiled
    pass, the same bits); ``sequence(times, batch_shape, rng)`` those of a whole run from a reset.
    """

    per_stage = False

    def __init__(self, sigma: float, period: float, zeta: float, step: float | None = None):
        for name, value, rule in (("sigma", sigma, ">= 0"), ("period", period, "> 0 s"),
                                  ("zeta", zeta, "> 0")):
            ok = isinstance(value, (int, float)) and math.isfinite(value) and (
                value >= 0 if name == "sigma" else value > 0)
            require(ok, f"disturbance.wave_{name}", value, f"must be a finite number {rule}")
        require(step is None or (isinstance(step, (int, float)) and math.isfinite(step)
                                 and step > 0), "disturbance.wave_step", step,
                "must be None or a finite step > 0 s")
        self.sigma, self.period, self.zeta = float(sigma), float(period), float(zeta)
        self.step = None if step is None else float(step)
        self.omega0 = 2.0 * math.pi / self.period
        self.q = self.sigma * math.sqrt(4.0 * self.zeta * self.omega0)
        w0, z = self.omega0, self.zeta
        self.A = np.array([[0.0, 1.0], [-w0 * w0, -2.0 * z * w0]])
        self.P = np.diag([self.q**2 / (4.0 * z * w0**3), self.q**2 / (4.0 * z * w0)])
        self._cache: dict[float, tuple[np.ndarray, np.ndarray]] = {}
        self._avg_cache: dict[float, tuple[np.ndarray, np.ndarray]] = {}
        self._rng: np.random.Generator | None = None
        self._x: np.ndarray | None = None  # the state at self._t_end
        self._x_start: np.ndarray | None = None  # the state at the held step's start self._t
        self._t: float | None = None
        self._t_end: float | None = None
        self._held: np.ndarray | None = None

    def transition(self, h: float) -> tuple[np.ndarray, np.ndarray]:
        """(Φ, L) of one step of length ``h`` [s]: x ← Φ x + L n (exact in distribution)."""
        key = _step_key(h)
        if key not in self._cache:
            phi = scipy.linalg.expm(self.A * h)
            Qd = self.P - phi @ self.P @ phi.T
            self._cache[key] = (phi, _factor(Qd))
        return self._cache[key]

    def averaged_transition(self, h: float) -> tuple[np.ndarray, np.ndarray]:
        """(G, L) of one step of length ``h`` > 0 [s] with the step's integral of w:
        [x(t+h); ∫w] = G x(t) + L n, n ~ N(0, I₃) (exact in distribution; G is 3×2, L 3×3).
        Van Loan: exp([[−Aₐ, b bᵀ], [0, Aₐᵀ]] h) = [[·, Φₐ⁻¹ Q], [0, Φₐᵀ]], Q = Φₐ (Φₐ⁻¹ Q)."""
        key = _step_key(h)
        if key not in self._avg_cache:
            Aa = np.zeros((3, 3))
            Aa[:2, :2] = self.A
            Aa[2, 1] = 1.0  # y' = w = x₂
            bbT = np.zeros((3, 3))
            bbT[1, 1] = self.q**2
            M = np.zeros((6, 6))
            M[:3, :3], M[:3, 3:], M[3:, 3:] = -Aa, bbT, Aa.T
            E = scipy.linalg.expm(M * h)
            phi_a = E[3:, 3:].T
            Q = phi_a @ E[:3, 3:]
            self._avg_cache[key] = (phi_a[:, :2].copy(), _factor(Q))
        return self._avg_cache[key]

    def held_variance(self, h: float) -> float:
        """Variance of the value held over a step of length ``h`` [s]: the step average of w,
        ∫w = x₁(t+h) − x₁(t), so 2(P₁₁ − (Φ(h) P)₁₁)/h² (σ² in the limit h → 0)."""
        phi, _ = self.transition(h)
        return float(2.0 * (self.P[0, 0] - (phi @ self.P)[0, 0]) / h**2)

    def step_average_psd(self, f, h: float) -> np.ndarray:
        """One-sided PSD of the held sequence at frequencies ``f`` [Hz] ≤ 1/(2h), for a step ``h``
        (σ²'s unit per Hz; what ``scipy.signal.welch`` estimates): the step average's spectrum
        S_w(ω)·sinc²(ωh/2), folded at the Nyquist frequency, with S_w(ω) = q²ω² / ((ω₀² − ω²)² +
        (2ζω₀ω)²) the filter output's two-sided density (∫S_w dω/2π = σ²)."""
        f = np.asarray(f, dtype=float)
        fs = 1.0 / h
        total = np.zeros_like(f)
        for m in range(-200, 201):  # the aliases f + m·fs; the tail decays like 1/f⁴
            om = 2.0 * math.pi * (f + m * fs)
            s_w = self.q**2 * om**2 / ((self.omega0**2 - om**2) ** 2
                                       + (2.0 * self.zeta * self.omega0 * om) ** 2)
            total = total + s_w * np.sinc((f + m * fs) * h) ** 2
        return 2.0 * total  # S_w(2πf) is the two-sided density per Hz; one-sided: twice that

    def reset(self, batch_shape, rng: np.random.Generator) -> None:
        self._rng = rng
        shape = (*tuple(batch_shape), 2)
        self._x = rng.standard_normal(shape) * np.sqrt(np.diag(self.P))
        self._x_start = self._x
        self._t = self._t_end = None
        self._held = None

    def __call__(self, t: float, x=None) -> np.ndarray:
        require(self._x is not None, "disturbance", "SecondOrderNoise", "call reset() first")
        if self._t is not None and t <= self._t:  # the same step (times only increase)
            return self._held
        if self._t is None:  # first call: the step, if known
            h = self.step
        else:
            # t_k − t_{k−1} added back to t_{k−1} may miss t_k by a rounding: that is the step end
            tol = _same_time_tol(t)
            if t < self._t_end - tol:  # inside the step drawn last: restart from its start
                self._x, self._t_end = self._x_start, self._t
            if t > self._t_end + tol:
                phi, L = self.transition(t - self._t_end)
                n = self._rng.standard_normal(self._x.shape)
                self._x = matvec(phi, self._x) + matvec(L, n)
            h = t - self._t
        self._t, self._x_start = t, self._x
        if h is None:  # the point value w(t₀): the average over a vanishing step
            self._t_end, self._held = t, self._x[..., 1]
            return self._held
        G, L = self.averaged_transition(h)
        batch = self._x.shape[:-1]
        n = self._rng.standard_normal((*batch, 3))
        x = self._x.reshape(-1, 2).copy()  # stepped in place by the one step of the recursion
        held, _ = _averaged_steps(x, n.reshape(1, -1, 3), G[None], L[None], np.array([h]))
        self._x, self._t_end, self._held = x.reshape(*batch, 2), t + h, held[0].reshape(batch)
        return self._held

    def sequence(self, times, batch_shape, rng: np.random.Generator) -> np.ndarray:
        """w at every time of ``times`` (ascending), shape (len(times), *batch_shape): the values
        ``__call__`` would return after ``reset(batch_shape, rng)``, with the same draws."""
        self.reset(batch_shape, rng)
        return self.at_times(times)

    def at_times(self, times) -> np.ndarray:
        """``np.stack([self(t) for t in times])`` from the current state, to the bit, and the
        state left as those calls leave it. After the first call, a regular sequence (each time
        at the end of the step drawn before it: t_k = k·dt) is one draw of all its normals, the
        same stream as one draw per call, and one compiled pass of the step recursion
        (:func:`_averaged_steps`); anything else is the calls themselves."""
        require(self._x is not None, "disturbance", "SecondOrderNoise", "call reset() first")
        times = np.asarray(times, dtype=float)
        # the first two calls of every run of times go through __call__: after a reset the first
        # may hold the point value w(t0) and the second then steps from t0 to t1 in two draws
        out = [self(float(t)) for t in times[:2]]
        rest = times[2:]
        if rest.size == 0:
            return np.stack(out) if out else np.empty((0, *self._x.shape[:-1]))
        t_prev = np.concatenate([[self._t], rest[:-1]])
        steps = rest - t_prev
        ends = np.concatenate([[self._t_end], t_prev[1:] + steps[:-1]])  # t_end before each call
        regular = np.all(rest > t_prev) and all(  # __call__'s tests: neither a restart nor a gap
            end - _same_time_tol(t) <= t <= end + _same_time_tol(t)
            for t, end in zip(rest.tolist(), ends.tolist(), strict=True))
        if not regular:
            out.extend(self(float(t)) for t in rest)
            return np.stack(out)
        # each step's (G, L) as the calls get them: the cached pair of its key, or the pair of
        # the first step with that key (the one whose call would fill the cache)
        pairs, position = [], {}
        which = np.empty(steps.size, dtype=np.int64)
        for i, h in enumerate(steps.tolist()):
            key = _step_key(h)
            if key not in position:
                position[key] = len(pairs)
                pairs.append(self.averaged_transition(h))
            which[i] = position[key]
        G = np.stack([g for g, _ in pairs])[which]
        L = np.stack([f for _, f in pairs])[which]
        batch = self._x.shape[:-1]
        noise = normal_steps(self._rng, rest.size, (*batch, 3))
        x = self._x.reshape(-1, 2).copy()  # the kernel steps it in place: not the held values' array
        held, x_start = _averaged_steps(x, noise.reshape(rest.size, -1, 3), G, L, steps)
        self._x_start = x_start.reshape(*batch, 2)
        self._x = x.reshape(*batch, 2)
        self._t, self._t_end = float(rest[-1]), float(rest[-1] + steps[-1])
        values = held.reshape(rest.size, *batch)
        self._held = values[-1]
        return np.concatenate([np.stack(out), values])


def _step_key(h: float) -> float:
    """The cache key of a step length [s]: t_k − t_{k−1} of t_k = k·dt misses dt by a rounding,
    and those steps share one transition (the first step with the key computes it)."""
    return round(h, 12)


def _same_time_tol(t: float) -> float:
    """How far a call's time may miss the end of the step drawn before it and still be that end
    [s] (t_k − t_{k−1} added back to t_{k−1} may miss t_k by a rounding)."""
    return 1e-9 * max(1.0, abs(t))


@numba.njit(cache=True, error_model="numpy")  # no fastmath: :func:`matvec`'s products and sums, in order
def _averaged_steps(x, noise, G, L, steps):
    """Steps of the averaged filter (A11) for ships ``x`` (ships, 2), updated in place — the one
    source of :meth:`SecondOrderNoise.__call__`'s averaged step and of :meth:`~SecondOrderNoise.at_times`:
    per step k, [x(t + h_k); ∫w] = z = G_k x + L_k n_k (each row's products left to right, the two
    added), x ← z[:2], w̄_k = z[2]/h_k (module docstring). Returns (w̄ (steps, ships), x at the
    last step's start)."""
    held = np.empty((steps.shape[0], x.shape[0]))
    x_start = x.copy()
    for k in range(steps.shape[0]):
        for i in range(x.shape[0]):
            x0, x1 = x[i, 0], x[i, 1]
            x_start[i, 0], x_start[i, 1] = x0, x1
            n0, n1, n2 = noise[k, i, 0], noise[k, i, 1], noise[k, i, 2]
            z0 = (x0 * G[k, 0, 0] + x1 * G[k, 0, 1]) + ((n0 * L[k, 0, 0] + n1 * L[k, 0, 1]) + n2 * L[k, 0, 2])
            z1 = (x0 * G[k, 1, 0] + x1 * G[k, 1, 1]) + ((n0 * L[k, 1, 0] + n1 * L[k, 1, 1]) + n2 * L[k, 1, 2])
            z2 = (x0 * G[k, 2, 0] + x1 * G[k, 2, 1]) + ((n0 * L[k, 2, 0] + n1 * L[k, 2, 1]) + n2 * L[k, 2, 2])
            x[i, 0], x[i, 1] = z0, z1
            held[k, i] = z2 / steps[k]
    return held, x_start


#: Pierson–Moskowitz modal frequency ω₀ = 0.40·√(g/H_s) (Fossen 2021 §10.2.1) [-]
PM_MODAL = 0.40
GRAVITY = 9.81


def pm_significant_height(period: float) -> float:
    """H_s [m] of the fully developed Pierson–Moskowitz sea whose peak period is ``period`` [s]:
    ω₀ = 2π/T₀ = 0.40·√(g/H_s) (Fossen 2021 §10.2.1), so H_s = g (0.40/ω₀)²; 2.55 m for 8 s."""
    require(isinstance(period, (int, float)) and math.isfinite(period) and period > 0,
            "disturbance.wave_period", period, "must be a finite period > 0 s")
    return GRAVITY * (PM_MODAL * period / (2.0 * math.pi)) ** 2


def calibrated_yaw_sigma(heading_sigma: float, period: float) -> float:
    """RMS σ_w [rad/s²] of the yaw acceleration (A11) that gives a wave-frequency heading of RMS
    ``heading_sigma`` σ_ψw [rad] at peak period ``period`` T₀ [s]::

        σ_w = ω₀² σ_ψw,   ω₀ = 2π/T₀.

    Why. Added to ṙ = −a r + … the noise w = ẋ₁ of (A11) drives the yaw rate r = x₁ − a∫r. At
    the wave frequency the hull's damping is negligible (a = 0.018 1/s ≪ ω₀ = 0.785 1/s for the
    Mariner at 8 s), so r ≈ x₁ with var(x₁) = q²/(4ζω₀³) = σ_w²/ω₀² exactly: σ_r = σ_w/ω₀
    (the Mariner's damping lowers it by 0.26 %, the step averaging by ≈ 0.5 % at dt = 0.3 s). The
    narrow-band heading oscillation has amplitude r/ω₀, hence σ_ψw = σ_r/ω₀ = σ_w/ω₀². This is
    Fossen's linear wave-frequency model (2021 §10.2.3): the heading's wave-frequency part is white
    noise through K_w s/(s² + 2λω₀s + ω₀²), here λ = ζ, with K_w fixed by the response's RMS
    rather than by the wave elevation (the model has no yaw RAO). The slow heading wander the same
    noise causes below ω₀ (its x₁ has a flat low-frequency spectrum) is the autopilot's to remove.
    """
    for name, value in (("wave_heading_sigma", heading_sigma), ("wave_period", period)):
        require(isinstance(value, (int, float)) and math.isfinite(value) and value >= 0,
                f"disturbance.{name}", value, "must be a finite number >= 0")
    require(period > 0, "disturbance.wave_period", period, "must be > 0 s")
    omega0 = 2.0 * math.pi / period
    return omega0 * omega0 * float(heading_sigma)


def _factor(Q: np.ndarray) -> np.ndarray:
    """L with L Lᵀ = Q for a symmetric positive semi-definite Q (eigen-decomposition, clipped)."""
    vals, vecs = np.linalg.eigh(0.5 * (Q + Q.T))
    return vecs * np.sqrt(np.clip(vals, 0.0, None))
