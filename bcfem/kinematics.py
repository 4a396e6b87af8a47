r"""Axisymmetric membrane kinematics on a 1-D reference mesh in R.

The mid-surface point at reference radius :math:`R` moves to
:math:`(r, z) = (R + u_r, u_z)`. The stretches are
:math:`\lambda_r = \sqrt{r'^2 + z'^2}` (meridian) and :math:`\lambda_\theta = r/R`
(hoop); incompressibility gives the thickness stretch
:math:`1/(\lambda_r\lambda_\theta)`. Gauss quadrature never samples R = 0, so the
1/R in :math:`\lambda_\theta` is harmless.

The reference radius may itself be an unknown (a debond radius R1): the mesh
coordinate is then ξ and R = R1 ξ, so that d/dR = (1/R1) d/dξ and
dA = 2π R1² ξ dξ, and the energy's derivative in R1 is the configurational
(transversality) condition of the moving edge.

This module is the one home of the axisymmetric weight: every term integrates a
density per unit reference area through :meth:`AxisymmetricMembrane.integral`.
"""

from __future__ import annotations

import math

import ufl
from mpi4py import MPI


class AxisymmetricMembrane:
    """Stretches, area and enclosed volume of an axisymmetric membrane.

    Args:
        u: displacement (u_r, u_z) on an interval mesh in R.
        quadrature_degree: explicit degree (UFL would otherwise estimate 13-21
            for the rational energies).
        radius: None for R = mesh coordinate, or a UFL scalar (a Constant or a
            real-space state) R1 that scales the mesh coordinate, R = R1 ξ.
    """

    def __init__(self, u, quadrature_degree: int, radius=None):
        mesh = u.function_space.mesh
        self.u = u
        xi = ufl.SpatialCoordinate(mesh)[0]
        scale = 1 if radius is None else radius
        self.scale = scale
        self.R = scale * xi
        self.r = self.R + u[0]
        self.z = u[1]
        self.dr = 1 + u[0].dx(0) / scale
        self.dz = u[1].dx(0) / scale
        self.lam_r = ufl.sqrt(self.dr**2 + self.dz**2)
        self.lam_theta = self.r / self.R
        self.I1 = self.lam_r**2 + self.lam_theta**2 + 1 / (self.lam_r * self.lam_theta) ** 2
        dx = ufl.Measure("dx", domain=mesh, metadata={"quadrature_degree": quadrature_degree})
        self._dx = dx
        x = mesh.geometry.x[:, 0]
        r_in = mesh.comm.allreduce(x.min() if x.size else float("inf"), op=MPI.MIN)
        r_out = mesh.comm.allreduce(x.max() if x.size else -float("inf"), op=MPI.MAX)
        #: reference area, the integral of dA (a UFL expression when the radius is unknown)
        self.reference_area = math.pi * (r_out**2 - r_in**2) * (1 if radius is None else radius**2)

    def integral(self, density):
        """The form of ``density`` integrated over the reference surface, dA = 2 pi R dR.

        The axisymmetric weight is applied here and nowhere else.
        """
        return density * 2 * ufl.pi * self.R * self.scale * self._dx

    @property
    def area_stretch(self):
        """Current area per reference area, lambda_r lambda_theta."""
        return self.lam_r * self.lam_theta

    @property
    def volume_density(self):
        r"""Enclosed volume per reference area.

        :math:`V = -\int \pi r^2 z' \, dR` (the volume between the membrane and
        the plane z = 0, valid for overhanging profiles too); per reference area
        :math:`2\pi R\,dR` that is :math:`-\lambda_\theta r z'/2`.
        """
        return -0.5 * self.lam_theta * self.r * self.dz
