"""Feedback-linearising path tracking of document 000 (Mariner), notes 000-0.5, 000-A13, 000-A14.

Design model (14): a Norrbin yaw equation with the path-frame kinematics, x = [y_r, ψ_r, r]::

    ẏ_r = u sin ψ_r + v cos ψ_r + d_y,   ψ̇_r = r,   ṙ = −H_N(r) + b_r + c δ,
    v = r₁ r + r₂ r³,   H_N(r) = a r + b r³   (eq. (16); T = 1, K = c of the W–O plant (25)).

Three controllers, each with the conventions of :mod:`shipgnc.control` (``Ts``, ``signals``,
``reset(batch_shape)``, ``step`` → ``(..., 1)``, batched) and the path geometry of
:class:`~shipgnc.control.lqr.PathLQR`: they read y_r, ψ_r and the active leg's course π_p as
references from :class:`~shipgnc.guidance.path.PathGuidance`, which switches the legs (A6):

* :class:`OutputFL` with ``lookahead = 0`` — ``fl_paper``, the literal design (19)–(23) on
  y = y_r. Differentiating twice (u̇ neglected, A13)::

      ÿ = f(x) + g(x) δ,  f = u r cos ψ_r − r₁ r² sin ψ_r + r₁ cos ψ_r (b_r − H_N(r)),
                          g = r₁ c cos ψ_r                                   (19)–(20)
      δ = (ν − f)/g,  ν = −k₁ y_r − k₂ ẏ_r   ⇒   ÿ + k₂ ẏ + k₁ y = 0           (21)–(24)

  with k₁ = 0.18 /min², k₂ = 0.7 /min (:data:`K1_PAPER`, :data:`K2_PAPER`; converted to SI).
  **It is internally unstable** (see :func:`zero_dynamics_pole`).
* :class:`OutputFL` with ``lookahead = l`` — ``fl_lookahead`` (default l = 0.1 nm): the same law
  on z = y_r + l sin ψ_r, a point l ahead of the CG; f and g follow with r₁ → r₁ + l.
* :class:`LOSFL` — ``los_fl``: LOS guidance with crab compensation
  ψ_d,r = −atan(y_r/Δ) − asin(d_y/u) (Δ = 0.5 nm) feeding an exact FL of the yaw loop,
  δ = (ν + H_N(r) − b_r)/c, ν = −k_p e − k_d (r − ψ̇_d,r), e = wrap(ψ_r − ψ_d,r),
  k_p = 1 /min², k_d = 2 /min. With ``integral_gain`` κ > 0 the LOS is **integral LOS**
  (Børhaug, Pavlov & Pettersen 2008; Fossen 2021 §12.4), which removes the steady cross-track
  offset of an *unknown* current and yaw bias; ``rate_from_positions`` takes ẏ_r from successive
  GPS positions instead of the known current.

With r₂ ≠ 0 the laws use ∂v/∂r = r₁ + 3r₂r² where note 000-0.5 (r₂ = 0) has r₁; for the Mariner
(r₂ = 0) they are the formulas of note 000-0.5 term by term.

**Known disturbances.** b_r (added to ṙ) and the cross current d_y are known to the controller
(A13; ``b_r`` [rad/s²], ``d_y`` [m/s] constructor arguments, default 0). The "measured" ẏ_r is the
cross-track component of the ground velocity, u sin ψ_r + v cos ψ_r + d_y, formed from the state
and the known current — what a GPS course-over-ground measurement gives. ``current_frame``:
``"path"`` (default, A10) takes d_y along Y_r of the active leg; ``"global"`` along global y
(east), whose cross-track component on a leg of angle ψ_r0 is d_y cos ψ_r0.

**Parameters.** ``params`` is any object with the plant's SI coefficients ``a`` [1/s], ``b`` [s],
``c`` [1/s²], ``r1`` [m/rad] and optionally ``r2`` [m·s²/rad³] (default 0) — e.g. the Mariner
model's parameters. Every command is clipped to ±``delta_max`` (35°); near the singularity
g = 0 (cos ψ_r = 0) the literal law saturates instead of dividing by zero.
"""

