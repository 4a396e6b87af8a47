r"""Unstable directions without a factorisation: the lowest eigenvalues of a Schur complement.

Order the tangent's unknowns as primal ones (displacements, lateral strains, …) and
multipliers (a mixed solid pressure, a gas pressure), with held rows and columns replaced
by the identity as for the inertia (:mod:`bcfem.stability.inertia`):

    K = [A  Bᵀ]      C the multipliers' block.
        [B  C ]

When C is negative definite (-M/κ for a mixed pressure, -V1/p² for a sealed gas),
Haynsworth's inertia additivity gives neg(K) = neg(C) + neg(S) = (multiplier unknowns) +
neg(S), with S = A - Bᵀ C⁻¹ B = A + Bᵀ (-C)⁻¹ B. So the count of unstable directions that
the inertia gives is the number of negative eigenvalues of S. S is symmetric and needs no
factorisation: it is applied with a conjugate-gradient solve on -C (a mass-like block). Its
lowest eigenvalues come from SLEPc's generalised Davidson method on S x = λ D x,
D = |diag A| (the signs are S's, by Sylvester's law), preconditioned by the primal part of a
Krylov solve of K [y; w] = [x; 0] (the primal block of K⁻¹ is S⁻¹) with the problem's own
field split. The eigenvectors of one count start the next, so along a path a count costs a
few preconditioned solves.

A multiplier whose block is zero (an incompressible liquid's volume, a mirror's traction)
has no complement. Its rows B_z constrain the primal unknowns instead: with Z a basis of
null(B_z) (B_z of full rank), neg(K) = (multiplier unknowns) + neg(Zᵀ S Z), counted through the
projection on null(B_z) (:mod:`bcfem.stability.projection`); the primal part of the Krylov
solve of K with every multiplier in it is Z (Zᵀ S Z)⁻¹ Zᵀ, so the same preconditioner serves.
(Moving such a constraint into the primal rows instead keeps the count exact, but its negative
eigenvalue lies far below zero, where the preconditioner does not lead the eigensolver: on the
liquid-filled cell it missed it.)
:class:`Unsupported` is left for a positive multiplier block, or one that couples a zero-block
multiplier.
"""

from __future__ import annotations

from collections.abc import Callable

from mpi4py import MPI
from petsc4py import PETSc

import numpy as np
from slepc4py import SLEPc

from bcfem.solver.kept_copy import KeptCopy
from bcfem.solver.reduced_lu import Refresh
from bcfem.stability.projection import Projection, Unsupported

__all__ = ["SchurSpectrum", "Unsupported"]


