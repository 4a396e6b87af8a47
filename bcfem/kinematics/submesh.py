r"""Fields on part of a body's boundary: a codimension-1 submesh coupled to the body.

A :class:`BoundaryPatch` is the submesh of the parent's facets with one tag (e.g. the
wetted top of a substrate, where a membrane lifts off). A field on it is a state of
the context like any other; every form that mixes it with parent fields is integrated
over the *parent's* facets (``kin.surface_integral(density, tag)``), and the entity map
that relates the two meshes reaches dolfinx through ``Context.entity_maps``.

Two traps of dolfinx 0.11 (FFCx 0.11, UFL 2026.1) shape this module:

- ``ufl.grad`` of a submesh function inside a parent facet integral is silently wrong
  (FFCx reads the submesh Jacobian from the first nodes of the parent *cell*, not from
  the facet). :meth:`BoundaryPatch.grad` gives the right surface gradient: both
  ``grad(f)`` and the gradient of the submesh's own coordinate field :math:`x_\Gamma`
  carry the same wrong inverse Jacobian :math:`K`, so
  :math:`\nabla f\,\nabla x_\Gamma^T / |\nabla x_\Gamma|^2` cancels it
  (:math:`= a\,t/|t|^2` with :math:`a = df/d\xi`, :math:`t = dx/d\xi`). Where ``grad``
  is right (a later dolfinx), :math:`\nabla x_\Gamma` is the tangential projector and
  the expression is :math:`\nabla f` itself. Checked on straight and curved (P2)
  parent facets.
- ``ufl.SpatialCoordinate(submesh)`` is wrong there too: use the parent's coordinate.
"""

from __future__ import annotations

import numpy as np
import ufl
from dolfinx import fem, mesh


class BoundaryPatch:
    """The submesh of the parent facets tagged ``tag``, and its coupling to the parent.

    Args:
        parent: the body's mesh.
        facet_tags: facet markers of ``parent``.
        tag: the marker of the patch's facets.
    """

    def __init__(self, parent: mesh.Mesh, facet_tags: mesh.MeshTags, tag: int):
        tdim = parent.topology.dim
        if facet_tags.dim != tdim - 1:
            raise ValueError(f"facet_tags must mark facets (dim {tdim - 1}), got dim {facet_tags.dim}")
        self.parent = parent
        self.tag = tag
        self.facets = facet_tags.find(tag)
        self.mesh, self.entity_map, self.vertex_map, self.node_map = mesh.create_submesh(
            parent, tdim - 1, self.facets)
        degree = self.mesh.geometry.cmaps[0].degree
        gdim = self.mesh.geometry.dim
        self._x = fem.Function(fem.functionspace(self.mesh, ("Lagrange", degree, (gdim,))))
        self._x.interpolate(lambda x: x[:gdim])

    def space(self, element) -> fem.FunctionSpace:
        """A function space on the patch, e.g. ``("Lagrange", 2, (2,))``."""
        return fem.functionspace(self.mesh, element)

    def state(self, ctx, name: str, element) -> fem.Function:
        """The unknown ``name`` of ``ctx`` on this patch, created on first request."""
        if name in ctx.states:
            return ctx.states[name]
        return ctx.state_in(name, self.space(element), self.entity_map)

    def grad(self, f):
        """The surface gradient of a patch function ``f`` (scalar or vector), for use in
        integrals over the parent's facets (``grad(f)`` alone is wrong there in 0.11)."""
        gx = ufl.grad(self._x)
        return ufl.dot(ufl.grad(f), gx.T) / ufl.inner(gx, gx)

    def vertex_dofs(self, space: fem.FunctionSpace, point) -> np.ndarray:
        """The local dofs of ``space`` (a patch space or one of its sub-spaces) at the patch
        vertex ``point`` (empty on ranks without it), e.g. for a Dirichlet condition."""
        p = np.zeros(3)
        p[: len(point)] = point
        tol = 1e-10 * max(1.0, float(np.abs(p).max()))
        vertices = mesh.locate_entities(
            self.mesh, 0, lambda x: np.all(np.abs(x - p[:, None]) <= tol, axis=0))
        self.mesh.topology.create_connectivity(0, self.mesh.topology.dim)
        return fem.locate_dofs_topological(space, 0, vertices)

