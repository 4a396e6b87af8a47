"""The reduced-space Newton step of ``vinewtonrsls``, factorised without a new analysis.

``vinewtonrsls`` solves J_II y_I = -F_I on the unknowns I not held at a bound. It extracts
J_II as a new matrix at every iteration, so a direct solver redoes its symbolic analysis
(ordering, elimination tree) every time. The same step solves the full-size system with
the held rows and columns replaced by the identity, [J_II 0; 0 1] y = [F_I; 0], whose
sparsity never changes: one analysis serves a whole path, and each iteration pays the
numerical factorisation alone.

An iterative inner solver (a field split) is a preconditioner only: the user's Krylov method
solves the reduced system to its tolerance whatever it is. Its set-up (GAMG's Galerkin
products, the Schur complement's) is then kept across Newton iterations and load steps while
it stays good (:class:`Refresh`), and redone when the Krylov iterations grow, a solve fails or
the active set changes.
"""

from __future__ import annotations

from mpi4py import MPI
from petsc4py import PETSc

import numpy as np

from bcfem.solver.kept_copy import KeptCopy


class Refresh:
    """When a kept preconditioner is set up again: before its first use, after a solve that
    failed or took more than ``growth`` times the iterations of the first solve after the
    last set-up (plus ``slack``), and after ``limit`` set-ups skipped in a row. Tell it each
    solve's iterations (:meth:`solved`, -1 for a failure); the counts must be global, so that
    every rank decides alike."""

    def __init__(self, growth: float = 1.5, slack: int = 4, limit: int = 20):
        self.growth, self.slack, self.limit = growth, slack, limit
        self._fresh: int | None = None  # iterations of the first solve after the set-up
        self._last: int | None = None
        self._skipped = 0
        #: set-ups done and skipped
        self.done = self.kept = 0

    def solved(self, iterations: int) -> None:
        if self._fresh is None and self.done:
            self._fresh = iterations
        self._last = iterations

    def due(self) -> bool:
        if self.done == 0 or self._skipped >= self.limit or self._fresh is None or self._last is None:
            return True
        return self._last < 0 or self._last > self.growth * self._fresh + self.slack

    def set_up(self) -> None:
        self._fresh, self._last, self._skipped = None, None, 0
        self.done += 1

    def skip(self) -> None:
        self._skipped += 1
        self.kept += 1


class ReducedLU:
    """A petsc4py ``python`` PC for the KSP of a ``vinewtonrsls`` SNES (see the module).

    Args:
        snes: the SNES; its Jacobian is assembled at the iterate when the PC is set up.
        solver_type: the factorisation package (e.g. ``mumps``).
        prefix: options prefix of the inner factorisation (the problem's, so that the
            user's ``-<prefix>mat_mumps_*`` options apply to it).
        factor: ``lu``, or ``cholesky`` (LDL^T, for MUMPS a symmetric indefinite one) when the
            Jacobian is symmetric: the identity rows and columns keep the symmetry.
        inner: instead of the factorisation, this KSP applied to the full-size system (e.g. one
            application of a field split: :mod:`bcfem.solver.fieldsplit`); it is destroyed with
            this PC; its set-up is kept while it serves (:class:`Refresh`).
    """

    def __init__(self, snes: PETSc.SNES, solver_type: str, prefix: str, factor: str = "lu",
                 inner: PETSc.KSP | None = None):
        self.snes = snes
        inner_is_factor = inner is None
        if inner is None:
            inner = PETSc.KSP().create(snes.comm)
            inner.setOptionsPrefix(prefix)
            inner.setType("preonly")
            inner.getPC().setType(factor)
            inner.getPC().setFactorSolverType(solver_type)
        self.ksp = inner
        #: when an iterative ``inner`` is set up again (a factorisation is, at every step)
        self.refresh = None if inner_is_factor else Refresh()
        self._copy = KeptCopy()
        self._inactive: np.ndarray | None = None
        self._held: np.ndarray | None = None
        self._scatter: PETSc.Scatter | None = None
        self._rhs: PETSc.Vec | None = None
        self._solution: PETSc.Vec | None = None
        #: symbolic analyses done (a new sparsity of the Jacobian needs one)
        self.analyses = 0

    def setUp(self, pc: PETSc.PC) -> None:
        jacobian = self.snes.getJacobian()[0]
        inactive = self.snes.getVIInactiveSet().getIndices()
        changed = self._inactive is None or not np.array_equal(inactive, self._inactive)
        # the scatter is rebuilt collectively: on every rank when the set changed on any
        if self.snes.comm.tompi4py().allreduce(changed, op=MPI.LOR):
            start, end = jacobian.getOwnershipRange()
            self._inactive = inactive.copy()
            self._held = np.setdiff1d(np.arange(start, end, dtype=inactive.dtype), inactive)
            if self._scatter is not None:
                self._scatter.destroy()
                self._scatter = None
        if self.refresh is not None and self.refresh.done:
            ksp = self.snes.getKSP()  # its last solve, with this preconditioner
            self.refresh.solved(ksp.getIterationNumber() if ksp.getConvergedReason() >= 0 else -1)
        if self.refresh is not None and self._copy.holds(jacobian) and not self.refresh.due():
            # the kept preconditioner serves this step too, its held rows maybe a few off
            self.refresh.skip()
            return
        if self._copy.update(jacobian):  # a discrete term added entries
            self._destroy_vectors()
            self._rhs, self._solution = self.matrix.createVecs()
            self.analyses += 1
        self.matrix.zeroRowsColumns(self._held, diag=1.0)
        self.ksp.setOperators(self.matrix)
        self.ksp.setUp()
        if self.refresh is not None:
            self.refresh.set_up()

    def apply(self, pc: PETSc.PC, x: PETSc.Vec, y: PETSc.Vec) -> None:
        if self._scatter is None:
            index_set = PETSc.IS().createGeneral(self._inactive, comm=self.snes.comm)
            self._scatter = PETSc.Scatter().create(self._rhs, index_set, x, None)
            index_set.destroy()
        assert self._rhs is not None  # set up first
        self._rhs.zeroEntries()
        self._scatter.scatter(x, self._rhs, PETSc.InsertMode.INSERT_VALUES, PETSc.ScatterMode.REVERSE)
        self.ksp.solve(self._rhs, self._solution)
        self._scatter.scatter(self._solution, y, PETSc.InsertMode.INSERT_VALUES, PETSc.ScatterMode.FORWARD)

    def reset(self, pc: PETSc.PC) -> None:
        """vinewtonrsls resets its KSP when the inactive set changes: the analysis stays."""

    @property
    def matrix(self) -> PETSc.Mat:
        """The kept copy of the Jacobian that is factorised (after the first setUp)."""
        if self._copy.matrix is None:
            raise RuntimeError("the reduced LU has no matrix before its first set-up")
        return self._copy.matrix

    def _destroy_vectors(self) -> None:
        for obj in (self._rhs, self._solution, self._scatter):
            if obj is not None:
                obj.destroy()
        self._rhs = self._solution = self._scatter = None

    def destroy(self, pc: PETSc.PC | None = None) -> None:
        """Free the factorisation and drop the SNES: the SNES owns this context through its
        PC, so holding it on would keep both alive (called by :meth:`Problem.close`)."""
        self._destroy_vectors()
        self._copy.destroy()
        self.ksp.destroy()
        self.snes = None
