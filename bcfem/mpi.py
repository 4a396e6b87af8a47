"""MPI-correct global scalars: the one place where ranks are summed.

Every volume, area, energy or point value reported by bcfem goes through
these helpers, so no caller can forget the reduction.
"""

from __future__ import annotations

from mpi4py import MPI

import numpy as np
from dolfinx import fem, geometry


def global_sum(form: fem.Form) -> float:
    """Assemble a compiled scalar form and sum it over the form's ranks."""
    comm = form.mesh.comm
    return comm.allreduce(fem.assemble_scalar(form), op=MPI.SUM)


def real_value(f: fem.Function) -> float:
    """Value of a function on the real (global-constant) element, on every rank."""
    imap = f.function_space.dofmap.index_map
    owned = f.x.array[: imap.size_local * f.function_space.dofmap.bs]
    return imap.comm.allreduce(float(owned.sum()), op=MPI.SUM)


class PointEvaluator:
    """Evaluates UFL expressions at one fixed reference point, on every rank.

    The owning cell is found once; the rank that owns it evaluates and the
    value is shared with a sum reduction (other ranks contribute zero).
    """

    def __init__(self, mesh, point):
        self.comm = mesh.comm
        x = np.zeros((1, 3))
        x[0, : len(point)] = point
        tdim = mesh.topology.dim
        imap = mesh.topology.index_map(tdim)
        tree = geometry.bb_tree(mesh, tdim, padding=1e-12)
        candidates = geometry.compute_collisions_points(tree, x)
        cells = geometry.compute_colliding_cells(mesh, candidates, x).links(0)
        owned = [c for c in cells if c < imap.size_local]
        rank_with_cell = self.comm.rank if owned else self.comm.size
        self.owner = self.comm.allreduce(rank_with_cell, op=MPI.MIN)
        if self.owner == self.comm.size:
            raise ValueError(f"point {point} lies outside the mesh")
        self.cell = np.array(owned[:1] if self.comm.rank == self.owner else [], dtype=np.int32)
        self.mesh = mesh
        self.x = x

    def reference_point(self):
        """The point in the owning cell's reference coordinates (owner rank only)."""
        if self.cell.size == 0:
            return None
        cell_geometry = self.mesh.geometry.x[self.mesh.geometry.dofmaps[0][self.cell[0]]]
        dim = self.mesh.geometry.dim
        return self.mesh.geometry.cmaps[0].pull_back(self.x[:, :dim], cell_geometry[:, :dim])

    def expression(self, expr) -> PointExpression:
        """Compile ``expr`` for evaluation at this point."""
        return PointExpression(self, expr)


class PointExpression:
    """A compiled expression bound to a :class:`PointEvaluator`; call it for the value."""

    def __init__(self, evaluator: PointEvaluator, expr):
        self.ev = evaluator
        ref = evaluator.reference_point()
        ref = np.zeros((1, evaluator.mesh.topology.dim)) if ref is None else ref
        self.compiled = fem.Expression(expr, ref)
        self.shape = self.compiled.value_size

    def __call__(self) -> np.ndarray:
        value = np.zeros(self.shape)
        if self.ev.cell.size:
            value[:] = self.compiled.eval(self.ev.mesh, self.ev.cell).reshape(-1)
        return self.ev.comm.allreduce(value, op=MPI.SUM)


def point_value(expr, mesh, point) -> np.ndarray:
    """One-off evaluation of ``expr`` at ``point`` (compiles each call; prefer PointEvaluator)."""
    return PointEvaluator(mesh, point).expression(expr)()


def cell_maximum(mesh, expr, degree: int = 1):
    """A callable giving the global maximum of ``expr`` sampled at Gauss points of every cell."""
    import basix

    points, _ = basix.make_quadrature(mesh.basix_cell(), max(2 * degree, 1))
    compiled = fem.Expression(expr, points)
    cells = np.arange(mesh.topology.index_map(mesh.topology.dim).size_local, dtype=np.int32)

    def maximum() -> float:
        local = compiled.eval(mesh, cells).max() if cells.size else -np.inf
        return mesh.comm.allreduce(float(local), op=MPI.MAX)

    return maximum


def coordinate_range(mesh, axis: int = 0) -> tuple[float, float]:
    """The smallest and largest reference coordinate ``axis`` of the mesh, on every rank."""
    x = mesh.geometry.x[:, axis]
    lo = mesh.comm.allreduce(float(x.min()) if x.size else np.inf, op=MPI.MIN)
    hi = mesh.comm.allreduce(float(x.max()) if x.size else -np.inf, op=MPI.MAX)
    return lo, hi


def sample(function: fem.Function, points: np.ndarray) -> np.ndarray:
    """Values of ``function`` at ``points`` (n x 3), on every rank: each point is evaluated by
    the ranks that own a cell containing it, and a point on a rank boundary, found twice, is
    averaged; a point outside the mesh is NaN."""
    mesh = function.function_space.mesh
    tdim = mesh.topology.dim
    tree = geometry.bb_tree(mesh, tdim, padding=1e-12)
    colliding = geometry.compute_colliding_cells(mesh, geometry.compute_collisions_points(tree, points), points)
    owned = mesh.topology.index_map(tdim).size_local
    size = function.function_space.dofmap.index_map_bs * max(1, int(np.prod(function.ufl_shape)) //
                                                             function.function_space.dofmap.index_map_bs)
    values = np.zeros((len(points), size))
    found = np.zeros(len(points))
    for k in range(len(points)):
        cells = [c for c in colliding.links(k) if c < owned]
        if cells:
            values[k] = function.eval(points[k:k + 1], np.array(cells[:1], dtype=np.int32)).reshape(-1)
            found[k] = 1
    values = mesh.comm.allreduce(values, op=MPI.SUM)
    found = mesh.comm.allreduce(found, op=MPI.SUM)
    with np.errstate(invalid="ignore", divide="ignore"):
        return values / found[:, None]


def global_dofs(functions) -> int:
    """The global number of dofs (block size included) of ``functions``, on every rank."""
    return sum(f.function_space.dofmap.index_map.size_global * f.function_space.dofmap.index_map_bs
               for f in functions)
