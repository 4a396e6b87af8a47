"""The stability count without a factorisation: the lowest eigenvalues of the Schur complement on
the multipliers give the tangent's inertia (Haynsworth), as MUMPS's LDLᵀ does, on saddle-point
matrices with unstable directions and held rows, and under a field split on a pressed block."""

from mpi4py import MPI
from petsc4py import PETSc

import numpy as np
import pytest

from bcfem.solver.reduced_lu import Refresh
from bcfem.stability.inertia import TangentInertia, unstable_modes
from bcfem.stability.spectrum import SchurSpectrum, Unsupported


def saddle(comm, shift: float, seed: int = 0, zero_c: int = 0, positive_c: bool = False):
    """K = [A Bᵀ; B C] (60 primal, 20 multipliers, interleaved rows) with A = L Lᵀ/n + diag(shift
    ... 3): negative eigenvalues of S for a negative shift; C = -diag(0.5 ... 2), its first
    ``zero_c`` entries 0 (one: a dense row of B; more: rows of B on three primal unknowns each),
    the first positive with ``positive_c``. Returns (the distributed matrix, its dense copy, the
    multipliers' global rows)."""
    rng = np.random.default_rng(seed)
    n, m = 60, 20
    L = rng.standard_normal((n, n))
    A = L @ L.T / n + np.diag(np.linspace(shift, 3, n))
    B = 0.3 * rng.standard_normal((m, n))
    C = -np.diag(rng.uniform(0.5, 2, m))
    C[range(zero_c), range(zero_c)] = 0
    if zero_c > 1:
        B[:zero_c] = 0
        for i in range(zero_c):
            B[i, 3 * i:3 * i + 3] = rng.uniform(0.5, 1, 3)
    if positive_c:
        C[0, 0] = 1.0
    perm = rng.permutation(n + m)
    K = np.block([[A, B.T], [B, C]])[np.ix_(perm, perm)]
    M = PETSc.Mat().createAIJ(((PETSc.DECIDE, n + m), (PETSc.DECIDE, n + m)), comm=comm)
    M.setPreallocationNNZ(n + m)
    start, end = M.getOwnershipRange()
    M.setValues(range(start, end), range(n + m), K[start:end])
    M.assemble()
    return M, K, np.flatnonzero(perm >= n)


def dense_negative(K: np.ndarray, held: np.ndarray) -> int:
    K = K.copy()
    K[held, :] = 0
    K[:, held] = 0
    K[held, held] = 1
    return int(np.sum(np.linalg.eigvalsh(K) < 0))


def owned(rows: np.ndarray, M: PETSc.Mat) -> np.ndarray:
    start, end = M.getOwnershipRange()
    return rows[(rows >= start) & (rows < end)].astype(PETSc.IntType)


@pytest.mark.mpi
@pytest.mark.parametrize("shift", [-0.3, -1.0])
def test_the_count_is_the_inertia_with_held_rows(shift):
    """neg(K) with two rows held (one a multiplier's): Haynsworth's count equals the dense
    eigenvalues' and MUMPS's, with none and with many unstable directions of S, along a path
    of three matrices (the eigenvectors of one count start the next)."""
    comm = MPI.COMM_WORLD
    spectrum = SchurSpectrum(comm)
    inertia = TangentInertia("bcfem_test_spectrum_")
    try:
        for seed in (0, 0, 1):
            M, K, multipliers = saddle(comm, shift, seed)
            held = np.array([3, int(multipliers[0])])
            expected = dense_negative(K, held)
            assert spectrum.negative(M, owned(held, M), owned(multipliers, M)) == expected
            assert inertia.negative(M, owned(held, M)) == expected
            M.destroy()
        # a held multiplier row is an identity row: m - 1 negative ones from C, more when S has some
        assert (expected > multipliers.size - 1) == (shift < -0.5)
    finally:
        spectrum.close()
        inertia.close()