from __future__ import annotations

import math

import numpy as np

from shipgnc.control.base import kernel_step
from shipgnc.control.lqr import (
    DELTA_MAX,
    I_EAST,
    I_NORTH,
    I_PSI,
    I_R,
    I_U,
    PATH_REFERENCE_NAMES,
    R_COURSE,
    R_PSI,
    R_Y,
    check_controller_args,
    nominal_speed,
    path_state,
    plant_coefficient,
    refuse_path,
    restore_path_state,
)
from shipgnc.environment.current import CURRENT_FRAMES
from shipgnc.errors import require
from shipgnc.kernels import Kernel, clip, flat, kernel_function, wrap
from shipgnc.models.base import Signal
from shipgnc.units import MINUTE, NAUTICAL_MILE

#: gains of (23) printed in the document [1/min², 1/min]
K1_PAPER, K2_PAPER = 0.18, 0.7
#: look-ahead distance of ``fl_lookahead`` [m] (0.1 nm)
LOOKAHEAD = 0.1 * NAUTICAL_MILE
#: LOS look-ahead Δ of ``los_fl`` [m] (0.5 nm) and its yaw-loop gains [1/min², 1/min]
LOS_DELTA = 0.5 * NAUTICAL_MILE
KP_PAPER, KD_PAPER = 1.0, 2.0


def zero_dynamics_pole(params, *, lookahead: float = 0.0, U: float | None = None) -> tuple[float, float]:
    """Pole of the zero dynamics of the FL output, −U/(r₁ + l): ``(per_minute, per_second)``.

    For the literal design (l = 0) and the Mariner (r₁ = −69.45 m/rad, U = 7.7167 m/s) this is
    **+U/|r₁| = +6.667 /min = +0.1111 /s**: the design is internally unstable.

    Why. The output y = y_r has relative degree 2 and the state [y_r, ψ_r, r] has dimension 3,
    so one state is left unobserved by the linearised output loop (22)–(24): the zero dynamics.
    Holding y ≡ 0 (hence ẏ ≡ 0) requires, with v = r₁r and no current,

        ẏ_r = u sin ψ_r + r₁ r cos ψ_r = 0   ⇒   r = ψ̇_r = −(u/r₁) tan ψ_r,

    whose linearisation at ψ_r = 0 is ψ̇_r = −(U/r₁) ψ_r. With r₁ < 0 (the pivot point lies
    ahead of the CG, physically right) the pole −U/r₁ is **positive**: while the law drives
    y_r → 0 the heading error grows like e^{+6.67 t/min}. Equivalently, the linearised transfer
    function y_r/δ = c(U + r₁s)/(s²(s + a)) has the right-half-plane zero s = U/|r₁| (the CG
    response is non-minimum-phase because v = r₁r first pushes it the wrong way), and the
    inversion (21) cancels it with an unstable pole. In simulation the heading error runs past
    90° (where g = r₁c cos ψ_r vanishes) and the ship ends in a rudder-saturated limit cycle
    roughly perpendicular to the leg, its cross-track error growing without bound.

    With the output z = y_r + l sin ψ_r (``lookahead`` l [m]) r₁ becomes r₁ + l: the pole
    −U/(r₁ + l) is negative for l > −r₁ (−4 /min for l = 0.1 nm). ``U`` [m/s] defaults to
    ``params.U`` or S/f. Raises :class:`~shipgnc.errors.ConfigError` at l = −r₁ (relative degree 3,
    no zero dynamics).
    """
    r1 = plant_coefficient(params, "r1")
    speed = nominal_speed(params) if U is None else float(U)
    arm = r1 + float(lookahead)
    require(arm != 0, "controller.lookahead", lookahead,
            "l = -r1 (the pivot point) leaves no zero dynamics (relative degree 3)")
    per_s = -speed / arm
    return per_s * MINUTE, per_s


