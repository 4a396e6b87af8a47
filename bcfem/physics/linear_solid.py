r"""Small-strain terms of an axisymmetric substrate under a sessile drop (chapter 5, §5.2).

The linear model of the wetting ridge (dissertation eq. 5.26, ``docs/ridge-theory.md``)
as energy terms on the kinematics of :class:`SubstrateKinematics`: isotropic linear
elasticity in a mixed form that holds for every ν in (-1, 1/2], the linearised solid
surface tension, and the drop's loads: the upward ring load γl sinθ and the inward pull
γl cosθ at the contact line R0, and the Laplace pressure 2γl sinθ/R0 on the wetted part.

Point values at the contact line (the ring loads) are written as integrals of a
derivative along the wetted top surface, 2πR0 f(R0) = 2π∫_0^{R0} ∂_R(R f) dR: exact for
the polynomial traces of Lagrange fields, and one form with the rest of the energy.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import ufl

from bcfem.kinematics.solid import AxisymmetricSolid
from bcfem.params import require
from bcfem.physics.protocols import Term

if TYPE_CHECKING:
    from bcfem.physics.context import Context


class SubstrateKinematics(AxisymmetricSolid):
    """:class:`~bcfem.kinematics.solid.AxisymmetricSolid` with the small strain and integrals along the
    top surface's meridian (no 2πR weight), for point values by the fundamental theorem."""

    @property
    def strain(self):
        """The small strain ε = sym(F - I) (3x3: the hoop strain u_r/R is the (2, 2) entry)."""
        H = self.F - ufl.Identity(3)
        return 0.5 * (H + H.T)

    def line_integral(self, density, boundary: int):
        """``density`` integrated along the boundary part's meridian, ∫ density dS (no 2πR)."""
        return density * self._ds(boundary)

    def ring_value(self, f, boundary: int):
        r"""2πR0 f(R0) as :math:`2\pi\int_0^{R_0} \partial_R(R f)\,dR` over ``boundary`` (the
        wetted top, Z = 0, from the axis to R0): exact for a continuous polynomial trace."""
        R = self.x[0]
        return self.line_integral(2 * ufl.pi * (f + R * ufl.grad(f)[0]), boundary)


@dataclass(frozen=True)
class LinearElasticity(Term):
    r"""Isotropic small-strain elasticity with a mixed pressure:

    .. math:: W = \mu\,\mathrm{dev}\,\varepsilon : \mathrm{dev}\,\varepsilon + p\,\mathrm{tr}\,\varepsilon
              - \frac{p^2}{2K}, \qquad K = \frac{2\mu(1+\nu)}{3(1-2\nu)},

    stationary in p where p = K tr ε, so that W = μ ε:ε + (λ/2)(tr ε)². 1/K is finite for
    ν > -1 and zero at ν = 1/2, so the same Taylor-Hood form holds for every ν.

    Adds the field state ``solid_pressure`` (its multiplier).

    Attributes:
        mu: shear modulus [Pa]; 1 in normalised units.
        nu: Poisson ratio in (-1, 0.5].
        pressure_degree: Lagrange degree of p (1 with P2 displacements: Taylor-Hood).
    """

    mu: float = 1.0  # [Pa]
    nu: float = 0.5  # [-]
    pressure_degree: int = 1
    name = "linear_elasticity"
    multipliers = ("solid_pressure",)

    def __post_init__(self):
        require(math.isfinite(self.mu) and self.mu > 0, f"mu must be > 0 (got {self.mu})")
        require(-1 < self.nu <= 0.5, f"nu must be in (-1, 0.5] (got {self.nu})")

    @property
    def compliance(self) -> float:
        """1/K [1/Pa]."""
        return 3 * (1 - 2 * self.nu) / (2 * self.mu * (1 + self.nu))

    def energy(self, ctx: Context) -> ufl.Form:
        kin = ctx.kin
        p = ctx.field_state("solid_pressure", self.pressure_degree)
        eps = kin.strain
        dev = eps - ufl.tr(eps) / 3 * ufl.Identity(3)
        own = ctx.parameters(self)
        return kin.integral(own.mu * ufl.inner(dev, dev) + p * ufl.tr(eps) - 0.5 * own.compliance * p**2)


@dataclass(frozen=True)
class LinearSurfaceTension(Term):
    r"""The solid surface tension of a flat surface to second order in the deflection,
    :math:`\tfrac{\gamma}{2}\int (\partial_R u_z)^2\,dA` (eqs. 5.25-5.26): its variation is the
    normal load γ∇²u_z. The first-order area change γ∫∇_s·u_t dA is a boundary term, left to
    :class:`LinearDropLoads` at the contact line (and, at the far rim of a half-space
    stand-in, left out: it is no load of a half-space).

    Attributes:
        gamma: surface tension [N/m], >= 0; the run-time constant ``name``.
        boundary: facet tag of a part of the top surface Z = 0.
        name: name of the run-time constant.
    """

    gamma: float
    boundary: int
    name: str = "gamma_s"
    multipliers = ()

    def __post_init__(self):
        require(self.gamma >= 0, f"gamma must be >= 0 (got {self.gamma})")

    def energy(self, ctx: Context) -> ufl.Form:
        gamma = ctx.parameters(self, {"gamma": self.name}).gamma
        slope = ufl.grad(ctx.u)[1, 0]
        return ctx.kin.surface_integral(0.5 * gamma * slope**2, self.boundary)


@dataclass(frozen=True)
class LinearDropLoads(Term):
    r"""The drop's loads on a flat substrate, fixed in the reference configuration:

    .. math:: \Pi = -\gamma_l\sin\theta\,2\pi R_0 u_z(R_0) + \Delta p\int_{R<R_0} u_z\,dA
              + f_t\,2\pi R_0 u_r(R_0), \qquad \Delta p = 2\gamma_l\sin\theta/R_0,

    the ring load pulling up, the Laplace pressure pushing down and a tangential line force
    f_t pulling inwards. The liquid pulls with f_t = γl cosθ (eq. 5.22, the dissertation's
    and ``bcfem.theory.ridge``'s model); the first-order change of the solid's surface
    energy adds (γls - γs) 2πR0 u_r(R0), so that with Young's angle the net pull
    f_t = γl cosθ + γls - γs vanishes (``balanced``).

    Attributes:
        gamma_l: liquid-vapour tension [N/m]; the run-time constant ``gamma_l``.
        theta: contact angle of the liquid (radians).
        contact_radius: R0 [m].
        wetted: facet tag of the wetted top surface (from the axis to R0).
        pull: the tangential line force per γl: cosθ (the liquid's), or 0 (balanced).
    """

    gamma_l: float
    theta: float
    contact_radius: float
    wetted: int
    pull: float
    name = "linear_drop_loads"
    multipliers = ()

    def __post_init__(self):
        require(self.gamma_l >= 0, f"gamma_l must be >= 0 (got {self.gamma_l})")
        require(0 < self.theta < math.pi, f"theta must be in (0, pi) (got {self.theta})")
        require(self.contact_radius > 0, f"contact_radius must be > 0 (got {self.contact_radius})")

    def energy(self, ctx: Context) -> ufl.Form:
        kin, u = ctx.kin, ctx.u
        own = ctx.parameters(self, {"gamma_l": "gamma_l"})
        normal = own.gamma_l * ufl.sin(own.theta)
        laplace = 2 * normal / own.contact_radius
        return (-normal * kin.ring_value(u[1], self.wetted)
                + kin.surface_integral(laplace * u[1], self.wetted)
                + own.gamma_l * own.pull * kin.ring_value(u[0], self.wetted))
