r"""Membrane kinematics on a planar reference mesh with a three-component displacement.

The mid-surface point X = (X1, X2, 0) of a flat reference outline moves to x = X + u,
u = (u1, u2, u3). The surface gradient F = ∂x/∂X is 3×2, the metric C = FᵀF is 2×2 and
the incompressible thickness stretch is :math:`\lambda_3 = 1/\sqrt{\det C}`, so that

.. math:: I_1 = \operatorname{tr} C + 1/\det C .

It offers what the axisymmetric membrane (:class:`bcfem.kinematics.AxisymmetricMembrane`)
offers the terms — ``I1``, ``integral``, ``mean``, ``area_stretch``, ``volume_density``,
``reference_area``, ``projected_area_density`` — so that the same term objects (strain
energy, surface tension, pressure–volume, wetted substrate) act on either. The enclosed
volume is that between the membrane and the plane z = 0: by the divergence theorem with
the field (0, 0, z), :math:`V = \int z\, n_z\, dA` with the area vector per reference area
:math:`n = x_{,1}\times x_{,2}` (the base z = 0 contributes nothing).
"""

from __future__ import annotations

from functools import cached_property

import ufl
from dolfinx import fem

from bcfem.mpi import global_sum


class PlanarMembrane:
    """Stretches, area and enclosed volume of a membrane whose reference state is flat.

    Args:
        u: displacement (u1, u2, u3) on a 2-D mesh of the reference outline in the plane z = 0.
        quadrature_degree: explicit degree (UFL would estimate a high one for the rational energies).
        cell_tags: region markers for :meth:`integral` over a part of the surface.
    """

    def __init__(self, u, quadrature_degree: int, cell_tags=None):
        mesh = u.function_space.mesh
        self.u = u
        X = ufl.SpatialCoordinate(mesh)
        self.x = ufl.as_vector([X[0] + u[0], X[1] + u[1], u[2]])
        self.F = ufl.as_matrix([[self.x[i].dx(a) for a in range(2)] for i in range(3)])
        self.C = self.F.T * self.F
        self.det_C = ufl.det(self.C)
        self.I1 = ufl.tr(self.C) + 1 / self.det_C
        #: area vector of the current surface per reference area, x_,1 × x_,2 (points to +z when flat)
        self.area_vector = ufl.cross(self.F[:, 0], self.F[:, 1])
        self.z = u[2]
        self._dx = ufl.Measure("dx", domain=mesh, subdomain_data=cell_tags,
                               metadata={"quadrature_degree": quadrature_degree})

    def integral(self, density, region: int | None = None):
        """The form of ``density`` integrated over the reference surface (over the cells
        tagged ``region`` only, if given)."""
        dx = self._dx if region is None else self._dx(region)
        return density * dx

    @cached_property
    def reference_area(self) -> float:
        """The reference outline's area (collective on first use)."""
        return global_sum(fem.form(self.integral(1.0)))

    def mean(self, density):
        """The reference-area mean of ``density``, (1/A) int density dA, as a form
        (the arc-length inner product, as :meth:`AxisymmetricMembrane.mean`)."""
        return self.integral(density / self.reference_area)

    @property
    def area_stretch(self):
        """Current area per reference area, sqrt(det C) = lambda_1 lambda_2."""
        return ufl.sqrt(self.det_C)

    @property
    def volume_density(self):
        """Enclosed volume per reference area, z n_z (see the module's docstring)."""
        return self.z * self.area_vector[2]

    @property
    def projected_area_density(self):
        """Area of the current surface projected on the plane z = 0, per reference area."""
        return self.area_vector[2]

    def principal_stretches(self):
        """(lambda_1, lambda_2), lambda_1 >= lambda_2: the square roots of C's eigenvalues."""
        half_trace = 0.5 * ufl.tr(self.C)
        root = ufl.sqrt(ufl.max_value(half_trace**2 - self.det_C, 0.0))
        return ufl.sqrt(half_trace + root), ufl.sqrt(ufl.max_value(half_trace - root, 0.0))

    def tension(self, dW_dI1, thickness: float = 1.0):
        r"""The membrane's tension tensor (force per current length) in the current
        tangent plane, as a 3×3 tensor, of an energy t0 W(I1) per reference area:
        :math:`N = \frac{1}{\lambda_1\lambda_2} F S F^T`, with the second
        Piola–Kirchhoff tension :math:`S = 2 t_0 W'(I_1)(I - C^{-1}/\det C)`."""
        S = 2 * thickness * dW_dI1 * (ufl.Identity(2) - ufl.inv(self.C) / self.det_C)
        return self.F * S * self.F.T / self.area_stretch
