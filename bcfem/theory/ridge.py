r"""Linear-elastic wetting ridge under a sessile drop (chapter 5): Hankel-transform solutions.

This module evaluates the surface displacement of a linear elastic substrate
(shear modulus μ, Poisson ratio ν ∈ (-1, 1/2]) loaded by an axisymmetric drop
of contact radius r0, for a half-space z ≤ 0 or a layer -h ≤ z ≤ 0 bonded to a
rigid base, with a uniform solid surface tension γs (the case γls = γs).

**Boundary-value problem.** (1-2ν)∇²u + ∇(∇·u) = 0 in the solid, and at z = 0
σ_zz = γs ∇²u_z + γl sinθ δ(r-r0) - (2γl sinθ/r0) H(r0-r) and
σ_rz = -γl cosθ δ(r-r0) (the liquid pulls along its interface,
v = -cosθ e_r + sinθ e_z). A uniform isotropic surface stress only adds the
normal membrane force: the first variation of γs·area is γs∫∇_s·u_t dA, a
boundary term, so it puts no tangential traction on the surface; a jump
γs - γls at r0 would add an outward line force γs - γls (= γl cosθ by Young).

**Hankel solution.** With û(k) = ∫ r u J_n(kr) dr (n = 1 for r-components,
0 for z), x = k r0, ρ = r/r0, the surface compliance is
[û_r, û_z] = (μk)⁻¹ M(kh) [σ̂_rz, σ̂_zz] with, for κ = 3-4ν, η = kh,
D = κ cosh 2η + 2η² + (1+κ²)/2:

    M_ss = (1-ν)(κ sinh 2η - 2η)/D,   M_tt = (1-ν)(κ sinh 2η + 2η)/D,
    M_st = [κ(1-2ν)(cosh 2η - 1) - 2η²]/(2D),

which tends to the half-space M_ss = M_tt = 1-ν, M_st = (1-2ν)/2. The loads
transform to σ̂_zz = -γl r0 sinθ J2(x) - γs k² û_z (ring minus Laplace
pressure: J0 - 2J1/x = -J2) and σ̂_rz = -γl r0 cosθ J1(x). Solving for û_z,
with g = γs/(μ r0) = 1/((1-ν)c), c = μ r0/((1-ν)γs), in units of γl/μ:

    u_z = -∫ [sinθ M_ss J2(x) + cosθ M_st J1(x)] J0(ρx) / (1 + g x M_ss) dx,
    u_r = -∫ {sinθ M_st J2(x)/(1 + g x M_ss)
              + cosθ [M_tt - g x M_st²/(1 + g x M_ss)] J1(x)} J1(ρx) dx.

No factor (1-2ν) is divided out, so ν = 1/2 needs no limit. For the
half-space 1/(1 + g x M_ss) = c/(c+x) =: w(x).

**Quadrature.** Half-space: W_ab(ρ) = ∫ J_a(x) J_b(ρx) w(x) dx is integrated on
[0, 1] and then up the line x = 1 + it, after writing the Bessel factor of
the larger argument as (H⁽¹⁾ + H⁽²⁾)/2: each half decays like exp(-|1-ρ|t)
on its side of the axis, and the two paths are complex conjugates, so one
suffices. Without
oscillation the line integral takes Gauss-Legendre panels doubling in length
up to t ≈ 1e15 (c+1): at ρ = 1 it decays only like c/t², i.e. like 1/k² on
the real axis. The constant part of the tangential-ring kernel,
∫ J1(x) J1(ρx) dx, and γs = 0 (c = ∞) use the closed forms of the bare
ring loads (complete elliptic integrals K, E of m = 4ρ/(1+ρ)²). A layer adds
the real-axis integral of (kernel - half-space kernel), which decays like
η² e^{-2η}. How the accuracy is known: an independent quadrature (adaptive
Gauss-Kronrod on the real axis to x = 100, the Hankel asymptotic tail by
QAWF, kernels from a numerical 2x2 solve) agrees to 7e-15 or better at every
point tested, half-space and layer, c from 0.1 to 1e5 and ∞; the closed forms
at c = ∞ agree with it equally; see tests/test_ridge_theory.py.

**Ridge height.** As c → ∞ (half-space), by Mellin transforms of J2 J0,
J1 J0 and of w,

    u_z(r0) μ/γl = (1-ν) sinθ [(ln c + C)/π + 1/c]
                  - (1-2ν) cosθ/4 [1 - (ln c + C + 3)/(π c)] + O(ln c/c²),

C = γ_E + 3 ln 2 - 4 ≈ -1.34334. Dissertation eq. 5.34 has π^{-1/4} instead
of 1/π and no constant. As c → 0 surface tension dominates (a membrane):
u_z μ/(γl c) → -(1-ν) sinθ (1-ρ²)/2 H(1-ρ) - (1-2ν) cosθ E(ρ²)/π (ρ ≤ 1;
:func:`membrane_deflection`).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from scipy import special

# C of the ridge height: the finite part at s = 1 of ∫ x^{s-1} J2(x) J0(x) dx
# (Weber-Schafheitlin) is (4 - γ_E - 3 ln 2)/π
RIDGE_CONSTANT = float(np.euler_gamma + 3.0 * np.log(2.0) - 4.0)

# 20-point Gauss-Legendre: exact to degree 39, so a panel spanning a few radians
# of oscillation, or a decay by e^-20, is integrated to round-off.
_NODES, _WEIGHTS = np.polynomial.legendre.leggauss(20)
# Beyond |z| = 200 the 12-term Hankel expansion is accurate to round-off
# (its terms still fall for n <= 2), and AMOS loses digits for huge |z|.
_SERIES_RADIUS = 200.0
_SERIES_TERMS = 12
_LINE_START = 1.0  # where the path leaves the real axis, x = 1 + it
_EXP_CUTOFF = 46.0  # 2η beyond which a layer is a half-space: η² e^-2η < 1e-17
_PAIRS = ((2, 0), (1, 0), (2, 1), (1, 1))  # J_a(x) J_b(ρx) of u_z^n, u_z^t, u_r^n, u_r^t


class Displacement(NamedTuple):
    """Surface displacement at z = 0 in units of γl/μ (arrays shaped like ρ)."""

    u_r: np.ndarray
    u_z: np.ndarray


def _panel_rule(breaks) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre nodes and weights on the panels between consecutive ``breaks``."""
    breaks = np.asarray(breaks, dtype=float)
    half = 0.5 * np.diff(breaks)[:, None]
    nodes = 0.5 * (breaks[:-1] + breaks[1:])[:, None] + half * _NODES
    return nodes.ravel(), (half * _WEIGHTS).ravel()


