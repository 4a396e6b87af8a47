r"""A cylindrical specimen with a double-chamber crater: a cylindrical crater with a spherical protuberance.

The octopus-inspired design of Baik et al. (Nature 2017), dissertation
chapter 9. Axisymmetric: the mesh is the half cross-section r >= 0 of the
(r, z) plane, with the bottom face on z = 0 (the plate) and the axis at r = 0.
The crater is the cylinder 0 <= r <= r0, 0 <= z <= H in the bottom face. A ball
of radius R0 centred on the axis at z_c = s + R0 hangs from the crater roof,
its lowest point a gap s above the plate; the ball reaches past the roof plane
(s + 2 R0 > H) and the solid is the union of the specimen without the crater
and the ball. The protuberance is thus the spherical zone of height
h = H - s below the roof, attached to it by a neck of radius
a_n = sqrt(h (2 R0 - h)). At rest the cavity's volume is

.. math:: V = \pi r_0^2 H - \frac{\pi h^2 (3 R_0 - h)}{3}, \qquad h = H - s.

Under compression the sidewall bulges onto the protuberance, closest to it at
the height of the ball's equator, which splits the cavity into the chamber C1
on the plate and the chamber C2 under the roof (:mod:`bcfem.scenes.crater_double.chambers`).

Geometry is second order (``order=2``) so that the arcs, and hence volumes,
are exact up to the quadratic interpolation of the circle. Built with the
OpenCASCADE kernel on rank 0 with one thread; every entity has exactly one
physical group:

cells: SPECIMEN (1); facets: BOTTOM (11, the face on the plate, r > r0),
TOP (13), AXIS (14), OUTER (15) (the numbers of :mod:`bcfem.geometry.crater`),
SIDEWALL (16, r = r0, 0 < z < H), ROOF (17, z = H, a_n < r < r0),
PROTUBERANCE (18, the spherical zone); points, as dolfinx's ``ridge_tags``:
RIM (21, (r0, 0) on the plate), ROOF_RIM (22, (r0, H)), NECK (23, (a_n, H)),
CORNER (24, the ball's lowest point (0, s) and the specimen's corners),
EQUATOR (25, (R0, z_c), the seam of OpenCASCADE's disk: a vertex on the
ball's equator, present when the equator lies below the roof).
With R0 = 0 there is no protuberance: a plain cylindrical crater, its roof
spanning 0 < r < r0 (no PROTUBERANCE facets, NECK or EQUATOR points).
Units are those of the inputs (the CLI uses mm).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from bcfem.params import require

SPECIMEN = 1
BOTTOM, TOP, AXIS, OUTER = 11, 13, 14, 15
SIDEWALL, ROOF, PROTUBERANCE = 16, 17, 18
RIM, ROOF_RIM, NECK, CORNER, EQUATOR = 21, 22, 23, 24, 25

#: the cavity's walls (the plate closes it)
WALLS = (SIDEWALL, ROOF, PROTUBERANCE)

# the dissertation's design (section 9.3), relative to the crater height H
CRATER_RADIUS, PROTUBERANCE_RADIUS, GAP = 0.52, 0.5, 0.03
# the default specimen, relative to r0 and H: a cylindrical hole perturbs a
# uniform far field by ~ (r0 / r)^2, 4 % at r = 5 r0, and 4 H of solid (7.7 r0)
# lies above the roof
SPECIMEN_RADIUS, SPECIMEN_HEIGHT = 5.0, 5.0
# neighbouring elements differ by at most this factor in the graded zones
GROWTH = 1.25


def cap_volume(sphere_radius: float, cap_height: float) -> float:
    """The volume of the spherical cap of height ``cap_height`` in [0, 2 R] of a ball of radius R."""
    h = min(max(cap_height, 0.0), 2 * sphere_radius)
    return math.pi * h * h * (3 * sphere_radius - h) / 3


@dataclass(frozen=True)
class DoubleCraterGeometry:
    """Dimensions and mesh sizes; the defaults are the dissertation's ratios (section 9.3).

    A field left at None takes its default relative to the crater height H (or
    to r0 for the specimen radius); the properties give the resolved values.

    Attributes:
        crater_height: H, the depth of the cylindrical crater, > 0.
        crater_radius: r0, None for 0.52 H.
        protuberance_radius: R0, None for 0.5 H, 0 for none (a plain
            cylindrical crater); the protuberance's widest radius (R0, or the
            neck radius if the centre lies above the roof) must be < r0.
        gap: s, the height of the ball's lowest point above the plate, in
            (0, H); None for 0.03 H. The ball must reach the roof: s + 2 R0 > H.
        radius: specimen radius, > r0; None for 5 r0 (far field within 4 %).
        height: specimen height, > H; None for 5 H.
        size_wall: element size on the crater's walls, relative to H.
        size_contact: element size where the sidewall comes closest to the
            protuberance (the likely contact zone), relative to H.
        size_corner: element size at the rims (r0, 0), (r0, H) and the neck,
            relative to H.
        size_far: largest element size, relative to H.
        order: geometry order (1 or 2).
    """

    crater_height: float = 1.0
    crater_radius: float | None = None
    protuberance_radius: float | None = None
    gap: float | None = None
    radius: float | None = None
    height: float | None = None
    size_wall: float = 0.02
    size_contact: float = 0.005
    size_corner: float = 0.005
    size_far: float = 0.25
    order: int = 2

    def __post_init__(self):
        H = self.crater_height
        require(H > 0, f"crater_height H must be > 0 (got {H})")
        r0, R0, s = self.r0, self.R0, self.s
        require(r0 > 0, f"crater_radius r0 must be > 0 (got {r0})")
        require(R0 >= 0, f"protuberance_radius R0 must be >= 0 (got {R0}; 0: none)")
        require(0 < s < H, f"gap s must be in (0, H = {H:g}) (got {s}): the protuberance must "
                "not reach the plate and must hang inside the crater")
        require(R0 == 0 or s + 2 * R0 > H, f"protuberance_radius R0 must be > (H - s) / 2 = {(H - s) / 2:g} "
                f"(got {R0}): the ball must reach the roof to hang from it")
        require(R0 == 0 or self.widest_radius < r0,
                f"protuberance_radius R0 = {R0:g} must leave a gap to the sidewall: its widest radius "
                f"{self.widest_radius:g} must be < crater_radius r0 = {r0:g}")
        require(self.specimen_radius > r0,
                f"radius (specimen) must be > crater_radius r0 = {r0:g} (got {self.specimen_radius})")
        require(self.specimen_height > H,
                f"height (specimen) must be > crater_height H = {H:g} (got {self.specimen_height})")
        require(0 < self.size_contact <= self.size_wall and 0 < self.size_corner <= self.size_wall,
                f"size_contact and size_corner must be in (0, size_wall = {self.size_wall}] "
                f"(got {self.size_contact}, {self.size_corner})")
        require(self.size_wall <= self.size_far,
                f"size_wall must be <= size_far = {self.size_far} (got {self.size_wall})")
        require(self.order in (1, 2), f"order must be 1 or 2 (got {self.order})")

    # resolved dimensions
    @property
    def r0(self) -> float:
        """Crater radius r0."""
        return CRATER_RADIUS * self.crater_height if self.crater_radius is None else self.crater_radius

    @property
    def R0(self) -> float:
        """Protuberance (ball) radius R0."""
        if self.protuberance_radius is None:
            return PROTUBERANCE_RADIUS * self.crater_height
        return self.protuberance_radius

    @property
    def s(self) -> float:
        """Gap s between the ball's lowest point and the plate."""
        return GAP * self.crater_height if self.gap is None else self.gap

    @property
    def specimen_radius(self) -> float:
        return SPECIMEN_RADIUS * self.r0 if self.radius is None else self.radius

    @property
    def specimen_height(self) -> float:
        return SPECIMEN_HEIGHT * self.crater_height if self.height is None else self.height

    @property
    def has_protuberance(self) -> bool:
        return self.R0 > 0

    @property
    def centre_height(self) -> float:
        """z_c = s + R0, the height of the ball's centre."""
        return self.s + self.R0

    @property
    def protuberance_height(self) -> float:
        """h = H - s, the height of the protuberance below the roof."""
        return self.crater_height - self.s

    @property
    def neck_radius(self) -> float:
        """a_n = sqrt(h (2 R0 - h)), the radius of the circle where the ball meets the roof."""
        h = self.protuberance_height
        return math.sqrt(max(h * (2 * self.R0 - h), 0.0))

    @property
    def widest_radius(self) -> float:
        """The protuberance's largest radius: R0 if its equator is below the roof, else a_n."""
        return self.R0 if self.centre_height <= self.crater_height else self.neck_radius

    @property
    def contact_height(self) -> float:
        """The height at which the sidewall comes closest to the protuberance (its equator, or the roof)."""
        return min(self.centre_height, self.crater_height)

    def protuberance_radius_at(self, z: float) -> float:
        """The radius of the protuberance's surface at height z in [s, H] (0 below s)."""
        return math.sqrt(max(self.R0**2 - (z - self.centre_height) ** 2, 0.0)) if z >= self.s else 0.0

    # closed forms at rest
    @property
    def protuberance_volume(self) -> float:
        """The ball's volume inside the crater (below the roof): the cap pi h^2 (3 R0 - h) / 3."""
        return cap_volume(self.R0, self.protuberance_height)

    @property
    def crater_volume(self) -> float:
        """The cavity's volume at rest, pi r0^2 H minus the protuberance."""
        return math.pi * self.r0**2 * self.crater_height - self.protuberance_volume

    @property
    def sidewall_area(self) -> float:
        return 2 * math.pi * self.r0 * self.crater_height

    @property
    def roof_area(self) -> float:
        """The annulus a_n < r < r0 of the roof."""
        return math.pi * (self.r0**2 - self.neck_radius**2)

    @property
    def protuberance_area(self) -> float:
        """The spherical zone of height h: 2 pi R0 h (Archimedes)."""
        return 2 * math.pi * self.R0 * self.protuberance_height

    @property
    def specimen_volume(self) -> float:
        return math.pi * self.specimen_radius**2 * self.specimen_height - self.crater_volume

    def chamber_volumes(self, z: float) -> tuple[float, float]:
        """The volumes at rest of the cavity below and above the plane at height z in [0, H]:
        (pi r0^2 z - cap(z - s), V - that), the chambers C1 and C2 split by a flat plug."""
        require(0 <= z <= self.crater_height, f"split height must be in [0, H] (got {z})")
        lower = math.pi * self.r0**2 * z - cap_volume(self.R0, z - self.s)
        return lower, self.crater_volume - lower


