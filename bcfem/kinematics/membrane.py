r"""Axisymmetric membrane kinematics on a 1-D reference mesh in R.

The mid-surface point at reference radius :math:`R` moves to
:math:`(r, z) = (R + u_r, u_z)`. The stretches are
:math:`\lambda_r = \sqrt{r'^2 + z'^2}` (meridian) and :math:`\lambda_\theta = r/R`
(hoop); incompressibility gives the thickness stretch
:math:`1/(\lambda_r\lambda_\theta)`. Gauss quadrature never samples R = 0, so the
1/R in :math:`\lambda_\theta` is harmless.

The reference radius may depend on unknowns (a debond radius R1): the mesh
coordinate is then ξ and a reference map gives R(ξ) and J = dR/dξ, so that
d/dR = (1/J) d/dξ and dA = 2π R J dξ, and the energy's derivative in R1 is the
configurational (transversality) condition of the moving edge. Maps:
:func:`scaled` (R = R1 ξ) and :func:`two_zone` (a blister on ξ < 1 and a
bonded annulus on 1 < ξ < 2 out to a fixed outer radius).

This module is the one home of the axisymmetric weight: every term integrates a
density per unit reference area through :meth:`AxisymmetricMembrane.integral`.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from functools import cached_property
from typing import Any

from mpi4py import MPI

import ufl
from dolfinx import fem

from bcfem.mpi import global_sum


class ReferenceMean:
    """The reference measure and the mean over it, for kinematics whose ``integral(density)``
    integrates over the reference body (fixed: no unknown in the reference map)."""

    def integral(self, density, region: int | None = None) -> ufl.Form:
        raise NotImplementedError

    @cached_property
    def reference_measure(self) -> float:
        """The reference body's area or volume, int 1 (collective on first use)."""
        return global_sum(fem.form(self.integral(1.0)))

    def mean(self, density):
        """The reference mean of ``density``, (1/|body|) int density, as a form: e.g. the
        mesh-independent inner product of arc length (:class:`bcfem.path.continuation.ArcLength`)."""
        return self.integral(density / self.reference_measure)


def scaled(radius):
    """R = radius ξ on ξ in [0, 1]."""
    return lambda xi: (radius * xi, radius)


def two_zone(front, outer: float):
    """R = front ξ on [0, 1] (the blister) and front + (outer - front)(ξ - 1) on [1, 2]."""

    def reference(xi):
        inner = ufl.lt(xi, 1.0)
        return (ufl.conditional(inner, front * xi, front + (outer - front) * (xi - 1.0)),
                ufl.conditional(inner, front, outer - front))

    return reference


class Meridian:
    """The densities of an axisymmetric meridian, shared by a membrane on its own mesh
    (:class:`AxisymmetricMembrane`) and one on a solid's boundary
    (:class:`bcfem.kinematics.surfaces.MembraneSurface`): each sets ``lam_r``, ``lam_theta``,
    ``r`` and ``dz``."""

    lam_r: Any
    lam_theta: Any
    r: Any
    dz: Any

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


class AxisymmetricMembrane(Meridian):
    """Stretches, area and enclosed volume of an axisymmetric membrane.

    Args:
        u: displacement (u_r, u_z) on an interval mesh in R.
        quadrature_degree: explicit degree (UFL would otherwise estimate 13-21
            for the rational energies).
        reference: None for R = mesh coordinate, or a map ξ -> (R, dR/dξ) of UFL
            expressions (:func:`scaled`, :func:`two_zone`).
        cell_tags: region markers for :meth:`integral` over a part of the surface.
    """

    def __init__(self, u, quadrature_degree: int, reference=None, cell_tags=None):
        mesh = u.function_space.mesh
        self.u = u
        xi = ufl.SpatialCoordinate(mesh)[0]
        self.reference: Callable[[Any], tuple[Any, Any]] = reference or (lambda x: (x, 1))
        R, J = self.reference(xi)  # R(ξ) and dR/dξ
        self.R: Any = R
        self.J: Any = J
        self.r = self.R + u[0]
        self.z = u[1]
        self.dr = 1 + u[0].dx(0) / self.J
        self.dz = u[1].dx(0) / self.J
        self.lam_r = ufl.sqrt(self.dr**2 + self.dz**2)
        self.lam_theta = self.r / self.R
        self.I1 = self.lam_r**2 + self.lam_theta**2 + 1 / (self.lam_r * self.lam_theta) ** 2
        self.I2 = (self.lam_r * self.lam_theta) ** 2 + 1 / self.lam_r**2 + 1 / self.lam_theta**2
        self._dx = ufl.Measure("dx", domain=mesh, subdomain_data=cell_tags,
                               metadata={"quadrature_degree": quadrature_degree})
        x = mesh.geometry.x[:, 0]
        xi_in = mesh.comm.allreduce(x.min() if x.size else float("inf"), op=MPI.MIN)
        xi_out = mesh.comm.allreduce(x.max() if x.size else -float("inf"), op=MPI.MAX)
        #: reference area, the integral of dA (a UFL expression when the map has unknowns)
        self.reference_area = math.pi * (self.reference(xi_out)[0] ** 2 - self.reference(xi_in)[0] ** 2)

    def integral(self, density, region: int | None = None):
        """The form of ``density`` integrated over the reference surface, dA = 2 pi R dR
        (over the cells tagged ``region`` only, if given).

        The axisymmetric weight is applied here and nowhere else.
        """
        dx = self._dx if region is None else self._dx(region)
        return density * 2 * ufl.pi * self.R * self.J * dx

    def mean(self, density):
        """The reference-area mean of ``density``, (1/A) int density dA, as a form.

        E.g. ``mean(inner(a, b))`` is the mesh-independent inner product of two
        displacements that measures arc length (:class:`bcfem.path.continuation.ArcLength`).
        """
        return self.integral(density / self.reference_area)

    @property
    def projected_area_density(self):
        """The current surface's area projected on the plane z = 0, per reference area:
        2 pi r r' dR over 2 pi R dR = lambda_theta r'."""
        return self.lam_theta * self.dr

