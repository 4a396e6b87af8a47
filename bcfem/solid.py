r"""Axisymmetric solid kinematics on a 2-D mesh in (r, z).

The deformation gradient of u = (u_r, u_z) is

.. math:: F = \begin{pmatrix} 1 + u_{r,r} & u_{r,z} & 0 \\ u_{z,r} & 1 + u_{z,z} & 0 \\
          0 & 0 & 1 + u_r/r \end{pmatrix},

Gauss points never sample r = 0, where u_r = 0 anyway. Every term integrates a
density per unit reference volume through :meth:`AxisymmetricSolid.integral`,
the one place the weight 2πr is applied for solids.
"""

from __future__ import annotations

from functools import cached_property

import ufl
from dolfinx import fem

from bcfem.mpi import global_sum


class AxisymmetricSolid:
    """F, J and I1 of an axisymmetric body.

    Args:
        u: displacement (u_r, u_z) on a mesh of the half cross-section r >= 0.
        quadrature_degree: explicit quadrature degree.
        cell_tags: region markers for integrals over part of the body.
        facet_tags: boundary markers for integrals over part of the surface.
    """

    def __init__(self, u, quadrature_degree: int, cell_tags=None, facet_tags=None):
        mesh = u.function_space.mesh
        self.u = u
        self.x = ufl.SpatialCoordinate(mesh)
        r = self.x[0]
        grad = ufl.grad(u)
        self.F = ufl.as_matrix([[1 + grad[0, 0], grad[0, 1], 0],
                                [grad[1, 0], 1 + grad[1, 1], 0],
                                [0, 0, 1 + u[0] / r]])
        self.J = ufl.det(self.F)
        self.I1 = ufl.tr(self.F.T * self.F)
        self._dx = ufl.Measure("dx", domain=mesh, subdomain_data=cell_tags,
                               metadata={"quadrature_degree": quadrature_degree})
        self._ds = ufl.Measure("ds", domain=mesh, subdomain_data=facet_tags,
                               metadata={"quadrature_degree": quadrature_degree + 2})
        # surface stretch: meridional |F T| (T the reference tangent) times hoop (r + u_r)/r
        N = ufl.FacetNormal(mesh)
        T = ufl.as_vector([-N[1], N[0]])
        FT = ufl.as_vector([self.F[0, 0] * T[0] + self.F[0, 1] * T[1], self.F[1, 0] * T[0] + self.F[1, 1] * T[1]])
        self.surface_stretch = ufl.sqrt(ufl.inner(FT, FT)) * self.F[2, 2]
        self.normal = N
        #: current height z = Z + u_z
        self.height = self.x[1] + u[1]

    def nanson(self):
        """cof(F) N on the boundary, components (r, z, theta): the current area vector per
        reference area (F is block-diagonal, so cof(F) N = (F_tt cof(F2) N, 0))."""
        F2 = ufl.as_matrix([[self.F[0, 0], self.F[0, 1]], [self.F[1, 0], self.F[1, 1]]])
        n2 = self.F[2, 2] * ufl.det(F2) * ufl.dot(ufl.inv(F2).T, self.normal)
        return ufl.as_vector([n2[0], n2[1], 0])

    def integral(self, density, region: int | None = None):
        """``density`` integrated over the reference body, dV = 2 pi r dA."""
        dx = self._dx if region is None else self._dx(region)
        return density * 2 * ufl.pi * self.x[0] * dx

    @cached_property
    def reference_volume(self) -> float:
        """The body's reference volume, int dV (collective on first use)."""
        return global_sum(fem.form(self.integral(1.0)))

    def mean(self, density):
        """The reference-volume mean of ``density``, (1/V) int density dV, as a form.

        E.g. ``mean(inner(a, b))`` is the mesh-independent inner product of two
        displacements that measures arc length (:class:`bcfem.continuation.ArcLength`).
        """
        return self.integral(density / self.reference_volume)

    def surface_integral(self, density, boundary: int):
        """``density`` integrated over the reference boundary part ``boundary``, dA = 2 pi r dS."""
        return density * 2 * ufl.pi * self.x[0] * self._ds(boundary)