class _PathFL:
    """Shared plumbing: plant coefficients, known disturbances, the path references, clipping,
    logging."""

    continuous = False
    reference_names = PATH_REFERENCE_NAMES

    def __init__(self, params, *, Ts: float, delta_max: float, b_r: float, d_y: float,
                 current_frame: str):
        check_controller_args(Ts, delta_max)
        for name, value in (("b_r", b_r), ("d_y", d_y)):
            require(isinstance(value, (int, float, np.floating)) and np.isfinite(value),
                    f"controller.{name}", value, "must be a finite number")
        require(current_frame in CURRENT_FRAMES, "controller.current_frame", current_frame,
                f"allowed: {', '.join(CURRENT_FRAMES)}")
        self.a, self.b, self.c = (plant_coefficient(params, k) for k in ("a", "b", "c"))
        self.r1 = plant_coefficient(params, "r1")
        self.r2 = float(getattr(params, "r2", 0.0) or 0.0)
        require(self.c != 0, "controller.params.c", self.c, "the rudder must act on the yaw rate")
        self.params = params
        self.Ts = float(Ts)
        self.delta_max = float(delta_max)
        self.b_r, self.d_y = float(b_r), float(d_y)
        self.current_frame = current_frame
        self._logged: dict[str, np.ndarray] = {}

    def reset(self, batch_shape) -> None:
        self._logged = {}

    def signal_values(self) -> dict[str, np.ndarray]:
        return self._logged

    def _kernel(self, function, batch_shape, *specific) -> Kernel:
        """The kernel of a path FL controller: ``p`` = [δ_max, a, b, c, r₁, r₂, b_r, d_y, global
        frame, *specific]; per-ship state of :func:`~shipgnc.control.lqr.path_state`."""
        params = flat(self.delta_max, self.a, self.b, self.c, self.r1, self.r2, self.b_r, self.d_y,
                      float(self.current_frame == "global"), *specific)
        return Kernel(function, params, path_state(self, batch_shape),
                      restore=lambda z: restore_path_state(self, batch_shape, z))

    def step(self, t: float, measurement: np.ndarray, reference: np.ndarray) -> np.ndarray:
        """The law for every ship: the batch of the class's kernel (:meth:`kernel`)."""
        command, self._logged = kernel_step(self, t, measurement, reference, 1)
        return command


class OutputFL(_PathFL):
    """FL of the output z = y_r + l sin ψ_r (``fl_paper``: l = 0; ``fl_lookahead``: l = 0.1 nm).

    ż = u sin ψ_r + (v + l r) cos ψ_r + d_y and, u̇ neglected, z̈ = f + g δ with m = r₁ + l + 3r₂r²::

        f = (u cos ψ_r − (v + l r) sin ψ_r) r + m cos ψ_r (b_r − H_N(r)),   g = m c cos ψ_r
        δ = (ν − f)/g,   ν = −k₁ z − k₂ ż

    (l = 0, r₂ = 0: exactly (20)–(23)). Gains in SI: ``k1`` [1/s²] = 0.18/60², ``k2`` [1/s] = 0.7/60
    by default; ``lookahead`` l [m]. Logged: ``fl_output`` z [m].
    """

    signals = (Signal("fl_output", "m", "linearised output z = y_r + l sin(psi_r)"),)

    def __init__(self, params, path=None, *, Ts: float, lookahead: float = 0.0,
                 k1: float = K1_PAPER / MINUTE**2, k2: float = K2_PAPER / MINUTE,
                 delta_max: float = DELTA_MAX, b_r: float = 0.0, d_y: float = 0.0,
                 current_frame: str = "path"):
        refuse_path(type(self), path)
        super().__init__(params, Ts=Ts, delta_max=delta_max, b_r=b_r, d_y=d_y,
                         current_frame=current_frame)
        require(isinstance(lookahead, (int, float, np.floating)) and np.isfinite(lookahead)
                and lookahead >= 0, "controller.lookahead", lookahead, "must be a finite length >= 0 m")
        require(abs(lookahead + self.r1) > 1e-6 * abs(self.r1) or self.r2 != 0, "controller.lookahead",
                lookahead,
                "l = -r1 (the pivot point) makes g = 0: the output has relative degree 3")
        for name, value in (("k1", k1), ("k2", k2)):
            require(isinstance(value, (int, float, np.floating)) and np.isfinite(value) and value > 0,
                    f"controller.{name}", value, "must be a finite number > 0")
        self.lookahead = float(lookahead)
        self.k1, self.k2 = float(k1), float(k2)

    def kernel(self, batch_shape) -> Kernel:
        """:meth:`step` for the composed loop (:func:`output_fl_step`), after ``reset``."""
        tiny = 1e-12 * abs(self.c) * (abs(self.r1) + self.lookahead + NAUTICAL_MILE)
        return self._kernel(output_fl_step, batch_shape, self.lookahead, self.k1, self.k2, tiny,
                            3.0 * self.r2)


