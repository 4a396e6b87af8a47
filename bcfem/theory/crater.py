r"""Closed forms of the crater's suction cycle (ch. 7-8), in normalised units.

Pressures in p_a, so μ/p_a = β; F~ = F/(p_a A0).

* Air, small preload (eq. 7.12, re-derived): Eshelby's spherical cavity in an
  infinite body changes its volume by ΔV1 = -3/2 (1-ν) ε V0 under the far strain ε
  and by ΔV2 = 3/4 (Δp/μ) V0 under a pressure change Δp. Boyle's law p2 V2 = p_a V1
  with A2 = A0 then gives F~ = 1 - p2/p_a as the small root of
  F~² - (1 + K) F~ + 2(1-ν) β ε = 0, K = 4β/3.
* Liquid, small preload (eq. 8.6): V2 = V1, so ΔV2 = ΔV1 gives Δp = -2(1-ν) ε μ and
  F~ = 2(1-ν) β ε (β ε at ν = 1/2).
* Gas permeation through the wall (eqs. 7.19-7.21): an upper bound of the relative
  leakage during unloading.
"""

from __future__ import annotations

import math


def eshelby_air(eps: float, beta: float, nu: float = 0.5) -> float:
    """F~ of an air crater at small preload ``eps`` (eq. 7.12)."""
    K = 4 * beta / 3
    return 0.5 * ((1 + K) - math.sqrt((1 + K) ** 2 - 8 * (1 - nu) * beta * eps))


def eshelby_liquid(eps: float, beta: float, nu: float = 0.5) -> float:
    """F~ of a liquid crater at small preload ``eps`` (eq. 8.6)."""
    return 2 * (1 - nu) * beta * eps


def permeation_estimate(pressure_drop: float, crater_radius_mm: float, unload_time_s: float = 200.0,
                        wall_mm: float = 6.0) -> dict:
    """Upper bound of the relative air leakage J/V0 during unloading (eqs. 7.19-7.21).

    CO2/PDMS Henry permeability 22.4 L/mol x 2e-12 mol/(m s Pa), times 3 for the
    30:1 curing ratio; A/V0 = 3/a for the hemisphere; T = 20 C; the pressure drop
    (over p_a) is the cycle's (the dissertation takes 0.2 atm, and a = 6.35 mm: its
    '0.635 mm' is a typo).
    """
    permeability = 3 * 22.4e-3 * 2e-12  # [m^3 (STP) m / (m^2 s Pa)]
    drop = pressure_drop * 101325.0
    area_over_volume = 3.0 / (crater_radius_mm * 1e-3)
    ratio = (293.15 / 273.15) * drop * permeability * area_over_volume * unload_time_s / (wall_mm * 1e-3)
    return {"J_over_V0": ratio, "pressure_drop_pa": drop, "note": "upper bound, eqs. 7.19-7.21"}
