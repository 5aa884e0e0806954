"""Course autopilots of document 003 for CyberShip II: PD (3) and sliding mode (9)–(15).

Controllers (names of note 003-3.8, built by :func:`course_controller`):

* ``pd`` — :class:`CoursePD`, eq. (3): δ_z = K_P wrap(ψ − ψ_d) + K_D r, K_P = 2, K_D = 50, on ψ_d
  directly (no reference model). The sign is right because b₂ < 0 (δ > 0 turns the bow to port).
* ``smc_consistent`` (alias ``fossen``) — :class:`SlidingModeCourse`, the Healey–Lienard / Fossen
  (1994) form of law (14) (notes 003-3.2, 003-B4)::

      δ_z = N ψ_z − Kᵀx + (hᵀB_h)⁻¹ [hᵀẋ_hz − η_h tanh(σ_h/φ_h)],   σ_h = hᵀ(x − x_z)

  with x = [ψ, r], x_z = [ψ_z, r_z], ẋ_hz = [r_z, ṙ_z] from the reference model (15).
* ``smc_printed`` (alias ``printed``) — the law as printed: no (hᵀB_h)⁻¹ and
  σ_h = h₁(ψ_z − ψ) + h₂(r_z − r) (eq. (9)); it is stable only because hᵀB_h < 0 (h₂ > 0, b₂ < 0).
* ``smc_tuned`` — :func:`smc_tuned`: the consistent law on the printed design model (18) with
  gains retuned for the nonlinear plant (a work-around: the surface is slowed because b₂ is 23 ×
  too small);
* ``smc_identified`` — :func:`smc_identified`: the consistent law designed with the document's
  rules on a first-order Nomoto model **identified from the plant** (a 20°/20° zig-zag fitted by
  least squares, :mod:`shipgnc.analysis.identification`).

Both printed-gain SMCs use λ₁ = −0.0005, λ₂ = −7.8128, η_h = 10, φ_h = 0.3 on the design model
(18) as printed (a₂₂ = 0.1057, b₂ = −0.0040), :func:`design_smc` doing the pole placement (10),
the eigenvector h and the reference gain N (12)–(13). The reference model (15),
ψ̈_z + 2ζω_n ψ̇_z + ω_n² ψ_z = ω_n² ψ_d (ω_n = 0.1, ζ = 0.85), is
:class:`~shipgnc.guidance.reference.HeadingReferenceModel`, started at ψ_z = ψ(0), r_z = 0.

Every controller reads the reference ``psi_d`` and the CyberShip II state
``[north, east, psi, u, v, r]`` and commands ``[n, delta_z]`` with the propellers held at
``propeller_rps`` (8.13 rps). Saturation and the rudder rate limit are the steering machine's
(:func:`shipgnc.models.cybership2.steering_machine`), not the controller's.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import control
import numpy as np

from shipgnc.errors import ConfigError, require
from shipgnc.frames import wrap_angle
from shipgnc.guidance.reference import HeadingReferenceModel
from shipgnc.kernels import Kernel, flat, kernel_function, wrap
from shipgnc.models.base import Signal
from shipgnc.models.cybership2 import CRUISE_RPS

#: eigenvalues of the document (§3 of seed 003) [1/s]
PAPER_LAMBDAS = (-0.0005, -7.8128)
SMC_FORMS = ("consistent", "printed")
CONTROLLER_NAMES = ("pd", "smc_printed", "smc_consistent", "smc_tuned", "smc_identified")
ALIASES = {"fossen": "smc_consistent", "printed": "smc_printed"}


def _check_positive(name: str, value: float) -> None:
    require(isinstance(value, (int, float, np.floating)) and np.isfinite(value) and value > 0,
            f"controller.{name}", value, "must be a finite number > 0")


class _CourseController:
    """Shared plumbing: sample time, references, held propeller speed, command stacking."""

    continuous = False
    reference_names = ("psi_d",)
    signals: tuple[Signal, ...] = ()

    def __init__(self, Ts: float, propeller_rps: float):
        _check_positive("Ts", Ts)
        require(np.isfinite(propeller_rps) and propeller_rps >= 0, "controller.propeller_rps",
                propeller_rps, "must be a finite number >= 0 rps")
        self.Ts = float(Ts)
        self.propeller_rps = float(propeller_rps)
        self._logged: dict[str, np.ndarray] = {}

    def _command(self, delta_z: np.ndarray) -> np.ndarray:
        return np.stack([np.full_like(delta_z, self.propeller_rps), delta_z], axis=-1)

    def signal_values(self) -> dict[str, np.ndarray]:
        return self._logged


class CoursePD(_CourseController):
    """PD course autopilot, eq. (3): δ_z = K_P wrap(ψ − ψ_d) + K_D r (K_P = 2, K_D = 50).

    On the design model (18) the closed-loop poles are −0.04715 ± 0.07601j (note 003-3.4).
    """

    def __init__(self, Kp: float = 2.0, Kd: float = 50.0, *, Ts: float = 0.1,
                 propeller_rps: float = CRUISE_RPS):
        super().__init__(Ts, propeller_rps)
        for name, value in (("Kp", Kp), ("Kd", Kd)):
            require(np.isfinite(value) and value >= 0, f"controller.{name}", value,
                    "must be a finite number >= 0")
        self.Kp, self.Kd = float(Kp), float(Kd)

    def reset(self, batch_shape) -> None:
        self._logged = {}

    def step(self, t: float, measurement: np.ndarray, reference: np.ndarray) -> np.ndarray:
        psi, r = measurement[..., 2], measurement[..., 5]
        delta_z = self.Kp * wrap_angle(psi - reference[..., 0]) + self.Kd * r
        return self._command(np.asarray(delta_z, dtype=float))

    def kernel(self, batch_shape) -> Kernel:
        """:meth:`step` for the composed loop (:func:`course_pd_step`); no per-ship state."""
        return Kernel(course_pd_step, flat(self.Kp, self.Kd, self.propeller_rps))


@kernel_function
def course_pd_step(t, x, ref, z, p, cmd, sig):
    """Eq. (3) for one ship, as :meth:`CoursePD.step`: δ_z = K_P wrap(ψ − ψ_d) + K_D r,
    n = the held propeller speed; ``p`` = [K_P, K_D, n]."""
    cmd[0] = p[2]
    cmd[1] = p[0] * wrap(x[2] - ref[0]) + p[1] * x[5]


@dataclass(frozen=True, eq=False)
class SMCDesign:
    """Pole placement for the design model ẋ_h = A_h x_h + B_h δ, ψ = C_h x_h (eq. (5)–(13)).

    ``K`` = [k₁, k₂] places eig(A_c = A_h − B_h Kᵀ) at (λ₁, λ₂); ``h`` is the unit eigenvector of
    A_cᵀ for λ₁ with h₂ > 0 (∝ [−λ₂, 1]); ``N`` = N_u + K N_x from (13); ``hB`` = hᵀB_h.
    """

    a22: float
    b2: float
    lam1: float
    lam2: float
    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    K: np.ndarray
    Nx: np.ndarray
    Nu: float
    N: float
    h: np.ndarray
    hB: float

    @property
    def A_c(self) -> np.ndarray:
        """A_h − B_h Kᵀ."""
        return self.A - self.B @ self.K.reshape(1, 2)


def design_smc(a22: float, b2: float, lam1: float, lam2: float) -> SMCDesign:
    """Gains of the sliding-mode autopilot for ṙ = a₂₂ r + b₂ δ (notes 003-3.2, 003-3.4).

    K by python-control (``place``; ``acker`` for a repeated eigenvalue), h from numpy's
    eigenvectors of A_cᵀ (eigenvalue nearest λ₁), N_x, N_u by solving (13). λ₁ and λ₂ must be real
    and negative, |λ₁| ≤ |λ₂| (λ₁ is the eigenvalue of smallest modulus, the one h belongs to).
    """
    for name, value in (("a22", a22), ("b2", b2), ("lam1", lam1), ("lam2", lam2)):
        require(isinstance(value, (int, float, np.floating)) and np.isfinite(value),
                f"controller.{name}", value, "must be a finite real number")
    require(b2 != 0, "controller.b2", b2, "the rudder must act on the yaw rate (b2 != 0)")
    require(lam1 < 0 and lam2 < 0, "controller.lam1/lam2", (lam1, lam2),
            "closed-loop eigenvalues must be real and < 0")
    require(abs(lam1) <= abs(lam2), "controller.lam1/lam2", (lam1, lam2),
            "lam1 is the eigenvalue of smallest modulus: need |lam1| <= |lam2|")
    A = np.array([[0.0, 1.0], [0.0, float(a22)]])
    B = np.array([[0.0], [float(b2)]])
    C = np.array([[1.0, 0.0]])
    D = np.array([[0.0]])
    poles = [float(lam1), float(lam2)]
    gain = control.acker(A, B, poles) if lam1 == lam2 else control.place(A, B, poles)
    K = np.asarray(gain, dtype=float).reshape(2)
    A_c = A - B @ K.reshape(1, 2)
    values, vectors = np.linalg.eig(A_c.T)
    i = int(np.argmin(np.abs(values - lam1)))
    h = np.real(vectors[:, i])
    h = h / np.linalg.norm(h)
    if h[1] < 0 or (h[1] == 0 and h[0] < 0):
        h = -h
    sol = np.linalg.solve(np.block([[A, B], [C, D]]), np.array([0.0, 0.0, 1.0]))
    Nx, Nu = sol[:2], float(sol[2])
    return SMCDesign(a22=float(a22), b2=float(b2), lam1=float(lam1), lam2=float(lam2), A=A, B=B, C=C,
                     D=D, K=K, Nx=Nx, Nu=Nu, N=float(Nu + K @ Nx), h=h, hB=float(h @ B[:, 0]))


class SlidingModeCourse(_CourseController):
    """Sliding-mode course autopilot, law (14) with the reference model (15) (module docstring).

    ``form="consistent"``: δ_z = Nψ_z − Kᵀx + (hᵀB_h)⁻¹[hᵀẋ_hz − η tanh(σ/φ)], σ = hᵀ(x − x_z);
    ``form="printed"``: δ_z = Nψ_z − Kᵀx + hᵀẋ_hz − η tanh(σ_p/φ), σ_p = hᵀ(x_z − x).

    Headings enter through wrap(ψ − ψ_z): Nψ_z − Kᵀx = −k₁ wrap(ψ − ψ_z) − k₂ r + (N − k₁)ψ_z, and
    N = k₁ for this design model (N_x = [1, 0], N_u = 0), so the last term vanishes.
    Logged: ``psi_z``, ``r_z`` (reference model) and ``sigma`` (σ of the chosen form).
    """

    signals = (
        Signal("psi_z", "rad", "reference-model heading (eq. 15)", angle=True),
        Signal("r_z", "rad/s", "reference-model yaw rate (eq. 15)"),
        Signal("sigma", "rad/s", "sliding surface"),
    )

    def __init__(self, design: SMCDesign, *, form: str = "consistent", eta: float = 10.0,
                 phi: float = 0.3, omega_n: float = 0.1, zeta: float = 0.85, Ts: float = 0.1,
                 propeller_rps: float = CRUISE_RPS):
        super().__init__(Ts, propeller_rps)
        require(isinstance(design, SMCDesign), "controller.design", type(design).__name__,
                "must be an SMCDesign (see design_smc)")
        require(form in SMC_FORMS, "controller.form", form, f"allowed: {', '.join(SMC_FORMS)}")
        require(np.isfinite(eta) and eta >= 0, "controller.eta", eta, "must be a finite number >= 0")
        _check_positive("phi", phi)
        require(design.hB != 0, "controller.design.hB", design.hB, "h^T B_h must not be 0")
        self.design = design
        self.form = form
        self.eta, self.phi = float(eta), float(phi)
        self.reference_model = HeadingReferenceModel(omega_n, zeta)

    @property
    def yaw_rate_gain(self) -> float:
        """∂δ_z/∂r inside the boundary layer [rad/(rad/s)]: |k₂| + η h₂/(φ|hᵀB_h|) (consistent) or
        |k₂| + η h₂/φ (printed). Times the plant's |(M⁻¹b)_r| and Ts it should stay well below 2."""
        g = self.design
        scale = abs(g.hB) if self.form == "consistent" else 1.0
        return float(abs(g.K[1]) + self.eta * abs(g.h[1]) / (self.phi * scale))

    def reset(self, batch_shape) -> None:
        self.reference_model.reset()
        self._logged = {}

    def step(self, t: float, measurement: np.ndarray, reference: np.ndarray) -> np.ndarray:
        g = self.design
        k1, k2 = g.K
        h1, h2 = g.h
        psi, r = measurement[..., 2], measurement[..., 5]
        ref = self.reference_model
        ref.start(psi)
        r_dot_z = ref.acceleration(reference[..., 0])
        e_psi = wrap_angle(psi - ref.psi)
        e_r = r - ref.rate
        u_eq = -k1 * e_psi - k2 * r + (g.N - k1) * ref.psi
        feedforward = h1 * ref.rate + h2 * r_dot_z
        if self.form == "consistent":
            sigma = h1 * e_psi + h2 * e_r
            delta_z = u_eq + (feedforward - self.eta * np.tanh(sigma / self.phi)) / g.hB
        else:
            sigma = -(h1 * e_psi + h2 * e_r)
            delta_z = u_eq + feedforward - self.eta * np.tanh(sigma / self.phi)
        self._logged = {"psi_z": ref.psi.copy(), "r_z": ref.rate.copy(),
                        "sigma": np.asarray(sigma, dtype=float)}
        ref.advance(r_dot_z, self.Ts)
        return self._command(np.asarray(delta_z, dtype=float))

    def kernel(self, batch_shape) -> Kernel:
        """:meth:`step` for the composed loop (:func:`sliding_mode_step`). Per-ship state
        ``[psi_z, r_z, started, psi_z, r_z, sigma]``: the reference model (15) and the last logged
        signals, which :meth:`restore <shipgnc.kernels.Kernel>` hands back."""
        g, ref = self.design, self.reference_model
        params = flat(g.K[0], g.K[1], g.h[0], g.h[1], g.N, g.hB, self.eta, self.phi, ref.omega,
                      ref.zeta, self.Ts, float(self.form == "consistent"), self.propeller_rps)
        state = np.zeros((*batch_shape, 6))
        if ref.psi is not None:
            state[..., 0], state[..., 1], state[..., 2] = ref.psi, ref.rate, 1.0
        names = [s.name for s in self.signals]

        def restore(z: np.ndarray) -> None:
            z = z.reshape(*batch_shape, 6)
            if np.all(z[..., 2] > 0):
                ref.psi, ref.rate = z[..., 0].copy(), z[..., 1].copy()
                self._logged = {name: z[..., 3 + j].copy() for j, name in enumerate(names)}

        return Kernel(sliding_mode_step, params, state, restore=restore)