def fl_paper(params, path=None, *, Ts: float, **options) -> OutputFL:
    """``fl_paper``: the literal FL (19)–(23) on y_r, k₁ = 0.18 /min², k₂ = 0.7 /min (unstable)."""
    return OutputFL(params, path, Ts=Ts, lookahead=0.0, **options)


def fl_lookahead(params, path=None, *, Ts: float, lookahead: float = LOOKAHEAD,
                 **options) -> OutputFL:
    """``fl_lookahead``: the same law on y_r + l sin ψ_r, l = 0.1 nm by default (stable for l > −r₁)."""
    return OutputFL(params, path, Ts=Ts, lookahead=lookahead, **options)


class LOSFL(_PathFL):
    """``los_fl``: (integral) LOS guidance feeding an exact FL of the yaw loop (note 000-0.5)::

        ρ = y_r + κ y_int,   ẏ_int = Δ y_r/(ρ² + Δ²)                 (integral LOS, κ ≥ 0)
        ψ_d,r = −atan(ρ/Δ) − asin(d_y/u);  ψ̇_d,r = −Δ (ẏ_r + κ ẏ_int)/(Δ² + ρ²)  (u̇ neglected)
        e = wrap(ψ_r − ψ_d,r);  ν = −k_p e − k_d (r − ψ̇_d,r);  δ = (ν + H_N(r) − b_r)/c.

    κ = 0 with b_r, d_y known is the law of note 000-0.5 (the document's oracle: ``knows_disturbance``).
    Without that knowledge (b_r = d_y = 0 here) plain LOS keeps a standing offset: the heading
    must settle at the crab angle −asin(d_y/U) plus the yaw loop's error b_r/k_p, which
    −atan(y_r/Δ) supplies only with y_r ≠ 0 (0.21 nm for the document's disturbances). The
    integral LOS of Børhaug, Pavlov & Pettersen (2008) (Fossen 2021 §12.4, eq. (12.108)–(12.109))
    builds that heading from κ y_int instead, so y_r → 0 on a straight leg for any constant
    current and yaw bias; the denominator (ρ² + Δ²) slows the integration far from the path
    (wind-up limited). Linearised on a leg, ÿ_r + (U/Δ) ẏ_r + (Uκ/Δ²) y_r = 0 (yaw loop fast):
    κ = U/4 (0.0625 nm/min for the Mariner, the scenarios' default) is critically damped: a
    double pole at −U/(2Δ) = −0.25 /min.
    y_int is a forward-Euler sum (the command at t_k uses y_int(t_k)) and is kept at a leg switch
    (the path-frame current is the same on every leg, as A7 keeps the LQR's e_I).

    ``rate_from_positions``: ẏ_r is the cross-track component of the ground velocity from the
    last two positions, ((n_k − n_{k−1})(−sin π_p) + (e_k − e_{k−1}) cos π_p)/(t_k − t_{k−1})
    (a GPS speed over ground; π_p the active leg's angle), instead of u sin ψ_r + v cos ψ_r + d_y
    from the known current; the first sample uses the latter.

    SI arguments: ``delta_los`` Δ [m] (0.5 nm), ``kp`` [1/s²] = 1/60², ``kd`` [1/s] = 2/60,
    ``integral_gain`` κ [m/s] (0 = plain LOS). Logged: ``los_heading`` ψ_d,r [rad] (relative to
    the leg).
    """

    signals = (Signal("los_heading", "rad", "LOS desired heading relative to the leg psi_d,r",
                      angle=True),)

    def __init__(self, params, path=None, *, Ts: float, delta_los: float = LOS_DELTA,
                 kp: float = KP_PAPER / MINUTE**2, kd: float = KD_PAPER / MINUTE,
                 delta_max: float = DELTA_MAX, b_r: float = 0.0, d_y: float = 0.0,
                 current_frame: str = "path", integral_gain: float = 0.0,
                 rate_from_positions: bool = False):
        refuse_path(LOSFL, path)
        super().__init__(params, Ts=Ts, delta_max=delta_max, b_r=b_r, d_y=d_y,
                         current_frame=current_frame)
        for name, value in (("delta_los", delta_los), ("kp", kp), ("kd", kd)):
            require(isinstance(value, (int, float, np.floating)) and np.isfinite(value) and value > 0,
                    f"controller.{name}", value, "must be a finite number > 0")
        require(isinstance(integral_gain, (int, float, np.floating)) and np.isfinite(integral_gain)
                and integral_gain >= 0, "controller.integral_gain", integral_gain,
                "must be a finite speed >= 0 m/s (0 = plain LOS)")
        self.delta_los, self.kp, self.kd = float(delta_los), float(kp), float(kd)
        self.integral_gain = float(integral_gain)
        self.rate_from_positions = bool(rate_from_positions)
        self.y_int: np.ndarray | None = None
        self._prev: tuple | None = None  # (t, north, east, ẏ_int) of the last sample

    def reset(self, batch_shape) -> None:
        super().reset(batch_shape)
        self.y_int = np.zeros(tuple(batch_shape))
        self._prev = None

    def kernel(self, batch_shape) -> Kernel:
        """:meth:`step` for the composed loop (:func:`los_fl_step`), after ``reset``; per-ship
        state :func:`~shipgnc.control.lqr.path_state` then [y_int, ẏ_int, t, north, east, has
        previous sample]."""
        shape = tuple(batch_shape)
        if self._prev is None:
            own = [self.y_int, 0.0, 0.0, 0.0, 0.0, 0.0]
        else:
            t0, n0, e0, rate0 = self._prev
            own = [self.y_int, rate0, t0, n0, e0, 1.0]
        own = np.stack([np.broadcast_to(np.asarray(v, dtype=float), shape) for v in own], axis=-1)
        z = np.concatenate([path_state(self, shape), own], axis=-1)
        params = flat(self.delta_max, self.a, self.b, self.c, self.r1, self.r2, self.b_r, self.d_y,
                      float(self.current_frame == "global"), self.delta_los, self.kp, self.kd,
                      self.delta_los**2, self.integral_gain, float(self.rate_from_positions))

        def restore(zf: np.ndarray) -> None:
            zf = zf.reshape(*shape, zf.shape[-1])
            restore_path_state(self, shape, zf[..., :_LOS_OWN])
            self.y_int = zf[..., _LOS_OWN].copy()
            if np.all(zf[..., _LOS_OWN + 5] > 0):
                self._prev = (float(zf.reshape(-1, zf.shape[-1])[0, _LOS_OWN + 2]),
                              zf[..., _LOS_OWN + 3].copy(), zf[..., _LOS_OWN + 4].copy(),
                              zf[..., _LOS_OWN + 1].copy())

        return Kernel(los_fl_step, params, z, restore=restore)