@pytest.mark.mpi
@pytest.mark.parametrize("zero_c", [1, 4])
@pytest.mark.parametrize("shift", [-0.3, -1.0])
def test_multipliers_without_a_block_are_projected_out(zero_c, shift):
    """Constraints with a zero block (one: an incompressible liquid's dense volume row; four:
    a mirror's rows) are eliminated by the projection on their null space: the count equals
    the dense eigenvalues' and MUMPS's, with a row held, along a path of two matrices."""
    comm = MPI.COMM_WORLD
    spectrum = SchurSpectrum(comm)
    inertia = TangentInertia("bcfem_test_spectrum_")
    try:
        for seed in (2, 3):
            M, K, multipliers = saddle(comm, shift, seed, zero_c=zero_c)
            held = np.array([5])
            expected = dense_negative(K, held)
            assert spectrum.negative(M, owned(held, M), owned(multipliers, M)) == expected
            assert inertia.negative(M, owned(held, M)) == expected
            M.destroy()
        assert (expected > multipliers.size) == (shift < -0.5)
    finally:
        spectrum.close()
        inertia.close()


def test_a_positive_multiplier_block_has_no_complement():
    """C with a positive entry: S = A - Bᵀ C⁻¹ B is not what counts, and the count says so."""
    M, _, multipliers = saddle(MPI.COMM_SELF, -0.3, positive_c=True)
    spectrum = SchurSpectrum(MPI.COMM_SELF)
    try:
        with pytest.raises(Unsupported, match="not negative definite"):
            spectrum.negative(M, np.empty(0, PETSc.IntType), multipliers.astype(PETSc.IntType))
    finally:
        spectrum.close()
        M.destroy()


@pytest.mark.mpi
def test_under_the_split_the_count_is_mumpss():
    """The pressed, tilted block of test_fieldsplit solved with the split: unstable_modes counts by
    the spectrum (preconditioned by the split) and equals MUMPS's inertia of the same tangent;
    without the split that count is refused."""
    from test_fieldsplit import PREFIX, SPLIT, block, user_options

    from bcfem.contact.plate_bounds import plate_bounds
    from bcfem.solver.problem import Problem

    comm = MPI.COMM_WORLD
    ctx, terms, bcs, bottom = block(comm, tilt=0.15)
    with user_options(SPLIT), Problem(ctx, terms, bcs, PREFIX, {"snes_type": "vinewtonrsls"},
                                      stability_count="spectrum") as problem:
        plate_bounds(problem, bottom, np.zeros(bottom.size))
        assert problem.solve(), problem.failure
        count = unstable_modes(problem)
        spectrum = problem.kept("tangent_spectrum", lambda: pytest.fail("not counted by the spectrum"))
        assert spectrum.lowest[0] > 0
        jacobian, _ = problem.jacobian()
        mumps = TangentInertia(PREFIX + "inertia_")
        try:
            negative = mumps.negative(jacobian, problem.held_rows())
        finally:
            mumps.close()
        assert count == negative - problem.global_size(problem.multipliers) == 0
        solved = spectrum.inner_iterations
        spectrum.inner_iterations = -1
        assert unstable_modes(problem) == 0 and spectrum.inner_iterations == -1  # the same tangent: not again
        assert solved > 0
    ctx, terms, bcs, _ = block(comm)
    with pytest.raises(ValueError, match="pc_type fieldsplit"):
        Problem(ctx, terms, bcs, PREFIX, stability_count="spectrum")


def test_a_kept_preconditioner_is_set_up_again_when_it_stops_serving():
    refresh = Refresh(growth=1.5, slack=4, limit=3)
    assert refresh.due()  # never set up
    refresh.set_up()
    refresh.solved(10)
    assert not refresh.due()
    refresh.skip()
    refresh.solved(19)  # within 1.5 x 10 + 4
    assert not refresh.due()
    refresh.solved(20)
    assert refresh.due()
    refresh.set_up()
    refresh.solved(8)
    refresh.solved(-1)  # a failed solve
    assert refresh.due()
    refresh.set_up()
    refresh.solved(8)
    for _ in range(3):
        assert not refresh.due()
        refresh.skip()
    assert refresh.due()  # the limit of skips in a row


def test_the_users_eigensolver_options_win():
    """``-<prefix>eps_max_it 1`` reaches the count's eigensolver: one iteration finds nothing."""
    prefix = "bcfem_test_spectrum_options_"
    options = PETSc.Options()
    options[prefix + "eps_max_it"] = 1
    spectrum = SchurSpectrum(MPI.COMM_SELF, prefix=prefix)
    M, _, multipliers = saddle(MPI.COMM_SELF, -1.0)
    try:
        with pytest.raises(RuntimeError, match="in 1 iterations"):
            spectrum.negative(M, np.empty(0, PETSc.IntType), multipliers.astype(PETSc.IntType))
    finally:
        options.delValue(prefix + "eps_max_it")
        spectrum.close()
        M.destroy()
