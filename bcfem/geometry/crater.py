r"""A cylindrical specimen with a spherical-cap crater at the centre of its bottom face.

Axisymmetric: the mesh is the half cross-section r >= 0 in the (r, z) plane,
with the bottom face on z = 0 (the plate) and the axis at r = 0. The crater has
base radius a and height b = alpha a; its sphere has radius
rho = (a^2 + b^2)/(2b) and centre (0, b - rho). An optional reinforcement
layer of thickness t lines the crater (the region between the spheres rho and
rho + t, above z = 0).

Geometry is second order (``order=2``) so that the crater surface, and hence
its volume, is exact up to the quadrature of the geometry map. The cells are
triangles, or quadrilaterals (``cell="quadrilateral"``: gmsh's triangles recombined at
twice the size, then every cell split into quadrilaterals, as Abaqus's CAX4H meshes). Built with the
OpenCASCADE kernel on rank 0 with one thread; every entity has exactly one
physical group:

cells: SPECIMEN (1), LAYER (2); facets: BOTTOM (11, the flat face outside the
crater), CRATER (12, the crater surface), TOP (13), AXIS (14), OUTER (15).
Units are those of the inputs (the CLI uses mm).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from bcfem.params import require

SPECIMEN, LAYER = 1, 2
BOTTOM, CRATER, TOP, AXIS, OUTER = 11, 12, 13, 14, 15
#: the cell shapes the mesher makes
CELLS = ("triangle", "quadrilateral")


@dataclass(frozen=True)
class CraterGeometry:
    """Dimensions and mesh sizes; defaults are the experiment's (section 7.2.1), in mm.

    Attributes:
        radius: specimen radius Rs (diameter 25.40 mm).
        height: specimen height Hs.
        crater_radius: crater base radius a (diameter 12.70 mm).
        alpha: crater aspect b/a in (0, 1]; 1 is the hemisphere.
        layer_thickness: reinforcement thickness t, 0 for none, < a/2.
        size_crater: element size on the crater surface, relative to a.
        size_far: element size far from the crater, relative to a.
        order: geometry order (1 or 2).
        cell: "triangle" or "quadrilateral".
    """

    radius: float = 12.70
    height: float = 35.13
    crater_radius: float = 6.35
    alpha: float = 1.0
    layer_thickness: float = 0.0
    size_crater: float = 0.06
    size_far: float = 0.5
    order: int = 2
    cell: str = "triangle"

    def __post_init__(self):
        require(self.radius > 0 and self.height > 0,
                f"specimen radius and height must be > 0 (got {self.radius}, {self.height})")
        require(0 < self.crater_radius < self.radius,
                f"crater radius a must be in (0, Rs = {self.radius}) (got {self.crater_radius})")
        require(0 < self.alpha <= 1, f"alpha = b/a must be in (0, 1] (got {self.alpha}): b > a is not a cap")
        require(0 <= self.layer_thickness < 0.5 * self.crater_radius,
                f"layer thickness t must be in [0, a/2) (got {self.layer_thickness})")
        require(self.crater_height + self.layer_thickness < self.height,
                f"the crater (b + t = {self.crater_height + self.layer_thickness}) must fit in the specimen height")
        require(0 < self.size_crater <= self.size_far, "need 0 < size_crater <= size_far")
        require(self.order in (1, 2), f"order must be 1 or 2 (got {self.order})")
        require(self.cell in CELLS, f"cell must be one of {list(CELLS)} (got {self.cell!r})")

    @property
    def crater_height(self) -> float:
        return self.alpha * self.crater_radius

    @property
    def sphere_radius(self) -> float:
        a, b = self.crater_radius, self.crater_height
        return (a * a + b * b) / (2 * b)

    @property
    def crater_volume(self) -> float:
        """Volume of the spherical cap (the crater at rest)."""
        a, b = self.crater_radius, self.crater_height
        return math.pi * b * (3 * a * a + b * b) / 6


def build_model(geometry: CraterGeometry):
    """Create the gmsh model (call on rank 0 only, after gmsh.initialize())."""
    import gmsh

    g = geometry
    occ = gmsh.model.occ
    gmsh.model.add("crater")
    rho, b = g.sphere_radius, g.crater_height
    zc = b - rho
    box = occ.addRectangle(0, 0, 0, g.radius, g.height)
    cutter = [(2, occ.addDisk(0, zc, 0, rho, rho))]
    layer = None
    if g.layer_thickness > 0:
        outer = occ.addDisk(0, zc, 0, rho + g.layer_thickness, rho + g.layer_thickness)
        inner = occ.addDisk(0, zc, 0, rho, rho)
        shell, _ = occ.cut([(2, outer)], [(2, inner)])
        clip = occ.addRectangle(0, 0, 0, g.radius, g.height)
        layer, _ = occ.intersect(shell, [(2, clip)])
    body, _ = occ.cut([(2, box)], cutter)
    if layer:
        pieces, _ = occ.fragment(body, layer)
    occ.synchronize()

    eps = 1e-6 * g.crater_radius
    surfaces = gmsh.model.getEntities(2)
    layer_surfaces: list[int] = []
    specimen_surfaces: list[int] = []
    for dim, tag in surfaces:
        x, y, _ = occ.getCenterOfMass(dim, tag)
        distance = math.hypot(x, y - zc)
        (layer_surfaces if g.layer_thickness > 0 and distance < rho + g.layer_thickness + eps
         and y < b + g.layer_thickness else specimen_surfaces).append(tag)
    gmsh.model.addPhysicalGroup(2, specimen_surfaces, SPECIMEN, name="specimen")
    if layer_surfaces:
        gmsh.model.addPhysicalGroup(2, layer_surfaces, LAYER, name="layer")

    def midpoint(tag):
        """A point on the curve (an arc's centre of mass is not on it)."""
        lo, hi = gmsh.model.getParametrizationBounds(1, tag)
        return gmsh.model.getValue(1, tag, [0.5 * (lo[0] + hi[0])])[:2]

    groups: dict[int, list[int]] = {BOTTOM: [], CRATER: [], TOP: [], AXIS: [], OUTER: [], 0: []}
    for dim, tag in gmsh.model.getEntities(1):
        x, y = midpoint(tag)
        if abs(y) < eps:
            groups[BOTTOM].append(tag)
        elif abs(y - g.height) < eps:
            groups[TOP].append(tag)
        elif abs(x) < eps:
            groups[AXIS].append(tag)
        elif abs(x - g.radius) < eps:
            groups[OUTER].append(tag)
        elif abs(math.hypot(x, y - zc) - rho) < 1e-3 * rho and y > 0:
            groups[CRATER].append(tag)
        else:
            groups[0].append(tag)  # the layer's outer boundary: interior
    names = {BOTTOM: "bottom", CRATER: "crater", TOP: "top", AXIS: "axis", OUTER: "outer"}
    for key, tags in groups.items():
        if key and tags:
            gmsh.model.addPhysicalGroup(1, tags, key, name=names[key])

    # refinement at the crater and its rim; quadrilaterals are made at twice the size and
    # split in four (a triangle Blossom left over in three): every cell a quadrilateral
    split = 2 if g.cell == "quadrilateral" else 1
    h0, h1 = split * g.size_crater * g.crater_radius, split * g.size_far * g.crater_radius
    field = gmsh.model.mesh.field
    distance = field.add("Distance")
    field.setNumbers(distance, "CurvesList", groups[CRATER])
    field.setNumber(distance, "Sampling", 200)
    threshold = field.add("Threshold")
    field.setNumber(threshold, "InField", distance)
    field.setNumber(threshold, "SizeMin", h0)
    field.setNumber(threshold, "SizeMax", h1)
    field.setNumber(threshold, "DistMin", 0.1 * g.crater_radius)
    field.setNumber(threshold, "DistMax", 1.5 * g.crater_radius)
    rim = gmsh.model.getEntities(0)
    rim_points = [t for d, t in rim if abs(occ.getCenterOfMass(d, t)[0] - g.crater_radius) < eps
                  and abs(occ.getCenterOfMass(d, t)[1]) < eps]
    rim_field = field.add("Distance")
    field.setNumbers(rim_field, "PointsList", rim_points)
    rim_threshold = field.add("Threshold")
    field.setNumber(rim_threshold, "InField", rim_field)
    field.setNumber(rim_threshold, "SizeMin", 0.4 * h0)
    field.setNumber(rim_threshold, "SizeMax", h1)
    field.setNumber(rim_threshold, "DistMin", 0.05 * g.crater_radius)
    field.setNumber(rim_threshold, "DistMax", 0.5 * g.crater_radius)
    minimum = field.add("Min")
    field.setNumbers(minimum, "FieldsList", [threshold, rim_threshold])
    field.setAsBackgroundMesh(minimum)
    gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
    gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
    gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)
    if g.cell == "quadrilateral":  # frontal-Delaunay for quads, Blossom's matching, then the split
        gmsh.option.setNumber("Mesh.Algorithm", 8)
        gmsh.option.setNumber("Mesh.RecombineAll", 1)
        gmsh.option.setNumber("Mesh.RecombinationAlgorithm", 1)
        gmsh.option.setNumber("Mesh.SubdivisionAlgorithm", 1)
    gmsh.model.mesh.generate(2)
    gmsh.model.mesh.setOrder(g.order)
    # dolfinx takes one cell type: a recombination that left a triangle is refused here
    shapes = {gmsh.model.mesh.getElementProperties(t)[0].split()[0].lower()
              for t in gmsh.model.mesh.getElementTypes(2)}
    if shapes != {g.cell}:
        raise RuntimeError(f"the mesh has cells {sorted(shapes)}, not only {g.cell}s")


def create_mesh(geometry: CraterGeometry, comm, msh_file=None):
    """Build the crater mesh on rank 0 and distribute it.

    Returns:
        dolfinx.io.gmsh.MeshData (mesh, cell_tags, facet_tags, ...).
    """
    from bcfem.geometry.mesh import distribute

    return distribute(lambda: build_model(geometry), comm, msh_file)
