"""Van Amerongen's frigate: a Norrbin-type autopilot model with speed-dependent gains.

Source: J. van Amerongen (1982), *Adaptive Steering of Ships — A Model Reference Approach to
Improved Manoeuvring and Economical Course Keeping*, PhD thesis, Delft University of Technology;
as tabulated in T. I. Fossen (2021), *Handbook of Marine Craft Hydrodynamics and Motion Control*,
2nd ed., and his MSS function ``frigate.m`` (L ≈ 100 m, controllable-pitch propeller)::

    T(U) ṙ + n₃(U) r³ + r = K(U) δ,      ψ̇ = r              (Norrbin 1963, n₁ = 1)

    U [m/s]    K [1/s]    T [s]    n₃ [s²/rad²]
      6         0.08       20        0.4
      9         0.18       27        0.6
     12         0.23       21        0.3

K, T and n₃ are interpolated linearly in U (extrapolated linearly between 5 and 6 m/s); the model
is valid for 5 ≤ U ≤ 12 m/s and refuses other speeds with a one-line error. Steering machine (MSS):
|δ| ≤ 30°, |δ̇| ≤ 10°/s, T_δ = 1 s. The yaw equation is :class:`~shipgnc.models.nomoto.NorrbinModel`
(a₁ = 1, a₃ = n₃) in the catalogue's layout (:class:`~shipgnc.vessels.nomoto.NomotoVessel`): a
constant-speed model (u = U, v = 0).
"""

from __future__ import annotations

import math

import numpy as np

from shipgnc.errors import ConfigError

#: van Amerongen (1982): rows (U [m/s], K [1/s], T [s], n3 [s²/rad²])
TABLE = ((6.0, 0.08, 20.0, 0.4), (9.0, 0.18, 27.0, 0.6), (12.0, 0.23, 21.0, 0.3))
SPEED_RANGE = (5.0, 12.0)
LENGTH = 100.0


def frigate_gains(U: float) -> tuple[float, float, float]:
    """(K [1/s], T [s], n₃ [s²/rad²]) at speed ``U`` [m/s], linear in U through the table (as MSS
    ``interp1(..., 'linear', 'extrap')``); outside 5–12 m/s a one-line ConfigError."""
    low, high = SPEED_RANGE
    if not (isinstance(U, (int, float)) and math.isfinite(U) and low <= U <= high):
        raise ConfigError(f"vessel frigate: speed_mps = {U!r} is outside the model's valid range "
                          f"{low:g}–{high:g} m/s (van Amerongen 1982)")
    speeds = np.array([row[0] for row in TABLE])
    i = int(np.clip(np.searchsorted(speeds, U) - 1, 0, len(TABLE) - 2))
    (u0, *a), (u1, *b) = TABLE[i], TABLE[i + 1]
    w = (U - u0) / (u1 - u0)
    K, T, n3 = ((1 - w) * p + w * q for p, q in zip(a, b, strict=True))
    return float(K), float(T), float(n3)


def frigate(U: float, **steering):
    """The frigate at ``U`` [m/s]: a :class:`~shipgnc.vessels.nomoto.NomotoVessel` holding
    :class:`~shipgnc.models.nomoto.NorrbinModel` (K(U), T(U), a₁ = 1, a₃ = n₃(U))."""
    from shipgnc.models.nomoto import NorrbinModel
    from shipgnc.vessels.nomoto import NomotoVessel

    K, T, n3 = frigate_gains(U)
    defaults = {"delta_max": math.radians(30.0), "delta_rate": math.radians(10.0), "T_delta": 1.0}
    defaults.update(steering)
    return NomotoVessel(NorrbinModel(K, T, 1.0, n3, U=float(U), delta_max=defaults["delta_max"]),
                        **defaults)
