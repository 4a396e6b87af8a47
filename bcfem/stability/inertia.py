r"""Loss of stability from the inertia of the tangent (Sylvester's law).

The Hessian of the Lagrangian is a saddle-point matrix: multiplier states (a
mixed solid pressure, a gas pressure, a volume constraint) each contribute one
negative eigenvalue when their constraint rows are independent, whatever the
stability of the body. So the number of unstable directions of the energy
(restricted to the constraints) is

    negative eigenvalues of the tangent - number of multiplier unknowns,

counted from an LDLᵀ factorisation (MUMPS, ICNTL(13) = 1 so that the count is
global under MPI). Unknowns held at a bound of a variational inequality
(contact) are fixed for the count: the body cannot move into the obstacle.
Only axisymmetric modes are seen by an axisymmetric model; :mod:`bcfem.stability.modes`
checks the non-axisymmetric ones.
"""

from __future__ import annotations

from mpi4py import MPI
from petsc4py import PETSc

import numpy as np

from bcfem.log import logger
from bcfem.solver import options
from bcfem.solver.kept_copy import KeptCopy


def unstable_modes(problem, multipliers: list[str] | None = None, active_tol: float = 1e-9,
                   held: tuple[str, ...] = ()) -> int:
    """Number of unstable directions at the current (converged) state of ``problem``.

    Args:
        multipliers: names of the multiplier states to subtract (those not in the problem
            are skipped); default: the ones its terms declare, ``problem.multipliers``.
        active_tol: relative distance from a bound within which an unknown is held there.
        held: states held fixed for the count, e.g. an arc-length load parameter (a platen
            displacement: the count is then that of displacement control), whose row is no
            equilibrium row.
    """
    with problem.timed("stability"):
        negative = _negative_modes(problem, active_tol, held)
    if multipliers is None:
        multipliers = problem.multipliers
    return negative - problem.global_size([n for n in multipliers if n in problem.names])


def _negative_modes(problem, active_tol: float, held: tuple[str, ...]) -> int:
    """Negative eigenvalues of the tangent with the unknowns at a bound and the states
    ``held`` held."""
    rows = problem.held_rows(active_tol)
    jacobian, x = problem.jacobian()
    if held:
        start, end = x.getOwnershipRange()
        fixed = np.concatenate([problem.global_indices(name) for name in held])
        rows = np.union1d(rows, fixed[(fixed >= start) & (fixed < end)]).astype(PETSc.IntType)
    last = problem.kept("last_count", _LastCount)
    key = (problem.assembly.tangents, jacobian.handle)
    if last.key == key and problem.comm.allreduce(bool(np.array_equal(rows, last.rows)), op=MPI.LAND):
        return last.negative  # the same tangent, the same rows held: a state counted already
    negative = None
    if problem.stability_count == "spectrum":
        negative = spectrum_count(problem, jacobian, rows)
    if negative is None:
        tangent = problem.kept("tangent_inertia", lambda: TangentInertia(problem.prefix + "inertia_"))
        negative = tangent.negative(jacobian, rows)
    last.key, last.rows, last.negative = key, rows, negative
    return negative


class _LastCount:
    """The last count and the tangent (assembly number, matrix) and held rows it was of."""

    def __init__(self):
        self.key: tuple | None = None
        self.rows = np.empty(0, PETSc.IntType)
        self.negative = 0

    def close(self) -> None:
        pass


def spectrum_count(problem, jacobian: PETSc.Mat, rows: np.ndarray) -> int | None:
    """The negative eigenvalues of ``jacobian`` (``rows`` held) from the lowest eigenvalues of
    its Schur complement on the multipliers, preconditioned by the problem's field split
    (:mod:`bcfem.stability.spectrum`); None where the multipliers' block is not negative
    definite (then MUMPS counts, and the problem says so once). Needs the problem's field split."""
    from bcfem.solver import fieldsplit
    from bcfem.stability.spectrum import SchurSpectrum, Unsupported

    split = problem.field_split
    spectrum = problem.kept("tangent_spectrum", lambda: SchurSpectrum(
        problem.snes.comm, lambda: fieldsplit.reduced_inner_ksp(problem, split),
        prefix=problem.prefix + "spectrum_"))
    if spectrum.unsupported:
        return None
    names = [n for n in problem.multipliers if n in problem.names]
    multipliers = np.sort(np.concatenate([fieldsplit.owned_rows(problem, n) for n in names])
                          if names else np.empty(0)).astype(PETSc.IntType)
    try:
        return spectrum.negative(jacobian, rows, multipliers)
    except Unsupported as error:
        spectrum.unsupported = str(error)
        logger.warning(f"{problem.prefix}: the stability count needs MUMPS's LDL^T here: {error}")
        return None


