r"""The smallest mirror cell of a lattice of spherical-cap craters in the bottom face of a
specimen of height H, in 3-D (z vertical, the plate z = 0).

Square lattice of spacing d: the quarter [0, d/2]² of the square prism around one crater
(a quarter crater at the origin), or its eighth 0 <= y <= x <= d/2, which the diagonal mirror
y = x halves. Hexagonal lattice (craters at i d + j d/2, j √3 d/2): the
rectangle [0, d/2] × [0, √3 d/2], with quarter craters at two opposite corners. Every side
face of either cell lies on a mirror plane of the lattice, so a lattice-symmetric response
keeps it plane. The area filling factor is F = π a² / (cell area per crater): d² (square),
√3 d²/2 (hexagonal); close packing (2a = d) is F = π/4 and π/(2√3).

Facets: BOTTOM, TOP, MIRROR_X (x = 0), MIRROR_Y (y = 0), SIDE_X (x = Lx), SIDE_Y (y = Ly),
DIAGONAL (y = x, the eighth cell's) and WALL + k for the k-th crater's wall. Built with
OpenCASCADE on rank 0; quadratic tetrahedra, refined towards the walls. Units are those of
the inputs (the crater scene's mm).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from bcfem.params import require

BOTTOM, TOP, DIAGONAL, MIRROR_X, MIRROR_Y, SIDE_X, SIDE_Y = 11, 13, 14, 16, 17, 18, 19
#: the first crater's wall; the k-th is WALL + k
WALL = 20
LATTICES = ("square", "hexagonal")
#: the mirror cells: a quarter of the lattice's rectangle, or (square lattice) an eighth
CELLS = ("quarter", "eighth")
#: the least gap between neighbouring craters' rims, over a: a thinner ligament meshes badly
MIN_LIGAMENT = 0.05


def close_packing(lattice: str) -> float:
    """The filling factor of touching craters (2a = d)."""
    return math.pi / 4 if lattice == "square" else math.pi / (2 * math.sqrt(3))


@dataclass(frozen=True)
class CraterCell:
    """A lattice cell: the lattice, filling factor F, crater base radius a and aspect α = b/a,
    specimen height H, element sizes on the walls, at their rims (where the wall meets the
    plate at an angle: the strains concentrate there) and far from them, over a, and which
    mirror cell (``cell``: the eighth is the square lattice's)."""

    lattice: str = "square"
    filling: float = 0.1
    crater_radius: float = 6.35
    alpha: float = 1.0
    height: float = 35.13
    size_wall: float = 0.3
    size_rim: float = 0.1
    size_far: float = 0.8
    cell: str = "quarter"

    def __post_init__(self):
        require(self.lattice in LATTICES, f"lattice must be one of {list(LATTICES)} (got {self.lattice!r})")
        require(self.cell in CELLS, f"cell must be one of {list(CELLS)} (got {self.cell!r})")
        require(self.cell == "quarter" or self.lattice == "square",
                f"the eighth cell is the square lattice's (got lattice {self.lattice!r})")
        densest = close_packing(self.lattice)
        require(0 < self.filling < densest * (1 - MIN_LIGAMENT) ** 2,
                f"filling must be below close packing, pi a^2 / cell area < {densest:.4g} for a {self.lattice} "
                f"lattice, with a ligament of {MIN_LIGAMENT:g} a between craters (got {self.filling:g}: "
                f"the crater would be as wide as the cell)")
        require(0 < self.alpha <= 1, f"alpha must be in (0, 1] (got {self.alpha:g})")
        require(self.alpha * self.crater_radius < self.height,
                f"height must exceed the crater's depth b = {self.alpha * self.crater_radius:g} (got {self.height:g})")

    @property
    def spacing(self) -> float:
        """d, the distance between neighbouring craters."""
        per_crater = math.pi * self.crater_radius**2 / self.filling
        return math.sqrt(per_crater if self.lattice == "square" else 2 * per_crater / math.sqrt(3))

    @property
    def extent(self) -> tuple[float, float]:
        """(Lx, Ly), the cell's sides."""
        d = self.spacing
        return (d / 2, d / 2) if self.lattice == "square" else (d / 2, math.sqrt(3) * d / 2)

    @property
    def centres(self) -> tuple[tuple[float, float], ...]:
        """The craters' centres on the plate, each a quarter crater in the cell."""
        return ((0.0, 0.0),) if self.lattice == "square" else ((0.0, 0.0), self.extent)

    @property
    def share(self) -> float:
        """The share of each crater the cell holds: a quarter, or an eighth."""
        return 0.125 if self.cell == "eighth" else 0.25

    @property
    def craters(self) -> float:
        """How many craters the cell holds."""
        return len(self.centres) * self.share

    @property
    def area(self) -> float:
        Lx, Ly = self.extent
        return Lx * Ly * (0.5 if self.cell == "eighth" else 1.0)

    @property
    def crater_volume(self) -> float:
        """A whole crater's volume, π b (3a² + b²)/6."""
        a, b = self.crater_radius, self.alpha * self.crater_radius
        return math.pi * b * (3 * a**2 + b**2) / 6

    def estimated_cells(self) -> float:
        """About how many tetrahedra the mesh has (the far size fills the cell, the walls refine)."""
        a = self.crater_radius
        far = self.area * self.height / (self.size_far * a) ** 3 * 6
        walls = self.craters * 4 * math.pi * a**2 / (self.size_wall * a) ** 2 * 8
        rims = self.craters * 4 * (self.size_wall / self.size_rim) ** 2 * 70
        return far + walls + rims

    def build_model(self) -> None:
        import gmsh

        from bcfem.geometry.mesh import graded_tetrahedra

        occ = gmsh.model.occ
        gmsh.model.add("crater_cell")
        a, b = self.crater_radius, self.alpha * self.crater_radius
        rho = (a**2 + b**2) / (2 * b)  # the cap's sphere, centred at z = b - rho
        Lx, Ly = self.extent
        if self.cell == "eighth":  # the triangle 0 <= y <= x <= Lx, extruded
            corners = [occ.addPoint(0, 0, 0), occ.addPoint(Lx, 0, 0), occ.addPoint(Lx, Lx, 0)]
            loop = occ.addCurveLoop([occ.addLine(corners[i], corners[(i + 1) % 3]) for i in range(3)])
            prism = [e for e in occ.extrude([(2, occ.addPlaneSurface([loop]))], 0, 0, self.height) if e[0] == 3]
        else:
            prism = [(3, occ.addBox(0, 0, 0, Lx, Ly, self.height))]
        balls = [(3, occ.addSphere(x, y, b - rho, rho)) for x, y in self.centres]
        body, _ = occ.cut(prism, balls)
        occ.synchronize()
        gmsh.model.addPhysicalGroup(3, [t for _, t in body], 1, name="specimen")
        tol = 1e-9 * max(Lx, Ly, self.height)
        walls = []
        for _, tag in gmsh.model.getEntities(2):
            x, y, z = occ.getCenterOfMass(2, tag)
            planes = ((x, 0, MIRROR_X), (y, 0, MIRROR_Y), (x, Lx, SIDE_X), (y, Ly, SIDE_Y),
                      (z, 0, BOTTOM), (z, self.height, TOP),
                      *(((x - y, 0, DIAGONAL),) if self.cell == "eighth" else ()))
            key = next((k for value, at, k in planes if abs(value - at) < tol), None)
            if key is None:  # a wall: the crater whose centre is nearest
                k = min(range(len(self.centres)), key=lambda i: math.dist((x, y), self.centres[i]))
                key = WALL + k
                walls.append(tag)
            gmsh.model.addPhysicalGroup(2, [tag], key)
        rims = {abs(tag) for wall in walls for _, tag in gmsh.model.getBoundary([(2, wall)], oriented=False)
                if abs(occ.getCenterOfMass(1, abs(tag))[2]) < tol}
        graded_tetrahedra(walls, self.size_wall * a, self.size_far * a, 0.1 * a, 1.5 * a,
                          curves=sorted(rims), size_curves=min(self.size_rim, self.size_wall) * a)


def create_mesh(cell: CraterCell, comm):
    """The cell's mesh, distributed over ``comm`` (dolfinx.io.gmsh.MeshData)."""
    from bcfem.geometry.mesh import distribute

    return distribute(cell.build_model, comm, gdim=3)