# ----------------------------------------------------------------------------------------------
# kernels (shipgnc.kernels): one ship's step, the one source of each law
# ----------------------------------------------------------------------------------------------

#: where :func:`los_fl_step` finds its own per-ship state (after :func:`path_state`'s 2 numbers)
_LOS_OWN = 2


@kernel_function
def path_kinematics(x, ref, p):
    """Path-frame quantities of the active leg for one ship: ``(y_r, ψ_r, π_p, u, r, v, ẏ_r, d_cross, sin ψ_r,
    cos ψ_r)`` from the path references (by name) and the state, with v = r₁ r + r₂ r³ and the
    "measured" ẏ_r = u sin ψ_r + v cos ψ_r + d_cross (d_cross = d_y, or d_y cos π_p in the
    global frame)."""
    r1, r2, d_y, frame_global = p[4], p[5], p[7], p[8]
    y_r, psi_r, course = ref[R_Y], ref[R_PSI], ref[R_COURSE]
    u, r = x[I_U], x[I_R]
    v = r1 * r + r2 * r * r * r
    d_cross = d_y * math.cos(course) if frame_global != 0.0 else d_y
    s, c = math.sin(psi_r), math.cos(psi_r)
    y_dot = u * s + v * c + d_cross
    return y_r, psi_r, course, u, r, v, y_dot, d_cross, s, c