@kernel_function
def sliding_mode_step(t, x, ref, z, p, cmd, sig):
    """Law (14) with the reference model (15) for one ship, as :meth:`SlidingModeCourse.step`
    operation for operation (both forms); ``p`` from :meth:`SlidingModeCourse.kernel`, ``z`` =
    [ψ_z, r_z, started, logged ψ_z, r_z, σ], ``sig`` = [ψ_z, r_z, σ] before the Euler step."""
    k1, k2, h1, h2, N, hB, eta, phi = p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7]
    w, zeta, Ts, consistent, rps = p[8], p[9], p[10], p[11], p[12]
    psi, r = x[2], x[5]
    if z[2] == 0.0:  # the reference model starts at the measured heading, r_z = 0
        z[0], z[1], z[2] = psi, 0.0, 1.0
    psi_z, r_z = z[0], z[1]
    r_dot_z = w * w * wrap(ref[0] - psi_z) - 2.0 * zeta * w * r_z
    e_psi = wrap(psi - psi_z)
    e_r = r - r_z
    u_eq = -k1 * e_psi - k2 * r + (N - k1) * psi_z
    feedforward = h1 * r_z + h2 * r_dot_z
    if consistent != 0.0:
        sigma = h1 * e_psi + h2 * e_r
        delta_z = u_eq + (feedforward - eta * math.tanh(sigma / phi)) / hB
    else:
        sigma = -(h1 * e_psi + h2 * e_r)
        delta_z = u_eq + feedforward - eta * math.tanh(sigma / phi)
    sig[0], sig[1], sig[2] = psi_z, r_z, sigma
    z[3], z[4], z[5] = psi_z, r_z, sigma
    z[0] = psi_z + Ts * r_z
    z[1] = r_z + Ts * r_dot_z
    cmd[0] = rps
    cmd[1] = delta_z


