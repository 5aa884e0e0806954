"""Course autopilots of document 003 for CyberShip II: PD (3) and sliding mode (9)–(15).

The laws (the scenario's controllers of note 003-3.8 are designed from them by
:func:`shipgnc.cases.cybership.course_controller`, with document 003's printed design models):

* ``pd`` — :class:`CoursePD`, eq. (3): δ_z = K_P wrap(ψ − ψ_d) + K_D r, K_P = 2, K_D = 50, on ψ_d
  directly (no reference model). The sign is right because b₂ < 0 (δ > 0 turns the bow to port).
* ``smc_consistent`` (alias ``fossen``) — :class:`SlidingModeCourse`, the Healey–Lienard / Fossen
  (1994) form of law (14) (notes 003-3.2, 003-B4)::

      δ_z = N ψ_z − Kᵀx + (hᵀB_h)⁻¹ [hᵀẋ_hz − η_h tanh(σ_h/φ_h)],   σ_h = hᵀ(x − x_z)

  with x = [ψ, r], x_z = [ψ_z, r_z], ẋ_hz = [r_z, ṙ_z] from the reference model (15).
* ``smc_printed`` (alias ``printed``) — the law as printed: no (hᵀB_h)⁻¹ and
  σ_h = h₁(ψ_z − ψ) + h₂(r_z − r) (eq. (9)); it is stable only because hᵀB_h < 0 (h₂ > 0, b₂ < 0).
* ``smc_tuned`` — :func:`~shipgnc.cases.cybership.smc_tuned`: the consistent law on the printed
  design model (18) with gains retuned for the nonlinear plant (a work-around: the surface is
  slowed because b₂ is 23 × too small);
* ``smc_identified`` — :func:`~shipgnc.cases.cybership.smc_identified`: the consistent law
  designed with the document's rules on a first-order Nomoto model **identified from the plant**
  (a 20°/20° zig-zag fitted by least squares, :mod:`shipgnc.analysis.identification`).

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

import numpy as np

from shipgnc.control.base import kernel_step
from shipgnc.errors import require
from shipgnc.guidance.reference import HeadingReferenceModel
from shipgnc.kernels import Kernel, flat, kernel_function, wrap
from shipgnc.models.base import Signal
from shipgnc.models.cybership2 import CRUISE_RPS

SMC_FORMS = ("consistent", "printed")


def _check_positive(name: str, value: float) -> None:
    require(isinstance(value, (int, float, np.floating)) and np.isfinite(value) and value > 0,
            f"controller.{name}", value, "must be a finite number > 0")


class _CourseController:
    """Shared plumbing: sample time, references, held propeller speed."""

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
        """Eq. (3) for every ship: the batch of :func:`course_pd_step`."""
        command, self._logged = kernel_step(self, t, measurement, reference, 2)
        return command

    def kernel(self, batch_shape) -> Kernel:
        """:meth:`step` for the composed loop (:func:`course_pd_step`); no per-ship state."""
        return Kernel(course_pd_step, flat(self.Kp, self.Kd, self.propeller_rps))


@kernel_function
def course_pd_step(t, x, ref, z, p, cmd, sig):
    """Eq. (3) of document 003 for one ship: δ_z = K_P wrap(ψ − ψ_d) + K_D r, n = the held
    propeller speed; ``p`` = [K_P, K_D, n]."""
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

    K by scipy's ``place_poles`` (YT, what python-control's ``place`` calls; python-control's
    ``acker`` for a repeated eigenvalue; the gain kept on disk by A, B and the poles,
    :func:`shipgnc.derived_cache.stored`), h from numpy's
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
    if lam1 == lam2:
        import control  # python-control (≈ 1 s to import, with matplotlib.pyplot): this case only

        gain = control.acker(A, B, poles)
    else:  # python-control's place is this call (YT method), kept on disk by its inputs
        from shipgnc.derived_cache import stored

        gain = stored("place-poles-yt", {"A": A, "B": B, "poles": poles}, (__name__,),
                      lambda: {"K": _place_poles(A, B, poles)}, shape={"K": [float] * 2})["K"]
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


def _place_poles(A: np.ndarray, B: np.ndarray, poles: list[float]) -> list[float]:
    """The state-feedback gain of ``scipy.signal.place_poles`` (method YT) as a list."""
    from scipy.signal import place_poles

    gain = place_poles(A, B, np.array(poles), method="YT").gain_matrix
    return np.asarray(gain, dtype=float).ravel().tolist()


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
        """Law (14) with the reference model (15) for every ship: the batch of
        :func:`sliding_mode_step`."""
        command, self._logged = kernel_step(self, t, measurement, reference, 2)
        return command

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
    """Law (14) of document 003 with the reference model (15) for one ship, both forms::

        consistent  δ_z = Nψ_z − Kᵀx + (hᵀB_h)⁻¹[hᵀẋ_hz − η tanh(σ/φ)],  σ = hᵀ(x − x_z)
        printed     δ_z = Nψ_z − Kᵀx + hᵀẋ_hz − η tanh(σ_p/φ),          σ_p = hᵀ(x_z − x)

    with headings through wrap(ψ − ψ_z): Nψ_z − Kᵀx = −k₁ wrap(ψ − ψ_z) − k₂ r + (N − k₁)ψ_z; the
    reference model (15) ψ̈_z = ω_n² wrap(ψ_d − ψ_z) − 2ζω_n ψ̇_z, started at ψ_z = ψ, r_z = 0 and
    advanced by one Euler step of Ts. ``p`` from :meth:`SlidingModeCourse.kernel`, ``z`` =
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