@kernel_function
def _log_path(z, sig, extra):
    """The logged signal ``extra``, also kept in ``z`` for ``signal_values``."""
    sig[0] = extra
    z[0], z[1] = extra, 1.0


@kernel_function
def output_fl_step(t, x, ref, z, p, cmd, sig):
    """The output FL of :class:`OutputFL` for one ship (document 000, (19)–(23) with
    r₁ → m = r₁ + l + 3r₂r²; u̇ neglected)::

        z = y_r + l sin ψ_r,   ż = ẏ_r + l r cos ψ_r,   H_N(r) = a r + b r³   (eq. (16))
        f = (u cos ψ_r − (v + l r) sin ψ_r) r + m cos ψ_r (b_r − H_N(r)),   g = m c cos ψ_r
        δ = clip((ν − f)/g, ±δ_max),   ν = −k₁ z − k₂ ż

    with |g| kept ≥ tiny (g = 0 only at ψ_r = ±90°, or r on the pivot point: saturate there
    instead of dividing). ``p`` = [common 9, l, k₁, k₂, tiny, 3r₂]."""
    delta_max, a, b, c_rudder, r1, b_r = p[0], p[1], p[2], p[3], p[4], p[6]
    l, k1, k2, tiny, r2_3 = p[9], p[10], p[11], p[12], p[13]
    y_r, _, _, u, r, v, y_dot, _, s, c = path_kinematics(x, ref, p)
    lateral = v + l * r
    out = y_r + l * s
    out_dot = y_dot + l * r * c
    m = r1 + l + r2_3 * (r * r)
    f = (u * c - lateral * s) * r + m * c * (b_r - (a * r + b * r * r * r))
    g = m * c_rudder * c
    nu = -k1 * out - k2 * out_dot
    if abs(g) < tiny:  # the g_safe guard of OutputFL.step (NaN passes through)
        g = -tiny if g < 0.0 else tiny
    _log_path(z, sig, out)
    cmd[0] = clip((nu - f) / g, -delta_max, delta_max)


@kernel_function
def los_fl_step(t, x, ref, z, p, cmd, sig):
    """The (integral) LOS + yaw-loop FL of :class:`LOSFL` for one ship (note 000-0.5; Fossen
    2021 §12.4, eq. (12.108)–(12.109)): y_int += h ẏ_int (forward Euler), ρ = y_r + κ y_int,
    ẏ_int = Δ y_r/(Δ² + ρ²), ψ_d,r = −atan(ρ/Δ) − asin(clip(d_cross/max(u, 1e-6))),
    ψ̇_d,r = −Δ (ẏ_r + κ ẏ_int)/(Δ² + ρ²) (ẏ_r from the last two positions when asked),
    e = wrap(ψ_r − ψ_d,r), ν = −k_p e − k_d (r − ψ̇_d,r), δ = clip((ν + H_N(r) − b_r)/c)
    (note 000-0.5). ``p`` = [common 9, Δ, k_p, k_d, Δ², κ, rate from positions];
    ``z`` = [path_state 2, y_int, ẏ_int, t, north, east, has previous]."""
    delta_max, a, b, c_rudder, b_r = p[0], p[1], p[2], p[3], p[6]
    D, kp, kd, D2, kappa, from_positions = p[9], p[10], p[11], p[12], p[13], p[14]
    y_r, psi_r, course, u, r, _, y_dot, d_cross, _, _ = path_kinematics(x, ref, p)
    o = _LOS_OWN
    if z[o + 5] != 0.0:
        h = t - z[o + 2]
        z[o] = z[o] + h * z[o + 1]
        if from_positions != 0.0:
            y_dot = ((x[I_NORTH] - z[o + 3]) * -math.sin(course)
                     + (x[I_EAST] - z[o + 4]) * math.cos(course)) / h
    rho = y_r + kappa * z[o]
    den = D2 + rho * rho
    rate = D * y_r / den
    u_safe = u if (u > 1e-6 or u != u) else 1e-6  # np.maximum(u, 1e-6), NaN kept
    crab = math.asin(clip(d_cross / u_safe, -1.0, 1.0))
    psi_d = -math.atan(rho / D) - crab
    psi_d_dot = -D * (y_dot + kappa * rate) / den
    z[o + 1], z[o + 2], z[o + 3], z[o + 4], z[o + 5] = rate, t, x[I_NORTH], x[I_EAST], 1.0
    e = wrap(psi_r - psi_d)
    nu = -kp * e - kd * (r - psi_d_dot)
    raw = (nu + (a * r + b * r * r * r) - b_r) / c_rudder
    _log_path(z, sig, psi_d)
    cmd[0] = clip(raw, -delta_max, delta_max)