def smc_paper(form: str = "consistent", design_model: tuple[float, float] | None = None, *,
              Ts: float = 0.1, propeller_rps: float = CRUISE_RPS) -> SlidingModeCourse:
    """The document's SMC: λ₁ = −0.0005, λ₂ = −7.8128, η = 10, φ = 0.3 on (18) as printed."""
    from shipgnc.analysis.nomoto import PRINTED_EQ18

    a22, b2 = PRINTED_EQ18 if design_model is None else design_model
    return SlidingModeCourse(design_smc(a22, b2, *PAPER_LAMBDAS), form=form, Ts=Ts,
                             propeller_rps=propeller_rps)


#: gains of ``smc_tuned`` on the design model (18): eigenvalues [1/s], the switching gain as a rudder
#: angle η_δ = η_h/|hᵀB_h| [rad] and the boundary layer φ_h [rad/s] (see :func:`smc_tuned`)
TUNED = {"lam1": -0.0005, "lam2": -0.2, "eta_rudder": 0.3, "phi": 0.03}


def smc_tuned(design_model: tuple[float, float] | None = None, *, Ts: float = 0.1,
              propeller_rps: float = CRUISE_RPS, **changes: float) -> SlidingModeCourse:
    """The consistent law (14) retuned for the nonlinear CyberShip II (``smc_tuned``, note 003-3.9).

    Same design model (18) as printed (a₂₂ = 0.1057, b₂ = −0.0040), same reference model
    (ω_n = 0.1, ζ = 0.85), same λ₁ = −0.0005; three changes (``TUNED``, overridable by keyword):

    ============  ==========  ==========================================================
    gain          paper       tuned
    ============  ==========  ==========================================================
    λ₂            −7.8128     −0.2 /s  (sliding-surface decay, time constant 5 s)
    η_h           10          η_δ·|hᵀB_h| with η_δ = 0.3 rad  (η_h = 1.18e-3)
    φ_h           0.3         0.03
    ============  ==========  ==========================================================

    Rationale. The first-order design model underestimates the plant's instantaneous
    rudder-to-yaw-acceleration gain (M⁻¹b)_r = −0.0918 s⁻² about 23-fold (b₂ = −0.0040). What
    matters for a sampled loop is ∂δ_z/∂r inside the boundary layer,
    g = |k₂| + η_h h₂/(φ_h|hᵀB_h|) (:attr:`SlidingModeCourse.yaw_rate_gain`), times
    |(M⁻¹b)_r|·Ts: the yaw-rate error then evolves roughly as e_r ← (1 − g|(M⁻¹b)_r|Ts) e_r per
    sample, unstable beyond 2 and oscillating beyond 1. With the paper's gains g ≈ 10 300
    (g·|(M⁻¹b)_r|·Ts ≈ 95: the consistent law limit-cycles on the rudder limits) — the printed
    form, without (hᵀB_h)⁻¹, still has ≈ 18 and chatters. Hence:

    * **slower λ₂**: k₂ = (a₂₂ − λ₁ − λ₂)/b₂ falls from −1980 to −76.5 (k₁ = λ₁λ₂/b₂ = −0.025;
      h = [0.196, 0.981], hᵀB_h = −3.92e-3);
    * **switching gain scaled by |hᵀB_h|**: in the consistent form the switching term is
      (η_h/|hᵀB_h|)·tanh(σ/φ_h) of rudder, so η_h = 0.3|hᵀB_h| gives at most 0.3 rad (17°) of
      switching rudder instead of 20 000 rad;
    * **thinner boundary layer** φ_h = 0.03 (σ is in rad/s, h unit): switching rudder per unit
      yaw-rate error η_δ h₂/φ_h = 9.8.

    Total g = 76.5 + 9.8 = 86.4, g·|(M⁻¹b)_r|·Ts = 0.79 (the PD's K_D = 50 gives 0.46): well
    below 2 and below 1. On the B7 course sequence (calm water, ``table1`` rudder, 35°, 19.4105°/s)
    it follows ψ_z within 7.6° (Σ wrap(ψ_z − ψ)² = 7.9 rad²), settles, and costs about the same
    as the PD (J ≈ 272 vs 264). The residual lag is the design model's doing: its feed-forward
    (ṙ_z − a₂₂r_z)/b₂ is 23 × too large at the start of a turn and, because a₂₂ > 0, opposes a
    steady turn; the feedback has to make up for it. The gains were chosen from a sweep of
    λ₂ ∈ [−0.1, −0.4], η_δ ∈ [0.05, 0.3], φ_h ∈ [0.005, 0.03], λ₁ ∈ [−0.03, −0.0005]:
    faster λ₂ or larger η_δ/φ_h track ψ_z more closely but push g·|(M⁻¹b)_r|·Ts past 1, and a
    faster λ₁ raised J.
    """
    from shipgnc.analysis.nomoto import PRINTED_EQ18

    unknown = set(changes) - set(TUNED)
    if unknown:
        raise ConfigError(f"smc_tuned: unknown option(s) {', '.join(sorted(unknown))}; "
                          f"allowed: {', '.join(TUNED)}")
    gains = {**TUNED, **changes}
    _check_positive("eta_rudder", gains["eta_rudder"])
    a22, b2 = PRINTED_EQ18 if design_model is None else design_model
    design = design_smc(a22, b2, gains["lam1"], gains["lam2"])
    return SlidingModeCourse(design, form="consistent", eta=gains["eta_rudder"] * abs(design.hB),
                             phi=gains["phi"], Ts=Ts, propeller_rps=propeller_rps)


