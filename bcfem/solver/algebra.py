"""Linear algebra at a problem's current state: blocked vectors, the Jacobian, its solves.

Mixed into :class:`bcfem.solver.problem.Problem`: tangents of a continuation, inertia counts and
the discrete terms' global rows all go through these, on the problem's own PETSc objects.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from petsc4py import PETSc

import numpy as np
from dolfinx import fem
from dolfinx.fem.petsc import assign

from bcfem.mpi import global_dofs

if TYPE_CHECKING:
    from mpi4py import MPI

    from dolfinx.fem.petsc import NonlinearProblem

    from bcfem.physics.context import Context


class ConvergedAlgebra:
    """Vectors, index maps and Jacobian solves of a :class:`bcfem.solver.problem.Problem` (which
    provides ``states``, ``names``, ``bcs``, ``ctx``, ``comm``, ``prefix``, ``options``, ``snes``,
    ``_nlp``, ``_bounds`` and ``_tangent_ksp``)."""

    states: list[fem.Function]
    names: list[str]
    bcs: list
    ctx: Context
    prefix: str
    options: dict[str, str]
    snes: PETSc.SNES
    _nlp: NonlinearProblem
    _bounds: tuple[PETSc.Vec, ...]
    _tangent_ksp: PETSc.KSP | None

    @property
    def comm(self) -> MPI.Comm:
        return self.ctx.mesh.comm

    def state(self, name: str) -> fem.Function:
        return self.ctx.states[name]

    def global_indices(self, name: str) -> np.ndarray:
        """The global row of every local (unrolled, ghosts included) dof of state ``name``."""
        v = self.new_vector()
        start, end = v.getOwnershipRange()
        v.array[:] = np.arange(start, end, dtype=float)
        functions = [fem.Function(s.function_space) for s in self.states]
        self.functions_from(v, functions)
        v.destroy()
        return np.rint(functions[self.names.index(name)].x.array).astype(np.int64)

    def global_size(self, names) -> int:
        """The global number of dofs (block size included) of the states ``names``."""
        unknown = [n for n in names if n not in self.names]
        if unknown:
            raise ValueError(f"no state {unknown[0]!r} in this problem (states: {', '.join(self.names)})")
        return global_dofs(self.state(n) for n in names)

    def constrained(self, name: str) -> np.ndarray:
        """A mask of the local (unrolled) dofs of state ``name`` held by a Dirichlet condition."""
        space = self.ctx.states[name].function_space
        imap = space.dofmap.index_map
        mask = np.zeros((imap.size_local + imap.num_ghosts) * space.dofmap.index_map_bs, dtype=bool)
        for bc in self.bcs:
            if space._cpp_object.contains(bc.function_space):
                dofs, _ = bc.dof_indices()
                mask[dofs] = True
        return mask

    def new_vector(self) -> PETSc.Vec:
        return self._nlp.b.duplicate()

    def vector_from(self, functions) -> PETSc.Vec:
        """A blocked vector holding the given functions (one per state)."""
        v = self.new_vector()
        assign(list(functions), v)
        return v

    def functions_from(self, vec: PETSc.Vec, functions) -> None:
        vec.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
        assign(vec, list(functions))

    def jacobian(self) -> tuple[PETSc.Mat, PETSc.Vec]:
        """(J, x): the Jacobian assembled at the current states, and those states as a vector
        (both owned by the problem: copy before changing them)."""
        x = self._nlp.x
        assign(self.states, x)
        x.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
        self.snes.computeJacobian(x, self._nlp.A, None)
        return self._nlp.A, x

    def held_rows(self, active_tol: float = 1e-9) -> np.ndarray:
        """The owned global rows of the unknowns held at a bound of the variational
        inequality (within ``active_tol``, relative) at the current states: the body cannot
        move into the obstacle. Empty without bounds."""
        if not self._bounds:
            return np.empty(0, dtype=PETSc.IntType)
        x = self._nlp.x
        assign(self.states, x)
        lower, upper = (b.array for b in self._bounds)
        at_bound = (np.abs(x.array - lower) <= active_tol * np.maximum(1.0, np.abs(lower))) | \
                   (np.abs(upper - x.array) <= active_tol * np.maximum(1.0, np.abs(upper)))
        start, _ = x.getOwnershipRange()
        return (np.flatnonzero(at_bound) + start).astype(PETSc.IntType)

    def solve_jacobian(self, rhs: PETSc.Vec) -> PETSc.Vec:
        """Solve J(x) y = rhs with the Jacobian assembled at the current states; the unknowns
        held at a bound (:meth:`held_rows`) stay there, y = 0 (the inequality's reduced system)."""
        held = self.held_rows()
        reduced = self.comm.allreduce(held.size) > 0
        A, _ = self.jacobian()
        if reduced:
            A = A.copy()
            A.zeroRowsColumns(held, diag=1.0)
            rhs = rhs.copy()
            rhs.setValues(held, np.zeros(held.size))
            rhs.assemble()
        if self._tangent_ksp is None:
            ksp = PETSc.KSP().create(self.comm)
            ksp.setOptionsPrefix(self.prefix + "tangent_")
            ksp.setType("preonly")
            ksp.getPC().setType("lu")
            ksp.getPC().setFactorSolverType("mumps")
            ksp.setFromOptions()
            self._tangent_ksp = ksp
        self._tangent_ksp.setOperators(A)
        y = rhs.duplicate()
        self._tangent_ksp.solve(rhs, y)
        if reduced:
            A.destroy()
            rhs.destroy()
        return y
