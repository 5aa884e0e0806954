"""The catalogue vessels' equations, each written once for one ship (:mod:`shipgnc.kernels`): the
composed loop calls these kernels, and a model's ``derivatives`` is their batch over ships
(:func:`shipgnc.derive.per_ship`, via :meth:`~shipgnc.vessels.base.CatalogueModel.derivatives`).
State layout and steering machine as :mod:`shipgnc.vessels.base`; ``d`` = [current_north,
current_east] (zeros when the run has no disturbance). Each model's module docstring gives its
equations in full, with every coefficient and the source.
"""

from __future__ import annotations

import math

from shipgnc.kernels import kernel_function


@kernel_function
def steering_rate(delta, delta_c, dmax, rate, T_delta):
    """The steering machine for one ship: δ̇ = sat((sat(δ_c, ±δ_max) − δ)/T_δ, ±δ̇_max) (Fossen 2021
    §9.5, MSS ``mariner.m``; :mod:`shipgnc.vessels.base`)."""
    target = min(max(delta_c, -dmax), dmax)
    return min(max((target - delta) / T_delta, -rate), rate)


@kernel_function
def kinematics(x, d, xdot):
    """Position and heading rates (base layout) plus the current ``d``: ṅ = u cos ψ − v sin ψ + c_N,
    ė = u sin ψ + v cos ψ + c_E, ψ̇ = r."""
    c, s = math.cos(x[2]), math.sin(x[2])
    xdot[0] = c * x[3] - s * x[4] + d[0]
    xdot[1] = s * x[3] + c * x[4] + d[1]
    xdot[2] = x[5]


@kernel_function
def steering_rhs(x, u, d, p, xdot):
    """The kinematics and the steering machine of a catalogue vessel (body and extra rates 0), for
    a vessel written only in numpy (:meth:`~shipgnc.vessels.base.CatalogueModel.derivatives`);
    p = [δ_max, rate, T_δ]."""
    kinematics(x, d, xdot)
    for i in range(3, xdot.shape[0]):
        xdot[i] = 0.0
    xdot[6] = steering_rate(x[6], u[0], p[0], p[1], p[2])


@kernel_function
def norrbin_rhs(x, u, d, p, xdot):
    """:class:`~shipgnc.vessels.nomoto.NomotoVessel` for one ship: Norrbin T ṙ + H_N(r) = K δ,
    H_N(r) = a₃r³ + a₂r² + a₁r + a₀ (document 000 eq. (3)–(6); Nomoto: a₁ = 1, the rest 0, H(r) = r
    exactly) at constant speed without sway (u̇ = v̇ = 0), δ the actual rudder; p = [K, T, a0, a1,
    a2, a3, δ_max, rate, T_δ]."""
    kinematics(x, d, xdot)
    r = x[5]
    H = ((p[5] * r + p[4]) * r + p[3]) * r + p[2]
    xdot[3] = 0.0
    xdot[4] = 0.0
    xdot[5] = (p[0] * x[6] - H) / p[1]
    xdot[6] = steering_rate(x[6], u[0], p[6], p[7], p[8])


@kernel_function
def nomoto2_rhs(x, u, d, p, xdot):
    """:class:`~shipgnc.vessels.nomoto.Nomoto2Vessel` for one ship: second-order Nomoto in observer
    canonical form ẇ = K δ − r, ṙ = (w − (T₁ + T₂) r + K T₃ δ)/(T₁T₂) (Nomoto et al. 1957; Fossen
    2021 eq. 7.50), constant speed; p = [K, T1, T2, T3, δ_max, rate, T_δ]."""
    kinematics(x, d, xdot)
    K, T1, T2, T3 = p[0], p[1], p[2], p[3]
    r, delta, w = x[5], x[6], x[7]
    xdot[3] = 0.0
    xdot[4] = 0.0
    xdot[5] = (w - (T1 + T2) * r + K * T3 * delta) / (T1 * T2)
    xdot[6] = steering_rate(delta, u[0], p[4], p[5], p[6])
    xdot[7] = K * delta - r


@kernel_function
def linear3dof_rhs(x, u, d, p, xdot):
    """:class:`~shipgnc.vessels.linear.Linear3DOFVessel` for one ship: ν̇ = M⁻¹(B δ − N ν),
    ν = [u − U, v, r] (Fossen 2021 §7.2, eq. 7.14–7.15); p = [U, A (3×3 row-major) = −M⁻¹N,
    b = M⁻¹B (3), δ_max, rate, T_δ]."""
    kinematics(x, d, xdot)
    n0, n1, n2 = x[3] - p[0], x[4], x[5]
    delta = x[6]
    for i in range(3):
        xdot[3 + i] = (n0 * p[1 + 3 * i] + n1 * p[2 + 3 * i] + n2 * p[3 + 3 * i]
                       + delta * p[10 + i])
    xdot[6] = steering_rate(delta, u[0], p[13], p[14], p[15])