#: gains of ``smc_identified`` on the identified Nomoto model (see :func:`smc_identified`)
IDENTIFIED = {"lam1": -0.0005, "lam2": -1.0, "eta_rudder": 0.3, "phi": 0.03}


def smc_identified(params=None, *, Ts: float = 0.1, propeller_rps: float = CRUISE_RPS,
                   design_model: tuple[float, float] | None = None,
                   **changes: float) -> SlidingModeCourse:
    """The consistent law (14) designed on a model **identified from the plant** (``smc_identified``).

    Design model: the first-order Nomoto model r/δ = K/(1 + Ts) fitted by least squares to the
    plant's 20°/20° zig-zag at ``propeller_rps`` (:func:`shipgnc.analysis.identification.identify_cybership2`;
    for the published CyberShip II with the ``table1`` rudder, 35° and 19.4105°/s: K = −0.264 s⁻¹,
    T = 8.70 s, so a₂₂ = −0.115 s⁻¹, b₂ = −0.0303 s⁻², 7.6 × the printed (18)'s b₂ and a third of
    the instantaneous (M⁻¹b)_r = −0.0918 s⁻²). ``design_model`` = (a₂₂, b₂) skips the
    identification (e.g. a fit of another manoeuvre).

    Gains (``IDENTIFIED``, overridable by keyword), by the document's rules — pole placement (10)
    with λ₁ the eigenvalue of smallest modulus (kept at the paper's −0.0005), h its eigenvector,
    N from (13) — and one sampled-loop rule for λ₂:

    * λ₂ = −1 /s: |λ₂|·Ts = 0.1 (the surface decays over ten samples), ten times the reference
      model's ω_n = 0.1 rad/s, so σ → 0 well inside the reference manoeuvre. On this model
      K = [−0.0165, −29.19], h = [0.7071, 0.7071], hᵀB_h = −0.02146; the inner-loop yaw-rate
      gain g = |k₂| + η_δ h₂/φ_h = 29.19 + 7.07 = 36.3 rad/(rad/s), so g·|(M⁻¹b)_r|·Ts = 0.33
      on the *plant's* instantaneous gain (well below 1; the paper's gains on this model give
      12.4, its k₂ alone 2.3);
    * switching gain as a rudder angle η_δ = η_h/|hᵀB_h| = 0.3 rad (half the 35° limit) and
      boundary layer φ_h = 0.03 rad/s, as ``smc_tuned`` (the switching term carries what the
      linear model misses: the course instability at small r and the speed loss).

    The paper's λ₂ = −7.81 with η_h = 10, φ_h = 0.3 on the identified model still limit-cycles
    (the switching rudder η_h/|hᵀB_h| is ≈ 2 600 rad). λ₂ from −0.7 to −1.5 gives nearly the same
    cost; λ₂ ≥ −0.3 lets the course-unstable ship lag its reference (the identified a₂₂ < 0 is an
    average over the zig-zag's large yaw rates; at small r the plant is unstable).
    """
    from shipgnc.analysis.identification import identify_cybership2

    unknown = set(changes) - set(IDENTIFIED)
    if unknown:
        raise ConfigError(f"smc_identified: unknown option(s) {', '.join(sorted(unknown))}; "
                          f"allowed: {', '.join(IDENTIFIED)}")
    gains = {**IDENTIFIED, **changes}
    _check_positive("eta_rudder", gains["eta_rudder"])
    if design_model is None:
        design_model = identify_cybership2(params, propeller_rps=propeller_rps).design_model
    a22, b2 = design_model
    design = design_smc(a22, b2, gains["lam1"], gains["lam2"])
    return SlidingModeCourse(design, form="consistent", eta=gains["eta_rudder"] * abs(design.hB),
                             phi=gains["phi"], Ts=Ts, propeller_rps=propeller_rps)