def _graded(field, distance: int, size: float, dist_min: float, size_max: float) -> int:
    """A Threshold field: ``size`` within ``dist_min``, then growing by GROWTH per element up to ``size_max``."""
    threshold = field.add("Threshold")
    field.setNumber(threshold, "InField", distance)
    field.setNumber(threshold, "SizeMin", size)
    field.setNumber(threshold, "SizeMax", size_max)
    field.setNumber(threshold, "DistMin", dist_min)
    field.setNumber(threshold, "DistMax", dist_min + (size_max - size) / (GROWTH - 1))
    return threshold


def build_model(geometry: DoubleCraterGeometry):
    """Create and mesh the gmsh model (call on rank 0 only, after gmsh.initialize())."""
    import gmsh

    g = geometry
    occ = gmsh.model.occ
    gmsh.model.add("double_crater")
    H, r0, R0, zc = g.crater_height, g.r0, g.R0, g.centre_height
    Rs, Hs = g.specimen_radius, g.specimen_height
    box = occ.addRectangle(0, 0, 0, Rs, Hs)
    cavity = [(2, occ.addRectangle(0, 0, 0, r0, H))]
    if g.has_protuberance:
        cavity, _ = occ.cut(cavity, [(2, occ.addDisk(0, zc, 0, R0, R0))])
    occ.cut([(2, box)], cavity)
    occ.synchronize()
    surfaces = [tag for _, tag in gmsh.model.getEntities(2)]
    if len(surfaces) != 1:
        raise RuntimeError(f"expected one surface, OpenCASCADE made {len(surfaces)}")
    gmsh.model.addPhysicalGroup(2, surfaces, SPECIMEN, name="specimen")

    eps = 1e-7 * H

    def midpoint(tag):
        """A point on the curve (an arc's centre of mass is not on it)."""
        lo, hi = gmsh.model.getParametrizationBounds(1, tag)
        return gmsh.model.getValue(1, tag, [0.5 * (lo[0] + hi[0])])[:2]

    groups: dict[int, list[int]] = {BOTTOM: [], TOP: [], AXIS: [], OUTER: [], SIDEWALL: [], ROOF: [], PROTUBERANCE: []}
    for _, tag in gmsh.model.getEntities(1):
        x, y = midpoint(tag)
        if abs(y) < eps:
            key = BOTTOM
        elif abs(y - Hs) < eps:
            key = TOP
        elif abs(x) < eps:
            key = AXIS
        elif abs(x - Rs) < eps:
            key = OUTER
        elif abs(x - r0) < eps:
            key = SIDEWALL
        elif abs(y - H) < eps:
            key = ROOF
        elif g.has_protuberance and abs(math.hypot(x, y - zc) - R0) < 1e-6 * R0:
            key = PROTUBERANCE
        else:
            raise RuntimeError(f"curve {tag} at ({x:g}, {y:g}) belongs to no boundary part")
        groups[key].append(tag)
    names = {BOTTOM: "bottom", TOP: "top", AXIS: "axis", OUTER: "outer", SIDEWALL: "sidewall",
             ROOF: "roof", PROTUBERANCE: "protuberance"}
    for key, tags in groups.items():
        if tags:  # no protuberance: none
            gmsh.model.addPhysicalGroup(1, tags, key, name=names[key])

    special = {RIM: (r0, 0.0), ROOF_RIM: (r0, H)}
    if g.has_protuberance:
        special |= {NECK: (g.neck_radius, H), EQUATOR: (R0, zc)}
    points: dict[int, list[int]] = {key: [] for key in (RIM, ROOF_RIM, NECK, CORNER, EQUATOR)}
    for _, tag in gmsh.model.getEntities(0):
        x, y = gmsh.model.getValue(0, tag, [])[:2]
        key = next((k for k, (px, py) in special.items() if math.hypot(x - px, y - py) < eps), CORNER)
        points[key].append(tag)
    for key, name in ((RIM, "rim"), (ROOF_RIM, "roof_rim"), (NECK, "neck"), (CORNER, "corner"),
                      (EQUATOR, "equator")):
        if points[key]:
            gmsh.model.addPhysicalGroup(0, points[key], key, name=name)

    # sizes: fine on the walls, finer where the sidewall and the ball come
    # closest (both sides of the likely contact) and at the re-entrant corners
    h_wall, h_far = g.size_wall * H, g.size_far * H
    field = gmsh.model.mesh.field
    walls = field.add("Distance")
    field.setNumbers(walls, "CurvesList", groups[SIDEWALL] + groups[ROOF] + groups[PROTUBERANCE])
    field.setNumber(walls, "Sampling", 400)
    sizes = [_graded(field, walls, h_wall, 0.05 * H, h_far)]
    zs = g.contact_height
    for px in (r0, g.protuberance_radius_at(zs)) if g.has_protuberance else ():
        near = field.add("MathEval")
        field.setString(near, "F", f"Sqrt((x - {px!r})^2 + (y - {zs!r})^2)")
        sizes.append(_graded(field, near, g.size_contact * H, 0.15 * H, h_far))
    corners = field.add("Distance")
    field.setNumbers(corners, "PointsList", points[RIM] + points[ROOF_RIM] + points[NECK])
    sizes.append(_graded(field, corners, g.size_corner * H, 0.0, h_far))
    minimum = field.add("Min")
    field.setNumbers(minimum, "FieldsList", sizes)
    field.setAsBackgroundMesh(minimum)
    gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
    gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
    gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)
    gmsh.model.mesh.generate(2)
    gmsh.model.mesh.setOrder(g.order)


def create_mesh(geometry: DoubleCraterGeometry, comm, msh_file=None):
    """Build the double-crater mesh on rank 0 and distribute it over ``comm``.

    Args:
        geometry: the validated dimensions and sizes.
        comm: the communicator of the mesh.
        msh_file: if given, rank 0 also writes the gmsh model there.

    Returns:
        dolfinx.io.gmsh.MeshData: mesh, cell_tags, facet_tags and ridge_tags
        (RIM, ROOF_RIM, NECK, CORNER, EQUATOR).
    """
    from bcfem.geometry.mesh import distribute

    return distribute(lambda: build_model(geometry), comm, msh_file)