class HeadingFL:
    """Heading autopilot for the Mariner: the exact feedback linearisation of the yaw loop of
    ``los_fl`` (note 000-0.5) on a heading reference [ψ_d, r_d] from guidance::

        e = wrap(ψ − ψ_d),  ν = −k_p e − k_d (r − r_d),  δ = (ν + H_N(r) − b_r)/c

    SI gains ``kp`` [1/s²] = 1/60², ``kd`` [1/s] = 2/60 by default (the ``los_fl`` loop); ``b_r``
    known [rad/s²]. Used to sail an optimal route's heading programme (note 002-2.9.6).
    """

    continuous = False
    reference_names = ("psi_d", "r_d")
    signals = ()

    def __init__(self, params, *, Ts: float, kp: float = KP_PAPER / MINUTE**2,
                 kd: float = KD_PAPER / MINUTE, delta_max: float = DELTA_MAX, b_r: float = 0.0):
        check_controller_args(Ts, delta_max)
        for name, value in (("kp", kp), ("kd", kd), ("b_r", b_r)):
            require(isinstance(value, (int, float, np.floating)) and np.isfinite(value)
                    and (value > 0 or name == "b_r"), f"controller.{name}", value,
                    "must be a finite number" + (" > 0" if name != "b_r" else ""))
        self.a, self.b, self.c = (plant_coefficient(params, k) for k in ("a", "b", "c"))
        self.Ts, self.kp, self.kd = float(Ts), float(kp), float(kd)
        self.delta_max, self.b_r = float(delta_max), float(b_r)

    def reset(self, batch_shape) -> None:
        pass

    def signal_values(self) -> dict[str, np.ndarray]:
        return {}

    def step(self, t: float, measurement: np.ndarray, reference: np.ndarray) -> np.ndarray:
        """The law for every ship: the batch of :func:`heading_fl_step`."""
        command, _ = kernel_step(self, t, measurement, reference, 1)
        return command

    def kernel(self, batch_shape) -> Kernel:
        """:meth:`step` for the composed loop (:func:`heading_fl_step`); no per-ship state."""
        return Kernel(heading_fl_step, flat(self.delta_max, self.a, self.b, self.c, self.kp, self.kd,
                                            self.b_r))


@kernel_function
def heading_fl_step(t, x, ref, z, p, cmd, sig):
    """The heading FL of :class:`HeadingFL` for one ship (note 000-0.5): e = wrap(ψ − ψ_d),
    ν = −k_p e − k_d (r − r_d), δ = clip((ν + a r + b r³ − b_r)/c).
    ``p`` = [δ_max, a, b, c, k_p, k_d, b_r]."""
    delta_max, a, b, c_rudder, kp, kd, b_r = p[0], p[1], p[2], p[3], p[4], p[5], p[6]
    psi, r = x[I_PSI], x[I_R]
    e = wrap(psi - ref[0])
    nu = -kp * e - kd * (r - ref[1])
    raw = (nu + a * r + b * r * r * r - b_r) / c_rudder
    cmd[0] = clip(raw, -delta_max, delta_max)