DESIGN_MODELS = ("eq18", "eq17", "eq16", "identified")


def design_model_of(params=None, which: str = "eq18", *, u0: float | None = None,
                    propeller_rps: float | None = None) -> tuple[float, float]:
    """(a₂₂, b₂) of a row of note 003-3.4: ``eq18`` the printed (18) (default, the document's),
    ``eq17`` the reduction of the printed (17), ``eq16`` the reduction of (16) from ``params``
    (CyberShip2Params, default the published ones) at ``u0`` (default 0.3 m/s), or
    ``identified``: the first-order Nomoto model fitted to the plant's 20°/20° zig-zag at
    ``propeller_rps`` (default 8.13 rps; :func:`shipgnc.analysis.identification.identify_cybership2`)."""
    from shipgnc.analysis.nomoto import (
        PRINTED_EQ17,
        PRINTED_EQ18,
        U0_EQ17,
        davidson_schiff,
        first_order_reduction,
        nomoto_second_order,
    )
    from shipgnc.models.cybership2 import CyberShip2Params

    require(which in DESIGN_MODELS, "controller.design_model", which,
            f"allowed: {', '.join(DESIGN_MODELS)}")
    if which == "eq18":
        return PRINTED_EQ18
    if which == "identified":
        from shipgnc.analysis.identification import identify_cybership2

        return identify_cybership2(params, propeller_rps=propeller_rps).design_model
    linear = PRINTED_EQ17 if which == "eq17" else davidson_schiff(
        params if params is not None else CyberShip2Params(), U0_EQ17 if u0 is None else u0)
    reduced = first_order_reduction(nomoto_second_order(*linear))
    return reduced.a22, reduced.b2