class SchurSpectrum:
    """Negative eigenvalues of a problem's tangent, counted along a path from the lowest
    eigenvalues of the Schur complement S on its multipliers (see the module). Destroy with
    :meth:`close` (collective).

    Args:
        comm: the tangent's communicator.
        preconditioner: makes a full-size preconditioner of the tangent (a KSP applied once:
            the problem's field split). It is set up at the first count and kept while the
            Krylov solves it preconditions take about as many iterations as then
            (:class:`~bcfem.solver.reduced_lu.Refresh`). None: Jacobi (small problems).
        tol: the eigensolver's relative tolerance (residual over eigenvalue): below 1, a
            converged eigenvalue's sign is that of the exact one near it.
        inner_rtol, inner_its: the Krylov solve of the preconditioner. The eigensolver
            needs it accurate: at 1e-3 it stalls on a nearly incompressible cell, at 1e-5
            it converges as with an exact inverse.
        prefix: the eigensolver's options prefix: ``-<prefix>eps_...`` override the above.
    """

    def __init__(self, comm, preconditioner: Callable[[], PETSc.KSP] | None = None,
                 tol: float = 1e-3, inner_rtol: float = 1e-5, inner_its: int = 100, prefix: str = ""):
        self.comm = comm
        self.prefix = prefix
        self._mpi = comm.tompi4py() if isinstance(comm, PETSc.Comm) else comm
        self._make_preconditioner = preconditioner
        self._preconditioner: PETSc.KSP | None = None
        self._operator: PETSc.Mat | None = None
        self._refresh = Refresh()
        self.tol, self.inner_rtol, self.inner_its = tol, inner_rtol, inner_its
        self._copy = KeptCopy()
        self._rows: np.ndarray | None = None
        self._sets: dict[str, PETSc.IS] = {}
        self._blocks: dict[str, PETSc.Mat] = {}
        self._vectors: list[PETSc.Vec] = []
        self._count = 0
        #: why this tangent has no Schur complement to count by, once found (then MUMPS counts)
        self.unsupported: str | None = None
        #: the fewest eigenvalues computed: one more than the last count
        self.least = 1
        #: the last count's lowest eigenvalues of S x = λ D x, its eigensolver iterations and
        #: the preconditioner's Krylov iterations (all of them)
        self.lowest: list[float] = []
        self.iterations = 0
        self.inner_iterations = 0

    def negative(self, jacobian: PETSc.Mat, held: np.ndarray, multipliers: np.ndarray) -> int:
        """Negative eigenvalues of ``jacobian`` with the owned global rows ``held`` and their
        columns replaced by the identity: the multiplier rows ``multipliers`` (owned, global;
        a held one is a primal row) plus neg(S). Collective."""
        fresh = self._copy.update(jacobian)
        K = self._copy.matrix
        assert K is not None
        K.zeroRowsColumns(held, diag=1.0)
        rows = np.setdiff1d(multipliers, held).astype(PETSc.IntType)
        if fresh or self._rows is None or not self._mpi.allreduce(bool(np.array_equal(rows, self._rows)),
                                                                   op=MPI.LAND):
            self._index_sets(K, rows)
            fresh = True
        self._extract(K, fresh)
        return self._mpi.allreduce(rows.size) + self._count_negative(K)

    def _index_sets(self, K: PETSc.Mat, rows: np.ndarray) -> None:
        """Primal rows ``p``, multipliers with a block ``c`` and with none ``z`` (K's diagonal 0)."""
        for obj in (*self._sets.values(), *self._blocks.values(), *self._vectors):
            obj.destroy()
        self._blocks, self._vectors = {}, []  # another primal space: no start from the last count
        self._rows = rows
        start, end = K.getOwnershipRange()
        primal = np.setdiff1d(np.arange(start, end, dtype=PETSc.IntType), rows)
        diagonal = K.getDiagonal()
        with diagonal as d:
            zero = d[rows - start] == 0
        diagonal.destroy()
        self._sets = {name: PETSc.IS().createGeneral(ix, comm=self.comm)
                      for name, ix in (("p", primal), ("c", rows[~zero]), ("z", rows[zero]))}

    def _extract(self, K: PETSc.Mat, fresh: bool) -> None:
        p, c, z = self._sets["p"], self._sets["c"], self._sets["z"]
        blocks = {"A": (p, p), "Bt": (p, c), "B": (c, p), "C": (c, c)}
        if z.getSize():
            blocks |= {"Bzt": (p, z), "Bz": (z, p), "Czc": (z, c), "Czz": (z, z)}
        for name, (rows, cols) in blocks.items():
            self._blocks[name] = K.createSubMatrix(rows, cols, submat=None if fresh else self._blocks[name])
        minus_c = self._blocks["C"]
        minus_c.scale(-1.0)
        diagonal = minus_c.getDiagonal()
        smallest = diagonal.min()[1] if diagonal.getSize() else 1.0
        diagonal.destroy()
        if smallest <= 0:
            raise Unsupported("a multiplier's block is not negative definite: S = A - B^T C^-1 B does not exist")
        if z.getSize() and max(self._blocks[k].norm(PETSc.NormType.FROBENIUS) for k in ("Czc", "Czz")) > 0:
            raise Unsupported("a multiplier with a zero diagonal couples to the multipliers: no projection")

    def _count_negative(self, K: PETSc.Mat) -> int:
        A, Bt, B, minus_c = (self._blocks[k] for k in ("A", "Bt", "B", "C"))
        schur = _Schur(A, Bt, B, minus_c)
        S = PETSc.Mat().createPython(A.getSizes(), schur, comm=self.comm)
        S.setUp()
        D = _scaling(A)
        projection, unprojected = None, None
        if "Bz" in self._blocks:
            diagonal = D.getDiagonal()
            sigma = diagonal.max()[1]
            diagonal.destroy()
            projection = Projection(S, self._blocks["Bz"], self._blocks["Bzt"], sigma)
            unprojected, S = S, PETSc.Mat().createPython(A.getSizes(), projection, comm=self.comm)
            S.setUp()
        inverse = _PrimalInverse(K, self._sets["p"], self._preconditioner_of(K), self.inner_rtol, self.inner_its)
        inverse.complement = projection
        try:
            nev = max(self.least, self._count + 1)
            while True:  # until a non-negative eigenvalue bounds the negative ones
                values = self._lowest(S, D, inverse, nev)
                negative = sum(v < 0 for v in values)
                if negative < len(values) or nev >= A.getSize()[0]:
                    break
                nev *= 2
        finally:
            for obj in (S, D):
                obj.destroy()
            schur.close()
            inverse.close()
            if projection is not None:
                projection.close()
            if unprojected is not None:
                unprojected.destroy()
        self.inner_iterations = inverse.iterations
        self._refresh.solved(inverse.most)
        self.lowest, self._count = values, negative
        return negative

    def _preconditioner_of(self, K: PETSc.Mat) -> PETSc.KSP | None:
        """The full-size preconditioner, set up on ``K`` when due (collective)."""
        if self._make_preconditioner is None:
            return None
        if self._preconditioner is None:
            self._preconditioner = self._make_preconditioner()
        if K is not self._operator:  # a new pattern: a new matrix, and a set-up on it
            self._preconditioner.setOperators(K)
            self._operator = K
            self._refresh = Refresh()
        pc = self._preconditioner.getPC()
        if self._refresh.due():
            pc.setReusePreconditioner(False)
            self._preconditioner.setUp()
            self._refresh.set_up()
        else:
            self._refresh.skip()
        pc.setReusePreconditioner(True)  # K's values change in place: keep this set-up
        return self._preconditioner

    def _lowest(self, S: PETSc.Mat, D: PETSc.Mat, inverse: _PrimalInverse, nev: int) -> list[float]:
        """The ``nev`` lowest eigenvalues of S x = λ D x, started from the last count's vectors."""
        eps = SLEPc.EPS().create(self.comm)
        try:
            eps.setOperators(S, D)
            eps.setProblemType(SLEPc.EPS.ProblemType.GHEP)
            eps.setType(SLEPc.EPS.Type.GD)  # LOBPCG needs a definite preconditioner; S⁻¹ need not be
            eps.setWhichEigenpairs(SLEPc.EPS.Which.SMALLEST_REAL)
            eps.setDimensions(nev=nev, ncv=2 * nev + 10)
            eps.setTolerances(self.tol, 1000)
            eps.setConvergenceTest(SLEPc.EPS.Conv.REL)
            st = eps.getST()
            st.setType(SLEPc.ST.Type.PRECOND)
            ksp = st.getKSP()
            ksp.setType("preonly")
            pc = ksp.getPC()
            pc.setType("python")
            pc.setPythonContext(inverse)
            eps.setOptionsPrefix(self.prefix)
            eps.setFromOptions()  # the user's options win
            if self._vectors:
                eps.setInitialSpace(self._vectors)
            eps.solve()
            self.iterations = eps.getIterationNumber()
            converged = eps.getConverged()
            if converged < nev:
                raise RuntimeError(f"the stability count found {converged} of the {nev} lowest eigenvalues of "
                                   f"the tangent's Schur complement in {self.iterations} iterations")
            pairs = []
            for i in range(converged):
                v = S.createVecRight()
                pairs.append((eps.getEigenpair(i, v).real, v))
            pairs.sort(key=lambda pair: pair[0])
            for v in self._vectors:
                v.destroy()
            self._vectors = [v for _, v in pairs[:nev]]
            for _, v in pairs[nev:]:
                v.destroy()
            return [value for value, _ in pairs[:nev]]
        finally:
            eps.destroy()

    def close(self) -> None:
        for obj in (*self._blocks.values(), *self._sets.values(), *self._vectors):
            obj.destroy()
        self._blocks, self._sets, self._vectors = {}, {}, []
        if self._preconditioner is not None:
            self._preconditioner.destroy()
            self._preconditioner = None
        self._copy.destroy()
        self._operator = None


