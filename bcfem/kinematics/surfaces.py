r"""Membranes and interfaces on the boundary of an axisymmetric solid (chapter 4).

A blister's membrane bonded to a soft substrate, and the liquid between them, are
described by meridians on the substrate's flat top :math:`Z = 0` (reference tangent
:math:`e_R`):

* the substrate surface itself, :math:`x_s(R) = (R + u_r, u_z)` of the solid's
  displacement on the top facets;
* the free membrane over the liquid, :math:`x_f = x_s + w` with the lift :math:`w` a
  field on a codim-1 submesh of the wetted facets (:class:`bcfem.kinematics.submesh.BoundaryPatch`),
  0 at the contact vertex, so that membrane and substrate share that material point;
* the bonded membrane beyond the contact line, which moves with the substrate surface.

With a mapped reference (:class:`bcfem.kinematics.solid.AxisymmetricSolid`'s ``reference``, a moving
debond front) the material radius is :math:`R(\xi)` of the mesh coordinate and slopes
are taken per :math:`dR = R'\,d\xi`.

:class:`MembraneSurface` gives such a meridian the interface of
:class:`bcfem.kinematics.membrane.AxisymmetricMembrane` (``r``, ``z``, ``dr``, ``dz``, the
stretches :math:`\lambda_r = |x'|`, :math:`\lambda_\theta = r/R`, the incompressible
membrane's ``I1``, ``area_stretch``, ``volume_density`` and the one weighted
``integral`` over the tagged facets, :math:`dA = 2\pi R\,dR`). :class:`LiquidGap` is the
liquid between two such meridians that meet at the axis and at the contact line: its
volume per reference area is the difference of their enclosed-volume densities,

.. math:: V = -\int_0^{R_0} \pi\,(r_f^2 z_f' - r_s^2 z_s')\,dR .

The membrane terms of chapter 3 (:class:`~bcfem.physics.energies.MembraneStrain`,
:class:`~bcfem.physics.energies.SurfaceTension`, :class:`~bcfem.physics.energies.PressureVolume`) read
only these members, so :class:`bcfem.physics.composite.OnSurface` evaluates any of them on a surface: the energy
of the term with ``ctx.kin`` replaced by the surface's kinematics. No energy is written
twice, and every residual is still the energy's derivative.
"""

from __future__ import annotations

import math

import ufl

from bcfem.kinematics.membrane import Meridian


class MembraneSurface(Meridian):
    """A membrane (or an interface) lying on the top facets ``tag`` of an axisymmetric solid.

    Args:
        solid: the solid's kinematics (:class:`bcfem.kinematics.solid.AxisymmetricSolid`).
        facet_tags: the solid's facet markers.
        tag: the marker of the facets the surface covers (on Z = 0, tangent e_R).
        radii: (R_in, R_out), the reference radii the facets span (for ``reference_area``).
        lift: None (the substrate's surface itself), or (w, dw/dR) of a lift on a
            boundary patch (``dw/dR`` from :meth:`BoundaryPatch.grad`, never ``ufl.grad``).
        quadrature_degree: of the facet integrals (rational densities: set it explicitly).
    """

    def __init__(self, solid, facet_tags, tag: int, radii: tuple[float, float], lift=None,
                 quadrature_degree: int = 6):
        u = solid.u
        mesh = u.function_space.mesh
        disp, slope = u, ufl.grad(u)[:, 0]
        if lift is not None:
            w, dw = lift
            disp, slope = disp + w, slope + dw
        X = ufl.SpatialCoordinate(mesh)  # the parent's (the submesh's is wrong in 0.11)
        self.tag = tag
        # the material radius and dR/dxi of the solid's reference map (the membrane bonded to
        # the substrate shares the substrate's material points)
        mapped = solid.X is not solid.x
        self.R = solid.X[0] if mapped else X[0]
        J = solid.X[0].dx(0) if mapped else 1
        self.r = X[0] + disp[0]
        self.z = X[1] + disp[1]
        self.dr = (1 + slope[0]) / J if mapped else 1 + slope[0]
        self.dz = slope[1] / J if mapped else slope[1]
        self.J, self.mapped = J, mapped
        self.lam_r = ufl.sqrt(self.dr**2 + self.dz**2)
        self.lam_theta = self.r / self.R
        self.I1 = self.lam_r**2 + self.lam_theta**2 + 1 / (self.lam_r * self.lam_theta) ** 2
        self.I2 = (self.lam_r * self.lam_theta) ** 2 + 1 / self.lam_r**2 + 1 / self.lam_theta**2
        self._ds = ufl.Measure("ds", domain=mesh, subdomain_data=facet_tags,
                               metadata={"quadrature_degree": quadrature_degree})
        self.reference_area = math.pi * (radii[1] ** 2 - radii[0] ** 2)

    def integral(self, density, region=None):
        """``density`` per reference area over the surface, dA = 2 pi R dR (``region`` must be
        None or the surface's own tag: a surface is one tagged part)."""
        if region not in (None, self.tag):
            raise ValueError(f"a MembraneSurface covers facet tag {self.tag} only (got region {region})")
        weight = self.R * self.J if self.mapped else self.R
        return density * 2 * ufl.pi * weight * self._ds(self.tag)

    def mean(self, density):
        """The reference-area mean of ``density`` over the surface, as a form."""
        return self.integral(density / self.reference_area)


class LiquidGap:
    """The liquid between an ``upper`` meridian (the free membrane) and a ``lower`` one (the
    wetted substrate) over the same facets, which meet at the axis and at the contact line."""

    def __init__(self, upper: MembraneSurface, lower: MembraneSurface):
        if upper.tag != lower.tag:
            raise ValueError(f"the two meridians must cover the same facets (tags {upper.tag}, {lower.tag})")
        self.upper, self.lower = upper, lower
        self.reference_area = upper.reference_area

    def integral(self, density, region=None):
        return self.upper.integral(density, region)

    def mean(self, density):
        return self.upper.mean(density)

    @property
    def volume_density(self):
        """Liquid volume per reference area: the exact difference of the enclosed volumes."""
        return self.upper.volume_density - self.lower.volume_density