def course_controller(name: str, params_or_design_model=None, Ts: float = 0.1, *,
                      design_model: str = "eq18", propeller_rps: float = CRUISE_RPS):
    """The controller called ``name`` in note 003-3.8: ``pd``, ``smc_printed`` (alias ``printed``),
    ``smc_consistent`` (alias ``fossen``), ``smc_tuned`` or ``smc_identified`` (designed on the
    model identified from the plant ``params``; a design model given directly is used as is).

    ``params_or_design_model`` is either the plant's
    :class:`~shipgnc.models.cybership2.CyberShip2Params` (or None), in which case the SMCs are
    designed on the row ``design_model`` of note 003-3.4 (default ``eq18``, the document's choice;
    ``eq16`` uses these parameters), or a design model given directly as (a₂₂, b₂) (e.g. a
    :class:`~shipgnc.analysis.nomoto.NomotoI`). The PD needs no design model.
    """
    from shipgnc.models.cybership2 import CyberShip2Params

    key = ALIASES.get(name, name)
    require(key in CONTROLLER_NAMES, "controller", name,
            f"allowed: {', '.join(CONTROLLER_NAMES)} (aliases: {', '.join(ALIASES)})")
    if key == "pd":
        return CoursePD(Ts=Ts, propeller_rps=propeller_rps)
    source = params_or_design_model
    if key == "smc_identified" and (source is None or isinstance(source, CyberShip2Params)):
        return smc_identified(source, Ts=Ts, propeller_rps=propeller_rps)
    if source is None or isinstance(source, CyberShip2Params):
        model = design_model_of(source, design_model)
    else:
        pair = (source.a22, source.b2) if hasattr(source, "a22") else source
        try:
            a22, b2 = (float(v) for v in pair)
        except (TypeError, ValueError):
            raise ConfigError(f"controller design model = {source!r}: need CyberShip2Params or "
                              "(a22, b2)") from None
        model = (a22, b2)
    if key == "smc_tuned":
        return smc_tuned(model, Ts=Ts, propeller_rps=propeller_rps)
    if key == "smc_identified":
        return smc_identified(design_model=model, Ts=Ts, propeller_rps=propeller_rps)
    form = "consistent" if key == "smc_consistent" else "printed"
    return smc_paper(form, model, Ts=Ts, propeller_rps=propeller_rps)
