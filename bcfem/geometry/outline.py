"""Planar outlines of a blister's initial delamination: circle, ellipse, rectangle or a
polygon, scaled to the area pi (lengths in units of the equivalent radius R0 = sqrt(A/pi))
and centred on their centroid, meshed by gmsh in the plane z = 0.

Physical groups: the surface ``MEMBRANE`` and its boundary ``EDGE``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

MEMBRANE, EDGE = 1, 1
KINDS = ("circle", "ellipse", "rectangle", "polygon")
#: gmsh's geometry order for curved outlines (P2 cells carry the curved edge exactly enough)
CURVED_ORDER = 2


def polygon_area(points: np.ndarray) -> float:
    """Signed area of a closed polygon (counter-clockwise positive), the shoelace formula."""
    x, y = points[:, 0], points[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))


def _segments_cross(p, q, r, s) -> bool:
    """Whether the closed segments pq and rs intersect (proper or touching)."""

    def orient(a, b, c):
        return np.sign((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))

    o1, o2, o3, o4 = orient(p, q, r), orient(p, q, s), orient(r, s, p), orient(r, s, q)
    if o1 != o2 and o3 != o4:
        return True

    def on(a, b, c):  # c on segment ab, given collinear
        return min(a[0], b[0]) <= c[0] <= max(a[0], b[0]) and min(a[1], b[1]) <= c[1] <= max(a[1], b[1])

    return ((o1 == 0 and on(p, q, r)) or (o2 == 0 and on(p, q, s))
            or (o3 == 0 and on(r, s, p)) or (o4 == 0 and on(r, s, q)))


def check_polygon(points: np.ndarray, name: str = "--vertices") -> None:
    """Raise ValueError (naming ``name``) for fewer than 3 vertices, repeated vertices, zero
    area or a self-intersecting outline."""
    if points.ndim != 2 or points.shape[1] != 2 or len(points) < 3:
        raise ValueError(f"{name} must give at least 3 vertices as 'x y' rows (got shape {points.shape})")
    if not np.all(np.isfinite(points)):
        raise ValueError(f"{name} holds a non-finite coordinate")
    n = len(points)
    edges = [(points[i], points[(i + 1) % n]) for i in range(n)]
    if min(np.hypot(*(b - a)) for a, b in edges) <= 1e-12 * np.ptp(points, axis=0).max():
        raise ValueError(f"{name} repeats a vertex")
    for i in range(n):
        for j in range(i + 2, n):
            if i == 0 and j == n - 1:
                continue  # neighbours through the closing edge
            if _segments_cross(*edges[i], *edges[j]):
                raise ValueError(f"{name} is self-intersecting (edges {i} and {j} cross)")
    if abs(polygon_area(points)) <= 1e-12 * np.ptp(points, axis=0).max() ** 2:
        raise ValueError(f"{name} encloses no area")


def read_vertices(path: str) -> np.ndarray:
    """The polygon of a text file of 'x y' rows (comments with #)."""
    try:
        points = np.loadtxt(path, comments="#", ndmin=2)
    except (OSError, ValueError) as err:
        raise ValueError(f"--vertices {path}: cannot read 'x y' rows ({err})") from None
    check_polygon(points)
    return points


@dataclass(frozen=True)
class Outline:
    """The reference outline, area pi, centroid at the origin.

    Attributes:
        kind: one of :data:`KINDS`.
        aspect: major over minor axis (ellipse) or side (rectangle), >= 1, along x.
        vertices: the polygon's vertices (any scale and position; kind 'polygon').
        size: element size over R0.
    """

    kind: str = "circle"
    aspect: float = 1.0
    vertices: tuple = ()
    size: float = 0.1

    @property
    def curved(self) -> bool:
        return self.kind in ("circle", "ellipse")

    def semi_axes(self) -> tuple[float, float]:
        """(a, b) of the ellipse (a circle's (1, 1)), a b = 1."""
        aspect = self.aspect if self.kind == "ellipse" else 1.0
        return math.sqrt(aspect), 1.0 / math.sqrt(aspect)

    def sides(self) -> tuple[float, float]:
        """(width, height) of the rectangle, width height = pi."""
        return math.sqrt(math.pi * self.aspect), math.sqrt(math.pi / self.aspect)

    def polygon(self) -> np.ndarray:
        """The polygon's vertices, counter-clockwise, scaled to area pi about their centroid."""
        points = np.asarray(self.vertices, dtype=float)
        area = polygon_area(points)
        if area < 0:
            points, area = points[::-1], -area
        x, y = points[:, 0], points[:, 1]
        cross = x * np.roll(y, -1) - np.roll(x, -1) * y
        centroid = np.array([np.dot(x + np.roll(x, -1), cross), np.dot(y + np.roll(y, -1), cross)]) / (6 * area)
        return (points - centroid) * math.sqrt(math.pi / area)

    def corners(self) -> np.ndarray:
        """The corners of the outline's bounding box, counter-clockwise from (min x, min y)."""
        if self.kind == "polygon":
            points = self.polygon()
            (x0, y0), (x1, y1) = points.min(axis=0), points.max(axis=0)
        else:
            half = self.semi_axes() if self.curved else tuple(0.5 * side for side in self.sides())
            (x0, y0), (x1, y1) = (-half[0], -half[1]), half
        return np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]])

    def estimated_cells(self) -> float:
        """Triangles of a uniform mesh of the outline (area pi) at this size."""
        return 2.3 * math.pi / self.size**2

    def build_model(self) -> None:
        """Add and mesh the outline in the current gmsh model (rank 0)."""
        import gmsh

        occ = gmsh.model.occ
        gmsh.model.add("outline")
        if self.curved:
            a, b = self.semi_axes()
            surface = occ.addDisk(0, 0, 0, a, b)
        elif self.kind == "rectangle":
            w, h = self.sides()
            surface = occ.addRectangle(-w / 2, -h / 2, 0, w, h)
        else:
            points = [occ.addPoint(px, py, 0) for px, py in self.polygon()]
            lines = [occ.addLine(points[i], points[(i + 1) % len(points)]) for i in range(len(points))]
            surface = occ.addPlaneSurface([occ.addCurveLoop(lines)])
        occ.synchronize()
        gmsh.model.addPhysicalGroup(2, [surface], MEMBRANE, name="membrane")
        curves = [tag for _, tag in gmsh.model.getBoundary([(2, surface)], oriented=False)]
        gmsh.model.addPhysicalGroup(1, curves, EDGE, name="edge")
        gmsh.option.setNumber("Mesh.MeshSizeMin", self.size)
        gmsh.option.setNumber("Mesh.MeshSizeMax", self.size)
        gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)
        gmsh.model.mesh.generate(2)
        if self.curved:
            gmsh.model.mesh.setOrder(CURVED_ORDER)


def create_mesh(outline: Outline, comm):
    """The outline's mesh, distributed over ``comm`` (dolfinx.io.gmsh.MeshData)."""
    from bcfem.geometry.mesh import distribute

    return distribute(outline.build_model, comm)
