"""A mesh of the outline that is exactly symmetric about both axes: gmsh meshes the quarter
x, y >= 0, and its nodes and triangles are reflected into the other three quarters.

gmsh's mesh of the whole outline is unstructured, so the discrete blister has no mirror
symmetry: a symmetry-breaking bifurcation of the continuum becomes an imperfect one, and the
arc-length path turns smoothly onto one side without the tangent ever losing stability. On
this mesh the discrete problem keeps both mirrors, the symmetric branch stays a solution past
the bifurcation (Newton converges to it whether or not it is stable), and the inertia of the
tangent counts the bifurcation exactly. Circles, ellipses and rectangles (centred on the
origin, axes along x and y) only.
"""

from __future__ import annotations

import numpy as np

from bcfem.geometry.outline import CURVED_ORDER, EDGE, MEMBRANE, Outline

#: gmsh element types: (triangle, line) of order 1 and 2
_TYPES = {1: (2, 1), 2: (9, 8)}
#: the nodes of a gmsh triangle (vertices, then edges 01 12 20) with vertices 1 and 2 swapped
_SWAP = {3: [0, 2, 1], 6: [0, 2, 1, 5, 4, 3]}
_SNAP = 1e-12  # coordinates closer than this to an axis are on it


def build_mirrored_model(outline: Outline) -> None:
    """Mesh the quarter of ``outline`` in x, y >= 0, reflect it, and put the whole mesh into
    the current gmsh model as discrete entities with the physical groups ``MEMBRANE`` and
    ``EDGE`` of :mod:`bcfem.geometry.outline` (rank 0)."""
    import gmsh

    if outline.kind not in ("circle", "ellipse", "rectangle"):
        raise ValueError(f"a mirrored mesh needs a circle, an ellipse or a rectangle (got {outline.kind})")
    occ = gmsh.model.occ
    gmsh.model.add("quarter")
    if outline.curved:
        a, b = outline.semi_axes()
        whole = occ.addDisk(0, 0, 0, a, b)
    else:
        w, h = outline.sides()
        whole = occ.addRectangle(-w / 2, -h / 2, 0, w, h)
    box = occ.addRectangle(0, 0, 0, 10.0, 10.0)
    (quarter,), _ = occ.intersect([(2, whole)], [(2, box)])
    occ.synchronize()
    gmsh.option.setNumber("Mesh.MeshSizeMin", outline.size)
    gmsh.option.setNumber("Mesh.MeshSizeMax", outline.size)
    gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)
    gmsh.model.mesh.generate(2)
    order = CURVED_ORDER if outline.curved else 1
    if outline.curved:
        gmsh.model.mesh.setOrder(order)
    triangle, line = _TYPES[order]
    tags, coords, _ = gmsh.model.mesh.getNodes()
    points = coords.reshape(-1, 3)[:, :2].copy()
    points[np.abs(points) < _SNAP] = 0.0
    index = np.zeros(int(tags.max()) + 1, dtype=np.int64)
    index[tags.astype(np.int64)] = np.arange(len(tags))
    _, nodes = gmsh.model.mesh.getElementsByType(triangle, quarter[1])
    cells = index[nodes.astype(np.int64)].reshape(len(nodes) // (3 * order), -1)
    pieces = []
    for _, curve in gmsh.model.getBoundary([quarter], oriented=False):
        _, nodes = gmsh.model.mesh.getElementsByType(line, abs(curve))
        segments = index[nodes.astype(np.int64)].reshape(-1, order + 1)
        if not np.all(np.any(points[segments] == 0.0, axis=2).all(axis=1)):  # not a cut along an axis
            pieces.append(segments)
    edges = np.vstack(pieces)
    gmsh.model.remove()

    # the four reflections; one that flips orientation swaps two vertices so cells stay counter-clockwise
    all_points, all_cells, all_edges = [], [], []
    for k, (sx, sy) in enumerate(((1, 1), (-1, 1), (-1, -1), (1, -1))):
        offset = k * len(points)
        all_points.append(points * (sx, sy))
        all_cells.append(cells[:, _SWAP[cells.shape[1]]] + offset if sx * sy < 0 else cells + offset)
        all_edges.append(edges + offset)
    merged, unique, cells, edges = _merge(np.vstack(all_points), np.vstack(all_cells), np.vstack(all_edges))

    gmsh.model.add("mirrored")
    curve = gmsh.model.addDiscreteEntity(1)
    surface = gmsh.model.addDiscreteEntity(2, -1, [curve])
    node_tags = np.arange(1, len(unique) + 1)
    xyz = np.column_stack([unique, np.zeros(len(unique))]).ravel()
    gmsh.model.mesh.addNodes(2, surface, node_tags, xyz)
    gmsh.model.mesh.addElementsByType(surface, triangle, [], (merged[cells] + 1).ravel())
    gmsh.model.mesh.addElementsByType(curve, line, [], (merged[edges] + 1).ravel())
    gmsh.model.addPhysicalGroup(2, [surface], MEMBRANE, name="membrane")
    gmsh.model.addPhysicalGroup(1, [curve], EDGE, name="edge")


def _merge(points, cells, edges):
    """(old node -> new node, the distinct points, cells, edges): the nodes on an axis, which
    two reflections share, become one."""
    scale = 1.0 / (1e3 * _SNAP)
    keys = np.rint(points * scale).astype(np.int64)
    _, first, merged = np.unique(keys, axis=0, return_index=True, return_inverse=True)
    return merged.ravel(), points[first], cells, edges


def create_mirrored_mesh(outline: Outline, comm):
    """The mirrored mesh of ``outline``, distributed over ``comm`` (dolfinx.io.gmsh.MeshData)."""
    from bcfem.geometry.mesh import distribute

    return distribute(lambda: build_mirrored_model(outline), comm)