def _hankel_series(n: int, z: np.ndarray, sign: int) -> np.ndarray:
    """H⁽¹⁾_n(z) e^{-iz} (sign = +1) or H⁽²⁾_n(z) e^{iz} (sign = -1), large |z|."""
    total = np.ones_like(z)
    term = np.ones_like(z)
    for k in range(1, _SERIES_TERMS):
        term = term * (1j * sign) * (4 * n * n - (2 * k - 1) ** 2) / (8 * k * z)
        total = total + term
    return np.sqrt(2.0 / (np.pi * z)) * np.exp(-1j * sign * (n * np.pi / 2 + np.pi / 4)) * total


def _hankel1e(n: int, z: np.ndarray) -> np.ndarray:
    """H⁽¹⁾_n(z) e^{-iz}."""
    z = np.asarray(z, dtype=complex)
    big = np.abs(z) > _SERIES_RADIUS
    out = np.empty_like(z)
    out[~big] = special.hankel1e(n, z[~big])
    out[big] = _hankel_series(n, z[big], 1)
    return out


def _jve(n: int, z: np.ndarray) -> np.ndarray:
    """J_n(z) e^{-Im z} for Im z >= 0."""
    z = np.asarray(z, dtype=complex)
    big = np.abs(z) > _SERIES_RADIUS
    out = np.empty_like(z)
    out[~big] = special.jve(n, z[~big])
    zb = z[big]
    out[big] = 0.5 * (_hankel_series(n, zb, 1) * np.exp(1j * zb.real - 2.0 * zb.imag)
                      + _hankel_series(n, zb, -1) * np.exp(-1j * zb.real))
    return out


def _real_breaks(end: float, width: float, scale: float) -> np.ndarray:
    """Panel ends on [0, end]: uniform of at most ``width``, graded near 0 below ``scale``."""
    uniform = np.linspace(0.0, end, math.ceil(end / width) + 1)
    graded = scale * 2.0 ** np.arange(-4, 60)
    return np.union1d(uniform, graded[graded < end])


