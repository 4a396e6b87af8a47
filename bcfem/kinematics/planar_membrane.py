r"""Membrane kinematics on a planar reference mesh with a three-component displacement.

The mid-surface point X = (X1, X2, 0) of a flat reference outline moves to x = X + u,
u = (u1, u2, u3). The surface gradient F = ∂x/∂X is 3×2, the metric C = FᵀF is 2×2 and
the incompressible thickness stretch is :math:`\lambda_3 = 1/\sqrt{\det C}`, so that

.. math:: I_1 = \operatorname{tr} C + 1/\det C .

It offers what the axisymmetric membrane (:class:`bcfem.kinematics.membrane.AxisymmetricMembrane`)
offers the terms — ``I1``, ``integral``, ``mean``, ``area_stretch``, ``volume_density``,
``reference_area``, ``projected_area_density`` — so that the same term objects (strain
energy, surface tension, pressure–volume, wetted substrate) act on either. The enclosed
volume is that between the membrane and the plane z = 0: by the divergence theorem with
the field (0, 0, z), :math:`V = \int z\, n_z\, dA` with the area vector per reference area
:math:`n = x_{,1}\times x_{,2}` (the base z = 0 contributes nothing).
"""

from __future__ import annotations

import ufl

from bcfem.kinematics.membrane import ReferenceMean


class PlanarMembrane(ReferenceMean):
    """Stretches, area and enclosed volume of a membrane whose reference state is flat.

    With ``relaxed`` the membrane cannot carry compression (tension-field theory): where the
    taut state's minor principal tension would be negative, λ2 < λ1^(-1/2) for an energy of
    I1 (whose tensions go as λi² − λ3²), the membrane wrinkles, contracting freely across its
    tension lines as in uniaxial tension, so that I1 = λ1² + 2/λ1 there. The relaxed energy is
    the quasiconvex envelope of W(I1) for membranes, so the problem stays well posed where the
    plain one has compressed, stiffness-free regions. It relaxes the strain energy only: an
    isotropic surface tension adds to the tensions and is not part of the criterion. The
    relaxed energy does not depend on λ2 where the membrane wrinkles, so its tangent is singular
    there; ``residual`` keeps that fraction of the taut energy's stiffness (I1 = I1_relaxed +
    residual (I1_taut − I1_relaxed)), the usual regularisation of tension-field solvers.

    Args:
        u: displacement (u1, u2, u3) on a 2-D mesh of the reference outline in the plane z = 0.
        quadrature_degree: explicit degree (UFL would estimate a high one for the rational energies).
        cell_tags: region markers for :meth:`integral` over a part of the surface.
        relaxed: the tension-field relaxation above.
        residual: the fraction of the taut energy kept where the membrane wrinkles, in (0, 1].
    """

    def __init__(self, u, quadrature_degree: int, cell_tags=None, relaxed: bool = False, residual: float = 1e-3):
        mesh = u.function_space.mesh
        self.u = u
        X = ufl.SpatialCoordinate(mesh)
        self.x = ufl.as_vector([X[0] + u[0], X[1] + u[1], u[2]])
        self.F = ufl.as_matrix([[self.x[i].dx(a) for a in range(2)] for i in range(3)])
        self.C = self.F.T * self.F
        self.det_C = ufl.det(self.C)
        self.taut_I1 = ufl.tr(self.C) + 1 / self.det_C
        #: the second invariant of the taut membrane (λ3 = 1/(λ1 λ2)); the relaxation is I1's
        self.I2 = self.det_C + ufl.tr(self.C) / self.det_C
        lam1, lam2 = self.principal_stretches()
        #: where the taut membrane would be compressed across its tension lines
        self.wrinkled = ufl.lt(lam2**4 * lam1**2, 1.0)
        uniaxial = lam1**2 + 2 / lam1
        self.I1 = (ufl.conditional(self.wrinkled, uniaxial + residual * (self.taut_I1 - uniaxial), self.taut_I1)
                   if relaxed else self.taut_I1)
        #: area vector of the current surface per reference area, ``x_,1 × x_,2`` (points to +z when flat)
        self.area_vector = ufl.cross(self.F[:, 0], self.F[:, 1])
        self.z = u[2]
        self._dx = ufl.Measure("dx", domain=mesh, subdomain_data=cell_tags,
                               metadata={"quadrature_degree": quadrature_degree})

    def integral(self, density, region: int | None = None):
        """The form of ``density`` integrated over the reference surface (over the cells
        tagged ``region`` only, if given)."""
        dx = self._dx if region is None else self._dx(region)
        return density * dx

    @property
    def reference_area(self) -> float:
        """The reference outline's area (collective on first use)."""
        return self.reference_measure

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

    def tension_direction(self):
        """The unit vector, in the current tangent plane, of the major principal stretch (the
        direction of wrinkles' crests where the membrane wrinkles; 0 where C is isotropic)."""
        a, b, c = self.C[0, 0], self.C[0, 1], self.C[1, 1]
        lam1_sq = self.principal_stretches()[0] ** 2
        # the eigenvector of C for lambda_1^2, from whichever row of C - lambda_1^2 I is larger
        first = ufl.as_vector([b, lam1_sq - a])
        second = ufl.as_vector([lam1_sq - c, b])
        v = ufl.conditional(ufl.gt(ufl.inner(first, first), ufl.inner(second, second)), first, second)
        t = self.F * v
        length = ufl.sqrt(ufl.inner(t, t))
        return ufl.conditional(ufl.gt(length, 1e-12), t / ufl.max_value(length, 1e-12), 0 * t)

    def principal_tensions(self, dW_dI1, thickness: float = 1.0, dW_dI2=0.0):
        r"""(N1, N2), the taut membrane's principal tensions (force per current length) of an
        energy t0 W(I1, I2): :math:`N_i = 2 t_0 (\lambda_i^2 - \lambda_3^2)(W_1 + \lambda_j^2 W_2)
        /(\lambda_1\lambda_2)`, j the other direction."""
        lam1, lam2 = self.principal_stretches()
        lam3_sq = 1 / self.det_C
        return tuple(2 * thickness * (lam**2 - lam3_sq) * (dW_dI1 + other**2 * dW_dI2) / (lam1 * lam2)
                     for lam, other in ((lam1, lam2), (lam2, lam1)))

    def tension(self, dW_dI1, thickness: float = 1.0):
        r"""The membrane's tension tensor (force per current length) in the current
        tangent plane, as a 3×3 tensor, of an energy t0 W(I1) per reference area:
        :math:`N = \frac{1}{\lambda_1\lambda_2} F S F^T`, with the second
        Piola–Kirchhoff tension :math:`S = 2 t_0 W'(I_1)(I - C^{-1}/\det C)`."""
        S = 2 * thickness * dW_dI1 * (ufl.Identity(2) - ufl.inv(self.C) / self.det_C)
        return self.F * S * self.F.T / self.area_stretch
