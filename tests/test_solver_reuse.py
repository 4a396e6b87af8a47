"""The Newton machinery's shortcuts change no result: a cycling solve stops at its first
repeat, and the reduced-space step of ``vinewtonrsls`` reuses one symbolic analysis."""

from mpi4py import MPI
from petsc4py import PETSc

import numpy as np
import pytest

from bcfem.solver.newton_cycles import RepeatedIterates
from bcfem.solver.reduced_lu import ReducedLU


def scalar_snes(residual, derivative, comm=MPI.COMM_SELF, max_it=25):
    """Newton with full steps on one unknown (rank 0 owns it)."""
    n = 1 if comm.rank == 0 else 0
    x = PETSc.Vec().createMPI((n, 1), comm=comm)
    f = x.duplicate()
    J = PETSc.Mat().createAIJ(((n, 1), (n, 1)), nnz=1, comm=comm)
    J.setUp()

    def function(snes, x, f):
        f.array[:] = residual(x.array_r)

    def jacobian(snes, x, J, P):
        if comm.rank == 0:
            J.setValue(0, 0, derivative(x.array_r[0]))
        J.assemble()

    snes = PETSc.SNES().create(comm)
    snes.setFunction(function, f)
    snes.setJacobian(jacobian, J)
    snes.setType("newtonls")
    snes.getLineSearch().setType("basic")
    snes.setTolerances(atol=1e-12, rtol=1e-14, stol=0.0, max_it=max_it)
    snes.getKSP().setType("preonly")
    snes.getKSP().getPC().setType("lu")
    return snes, x


def signed_root(x):
    """f = sign(x) |x|^(1/2): Newton maps x to -x exactly, a 2-cycle from any start."""
    return np.sign(x) * np.sqrt(np.abs(x))


@pytest.mark.mpi
def test_a_two_cycle_stops_at_its_first_repeat_with_the_reason_max_it_would_give():
    comm = MPI.COMM_WORLD
    snes, x = scalar_snes(signed_root, lambda x: 0.5 / np.sqrt(abs(x)), comm)
    x.set(1.0)
    snes.solve(None, x)
    assert snes.getConvergedReason() == PETSc.SNES.ConvergedReason.DIVERGED_MAX_IT
    assert snes.getIterationNumber() == 25  # without the monitor: the whole budget

    cycles = RepeatedIterates(snes, comm)
    x.set(1.0)
    snes.solve(None, x)
    assert snes.getConvergedReason() == PETSc.SNES.ConvergedReason.DIVERGED_MAX_IT
    assert snes.getIterationNumber() == 2 and cycles.period == 2 and cycles.stopped == 1


@pytest.mark.mpi
def test_a_creeping_solve_is_no_cycle():
    """Steps shortened to 1e-7 of Newton's move little, and the residual hardly falls; the
    iterates never come back, so the solve is left to its iteration budget."""
    comm = MPI.COMM_WORLD
    snes, x = scalar_snes(signed_root, lambda x: 0.5 / np.sqrt(abs(x)), comm, max_it=12)

    def shorten(x, y):
        y.scale(1e-7)

    snes.setLineSearchPreCheck(shorten)
    cycles = RepeatedIterates(snes, comm)
    x.set(1.0)
    snes.solve(None, x)
    assert snes.getIterationNumber() == 12 and cycles.stopped == 0


@pytest.mark.mpi
def test_a_converging_solve_is_left_alone():
    comm = MPI.COMM_WORLD
    # Newton on x^2 - 2 from 1: the iterates approach each other, the residual falls
    snes, x = scalar_snes(lambda x: x**2 - 2.0, lambda x: 2.0 * x, comm)
    cycles = RepeatedIterates(snes, comm)
    x.set(1.0)
    snes.solve(None, x)
    assert snes.getConvergedReason() > 0 and cycles.period == 0
    value = comm.bcast(x.array_r[0] if comm.rank == 0 else None)
    assert value == pytest.approx(np.sqrt(2.0), rel=1e-14)


def obstacle_snes(comm, n, reduced: bool, loaded: float = 1.0, factor: str = "lu"):
    """A discrete membrane -u'' + u^3 = -g (u = 0 at both ends) over the obstacle
    u >= -0.3, solved by vinewtonrsls; g = 10 on the first ``loaded`` part of the span."""
    h = 1.0 / (n + 1)
    x = PETSc.Vec().createMPI(n, comm=comm)
    start, end = x.getOwnershipRange()
    J = PETSc.Mat().createAIJ((n, n), nnz=(3, 2), comm=comm)
    J.setUp()
    scatter, local = PETSc.Scatter().toAll(x)

    def function(snes, x, f):
        scatter.scatter(x, local)
        u = np.concatenate(([0.0], local.array_r, [0.0]))
        i = np.arange(start, end) + 1
        f.array[:] = (2 * u[i] - u[i - 1] - u[i + 1]) / h**2 + u[i] ** 3 + 10.0 * (i <= loaded * n)

    def jacobian(snes, x, J, P):
        scatter.scatter(x, local)
        for row in range(start, end):
            J.setValue(row, row, 2 / h**2 + 3 * local.array_r[row] ** 2)
            for col in (row - 1, row + 1):
                if 0 <= col < n:
                    J.setValue(row, col, -1 / h**2)
        J.assemble()

    snes = PETSc.SNES().create(comm)
    snes.setFunction(function, x.duplicate())
    snes.setJacobian(jacobian, J)
    snes.setType("vinewtonrsls")
    snes.setTolerances(atol=1e-10, rtol=1e-12, max_it=50)
    snes.getKSP().setType("preonly")
    pc = snes.getKSP().getPC()
    pc.setType("lu")
    pc.setFactorSolverType("mumps")
    lower, upper = x.duplicate(), x.duplicate()
    lower.set(-0.3)
    upper.set(1e20)
    snes.setVariableBounds(lower, upper)
    context = None
    if reduced:
        context = ReducedLU(snes, "mumps", "reduced_test_", factor)
        pc.setType("python")
        pc.setPythonContext(context)
    return snes, x, context


@pytest.mark.mpi
@pytest.mark.parametrize("loaded", [1.0, 0.3])  # 0.3: the contact set changes on rank 0's rows only
@pytest.mark.parametrize("factor", ["lu", "cholesky"])  # this Jacobian is symmetric
def test_the_reduced_step_on_the_full_sparsity_gives_vinewtonrsls_own_iterates(loaded, factor):
    comm = MPI.COMM_WORLD
    solutions, histories = [], []
    for reduced in (False, True):
        snes, x, context = obstacle_snes(comm, 200, reduced, loaded, factor)
        snes.setConvergenceHistory()
        x.set(0.0)
        snes.solve(None, x)
        assert snes.getConvergedReason() > 0
        solutions.append(x.copy())
        histories.append(snes.getConvergenceHistory()[0])
        if reduced:
            # the active set changed from iteration to iteration, the analysis was done once
            assert snes.getIterationNumber() >= 2 and context.analyses == 1
            assert context.ksp.getPC().getType() == factor
    held = comm.allreduce(int(np.sum(solutions[1].array_r <= -0.3 + 1e-12)))
    assert 0 < held < 200  # the obstacle is touched, not everywhere
    assert len(histories[0]) == len(histories[1])
    np.testing.assert_allclose(histories[1], histories[0], rtol=1e-8, atol=1e-9)  # round-off: 1e-11
    solutions[1].axpy(-1.0, solutions[0])
    assert solutions[1].norm(PETSc.NormType.INFINITY) <= 1e-12