def _contour_integrals(rho: float, c: float) -> dict:
    """W_ab(ρ) = ∫₀^∞ J_a(x) J_b(ρx) c/(c+x) dx for the four pairs, finite c."""
    x0 = _LINE_START
    x, wx = _panel_rule(_real_breaks(x0, 2.0 / (1.0 + rho), c))
    # the path x0 + it is free of oscillation; it decays like exp(-|1-ρ| t)
    # and, at ρ = 1, like c/t², so panels double until both are spent
    t_end = 1e15 * (c + 1.0)
    if rho != 1.0:
        t_end = min(t_end, 50.0 / abs(1.0 - rho))
    first = min(1.0, 1.0 / (1.0 + rho))
    doublings = np.arange(0, 1 + math.ceil(math.log2(t_end / first)))
    t, wt = _panel_rule(np.concatenate([[0.0], first * 2.0 ** doublings]))
    z = x0 + 1j * t
    on_axis = {n: special.jv(n, x) for n in (0, 1, 2)}
    near = {n: special.jv(n, rho * x) for n in (0, 1)}
    if rho <= 1.0:  # J_b(ρz) kept whole; H⁽¹⁾_a(z) decays upwards
        fast = {n: _hankel1e(n, z) for n in (1, 2)}
        slow = {n: _jve(n, rho * z) for n in (0, 1)}
        phase = np.exp(1j * x0 - (1.0 - rho) * t)
    else:  # H⁽¹⁾_b(ρz) decays upwards faster than J_a(z) grows
        fast = {n: _jve(n, z) for n in (1, 2)}
        slow = {n: _hankel1e(n, rho * z) for n in (0, 1)}
        phase = np.exp(1j * rho * x0 - (rho - 1.0) * t)
    axis_weight = wx * c / (c + x)
    path_weight = 1j * wt * phase * c / (c + z)  # dz = i dt
    return {(a, b): float(np.sum(on_axis[a] * near[b] * axis_weight)
                          + np.real(np.sum(fast[a] * slow[b] * path_weight)))
            for a, b in _PAIRS}


def _disc(rho: float) -> float:
    """∫₀^∞ J1(x) J0(ρx)/x dx: the uniform disc load (complete elliptic integrals)."""
    if rho <= 1.0:
        return 2.0 / np.pi * float(special.ellipe(rho * rho))
    m = 1.0 / (rho * rho)
    return 2.0 / np.pi * rho * float(special.ellipe(m) - (1.0 - m) * special.ellipk(m))


def _bare_integrals(rho: float) -> dict:
    """∫₀^∞ J_a(x) J_b(ρx) dx of the four pairs in closed form (bare ring loads)."""
    m = 4.0 * rho / (1.0 + rho) ** 2
    k, e = float(special.ellipk(m)), float(special.ellipe(m))
    ring = 2.0 / (np.pi * (1.0 + rho)) * k  # ∫ J0(x) J0(ρx) dx; J2 = 2J1/x - J0
    # Weber-Schafheitlin's discontinuous integrals take the mean value at ρ = 1
    step = 1.0 if rho < 1.0 else (0.5 if rho == 1.0 else 0.0)
    if rho == 0.0:
        cerruti = 0.0
    elif rho == 1.0:
        cerruti = np.inf
    else:  # ∫ J1(x) J1(ρx) dx, the radial ring load
        cerruti = (1.0 + rho) / (np.pi * rho) * ((1.0 - m / 2.0) * k - e)
    return {(2, 0): 2.0 * _disc(rho) - ring, (1, 0): step, (2, 1): rho * step, (1, 1): cerruti}