class TangentInertia:
    """Negative eigenvalues of a problem's tangent with some rows and columns held, counted
    along a path: the tangent's values go into one kept copy, so MUMPS analyses its pattern
    once and every later count is a numerical factorisation. A discrete term that adds
    entries (new contacts) changes the pattern, and the copy and its analysis are made
    afresh. Destroy with :meth:`close` (collective)."""

    def __init__(self, prefix: str):
        self.prefix = prefix
        self._copy = KeptCopy()
        self._inertia = Inertia(prefix)
        #: symbolic analyses done
        self.analyses = 0

    def negative(self, jacobian: PETSc.Mat, rows: np.ndarray) -> int:
        """Negative eigenvalues of ``jacobian`` with ``rows`` (owned, global) and their
        columns replaced by those of the identity."""
        if self._copy.update(jacobian):
            self._inertia.close()  # its analysis belonged to the matrix before
            self.analyses += 1
        matrix = self._copy.matrix
        assert matrix is not None  # update() made it
        matrix.zeroRowsColumns(rows, diag=1.0)
        return self._inertia.negative(matrix)

    def close(self) -> None:
        self._inertia.close()
        self._copy.destroy()


def negative_eigenvalues(A: PETSc.Mat, prefix: str) -> int:
    """The number of negative eigenvalues of the symmetric matrix ``A`` (all ranks), from
    MUMPS' LDLᵀ factorisation; options under ``prefix`` (e.g. ``-PREFIX mat_mumps_icntl_14``)."""
    inertia = Inertia(prefix)
    try:
        return inertia.negative(A)
    finally:
        inertia.close()


class Inertia:
    """Negative eigenvalues of symmetric matrices that share one matrix object (and so one
    sparsity pattern): MUMPS analyses the pattern at the first count, and every later count
    is a numerical LDLᵀ factorisation only. Destroy with :meth:`close` (collective)."""

    def __init__(self, prefix: str):
        self.prefix = prefix
        self._ksp: PETSc.KSP | None = None
        self._matrix: PETSc.Mat | None = None

    def negative(self, A: PETSc.Mat) -> int:
        """Negative eigenvalues of ``A``, a matrix whose values may have changed since the
        last count (a new matrix object means a new analysis)."""
        A.setOption(PETSc.Mat.Option.SYMMETRIC, True)
        ksp, fresh = self._ksp, self._ksp is None or self._matrix is None or A.handle != self._matrix.handle
        if ksp is None or fresh:
            ksp = self._create(A)
        try:
            ksp.setOperators(A)  # new values: a numerical factorisation only
            with options.inserted(self.prefix, options.users_mumps()):
                ksp.setUp()  # MUMPS reads its options at the analysis
        except PETSc.Error:
            self.close()  # a failed factorisation would otherwise stick to the PC
            raise
        finally:
            if fresh:
                for key, _ in self._OPTIONS:
                    PETSc.Options().delValue(self.prefix + key)
        negative, _, _ = ksp.getPC().getFactorMatrix().getInertia()
        return int(negative)

    # no ScaLAPACK root (ICNTL 13): a global inertia; detect null pivots rather than fail (24)
    _OPTIONS = (("mat_mumps_icntl_13", 1), ("mat_mumps_icntl_24", 1))

    def _create(self, A: PETSc.Mat) -> PETSc.KSP:
        self.close()
        opts = PETSc.Options()
        for key, value in self._OPTIONS:
            opts[self.prefix + key] = value
        ksp = PETSc.KSP().create(A.getComm())
        try:
            ksp.setOptionsPrefix(self.prefix)
            ksp.setType("preonly")
            pc = ksp.getPC()
            pc.setType("cholesky")
            pc.setFactorSolverType("mumps")
            ksp.setOperators(A)
            ksp.setFromOptions()
        except BaseException:
            ksp.destroy()
            for key, _ in self._OPTIONS:
                opts.delValue(self.prefix + key)
            raise
        self._ksp, self._matrix = ksp, A
        return ksp

    def close(self) -> None:
        if self._ksp is not None:
            self._ksp.destroy()
        self._ksp = self._matrix = None