def _scaling(A: PETSc.Mat) -> PETSc.Mat:
    """D = |diag A| (1 where it vanishes) as a diagonal matrix."""
    d = A.getDiagonal()
    d.abs()
    with d as a:
        a[a == 0] = 1.0
    D = PETSc.Mat().createAIJ(A.getSizes(), nnz=(1, 0), comm=A.getComm())
    D.setDiagonal(d)
    D.assemble()
    d.destroy()
    return D


class _Schur:
    """S x = A x + Bᵀ (-C)⁻¹ B x, a petsc4py ``python`` matrix; (-C)⁻¹ by CG with Jacobi."""

    def __init__(self, A: PETSc.Mat, Bt: PETSc.Mat, B: PETSc.Mat, minus_c: PETSc.Mat):
        self.A, self.Bt, self.B = A, Bt, B
        self.ksp = PETSc.KSP().create(A.getComm())
        self.ksp.setType("cg")
        self.ksp.getPC().setType("jacobi")
        self.ksp.setOperators(minus_c)
        self.ksp.setTolerances(rtol=1e-12, atol=0.0, max_it=1000)
        self.ksp.setNormType(PETSc.KSP.NormType.UNPRECONDITIONED)
        self._b, self._z = minus_c.createVecs()

    def mult(self, mat, x, y):
        self.A.mult(x, y)
        if self._b.getSize() == 0:
            return
        self.B.mult(x, self._b)
        self.ksp.solve(self._b, self._z)
        if self.ksp.getConvergedReason() < 0:
            raise Unsupported(f"CG on the multipliers' block stopped ({self.ksp.getConvergedReason()}): "
                              "it is not negative definite")
        self.Bt.multAdd(self._z, y, y)

    def close(self) -> None:
        for obj in (self.ksp, self._b, self._z):
            obj.destroy()