def layer_compliance(eta, nu: float):
    """Dimensionless surface compliance (M_tt, M_st, M_ss) of a bonded layer.

    Args:
        eta: k h, wavenumber times thickness (array-like, >= 0; ``np.inf`` for
            the half-space).
        nu: Poisson ratio.

    Returns:
        Tuple of arrays: μk û_r/σ̂_rz, μk û_r/σ̂_zz (= μk û_z/σ̂_rz) and μk û_z/σ̂_zz.
    """
    # multiplied through by 2e^{-2η} so that nothing overflows for thick layers;
    # beyond η = 1e3, e^{-2η} underflows to 0 and the half-space is exact
    eta = np.minimum(np.asarray(eta, dtype=float), 1e3)
    kappa = 3.0 - 4.0 * nu
    e = np.exp(-2.0 * eta)
    eta_e = eta * e
    eta2_e = eta * eta_e
    den = kappa * (1.0 + e * e) + (1.0 + kappa * kappa) * e + 4.0 * eta2_e
    m_ss = (1.0 - nu) * (kappa * (1.0 - e * e) - 4.0 * eta_e) / den
    m_tt = (1.0 - nu) * (kappa * (1.0 - e * e) + 4.0 * eta_e) / den
    m_st = (kappa * (1.0 - 2.0 * nu) * (1.0 - e) ** 2 - 4.0 * eta2_e) / (2.0 * den)
    return m_tt, m_st, m_ss


def _kernels(x, g: float, nu: float, eta) -> dict:
    """Kernels of the four pairs at η = kh, keyed like ``_PAIRS`` (minus sign included)."""
    m_tt, m_st, m_ss = layer_compliance(eta, nu)
    soft = 1.0 / (1.0 + g * x * m_ss)
    return {(2, 0): -m_ss * soft, (1, 0): -m_st * soft, (2, 1): -m_st * soft,
            (1, 1): -(m_tt - g * x * m_st * m_st * soft)}


def _layer_corrections(rho: float, g: float, nu: float, thickness: float) -> dict:
    """∫ J_a J_b (layer kernel - half-space kernel) dx: decays like η² e^{-2η}."""
    end = _EXP_CUTOFF / (2.0 * thickness)
    width = min(2.0 / (1.0 + rho), 1.0 / thickness)
    x, wx = _panel_rule(_real_breaks(end, width, 1.0 / g if g > 0 else end))
    layer = _kernels(x, g, nu, x * thickness)
    half = _kernels(x, g, nu, np.inf)
    bessel = {n: special.jv(n, x) for n in (1, 2)}
    near = {n: special.jv(n, rho * x) for n in (0, 1)}
    return {(a, b): float(np.sum(bessel[a] * near[b] * (layer[a, b] - half[a, b]) * wx))
            for a, b in _PAIRS}


def _check(c: float, nu: float, thickness) -> None:
    if not -1.0 < nu <= 0.5:
        raise ValueError(f"nu = {nu} must lie in (-1, 0.5]")
    if not c > 0.0:
        raise ValueError(f"c = {c} must be positive (np.inf for no surface tension)")
    if thickness is not None and not thickness > 0.0:
        raise ValueError(f"thickness = {thickness} (h/r0) must be positive or None")


def ring_responses(rho, c: float, nu: float,
                   thickness: float | None = None) -> tuple[Displacement, Displacement]:
    """Responses to the normal and the tangential drop loads, per unit γl sinθ and γl cosθ.

    Args:
        rho: r/r0 (array-like, >= 0).
        c: μ r0/((1-ν) γs); ``np.inf`` for γs = 0.
        nu: Poisson ratio in (-1, 0.5].
        thickness: h/r0 of a layer on a rigid base; None (or inf) for a half-space.

    Returns:
        (normal, tangential): :class:`Displacement` in units of γl/μ; "normal" is
        the upward ring load with its Laplace pressure, "tangential" the inward
        ring load. At ρ = 1 they are infinite where the bare ring loads are.
    """
    _check(c, nu, thickness)
    if thickness is not None and np.isinf(thickness):
        thickness = None
    rho = np.asarray(rho, dtype=float)
    g = 0.0 if np.isinf(c) else 1.0 / ((1.0 - nu) * c)
    half = _kernels(0.0, 0.0, nu, np.inf)  # the half-space kernels at γs = 0
    q = (1.0 - 2.0 * nu) ** 2 / (4.0 * (1.0 - nu))  # M_st²/M_ss of the half-space
    values = np.empty((4,) + rho.shape)
    for index, r in np.ndenumerate(rho):
        if r < 0:
            raise ValueError(f"rho = {r} must be >= 0")
        bare = _bare_integrals(float(r))
        if g == 0.0:
            total = {p: half[p] * bare[p] for p in _PAIRS}
        else:
            # half-space: every kernel is a multiple of w(x), except the tangential
            # ring's u_r, -[(1-ν-q) + q w]; its constant part is the bare Cerruti ring
            weighted = _contour_integrals(float(r), c)
            total = {p: half[p] * weighted[p] for p in _PAIRS}
            total[1, 1] = -((1.0 - nu - q) * bare[1, 1] + q * weighted[1, 1])
        if thickness is not None:
            extra = _layer_corrections(float(r), g, nu, thickness)
            total = {p: total[p] + extra[p] for p in _PAIRS}
        values[(slice(None),) + index] = [total[p] for p in _PAIRS]
    return (Displacement(values[2], values[0]), Displacement(values[3], values[1]))


