r"""Three-dimensional solid kinematics on a 3-D mesh in (x, y, z), z vertical.

F = I + ∇u is 3×3, J = det F, I1 = tr FᵀF. It offers the solid terms what
:class:`bcfem.kinematics.solid.AxisymmetricSolid` offers them — ``F``, ``J``, ``I1``, ``integral``,
``mean``, ``reference_volume``, ``surface_integral``, ``surface_stretch``, ``nanson()``,
``vertical_area()`` and ``height`` — so that a term written once (a strain energy, a surface
energy, a cavity's volume) acts on an axisymmetric body and on a 3-D one, such as a wedge of
it or a periodic cell of an array, with no weight 2πr anywhere.
"""

from __future__ import annotations

import ufl

from bcfem.kinematics.membrane import ReferenceMean

#: the index of the vertical axis (the plate is z = 0)
VERTICAL = 2


class Solid3D(ReferenceMean):
    """F, J and I1 of a three-dimensional body.

    Args:
        u: displacement (u_x, u_y, u_z) on a 3-D mesh.
        quadrature_degree: explicit quadrature degree.
        cell_tags: region markers for integrals over part of the body.
        facet_tags: boundary markers for integrals over part of the surface.
        lift: None, or a UFL vector added to ``u`` in every kinematic quantity.
    """

    def __init__(self, u, quadrature_degree: int, cell_tags=None, facet_tags=None, lift=None):
        mesh = u.function_space.mesh
        self.u = u
        if lift is not None:
            u = u + lift
        self.x = self.X = ufl.SpatialCoordinate(mesh)
        self.F = ufl.Identity(3) + ufl.grad(u)
        self.J = ufl.det(self.F)
        self.I1 = ufl.tr(self.F.T * self.F)
        self.normal = ufl.FacetNormal(mesh)
        self._cofactor_normal = self.J * ufl.inv(self.F).T * self.normal
        #: current area per reference area of the boundary, ``|cof(F) N|``
        self.surface_stretch = ufl.sqrt(ufl.inner(self._cofactor_normal, self._cofactor_normal))
        #: current height z = Z + u_z
        self.height = self.x[VERTICAL] + u[VERTICAL]
        self._dx = ufl.Measure("dx", domain=mesh, subdomain_data=cell_tags,
                               metadata={"quadrature_degree": quadrature_degree})
        self._ds = ufl.Measure("ds", domain=mesh, subdomain_data=facet_tags,
                               metadata={"quadrature_degree": quadrature_degree + 2})

    def nanson(self):
        """cof(F) N on the boundary, components (x, y, z): the current area vector per reference area."""
        return self._cofactor_normal

    def vertical_area(self):
        """The vertical component of :meth:`nanson` (what a cavity closed by the plate needs)."""
        return self._cofactor_normal[VERTICAL]

    def integral(self, density, region: int | None = None):
        """``density`` integrated over the reference body."""
        dx = self._dx if region is None else self._dx(region)
        return density * dx

    @property
    def reference_volume(self) -> float:
        return self.reference_measure

    def surface_integral(self, density, boundary: int | tuple[int, ...]):
        """``density`` integrated over the reference boundary part ``boundary``."""
        return density * self._ds(boundary)
