r"""A sessile drop of fixed volume on a deforming substrate: a spherical cap (chapter 5, §5.3).

The liquid is a spherical cap spanning the contact circle, which is pinned to the material
point R0 of the substrate's top surface and moves with it to (r_c, z_c) = (R0 + u_r, u_z).
Its shape is one global unknown, t = tan(θ/2) with θ the cap's angle to the horizontal at
the contact line; its Laplace pressure is the multiplier of the volume constraint:

.. math:: L = \gamma_l A(r_c, t) - p\,[V(u, t) - V_0],\quad A = \pi r_c^2 (1 + t^2),

.. math:: V = \frac{\pi}{6} r_c^3\, t(3 + t^2) + \pi r_c^2 z_c - \int_{wet} z\,(\mathrm{cof}F\,N)_z\,dA,

the cap above the contact plane, the cylinder down to z = 0, minus what the wetted
surface holds below z = 0 (the divergence theorem with the field z e_z, mapped by
Nanson's formula; it holds for an overhanging cap, t > 1, too). Stationarity in t gives
p = 2γl sinθ/r_c (Laplace), in p the volume, and in u the liquid's pull γl along the cap at
the contact line plus the pressure on the wetted surface (a follower load, exact).

The contact-point terms are polynomials in r_c and z_c that vanish on the axis, so they are
written as integrals of their R-derivative along the wetted meridian (exact with a
quadrature of degree >= 5 for P2 displacements): one form, no point evaluation.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import ufl

from bcfem.params import require
from bcfem.physics.protocols import Term

if TYPE_CHECKING:
    from bcfem.physics.context import Context


def cap_volume(radius: float, theta: float) -> float:
    """Volume of a spherical cap of base radius ``radius`` and contact angle ``theta``."""
    t = math.tan(theta / 2)
    return math.pi / 6 * radius**3 * t * (3 + t * t)


@dataclass(frozen=True)
class SphericalCapDrop(Term):
    r"""The drop's liquid-vapour energy and its volume constraint (see the module).

    Adds the states ``cap_slope`` (t = tan(θ/2), start it at the rest angle) and
    ``drop_pressure`` (p, the Laplace pressure: the multiplier of V = V0); the constant
    ``gamma_l`` (γl, may be ramped).

    Attributes:
        gamma_l: liquid-vapour tension [N/m], >= 0.
        volume: V0, the drop's volume [m^3], > 0.
        contact_radius: R0, the reference radius of the contact line [m].
        wetted: facet tag of the wetted top surface (Z = 0, from the axis to R0).
    """

    gamma_l: float
    volume: float
    contact_radius: float
    wetted: int
    name = "spherical_cap_drop"
    multipliers = ("drop_pressure",)

    def __post_init__(self):
        require(self.gamma_l >= 0, f"gamma_l must be >= 0 (got {self.gamma_l})")
        require(self.volume > 0, f"volume must be > 0 (got {self.volume})")
        require(self.contact_radius > 0, f"contact_radius must be > 0 (got {self.contact_radius})")

    def energy(self, ctx: Context) -> ufl.Form:
        kin, u = ctx.kin, ctx.u
        own = ctx.parameters(self, {"gamma_l": "gamma_l", "volume": "drop_volume"})
        gamma, v0 = own.gamma_l, own.volume
        t = ctx.real_state("cap_slope")
        p = ctx.real_state("drop_pressure")
        r = kin.x[0] + u[0]
        z = kin.height

        def at_contact(f):
            # f(r_c, z_c) = ∫_0^{R0} ∂_R f dR, since f = 0 on the axis (r = 0)
            return kin.line_integral(ufl.grad(f)[0], self.wetted)

        area = at_contact(ufl.pi * (1 + t * t) * r**2)
        volume = (at_contact(ufl.pi / 6 * t * (3 + t * t) * r**3 + ufl.pi * r**2 * z)
                  - kin.surface_integral(z * kin.vertical_area(), self.wetted))
        # V0 spread along the wetted meridian (length R0), so that the term is one form
        spread = kin.line_integral(v0 / own.contact_radius, self.wetted)
        return gamma * area - p * volume + p * spread

    def angle(self, t: float) -> float:
        """θ of the cap from its state t."""
        return 2 * math.atan(t)
