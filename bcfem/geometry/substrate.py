r"""A soft substrate block, meshed with a grading towards the contact line on its top surface.

Axisymmetric: the mesh is the cross-section 0 <= R <= L R0, -H <= Z <= 0 of
the (R, Z) plane, with the axis at R = 0 and the free or loaded top surface on
Z = 0. The contact line is the circle R = R0 on the top surface: the edge of a
blister bonded to the substrate (dissertation chapter 4) or of a droplet
sitting on it (chapter 5). It is the point (R0, 0) of the section, a vertex of
the mesh. The depth H is L R0 by default, a half-space stand-in, or a given
layer thickness h on a rigid base.

The element size grows linearly with the distance d from the contact point,
h(d) = min(h_min + (g - 1) d, h_max): neighbouring elements differ by the
factor g, so the sizes form a geometric sequence and the element count grows
like log(h_max / h_min), not like 1 / h_min. Built with gmsh's built-in kernel
on rank 0 with one thread; every entity has exactly one physical group:

cells: SUBSTRATE (1); facets: WETTED (11, top, R < R0), OUTER_TOP (12, top,
R > R0: the bonded surface of a blister or the dry surface of a droplet), FAR
(13, R = L R0), BOTTOM (14, Z = -H), AXIS (15, R = 0); points, as dolfinx's
``ridge_tags``: CONTACT (21, the contact point (R0, 0)), CORNER (22, the other
four corners). Lengths are in the units of R0 (the scenes use R0 = 1).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from bcfem.params import require

SUBSTRATE = 1
WETTED, OUTER_TOP, FAR, BOTTOM, AXIS = 11, 12, 13, 14, 15
CONTACT, CORNER = 21, 22

# the far-field size of a layer is at most this fraction of its thickness:
# a few quadratic elements across the layer resolve its bending and shear
LAYER_ELEMENTS = 4


@dataclass(frozen=True)
class SubstrateGeometry:
    """Dimensions and mesh sizes of the substrate; sizes are relative to R0.

    Attributes:
        contact_radius: R0, the radius of the contact line, > 0.
        size_factor: L > 1; the block is L R0 wide (the dissertation uses 10).
        thickness: H, the depth of the block; None for L R0 (a half-space
            stand-in), else a layer of thickness h on a rigid base.
        size_contact: element size at the contact point, in (0, size_far).
        size_far: largest element size, in (size_contact, H / R0]; None for
            min(L / 10, H / (4 R0)), so that a thin layer has four elements
            across.
        growth: ratio g of the sizes of neighbouring elements, in (1, 2].
        size_wetted: largest element size on the wetted top (R < R0, the contact point
            too), in R0; the size
            grows from that line into the block with the same ratio g. None: the
            grading from the contact point alone (a membrane over the wetted top, a
            blister's, needs this far from the contact line where the grading is coarse).
        refine: k >= 0 scales every element size by 1 / 2^k (the grading
            function, not the growth ratio of the coarse mesh), for sequences
            of meshes in convergence studies; each level has about four times
            the cells. The meshes are not nested.
        order: geometry order, 1 or 2. The edges are straight, so 2 only adds
            nodes: use it when P2 fields go to XDMF, which needs the geometry
            degree of the field.
    """

    contact_radius: float = 1.0
    size_factor: float = 10.0
    thickness: float | None = None
    size_contact: float = 2e-3
    size_far: float | None = None
    growth: float = 1.2
    size_wetted: float | None = None
    refine: int = 0
    order: int = 1

    def __post_init__(self):
        require(self.contact_radius > 0, f"contact_radius R0 must be > 0 (got {self.contact_radius})")
        require(self.size_factor > 1, f"size_factor L must be > 1 (got {self.size_factor}): "
                "the contact line R0 must lie inside the block")
        require(self.thickness is None or self.thickness > 0,
                f"thickness h must be > 0, or None for L R0 (got {self.thickness})")
        require(self.size_contact > 0, f"size_contact must be > 0 (got {self.size_contact})")
        if self.size_far is not None:
            require(self.size_contact < self.size_far <= self.height / self.contact_radius,
                    f"size_far must be in (size_contact = {self.size_contact}, H / R0 = "
                    f"{self.height / self.contact_radius:g}] (got {self.size_far})")
        require(self.size_contact < self.far_size,
                f"size_contact must be < size_far = {self.far_size:g} (got {self.size_contact})")
        require(1 < self.growth <= 2, f"growth must be in (1, 2] (got {self.growth})")
        require(self.size_wetted is None or self.size_wetted > 0, f"size_wetted must be > 0 (got {self.size_wetted})")
        require(isinstance(self.refine, int) and self.refine >= 0,
                f"refine must be an integer >= 0 (got {self.refine})")
        require(self.order in (1, 2), f"order must be 1 or 2 (got {self.order})")

    @property
    def width(self) -> float:
        """L R0, the radius of the block."""
        return self.size_factor * self.contact_radius

    @property
    def height(self) -> float:
        """H, the depth of the block."""
        return self.width if self.thickness is None else self.thickness

    @property
    def far_size(self) -> float:
        """The largest element size relative to R0 (``size_far`` or its default), before ``refine``."""
        if self.size_far is not None:
            return self.size_far
        return min(self.size_factor / 10, self.height / (LAYER_ELEMENTS * self.contact_radius))

    def element_size(self, distance):
        """The target element size at a distance (a number or an array) from the contact point,
        in absolute units."""
        r0, slope = self.contact_radius, self.growth - 1
        size = np.minimum(self.size_contact * r0 + slope * np.asarray(distance), self.far_size * r0)
        return size / 2**self.refine

    def size_at(self, R, Z):
        """The target element size at the point (R, Z) (numbers or arrays, absolute units): the
        grading from the contact point, capped by that from the wetted top if ``size_wetted``."""
        r0 = self.contact_radius
        size = self.element_size(np.hypot(np.asarray(R) - r0, Z))
        if self.size_wetted is not None:
            beyond = np.hypot(np.maximum(np.asarray(R) - r0, 0.0), Z)  # distance to the segment
            wetted = np.minimum(self.size_wetted * r0 + (self.growth - 1) * beyond, self.far_size * r0)
            size = np.minimum(size, wetted / 2**self.refine)
        return size

    def estimated_cells(self) -> float:
        """The triangles gmsh makes, before meshing: the block's area over that of an equilateral
        triangle of the local size, summed on a grid graded towards the contact point (within
        15 % of gmsh's counts from 700 to 160 000 cells)."""
        h_min = float(self.element_size(0.0))

        def graded(low, high, centre):
            steps = np.geomspace(h_min / 10, max(high - low, h_min), 120)
            return np.unique(np.clip(np.concatenate([[low, high, centre], centre - steps, centre + steps]), low, high))

        r = graded(0.0, self.width, self.contact_radius)
        z = graded(-self.height, 0.0, 0.0)
        R, Z = np.meshgrid(0.5 * (r[1:] + r[:-1]), 0.5 * (z[1:] + z[:-1]))
        size = self.size_at(R, Z)
        return float(np.sum(np.outer(np.diff(z), np.diff(r)) / (np.sqrt(3) / 4 * size**2)))


def build_model(geometry: SubstrateGeometry):
    """Create and mesh the gmsh model (call on rank 0 only, after gmsh.initialize())."""
    import gmsh

    g = geometry
    geo = gmsh.model.geo
    gmsh.model.add("substrate")
    r0, width, height = g.contact_radius, g.width, g.height
    # counter-clockwise from the axis on the top surface, so that line i runs from corner i to i + 1
    corners = [(0, 0), (r0, 0), (width, 0), (width, -height), (0, -height)]
    points = [geo.addPoint(x, z, 0) for x, z in corners]
    lines = [geo.addLine(points[i], points[(i + 1) % 5]) for i in range(5)]
    surface = geo.addPlaneSurface([geo.addCurveLoop(lines)])
    geo.synchronize()

    gmsh.model.addPhysicalGroup(2, [surface], SUBSTRATE, name="substrate")
    for line, tag, name in zip(lines, (WETTED, OUTER_TOP, FAR, BOTTOM, AXIS),
                               ("wetted", "outer_top", "far", "bottom", "axis")):
        gmsh.model.addPhysicalGroup(1, [line], tag, name=name)
    contact = points[1]
    gmsh.model.addPhysicalGroup(0, [contact], CONTACT, name="contact")
    gmsh.model.addPhysicalGroup(0, [p for p in points if p != contact], CORNER, name="corner")

    # the Threshold field interpolates linearly between its sizes, which is
    # element_size(d): h_min at the contact point, slope g - 1, capped at h_max
    h_min, h_max = g.element_size(0.0), g.element_size(float("inf"))
    field = gmsh.model.mesh.field
    distance = field.add("Distance")
    field.setNumbers(distance, "PointsList", [contact])
    threshold = field.add("Threshold")
    field.setNumber(threshold, "InField", distance)
    field.setNumber(threshold, "SizeMin", h_min)
    field.setNumber(threshold, "SizeMax", h_max)
    field.setNumber(threshold, "DistMin", 0.0)
    field.setNumber(threshold, "DistMax", (h_max - h_min) * 2**g.refine / (g.growth - 1))
    background = threshold
    if g.size_wetted is not None:  # the same slope from the wetted top, the smaller size wins
        h_wet = g.size_wetted * r0 / 2**g.refine
        to_top = field.add("Distance")
        field.setNumbers(to_top, "CurvesList", [lines[0]])
        field.setNumber(to_top, "Sampling", max(100, int(4 * r0 / h_wet)))
        wetted = field.add("Threshold")
        field.setNumber(wetted, "InField", to_top)
        field.setNumber(wetted, "SizeMin", h_wet)
        field.setNumber(wetted, "SizeMax", h_max)
        field.setNumber(wetted, "DistMin", 0.0)
        field.setNumber(wetted, "DistMax", max(h_max - h_wet, 0.0) * 2**g.refine / (g.growth - 1))
        background = field.add("Min")
        field.setNumbers(background, "FieldsList", [threshold, wetted])
    field.setAsBackgroundMesh(background)
    gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
    gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
    gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)
    gmsh.model.mesh.generate(2)
    gmsh.model.mesh.setOrder(g.order)


def create_mesh(geometry: SubstrateGeometry, comm, msh_file=None):
    """Build the substrate mesh on rank 0 and distribute it over ``comm``.

    Args:
        geometry: the validated dimensions and sizes.
        comm: the communicator of the mesh.
        msh_file: if given, rank 0 also writes the gmsh model there.

    Returns:
        dolfinx.io.gmsh.MeshData: mesh, cell_tags, facet_tags and ridge_tags
        (the CONTACT and CORNER points).
    """
    from bcfem.geometry.mesh import distribute

    return distribute(lambda: build_model(geometry), comm, msh_file)
