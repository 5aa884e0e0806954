"""Document 003's course autopilots as its scenarios design them (notes 003-3.4, 003-3.8): the
printed design models (17) and (18), the paper's eigenvalues, and the controllers by name.

The laws themselves (PD (3), the sliding-mode law (9)–(15), its pole placement) are components in
:mod:`shipgnc.control.course`; the Nomoto reduction of a sway–yaw model is
:mod:`shipgnc.models.nomoto_reduction`. Here the document's constants meet them:

* :data:`PRINTED_EQ17`, :data:`PRINTED_EQ18`, :data:`U0_EQ17` — (17) and (18) as printed (the
  discrepancy B2 of (17) is explained in :mod:`shipgnc.models.nomoto_reduction`);
* :data:`PAPER_LAMBDAS` — λ₁ = −0.0005, λ₂ = −7.8128 [1/s] (§3 of the document);
* :func:`smc_paper`, :func:`smc_tuned`, :func:`smc_identified` — the SMC rows of note 003-3.8;
* :func:`design_model_of` — (a₂₂, b₂) of a row of note 003-3.4;
* :func:`course_controller` — a controller of note 003-3.8 by name (``pd``, ``smc_printed``,
  ``smc_consistent``, ``smc_tuned``, ``smc_identified``; aliases ``printed``, ``fossen``).
"""

from __future__ import annotations

import numpy as np

from shipgnc.analysis.identification import identify_cybership2
from shipgnc.control.course import CoursePD, SlidingModeCourse, _check_positive, design_smc
from shipgnc.errors import ConfigError, require
from shipgnc.models.cybership2 import CRUISE_RPS, CyberShip2Params
from shipgnc.models.nomoto_reduction import (
    SwayYawModel,
    davidson_schiff,
    first_order_reduction,
    nomoto_second_order,
)


def _frozen(values) -> np.ndarray:
    arr = np.array(values, dtype=float)
    arr.setflags(write=False)
    return arr


#: eq. (17) as printed: M, N(0.3) with the erroneous N₂₂ = 2.9948 (B2), b
PRINTED_EQ17 = SwayYawModel(M=_frozen([[33.8, 1.0948], [1.0948, 2.76]]),
                            N=_frozen([[0.8897, 14.99], [2.3687, 2.9948]]),
                            b=_frozen([0.4304, -0.2363]))
#: eq. (18) as printed: (a₂₂, b₂) of the first-order design model, rounded by the document
PRINTED_EQ18 = (0.1057, -0.0040)
#: the linearisation speed of (17) [m/s]
U0_EQ17 = 0.3
def _gains(name: str, defaults: dict, changes: dict) -> dict:
    """``defaults`` updated by ``changes`` (known keys only), the switching gain checked."""
    unknown = set(changes) - set(defaults)
    if unknown:
        raise ConfigError(f"{name}: unknown option(s) {', '.join(sorted(unknown))}; "
                          f"allowed: {', '.join(defaults)}")
    gains = {**defaults, **changes}
    _check_positive("eta_rudder", gains["eta_rudder"])
    return gains


#: eigenvalues of the document (§3 of seed 003) [1/s]
PAPER_LAMBDAS = (-0.0005, -7.8128)
CONTROLLER_NAMES = ("pd", "smc_printed", "smc_consistent", "smc_tuned", "smc_identified")
ALIASES = {"fossen": "smc_consistent", "printed": "smc_printed"}


def smc_paper(form: str = "consistent", design_model: tuple[float, float] | None = None, *,
              Ts: float = 0.1, propeller_rps: float = CRUISE_RPS) -> SlidingModeCourse:
    """The document's SMC: λ₁ = −0.0005, λ₂ = −7.8128, η = 10, φ = 0.3 on (18) as printed."""
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
    gains = _gains("smc_tuned", TUNED, changes)
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
    gains = _gains("smc_identified", IDENTIFIED, changes)
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

    require(which in DESIGN_MODELS, "controller.design_model", which,
            f"allowed: {', '.join(DESIGN_MODELS)}")
    if which == "eq18":
        return PRINTED_EQ18
    if which == "identified":
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
    :class:`~shipgnc.models.nomoto_reduction.NomotoI`). The PD needs no design model.
    """
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