class _PrimalInverse:
    """A python PC on the primal unknowns: the primal part of y in K [y; w] = [x; 0], by FGMRES
    to ``rtol`` preconditioned by ``preconditioner`` (a full-size KSP applied once) or Jacobi."""

    def __init__(self, K: PETSc.Mat, primal: PETSc.IS, preconditioner: PETSc.KSP | None, rtol: float, its: int):
        self.primal = primal
        self.ksp = PETSc.KSP().create(K.getComm())
        self.ksp.setType("fgmres")
        self.ksp.setOperators(K)
        self.ksp.setTolerances(rtol=rtol, atol=0.0, max_it=its)
        pc = self.ksp.getPC()
        if preconditioner is None:
            pc.setType("jacobi")
        else:
            pc.setType("python")
            pc.setPythonContext(_Applied(preconditioner))
        self.rhs, self.solution = K.createVecs()
        #: Krylov iterations, all and the most in one solve
        self.iterations = self.most = 0
        #: the projection of zero-block multipliers that completes the inverse, if any
        self.complement: Projection | None = None

    def apply(self, pc, x, y):
        self.rhs.zeroEntries()
        part = self.rhs.getSubVector(self.primal)
        x.copy(part)
        self.rhs.restoreSubVector(self.primal, part)
        self.solution.zeroEntries()
        self.ksp.solve(self.rhs, self.solution)  # short of rtol it is a weaker preconditioner, no error
        its = self.ksp.getIterationNumber()
        self.iterations += its
        self.most = max(self.most, its)
        part = self.solution.getSubVector(self.primal)
        part.copy(y)
        self.solution.restoreSubVector(self.primal, part)
        if self.complement is not None:
            self.complement.precondition(x, y)

    def matApply(self, pc, X, Y):
        """Column by column: SLEPc applies blocks of vectors."""
        for i in range(X.getSize()[1]):
            x, y = X.getDenseColumnVec(i, "r"), Y.getDenseColumnVec(i, "w")
            self.apply(pc, x, y)
            X.restoreDenseColumnVec(i, "r")
            Y.restoreDenseColumnVec(i, "w")

    def close(self):
        for obj in (self.ksp, self.rhs, self.solution):
            obj.destroy()


class _Applied:
    """A python PC that applies a set-up KSP once."""

    def __init__(self, ksp: PETSc.KSP):
        self.ksp = ksp

    def apply(self, pc, x, y):
        self.ksp.solve(x, y)
