"""A wedge 0 <= theta <= pi/m of the cylindrical specimen with a hemispherical crater at the
centre of its bottom face, in 3-D: the mirror faces theta = 0 (y = 0) and theta = pi/m cut it
(m = 2: the quarter x, y >= 0; m = 1: the half y >= 0), z is vertical, the plate is z = 0.
Built with OpenCASCADE on rank 0; quadratic tetrahedra, refined towards the crater.

Facets: BOTTOM (the flat face outside the crater), WALL (the crater), TOP, OUTER, MIRROR_START
(theta = 0), MIRROR_END (theta = pi/m; for m = 1 the plane y = 0 too, tagged MIRROR_START), and
with a lining INTERFACE (its outer sphere, inside the body). The quarter's names MIRROR_X and
MIRROR_Y are MIRROR_END and MIRROR_START.
Cells: SPECIMEN (1), LAYER (2, the lining a <= rho <= a + t, as :mod:`bcfem.geometry.crater`'s).
Units are those of the inputs (the crater scene's mm).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

BOTTOM, WALL, TOP, OUTER, MIRROR_END, MIRROR_START, INTERFACE = 11, 12, 13, 15, 16, 17, 18
MIRROR_X, MIRROR_Y = MIRROR_END, MIRROR_START
SPECIMEN, LAYER = 1, 2


@dataclass(frozen=True)
class CraterSector:
    """Dimensions (the experiment's, section 7.2.1, as :class:`bcfem.geometry.crater.CraterGeometry`)
    and the element sizes on the wall and far from it, over the crater radius a; a lining of
    thickness ``layer_thickness`` t/a (0: none); the wedge's angle pi/``wedge_waves`` (m: the
    wedge admits the modes cos(k m theta), k = 0, 1, 2, ...)."""

    radius: float = 12.70
    height: float = 35.13
    crater_radius: float = 6.35
    size_wall: float = 0.25
    size_far: float = 0.6
    layer_thickness: float = 0.0
    wedge_waves: int = 2

    @property
    def angle(self) -> float:
        """The wedge's angle pi/m."""
        return math.pi / self.wedge_waves

    @property
    def share(self) -> int:
        """The wedge's share of the specimen: 1/(2m)."""
        return 2 * self.wedge_waves

    def _cutter(self, radius: float, height: float) -> int:
        """The solid wedge 0 <= theta <= pi/m, r <= radius, 0 <= z <= height (the quarter a box,
        as it always was, so that its mesh is unchanged)."""
        occ = __import__("gmsh").model.occ
        if self.wedge_waves == 2:
            return occ.addBox(0, 0, 0, radius, radius, height)
        return occ.addCylinder(0, 0, 0, 0, 0, height, radius, angle=self.angle)

    def build_model(self) -> None:
        import gmsh

        from bcfem.geometry.mesh import graded_tetrahedra

        occ = gmsh.model.occ
        gmsh.model.add("crater_sector")
        a = self.crater_radius
        cylinder = occ.addCylinder(0, 0, 0, 0, 0, self.height, self.radius)
        quarter = self._cutter(2 * self.radius, self.height)
        ball = occ.addSphere(0, 0, 0, a)
        body, _ = occ.intersect([(3, cylinder)], [(3, quarter)])
        body, _ = occ.cut(body, [(3, ball)])
        lining = []
        t = self.layer_thickness * a
        if t > 0:
            box = self._cutter(2 * a, 2 * a)
            shell, _ = occ.intersect([(3, occ.addSphere(0, 0, 0, a + t))], [(3, box)])
            shell, _ = occ.cut(shell, [(3, occ.addSphere(0, 0, 0, a))])
            pieces, _ = occ.fragment(body, shell)
            occ.synchronize()
            lining = [tag for dim, tag in pieces if dim == 3 and math.hypot(*occ.getCenterOfMass(3, tag)) < a + t]
            body = [(3, tag) for dim, tag in pieces if dim == 3 and tag not in lining]
        occ.synchronize()
        gmsh.model.addPhysicalGroup(3, [t for _, t in body], SPECIMEN, name="specimen")
        if lining:
            gmsh.model.addPhysicalGroup(3, lining, LAYER, name="layer")
        wall: list = []
        groups: dict[int, list] = {}
        sin, cos = math.sin(self.angle), math.cos(self.angle)
        for _, tag in gmsh.model.getEntities(2):
            x, y, z = occ.getCenterOfMass(2, tag)
            reach = gmsh.model.getBoundingBox(2, tag)[3]  # a sphere's radius, the cylinder's (theta = 0 in every wedge)
            if abs(y) < 1e-9 * self.radius:
                key = MIRROR_START
            elif abs(cos * y - sin * x) < 1e-9 * self.radius:
                key = MIRROR_END
            elif abs(z) < 1e-9 * self.height:
                key = BOTTOM
            elif abs(z - self.height) < 1e-9 * self.height:
                key = TOP
            elif t > 0 and abs(reach - a - t) < 0.5 * t:
                key = INTERFACE
                wall.append(tag)
            elif abs(reach - a) < 0.5 * (t if t > 0 else a):
                key = WALL
                wall.append(tag)
            else:
                key = OUTER
            groups.setdefault(key, []).append(tag)
        for key, tags in groups.items():
            gmsh.model.addPhysicalGroup(2, tags, key)
        graded_tetrahedra(wall, self.size_wall * a, self.size_far * a, 0.1 * a, 1.5 * a)


def create_mesh(sector: CraterSector, comm):
    """The sector's mesh, distributed over ``comm`` (dolfinx.io.gmsh.MeshData)."""
    from bcfem.geometry.mesh import distribute

    return distribute(sector.build_model, comm, gdim=3)
