"""LQR trajectory tracking of document 000 (Mariner, de Wit–Oppe plant), notes 000-0.4, 000-A6–000-A8,
000-A12.

Design model, eq. (7)–(9): the path-frame kinematics ẏ_r = Uψ_r (sway neglected) with the
linear yaw equation ṙ = −a r + c δ and the integral e_I = ∫ y_r dt::

    x = [y_r, ψ_r, r, e_I],   A = [[0, U, 0, 0],     B = [0, 0, c, 0]ᵀ
                                   [0, 0, 1, 0],
                                   [0, 0, −a, 0],
                                   [1, 0, 0, 0]],

criterion (10) J = ∫(ρ_y y_r² + ρ_ψ ψ_r² + ρ_e e_I² + R δ²) dt with Q = diag[0.1, 4, 0, 0.1],
control law (13) δ = −K x, K = [k_y, k_ψ, k_r, k_e] > 0 (negative feedback, A8).

**Units.** The document designs in minutes, nautical miles and radians, and the same Q, R give
different gains in other units (note 000-0.4 table), so :func:`design_lqr` designs in paper units
and :func:`gain_to_si` converts K at the controller's boundary (:data:`PAPER_STATE_UNITS`).
The printed gain :data:`PAPER_LQR_GAIN` = [3.4, 3.2, 1, 0.45] is reproduced with **R = 0.5**
(A12), not with the stated R = 1, which gives [2.4455, 2.3244, 0.8788, 0.3162]
(k_e = √(ρ_e/R) in every unit system).

**Controller.** :class:`PathLQR` reads the path-frame errors y_r, ψ_r of the active leg as
references (``reference_names``: ``cross_track_error``, ``heading_error``, ``path_course``, each
found by name) from :class:`~shipgnc.guidance.path.PathGuidance`, which holds the
:class:`~shipgnc.paths.WaypointPath` and switches the legs (A6: leg i+1 becomes active once the
along-track distance x_r on leg i reaches its length; the last leg is a half-line). The law keeps
only its integrator e_I, which is not reset at a switch (A7).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from shipgnc.control.base import kernel_step
from shipgnc.errors import ConfigError, require
from shipgnc.guidance.path import PATH_REFERENCES
from shipgnc.kernels import Kernel, clip, flat, kernel_function, sign
from shipgnc.models.base import Signal, state_index
from shipgnc.models.mariner import MarinerWitOppe, tracking_model  # the design model (8)/(9)
from shipgnc.units import MINUTE, NAUTICAL_MILE, deg

#: K = [k_y, k_ψ, k_r, k_e] printed in the document (min / nm / rad, state order [y_r, ψ_r, r, e_I])
PAPER_LQR_GAIN = (3.4, 3.2, 1.0, 0.45)
#: diagonal of Q as stated, [ρ_y, ρ_ψ, 0, ρ_e] (paper units)
PAPER_Q = (0.1, 4.0, 0.0, 0.1)
#: R as stated (the gain it gives is *not* the printed one, A12)
PAPER_R = 1.0
#: R that reproduces the printed gain within its rounding (A12; ≡ 2Q with R = 1)
REPRODUCING_R = 0.5
#: one paper unit of each LQR state in SI: 1 nm, 1 rad, 1 rad/min, 1 nm·min
PAPER_STATE_UNITS = np.array([NAUTICAL_MILE, 1.0, 1.0 / MINUTE, NAUTICAL_MILE * MINUTE])
#: rudder limit of the Mariner (35°) [rad]
DELTA_MAX = deg(35.0)

#: indices of the Mariner's states north, east, psi, u, r (document 000 eq. (25)), found by name
#: in the model's state list (constants of the compiled laws)
I_NORTH, I_EAST, I_PSI, I_U, I_R = (state_index(MarinerWitOppe, name)
                                    for name in ("north", "east", "psi", "u", "r"))


def gain_to_si(K_paper) -> np.ndarray:
    """K in min / nm / rad → K in s / m / rad: [rad/m, rad/rad, s, rad/(m·s)].

    δ = −K_p x_p with x_p = x_SI / :data:`PAPER_STATE_UNITS`, so K_SI = K_p / PAPER_STATE_UNITS
    (e.g. [3.4172, 3.2080, 1.0729, 0.4472] → [1.8451e-3, 3.2080, 64.37, 4.024e-6]).
    """
    return _gain_vector(K_paper, "K_paper") / PAPER_STATE_UNITS


def gain_to_paper(K_si) -> np.ndarray:
    """K in s / m / rad → K in min / nm / rad (inverse of :func:`gain_to_si`)."""
    return _gain_vector(K_si, "K_si") * PAPER_STATE_UNITS


def _gain_vector(K, field: str) -> np.ndarray:
    K = np.asarray(K, dtype=float).reshape(-1)
    require(K.shape == (4,) and bool(np.all(np.isfinite(K))), f"controller.{field}", K.tolist(),
            "need four finite gains [k_y, k_psi, k_r, k_e]")
    return K


def lqr_tracking_gain(a: float, c: float, U: float, Q=PAPER_Q, R: float = PAPER_R
                      ) -> tuple[np.ndarray, np.ndarray]:
    """LQR gain K (4,) and closed-loop poles eig(A − BK) (4,) of the design model (8)/(9).

    The stabilising solution X of the continuous algebraic Riccati equation
    AᵀX + XA − XBR⁻¹BᵀX + Q = 0 (:func:`scipy.linalg.solve_continuous_are`), K = R⁻¹BᵀX and
    eig(A − BK): the arithmetic of ``control.lqr`` (python-control without slycot; tested to the
    bit) without its 1.4 s import, on A, B of :func:`tracking_model`; ``Q`` is the diagonal
    (4 numbers) or a 4 × 4 matrix, ``R`` > 0 a number. Units are those of a, c, U (and Q, R):
    with the paper's a = 1.084 /min, c = 3.553 /min², U = 0.25 nm/min, Q = diag[0.1, 4, 0, 0.1]:
    R = 1 → K = [2.4455, 2.3244, 0.8788, 0.3162], poles −1.961±1.805j, −0.142±0.139j /min;
    R = 0.5 → K = [3.4172, 3.2080, 1.0729, 0.4472], poles −2.306±2.175j, −0.142±0.139j /min.
    """
    A, B = tracking_model(a, c, U)
    Q = np.asarray(Q, dtype=float)
    if Q.ndim == 1:
        require(Q.shape == (4,), "controller.Q", Q.tolist(), "need 4 diagonal weights or a 4x4 matrix")
        Q = np.diag(Q)
    require(Q.shape == (4, 4) and bool(np.all(np.isfinite(Q))), "controller.Q", Q.tolist(),
            "need 4 diagonal weights or a 4x4 matrix")
    require(bool(np.allclose(Q, Q.T)) and float(np.linalg.eigvalsh(Q).min()) >= -1e-12,
            "controller.Q", Q.tolist(), "must be symmetric positive semi-definite")
    require(isinstance(R, (int, float, np.floating)) and np.isfinite(R) and R > 0, "controller.R", R,
            "must be a finite number > 0")
    from scipy.linalg import solve_continuous_are

    Rm = np.array([[float(R)]])
    try:
        with np.errstate(all="ignore"), warnings.catch_warnings():
            warnings.simplefilter("ignore")
            X = solve_continuous_are(A, B, Q, Rm)
            K = np.linalg.solve(Rm, B.T @ X)
            poles = np.linalg.eig(A - B @ K)[0]
    except (ValueError, np.linalg.LinAlgError, ArithmeticError) as exc:
        raise ConfigError(f"controller.Q = {np.diag(Q).tolist()}, R = {R}: the Riccati equation has no "
                          f"stabilising solution for a = {a:g}, c = {c:g}, U = {U:g} ({exc})") from None
    poles = np.asarray(poles, dtype=complex).reshape(4)
    if not (np.all(np.isfinite(poles)) and poles.real.max() < 0):
        raise ConfigError(f"controller.Q = {np.diag(Q).tolist()}: the design leaves closed-loop poles "
                          f"{np.round(poles, 6).tolist()} on or right of the imaginary axis; weight "
                          "y_r and e_I (Q[0] > 0, Q[3] > 0)")
    return np.asarray(K, dtype=float).reshape(4), poles


@dataclass(frozen=True, eq=False)
class LQRDesign:
    """An LQR design in paper units and its SI gain.

    ``K_paper`` (min / nm / rad), ``K_si`` (s / m / rad), ``poles_per_min`` of A − BK [1/min],
    and the design inputs a [1/min], c [1/min²], U [nm/min], Q, R.
    """

    K_paper: np.ndarray
    K_si: np.ndarray
    poles_per_min: np.ndarray
    a: float
    c: float
    U: float
    Q: np.ndarray
    R: float

    @property
    def poles_per_s(self) -> np.ndarray:
        return self.poles_per_min / MINUTE


def design_lqr(params, *, Q=PAPER_Q, R: float = PAPER_R, U: float | None = None) -> LQRDesign:
    """The document's LQR (``lqr``: R = 1 as stated; R = 0.5 reproduces the print), in paper units.

    ``params`` holds the plant's SI coefficients ``a`` [1/s] and ``c`` [1/s²] (and, unless ``U``
    [m/s] is given, ``U`` or ``S`` [m/s²] and ``f`` [1/s] with U = S/f); they are converted to
    /min, /min², nm/min for the design (note 000-0.4: the gain is in min / nm / rad).
    """
    a_si, c_si = plant_coefficient(params, "a"), plant_coefficient(params, "c")
    U_si = nominal_speed(params) if U is None else float(U)
    require(np.isfinite(U_si) and U_si > 0, "controller.U", U_si, "must be a speed > 0 m/s")
    a, c, U_p = a_si * MINUTE, c_si * MINUTE**2, U_si * MINUTE / NAUTICAL_MILE
    K, poles = lqr_tracking_gain(a, c, U_p, Q, R)
    Qm = np.diag(np.asarray(Q, dtype=float)) if np.ndim(Q) == 1 else np.asarray(Q, dtype=float)
    return LQRDesign(K_paper=K, K_si=gain_to_si(K), poles_per_min=poles, a=a, c=c, U=U_p, Q=Qm,
                     R=float(R))


def nominal_speed(params) -> float:
    """U [m/s]: ``params.U`` if present, else the straight-running equilibrium S/f of eq. (25)."""
    if getattr(params, "U", None) is not None:
        return float(params.U)
    return plant_coefficient(params, "S") / plant_coefficient(params, "f")


def plant_coefficient(params, name: str) -> float:
    value = getattr(params, name, None)
    require(value is not None, f"controller.params.{name}", type(params).__name__,
            f"the design needs the plant coefficient '{name}' (SI)")
    value = float(value)
    require(np.isfinite(value), f"controller.params.{name}", value, "must be finite")
    return value


def check_controller_args(Ts: float, delta_max: float) -> None:
    for name, value in (("Ts", Ts), ("delta_max", delta_max)):
        require(isinstance(value, (int, float, np.floating)) and np.isfinite(value) and value > 0,
                f"controller.{name}", value, "must be a finite number > 0")


#: the references a path law reads (:class:`~shipgnc.guidance.path.PathGuidance`'s, by name)
PATH_REFERENCE_NAMES = tuple(s.name for s in PATH_REFERENCES)
#: where each of them is in the reference vector
R_Y, R_PSI, R_COURSE = (PATH_REFERENCE_NAMES.index(name)
                        for name in ("cross_track_error", "heading_error", "path_course"))


def refuse_path(cls: type, path) -> None:
    """A clear error for the former call form ``Law(..., path, ...)``: the path is guidance now."""
    if path is not None:
        raise ConfigError(f"{cls.__name__}: the path is no longer the controller's; give it as "
                          f"guidance=PathGuidance(path) (shipgnc.guidance.path) and leave it out here")


class PathLQR:
    """LQR path tracking, law (13) δ = −K_SI [y_r, ψ_r, r, e_I] on the Mariner state.

    ``K_si``: [k_y, k_ψ, k_r, k_e] in s / m / rad (:func:`gain_to_si` of a paper-unit gain, or
    ``design_lqr(...).K_si``). Measurement: the Mariner state ``[north, east, psi, u, r]`` (SI);
    references: y_r and ψ_r of the active leg (``cross_track_error``, ``heading_error``:
    :class:`~shipgnc.guidance.path.PathGuidance`, which also switches the legs, A6); command
    ``[delta]`` [rad], clipped to ±``delta_max`` (the actuator's limit; the rate limit stays the
    actuator's).

    The integrator e_I = ∫ y_r dt is a forward-Euler sum over the samples (the command at t_k
    uses e_I(t_k), then e_I += Ts·y_r(t_k)); it starts at 0 and is **not** reset at a leg switch
    (A7). The document's law has no anti-windup, and neither has this controller by default;
    ``anti_windup=True`` adds conditional integration: e_I holds while the
    unclipped law is beyond ±δ_max *and* integrating would push it further out (sign(k_e y_r) =
    sign(K x)), so it only winds back. Document 000 is silent on anti-windup, and the indicative
    note 000-0.8 figures for ``lqr``/``lqr_paper`` (settling 25.9 min, overshoot 0.63 nm) are those of
    ``anti_windup=False``; with it the 1.5 nm capture of note 000-0.6 settles in 25.46 min with a
    0.486 nm overshoot (25.93 min, 0.635 nm without), and the steady state (e_I absorbs b_r,
    d_y) is the same. Logged: ``integral_error`` (e_I, before the update).
    """

    continuous = False
    reference_names = PATH_REFERENCE_NAMES
    signals = (Signal("integral_error", "m s", "integral of the cross-track error e_I"),)

    def __init__(self, K_si, path=None, *, Ts: float, delta_max: float = DELTA_MAX,
                 anti_windup: bool = False):
        refuse_path(PathLQR, path)
        check_controller_args(Ts, delta_max)
        self.K = _gain_vector(K_si, "K_si")
        self.Ts = float(Ts)
        self.delta_max = float(delta_max)
        self.anti_windup = bool(anti_windup)
        self.e_I: np.ndarray | None = None
        self._logged: dict[str, np.ndarray] = {}

    @property
    def K_paper(self) -> np.ndarray:
        """The gain in min / nm / rad (for the ``lqr_gain`` metric)."""
        return gain_to_paper(self.K)

    def reset(self, batch_shape) -> None:
        self.e_I = np.zeros(tuple(batch_shape))
        self._logged = {}

    def step(self, t: float, measurement: np.ndarray, reference: np.ndarray) -> np.ndarray:
        """Law (13) for every ship: the batch of :func:`path_lqr_step`."""
        command, self._logged = kernel_step(self, t, measurement, reference, 1)
        return command

    def signal_values(self) -> dict[str, np.ndarray]:
        return self._logged

    def kernel(self, batch_shape) -> Kernel:
        """:meth:`step` for the composed loop (:func:`path_lqr_step`), after ``reset``; per-ship
        state ``[e_I, logged e_I, logged]`` (see :func:`path_state`)."""
        params = flat(self.K, self.delta_max, self.Ts, float(self.anti_windup))
        state = path_state(self, batch_shape, self.e_I)
        shape = tuple(batch_shape)

        def restore(z: np.ndarray) -> None:
            self.e_I = restore_path_state(self, shape, z, n_own=1)[..., 0].copy()

        return Kernel(path_lqr_step, params, state, restore=restore)


def path_state(ctrl, batch_shape, *own) -> np.ndarray:
    """Initial per-ship state of a path law's kernel: ``[*own, signals, logged]`` (its own
    numbers, e.g. PathLQR's e_I, the last logged signal values and a flag: 1 once ``step`` has
    run, as ``signal_values()`` is empty before)."""
    shape = tuple(batch_shape)
    logged = ctrl.signal_values()
    parts = [*own, *(logged.get(s.name, np.zeros(shape)) for s in ctrl.signals),
             np.full(shape, float(bool(logged)))]
    return np.stack([np.broadcast_to(np.asarray(v, dtype=float), shape) for v in parts], axis=-1)


def restore_path_state(ctrl, batch_shape, z: np.ndarray, *, n_own: int = 0) -> np.ndarray:
    """Leave a path law's logged signal values as its numpy ``step`` would, from the final
    per-ship state of :func:`path_state` (its ``n_own`` own numbers first); returns that state
    shaped ``(*batch_shape, n_z)``."""
    z = z.reshape(*tuple(batch_shape), z.shape[-1])
    n_sig = len(ctrl.signals)
    if np.all(z[..., n_own + n_sig] > 0):
        ctrl._logged = {s.name: z[..., n_own + j].copy() for j, s in enumerate(ctrl.signals)}
    return z


@kernel_function
def path_lqr_step(t, x, ref, z, p, cmd, sig):
    """Law (13) of document 000 for one ship: δ = clip(−K·[y_r, ψ_r, r, e_I], ±δ_max) (the sum
    left to right), then the forward-Euler integral e_I += Ts·y_r, held by the anti-windup (if
    on) while the unclipped law is beyond ±δ_max and sign(−k_e y_r) = sign(raw).
    ``p`` = [K (4), δ_max, Ts, anti-windup];
    ``ref`` = the path references (y_r, ψ_r by name); ``z`` = [e_I, e_I logged, logged]."""
    k_y, k_psi, k_r, k_e = p[0], p[1], p[2], p[3]
    delta_max, Ts, anti_windup = p[4], p[5], p[6]
    y_r, psi_r = ref[R_Y], ref[R_PSI]
    e_I = z[0]
    raw = -(y_r * k_y + psi_r * k_psi + x[I_R] * k_r + e_I * k_e)
    delta = clip(raw, -delta_max, delta_max)
    integrate = True
    if anti_windup != 0.0:  # hold e_I when integrating would deepen the saturation
        deepens = sign(-k_e * y_r) == sign(raw)
        integrate = abs(raw) <= delta_max or not deepens
    if integrate:
        z[0] = e_I + Ts * y_r
    sig[0] = e_I
    z[1], z[2] = e_I, 1.0
    cmd[0] = delta