@kernel_function
def mariner_cst_rhs(x, u, d, p, xdot):
    """:class:`~shipgnc.vessels.mariner_cst.MarinerCST` for one ship (Chislett & Strøm-Tejsen 1965,
    as in Fossen 2021 and MSS ``mariner.m``): the polynomial X', Y', N' in u' = Δu/U, v' = v/U,
    r' = r L/U, δ_h = −δ of the module docstring, then u̇ = X' (U²/L)/(m' − X'_u̇),
    v̇ = (m'₃₃ Y' − m'₂₃ N') (U²/L)/det, ṙ = (−m'₃₂ Y' + m'₂₂ N') (U²/L²)/det; p = [U0, L, δ_max,
    rate, T_δ, then the coefficients in :data:`~shipgnc.vessels.mariner_cst.KERNEL_ORDER`]."""
    kinematics(x, d, xdot)
    U0, L = p[0], p[1]
    (m, Iz, xG, Xudot, Xu, Xuu, Xuuu, Xvv, Xrr, Xdd, Xudd, Xrv, Xvd, Xuvd,
     Yvdot, Yrdot, Yv, Yr, Yvvv, Yvvr, Yvu, Yru, Yd, Yddd, Yud, Yuud, Yvdd, Yvvd, Y0, Y0u, Y0uu,
     Nvdot, Nrdot, Nv, Nr, Nvvv, Nvvr, Nvu, Nru, Nd, Nddd, Nud, Nuud, Nvdd, Nvvd, N0, N0u,
     N0uu) = (p[5], p[6], p[7], p[8], p[9], p[10], p[11], p[12], p[13], p[14], p[15], p[16],
              p[17], p[18], p[19], p[20], p[21], p[22], p[23], p[24], p[25], p[26], p[27], p[28],
              p[29], p[30], p[31], p[32], p[33], p[34], p[35], p[36], p[37], p[38], p[39], p[40],
              p[41], p[42], p[43], p[44], p[45], p[46], p[47], p[48], p[49], p[50], p[51], p[52])
    du, v, r, delta = x[3] - U0, x[4], x[5], x[6]
    U = math.sqrt((U0 + du) ** 2 + v * v)
    u_, v_, r_ = du / U, v / U, r * L / U
    dd = -delta
    u2, v2, d2 = u_ * u_, v_ * v_, dd * dd
    X = (Xu * u_ + Xuu * u2 + Xuuu * u2 * u_ + Xvv * v2 + Xrr * r_ * r_ + Xrv * r_ * v_
         + Xdd * d2 + Xudd * u_ * d2 + Xvd * v_ * dd + Xuvd * u_ * v_ * dd)
    Y = (Yv * v_ + Yr * r_ + Yvvv * v2 * v_ + Yvvr * v2 * r_ + Yvu * v_ * u_ + Yru * r_ * u_
         + Yd * dd + Yddd * d2 * dd + Yud * u_ * dd + Yuud * u2 * dd + Yvdd * v_ * d2
         + Yvvd * v2 * dd + (Y0 + Y0u * u_ + Y0uu * u2))
    N = (Nv * v_ + Nr * r_ + Nvvv * v2 * v_ + Nvvr * v2 * r_ + Nvu * v_ * u_ + Nru * r_ * u_
         + Nd * dd + Nddd * d2 * dd + Nud * u_ * dd + Nuud * u2 * dd + Nvdd * v_ * d2
         + Nvvd * v2 * dd + (N0 + N0u * u_ + N0uu * u2))
    m11 = m - Xudot
    m22 = m - Yvdot
    m23 = m * xG - Yrdot
    m32 = m * xG - Nvdot
    m33 = Iz - Nrdot
    det = m22 * m33 - m23 * m32
    scale = U * U / L
    xdot[3] = X * scale / m11
    xdot[4] = (m33 * Y - m23 * N) * scale / det
    xdot[5] = (-m32 * Y + m22 * N) * scale / L / det
    xdot[6] = steering_rate(delta, u[0], p[2], p[3], p[4])


