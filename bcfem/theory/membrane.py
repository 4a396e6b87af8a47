r"""Small-deflection membrane theories and the droplet limit, in normalised units.

Units: lengths by the radius a = R0, pressure P = Δp a/(μ t0), V0 = 4πa³/3.
The membrane is incompressible linear elastic (ν = 1/2, E = 3μ).

* Simple membrane theory (eq. 3.17): a one-term Ritz solution with
  w = h(1 - ρ²), u = c r(1 - r/a). Minimising the Föppl energy over (c, h) gives
  c = 2(3-ν)h²/(5a) and h³/a³ = 75(1-ν)P/(16(23+18ν-3ν²)) = 0.075 P at ν = 1/2,
  which reproduces eq. 3.17 (with μ, as printed). With V/V0 = 3h/(8a):
  P = (8 V/(3 V0))³ / 0.075.
* Föppl (moderate) membrane theory, eqs. 3.19-3.20, solved exactly. With
  S = r N_r the radial equilibrium integrates to N_r w' = -Δp r/2; compatibility
  then gives Hencky's equation s'' + 3 s'/ρ + 1/s² = 0 for the scaled radial
  tension s(ρ) = N_r/K, K³ = E t Δp² a²/8, with s'(0) = 0 and, from u(a) = 0,
  (1-ν) s(1) + s'(1) = 0. Then V = π a⁴ Δp/(2K) ∫ρ³/s dρ, so
  P = (3/8) (8 V/(3 V0 I3))³ with I3 = ∫₀¹ ρ³/s dρ, and
  w(0)/a = (8P/3)^{1/3} I1/2 with I1 = ∫₀¹ ρ/s dρ.
* Droplet (spherical cap, μ t0 → 0) with contact angle θ = π - φ0:
  Δp a/γ = 2 sin θ, z(0)/a = (1 - cos θ)/sin θ and
  V/V0 = (1 - cos θ)²(2 + cos θ)/(4 sin³ θ). Eq. 3.86 prints sin φ0 in the last
  denominator; it must be sin³ φ0 (a cap of angle π/2 is a hemisphere, V/V0 = 1/2).
"""

from __future__ import annotations

import math
from functools import cache

import numpy as np

NU = 0.5
RITZ = 75 * (1 - NU) / (16 * (23 + 18 * NU - 3 * NU**2))  # = 0.075


def simple_membrane_pressure(v_over_v0):
    """P(V/V0) of the simple membrane theory (eq. 3.17)."""
    h = 8.0 / 3.0 * np.asarray(v_over_v0)
    return h**3 / RITZ


def simple_membrane_deflection(P):
    """z(0)/R0 against P, eq. 3.17."""
    return np.cbrt(RITZ * np.asarray(P))


def _hencky_rhs(rho, y):
    s, ds = y
    return [ds, -3.0 * ds / rho - 1.0 / s**2]


def _hencky_solution(s0: float, rtol: float = 1e-13):
    from scipy.integrate import solve_ivp

    rho0 = 1e-6  # series start: s = s0 - rho^2/(8 s0^2)
    y0 = [s0 - rho0**2 / (8 * s0**2), -rho0 / (4 * s0**2)]
    return solve_ivp(_hencky_rhs, (rho0, 1.0), y0, method="DOP853", rtol=rtol, atol=1e-15,
                     dense_output=True)


@cache
def foppl_constants(nu: float = NU) -> tuple[float, float, float]:
    """(s0, I1, I3) of the exact Föppl-Hencky solution, to ~1e-12."""
    from scipy.integrate import quad
    from scipy.optimize import brentq


    def edge_condition(s0):
        sol = _hencky_solution(s0)
        s1, ds1 = sol.y[:, -1]
        return (1 - nu) * s1 + ds1

    s0 = brentq(edge_condition, 0.3, 3.0, xtol=1e-15, rtol=1e-15)
    sol = _hencky_solution(s0)

    def s_of(rho):
        return s0 - rho**2 / (8 * s0**2) if rho < 1e-6 else sol.sol(rho)[0]

    opts = dict(epsabs=1e-15, epsrel=1e-13, limit=200)
    I1 = quad(lambda r: r / s_of(r), 0, 1, **opts)[0]
    I3 = quad(lambda r: r**3 / s_of(r), 0, 1, **opts)[0]
    return s0, I1, I3


def foppl_pressure(v_over_v0):
    """P(V/V0) of the exact Föppl (moderate membrane) theory, eq. 3.19."""
    _, _, I3 = foppl_constants()
    return 3.0 / 8.0 * (8.0 * np.asarray(v_over_v0) / (3.0 * I3)) ** 3


def foppl_deflection(P):
    """z(0)/R0 against P for the Föppl theory."""
    _, I1, _ = foppl_constants()
    return np.cbrt(8.0 * np.asarray(P) / 3.0) * I1 / 2.0


def foppl_to_simple_ratio() -> float:
    """P_Föppl / P_simple at equal volume (a constant: both scale as V³)."""
    return float(foppl_pressure(1.0) / simple_membrane_pressure(1.0))


def droplet(theta):
    """Spherical-cap droplet with contact angle theta (rad) on a base of radius R0.

    Returns:
        (Δp R0/γ, z(0)/R0, V/V0)
    """
    theta = np.asarray(theta, dtype=float)
    s, c = np.sin(theta), np.cos(theta)
    return 2 * s, (1 - c) / s, (1 - c) ** 2 * (2 + c) / (4 * s**3)


def droplet_angle_from_volume(v_over_v0: float) -> float:
    """Contact angle theta in (0, pi) of the cap with volume V/V0.

    With t = tan(theta/2) = z(0)/R0 the cap's volume is V/V0 = t (3 + t²)/8, a cubic with one
    real root, t = A - 1/A, A = cbrt(4v + sqrt(16v² + 1)) (Cardano).
    """
    v = float(v_over_v0)
    A = np.cbrt(4 * v + math.sqrt(16 * v * v + 1))
    t = A - 1 / A
    t -= (t**3 + 3 * t - 8 * v) / (3 * t * t + 3)  # one Newton step: A - 1/A cancels for small v
    return 2 * math.atan(t)