def surface_displacement(rho, c: float, nu: float, theta: float = np.pi / 2,
                         thickness: float | None = None) -> Displacement:
    """Surface displacement under a drop of contact angle θ, in units of γl/μ.

    Args:
        rho: r/r0 (array-like, >= 0).
        c: μ r0/((1-ν) γs); ``np.inf`` for γs = 0.
        nu: Poisson ratio in (-1, 0.5].
        theta: contact angle θ of the liquid (radians).
        thickness: h/r0 of a layer on a rigid base; None for a half-space.

    Returns:
        :class:`Displacement` (u_r, u_z) · μ/γl at z = 0.
    """
    normal, tangential = ring_responses(rho, c, nu, thickness)
    weights = (math.sin(theta), math.cos(theta))
    # a load that is absent contributes nothing, even where the other is infinite
    parts = [(wt, resp) for wt, resp in zip(weights, (normal, tangential)) if wt != 0.0]
    zero = np.zeros_like(np.asarray(rho, dtype=float))
    return Displacement(zero + sum(wt * resp.u_r for wt, resp in parts),
                        zero + sum(wt * resp.u_z for wt, resp in parts))


def ridge_height(c: float, nu: float, theta: float = np.pi / 2,
                 thickness: float | None = None) -> float:
    """u_z(r0) · μ/γl, the height of the wetting ridge's tip (infinite for c = ∞)."""
    return float(surface_displacement(1.0, c, nu, theta, thickness).u_z)


def ridge_height_asymptote(c, nu: float, theta: float = np.pi / 2):
    """Large-c expansion of :func:`ridge_height` for the half-space, error O(ln c/c²).

    u_z(r0) μ/γl ≈ (1-ν) sinθ [(ln c + C)/π + 1/c]
    - (1-2ν) cosθ/4 [1 - (ln c + C + 3)/(π c)], C = γ_E + 3 ln 2 - 4
    (:data:`RIDGE_CONSTANT`). The leading terms are the Mellin residues at
    s = 1 of ∫x^{s-1} J2 J0 dx (a pole, from J2 J0 ~ -1/(πx)) and of
    ∫x^{s-1} J1 J0 dx (regular, = 1/2); the 1/c terms come from s = 2.
    """
    log_c = np.log(c)
    normal = (1.0 - nu) * ((log_c + RIDGE_CONSTANT) / np.pi + 1.0 / c)
    tangential = -(1.0 - 2.0 * nu) / 4.0 * (1.0 - (log_c + RIDGE_CONSTANT + 3.0) / (np.pi * c))
    return math.sin(theta) * normal + math.cos(theta) * tangential


def membrane_deflection(rho, nu: float, theta: float = np.pi / 2):
    """lim_{c→0} u_z μ/(γl c) of the half-space: the surface is a membrane of tension γs.

    The ring load and the Laplace pressure balance, so the membrane is flat
    outside the drop and a paraboloid inside, -(1-ν) sinθ (1-ρ²)/2. The
    tangential ring acts through the elastic coupling (1-2ν)/(2(1-ν)) as a
    normal load and adds -(1-2ν) cosθ/2 ∫ J1(x) J0(ρx)/x dx, a disc's profile.
    The error is O(c).
    """
    rho = np.asarray(rho, dtype=float)
    inside = np.where(rho < 1.0, (1.0 - rho * rho) / 2.0, 0.0)
    disc = np.vectorize(_disc)(rho)
    return -(1.0 - nu) * math.sin(theta) * inside - (1.0 - 2.0 * nu) / 2.0 * math.cos(theta) * disc
