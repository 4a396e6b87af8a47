r"""Axisymmetric solid kinematics on a 2-D mesh in (r, z).

The deformation gradient of u = (u_r, u_z) is

.. math:: F = \begin{pmatrix} 1 + u_{r,r} & u_{r,z} & 0 \\ u_{z,r} & 1 + u_{z,z} & 0 \\
          0 & 0 & 1 + u_r/r \end{pmatrix},

Gauss points never sample r = 0, where u_r = 0 anyway. Every term integrates a
density per unit reference volume through :meth:`AxisymmetricSolid.integral`,
the one place the weight 2πr is applied for solids.

The reference configuration may be a map X(ξ) of the mesh coordinate ξ that depends on
unknowns (a moving debond front, as for the membrane's ``reference`` in
:mod:`bcfem.kinematics.membrane`). The position is then x = ξ + u, so u is not x - X, and
:math:`F = (I + \nabla_\xi u)(\nabla_\xi X)^{-1}`, :math:`F_{\theta\theta} = r/X_r`,
:math:`dV = 2\pi X_r \det\nabla_\xi X\,d\xi`. Only the strain measures see the map;
whatever depends on positions alone (volumes, current areas) does not.

The displacement may carry a ``lift``, a UFL vector added to u (e.g. a platen state w
times a shape φ that is 1 on the top face: u + w φ e_z), so that a Dirichlet value
becomes an unknown that arc-length continuation can drive.
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
        lift: None, or a UFL vector added to ``u`` in every kinematic quantity.
    """

    def __init__(self, u, quadrature_degree: int, cell_tags=None, facet_tags=None, reference=None, lift=None):
        mesh = u.function_space.mesh
        self.u = u
        if lift is not None:
            u = u + lift
        self.x = ufl.SpatialCoordinate(mesh)
        #: the material coordinates X(ξ) (the mesh coordinate when not mapped)
        self.X = self.x if reference is None else reference
        grad = ufl.grad(u)
        F2 = ufl.as_matrix([[1 + grad[0, 0], grad[0, 1]], [grad[1, 0], 1 + grad[1, 1]]])
        N = ufl.FacetNormal(mesh)
        T = ufl.as_vector([-N[1], N[0]])
        if reference is None:
            self._G = None
            self._weight, self._line = self.x[0], 1
        else:
            G = ufl.grad(reference)
            self._G = G
            F2 = F2 * ufl.inv(G)
            self._weight = self.X[0] * ufl.det(G)
            self._line = ufl.sqrt(ufl.inner(G * T, G * T))  # reference length per mesh length
        self.F = ufl.as_matrix([[F2[0, 0], F2[0, 1], 0],
                                [F2[1, 0], F2[1, 1], 0],
                                [0, 0, 1 + u[0] / self.x[0] if reference is None
                                 else (self.x[0] + u[0]) / self.X[0]]])
        self.J = ufl.det(self.F)
        self.I1 = ufl.tr(self.F.T * self.F)
        self._dx = ufl.Measure("dx", domain=mesh, subdomain_data=cell_tags,
                               metadata={"quadrature_degree": quadrature_degree})
        self._ds = ufl.Measure("ds", domain=mesh, subdomain_data=facet_tags,
                               metadata={"quadrature_degree": quadrature_degree + 2})
        # surface stretch: current over reference length of the meridian times the hoop stretch
        FT = ufl.as_vector([(1 + grad[0, 0]) * T[0] + grad[0, 1] * T[1], grad[1, 0] * T[0] + (1 + grad[1, 1]) * T[1]])
        length = ufl.sqrt(ufl.inner(FT, FT))
        self.surface_stretch = (length if reference is None else length / self._line) * self.F[2, 2]
        self.normal = N
        #: current height z = Z + u_z
        self.height = self.x[1] + u[1]

    def nanson(self):
        """cof(F) N on the boundary, components (r, z, theta): the current area vector per
        reference area (F is block-diagonal, so cof(F) N = (F_tt cof(F2) N, 0))."""
        if self._G is not None:
            raise NotImplementedError("nanson() of a mapped reference configuration")
        F2 = ufl.as_matrix([[self.F[0, 0], self.F[0, 1]], [self.F[1, 0], self.F[1, 1]]])
        n2 = self.F[2, 2] * ufl.det(F2) * ufl.dot(ufl.inv(F2).T, self.normal)
        return ufl.as_vector([n2[0], n2[1], 0])

    def vertical_area(self):
        """The vertical (z) component of :meth:`nanson` (what a cavity closed by the plate needs)."""
        return self.nanson()[1]

    def integral(self, density, region: int | None = None):
        """``density`` integrated over the reference body, dV = 2 pi R dA."""
        dx = self._dx if region is None else self._dx(region)
        return density * 2 * ufl.pi * self._weight * dx

    @cached_property
    def reference_volume(self) -> float:
        """The body's reference volume, int dV (collective on first use)."""
        return global_sum(fem.form(self.integral(1.0)))

    def mean(self, density):
        """The reference-volume mean of ``density``, (1/V) int density dV, as a form.

        E.g. ``mean(inner(a, b))`` is the mesh-independent inner product of two
        displacements that measures arc length (:class:`bcfem.path.continuation.ArcLength`).
        """
        return self.integral(density / self.reference_volume)

    def surface_integral(self, density, boundary: int | tuple[int, ...]):
        """``density`` integrated over the reference boundary part ``boundary``, dA = 2 pi r dS."""
        weight = self.x[0] if self._G is None else self.X[0] * self._line
        return density * 2 * ufl.pi * weight * self._ds(boundary)