@kernel_function
def kvlcc2_rhs(x, u, d, p, xdot):
    """:class:`~shipgnc.vessels.kvlcc2.KVLCC2` for one ship: the MMG equations of Yasukawa &
    Yoshimura (2015), eq. 4–17 (module docstring of :mod:`shipgnc.vessels.kvlcc2`): hull, propeller
    (T = ρD²(k₀(nD)² + k₁ nD u_P + k₂ u_P²), finite at n = 0) and rudder forces, the surge and the
    sway–yaw mass matrices, ṅ = (sat(n_c, 0, n_max) − n)/T_n; p as :meth:`KVLCC2.kernel` lays it
    out."""
    kinematics(x, d, xdot)
    (R0, Xvv, Xvr, Xrr, Xvvvv, Yv, Yr, Yvvv, Yvvr, Yvrr, Yrrr, Nv, Nr, Nvvv, Nvvr, Nvrr, Nrrr,
     t_P, w_P0, k0, k1, k2, C1, C2p, C2m, x_P, t_R, a_H, x_H, x_R, gm, gp, l_R, eps, kappa,
     f_alpha) = (p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7], p[8], p[9], p[10], p[11], p[12],
                 p[13], p[14], p[15], p[16], p[17], p[18], p[19], p[20], p[21], p[22], p[23],
                 p[24], p[25], p[26], p[27], p[28], p[29], p[30], p[31], p[32], p[33], p[34],
                 p[35])
    rho, L, dr, m, m_x, m_y, x_G, D, eta, A_R = (p[36], p[37], p[38], p[39], p[40], p[41], p[42],
                                                 p[43], p[44], p[45])
    Mi00, Mi01, Mi10, Mi11 = p[46], p[47], p[48], p[49]
    dmax, rate, T_delta, T_n, n_max = p[50], p[51], p[52], p[53], p[54]
    su, sv, sr, delta, n = x[3], x[4], x[5], x[6], x[7]
    U2 = su * su + sv * sv
    U = math.sqrt(U2)
    Us = max(U, 1e-9)
    v_, r_ = sv / Us, sr * L / Us
    beta = math.atan2(-sv, su)
    q = 0.5 * rho * L * dr * U2
    v2, r2 = v_ * v_, r_ * r_
    X_H = q * (-R0 + Xvv * v2 + Xvr * v_ * r_ + Xrr * r2 + Xvvvv * v2 * v2)
    Y_H = q * (Yv * v_ + Yr * r_ + Yvvv * v2 * v_ + Yvvr * v2 * r_ + Yvrr * v_ * r2
               + Yrrr * r2 * r_)
    N_H = q * L * (Nv * v_ + Nr * r_ + Nvvv * v2 * v_ + Nvvr * v2 * r_ + Nvrr * v_ * r2
                   + Nrrr * r2 * r_)
    beta_P = beta - x_P * r_
    C2 = C2p if beta_P > 0 else C2m
    w_P = 1 - (1 - w_P0) * (1 + (1 - math.exp(-C1 * abs(beta_P))) * (C2 - 1))
    u_P = su * (1 - w_P)
    nD = n * D
    T = rho * D * D * (k0 * nD * nD + k1 * nD * u_P + k2 * u_P * u_P)
    X_P = (1 - t_P) * T
    # rudder inflow: u_R = ε u_P √(η{1 + κ(√(1 + 8K_T/(πJ²)) − 1)}² + 1 − η), written as
    # ε √(η{u_P + κ(√(u_P² + 8T/(ρπD²)) − u_P)}² + (1 − η) u_P²) (finite at u_P = 0)
    slip = math.sqrt(max(u_P * u_P + 8 * T / (rho * math.pi * D * D), 0.0))
    a = u_P + kappa * (slip - u_P)
    u_R = eps * math.sqrt(eta * a * a + (1 - eta) * u_P * u_P)
    beta_R = beta - l_R * r_
    gamma = gm if beta_R < 0 else gp
    v_R = U * gamma * beta_R
    alpha_R = delta - math.atan2(v_R, u_R)
    F_N = 0.5 * rho * A_R * (u_R * u_R + v_R * v_R) * f_alpha * math.sin(alpha_R)
    X_R = -(1 - t_R) * F_N * math.sin(delta)
    Y_R = -(1 + a_H) * F_N * math.cos(delta)
    N_R = -(x_R + a_H * x_H) * L * F_N * math.cos(delta)
    X, Y, N = X_H + X_P + X_R, Y_H + Y_R, N_H + N_R
    xdot[3] = (X + (m + m_y) * sv * sr + x_G * m * sr * sr) / (m + m_x)
    rhs_v = Y - (m + m_x) * su * sr
    rhs_r = N - x_G * m * su * sr
    xdot[4] = Mi00 * rhs_v + Mi01 * rhs_r
    xdot[5] = Mi10 * rhs_v + Mi11 * rhs_r
    xdot[6] = steering_rate(delta, u[0], dmax, rate, T_delta)
    n_c = min(max(u[1], 0.0), n_max)
    xdot[7] = (n_c - n) / T_n
