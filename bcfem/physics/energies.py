r"""Energy terms: each returns one scalar UFL form in the reference configuration.

A term is a frozen dataclass with ``energy(ctx)`` (:class:`bcfem.physics.protocols.Term`).
Residuals and tangents are never written by hand: the problem builder
differentiates the sum of the terms.
Every parameter reaches UFL as a ``fem.Constant`` of the term's own
(``ctx.parameters(self)``), so each form compiles once, whatever the values.

All lengths are in units of the blister radius R0 and energies in units of
mu_f t0 R0^2 when the membrane scenes use them, but the terms themselves are
unit-agnostic.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import ufl

from bcfem.mpi import cell_maximum
from bcfem.params import require
from bcfem.physics.materials import slopes
from bcfem.physics.protocols import Term

if TYPE_CHECKING:
    from bcfem.physics.context import Context
    from bcfem.physics.protocols import Hyperelastic, Shape, SolidMaterial


@dataclass(frozen=True)
class MembraneStrain(Term):
    r"""Strain energy of a thin incompressible membrane, :math:`U_f = \int t_0 W(I_1)\, dA` (eq. 3.25).

    Attributes:
        material: a material with ``strain_energy(I1, I2)``.
        thickness: reference thickness t0 [m]; 1 in normalised units.
    """

    material: Hyperelastic
    thickness: float = 1.0  # [m]
    name = "membrane_strain"
    multipliers = ()

    def __post_init__(self):
        require(self.thickness > 0, f"thickness must be > 0 (got {self.thickness})")

    def energy(self, ctx: Context) -> ufl.Form:
        kin = ctx.kin
        thickness, material = ctx.parameters(self).thickness, ctx.parameters(self.material)
        return kin.integral(thickness * material.strain_energy(kin.I1, kin.I2))

    def tractions(self, ctx):
        r"""Membrane tractions (force per current length), eq. 3.35:
        :math:`N_r = (t_0/\lambda_\theta)\,\partial W/\partial\lambda_r`,
        :math:`N_\theta = (t_0/\lambda_r)\,\partial W/\partial\lambda_\theta`, with
        :math:`\partial W/\partial\lambda = W_1\,\partial I_1/\partial\lambda + W_2\,\partial I_2/\partial\lambda`."""
        kin = ctx.kin
        thickness, material = ctx.parameters(self).thickness, ctx.parameters(self.material)
        W1, W2 = slopes(material, kin.I1, kin.I2)
        lr, lt = kin.lam_r, kin.lam_theta
        N_r = thickness / lt * (W1 * (2 * lr - 2 / (lr**3 * lt**2)) + W2 * (2 * lr * lt**2 - 2 / lr**3))
        N_t = thickness / lr * (W1 * (2 * lt - 2 / (lr**2 * lt**3)) + W2 * (2 * lt * lr**2 - 2 / lt**3))
        return N_r, N_t


@dataclass(frozen=True)
class SurfaceTension(Term):
    r"""Interface energy in the current configuration, :math:`\gamma A = \int \gamma\,\lambda_r\lambda_\theta\, dA`.

    The tension is isotropic and independent of strain (a liquid/solid
    interface, eq. 3.42); ``gamma`` is the run-time constant ``name``. With a
    ``profile`` the energy per current area is :math:`\gamma f(R)/\max|f|` at the
    material radius R (``ctx.kin.R``): the energy belongs to the material points
    (eq. 10.1's :math:`\Delta\gamma(X)`), and ``gamma`` is its scale.

    Attributes:
        gamma: surface energy density [N/m], >= 0.
        name: name of the run-time constant.
        region: cell tag of the wetted part of the membrane (None: all of it).
        profile: None, or a :class:`bcfem.radial_profile.RadialProfile` (values in [0, 1] times gamma).
    """

    gamma: float
    name: str = "gamma_l"
    region: int | None = None
    profile: Shape | None = None
    multipliers = ()

    def __post_init__(self):
        require(self.gamma >= 0, f"gamma must be >= 0 (got {self.gamma})")

    def energy(self, ctx: Context) -> ufl.Form:
        gamma = ctx.parameters(self, {"gamma": self.name}).gamma
        if self.profile is not None:
            gamma = gamma * self.profile.shape(ctx.kin.R)
        return ctx.kin.integral(gamma * ctx.kin.area_stretch, self.region)


@dataclass(frozen=True)
class PressureVolume(Term):
    r"""Pressure work with the pressure as a global unknown: :math:`-p\,(V(u) - \hat V)`.

    ``p`` is the real-space state ``pressure`` (pressure difference Δp [Pa]).
    Differentiating in ``p`` gives the volume constraint :math:`V(u) = \hat V`
    (volume control, ``volume_target`` constant). Under arc-length
    continuation the pressure row is replaced by the arc-length equation and
    :math:`\hat V` stays 0, so the term is the plain pressure work
    :math:`-\Delta p\, V`. Either way its value is the free energy's -ΔpV.

    Adds the state ``pressure`` and the constant ``volume_target``. The pressure
    is the multiplier of the volume constraint (one negative eigenvalue of the
    tangent under volume control); a problem that replaces its row does not
    count it as one.
    """

    name = "pressure_volume"
    multipliers = ("pressure",)

    def energy(self, ctx: Context) -> ufl.Form:
        p = ctx.real_state("pressure")
        v_target = ctx.constant("volume_target", 0.0)
        kin = ctx.kin
        # V-hat is spread over the reference area so the whole term is one integrand
        return kin.integral(-p * (kin.volume_density - v_target / kin.reference_area))


@dataclass(frozen=True)
class WettedSubstrate(Term):
    r"""Interface energy change where the liquid wets the substrate, :math:`\gamma\,\pi r_0^2`.

    :math:`\pi r_0^2` is the projected area inside the current edge radius
    :math:`r_0 = r(R_1)`, written as the domain integral
    :math:`\int 2\pi r r'\,dR = \int \lambda_\theta r'\,dA`, so that its
    variation in the edge position (and in an unknown debond radius) is exact.
    ``gamma`` is the energy per wetted area: :math:`\gamma_{ls} - \gamma_s`
    for a sliding edge, :math:`\gamma_{ls} - \Delta\gamma` for an adhesive one
    (eq. 3.42).

    With ``region`` the projected area is that of the tagged part only (its
    outer edge radius squared times π, when the part starts on the axis).

    With a ``profile`` the energy per wetted area is :math:`\gamma f(r)/\max|f|` at the
    current radius r, the rigid substrate's point under the membrane, so the energy is
    :math:`\int_0^{r_0}\gamma f(\rho)\,2\pi\rho\,d\rho` (r increasing along the meridian)
    and its variation in :math:`r_0` sees the local value :math:`f(r_0)`.

    Attributes:
        gamma: energy per wetted area [N/m] (any sign).
        name: name of the run-time constant.
        region: cell tag of the part of the membrane that covers the area (None: all).
        profile: None, or a :class:`bcfem.radial_profile.RadialProfile` (values in [-1, 1] times gamma).
    """

    gamma: float
    name: str = "gamma_wet"
    region: int | None = None
    profile: Shape | None = None
    multipliers = ()

    def energy(self, ctx: Context) -> ufl.Form:
        gamma = ctx.parameters(self, {"gamma": self.name}).gamma
        if self.profile is not None:
            gamma = gamma * self.profile.shape(ctx.kin.r)
        return ctx.kin.integral(gamma * ctx.kin.projected_area_density, self.region)


@dataclass(frozen=True)
class SolidStrain(Term):
    r"""Strain energy of a (nearly) incompressible solid with a mixed pressure,
    :math:`\int W(F, p)\, dV` (Taylor-Hood: P2 displacement, P1 pressure).

    Adds the field state ``solid_pressure`` (shared by every region's term), the
    multiplier of the volumetric constraint J - 1 = p/κ.

    Attributes:
        material: e.g. ``NearlyIncompressibleNeoHookean``.
        region: cell tag of the part made of this material (None: all).
        pressure_degree: Lagrange degree of the pressure (1 for Taylor-Hood P2-P1; 0: constant
            per cell, as Q1-P0).
    """

    material: SolidMaterial
    region: int | None = None
    pressure_degree: int = 1
    name = "solid_strain"
    multipliers = ("solid_pressure",)

    def energy(self, ctx: Context) -> ufl.Form:
        p = ctx.field_state("solid_pressure", self.pressure_degree)
        return ctx.kin.integral(ctx.parameters(self.material).density(ctx.kin, p), self.region)

    def inadmissible(self, ctx: Context) -> str | None:
        """An inverted solid: J <= 0 at a quadrature point (the energy's ln J is then undefined,
        though a residual in 1/J may still vanish)."""
        smallest = -ctx.cached("solid_J_min", lambda: cell_maximum(
            ctx.mesh, -ctx.kin.J, ctx.u.function_space.element.basix_element.degree))()
        return None if smallest > 0 else f"the solid inverts: J = {smallest:.3g} <= 0 at a quadrature point"


@dataclass(frozen=True)
class SolidSurfaceEnergy(Term):
    r"""Surface energy of part of a solid's boundary in the current configuration,
    :math:`\gamma \int \lambda_s\lambda_\theta\, dA` (isotropic, strain-independent).

    Attributes:
        gamma: surface energy density [N/m], >= 0; the run-time constant ``name``.
        boundary: facet tag (or tuple of tags) of the surface.
        name: name of the run-time constant.
    """

    gamma: float
    boundary: int | tuple[int, ...]
    name: str = "gamma_solid"
    multipliers = ()

    def __post_init__(self):
        require(self.gamma >= 0, f"gamma must be >= 0 (got {self.gamma})")

    def energy(self, ctx: Context) -> ufl.Form:
        gamma = ctx.parameters(self, {"gamma": self.name}).gamma
        return ctx.kin.surface_integral(gamma * ctx.kin.surface_stretch, self.boundary)
