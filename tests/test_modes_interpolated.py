"""The Fourier-mode block is quadratic in the wave number n (bcfem.stability.modes): a scan that
interpolates it from three wave numbers gives the matrices and the counts of assembling
each n."""

from mpi4py import MPI
from petsc4py import PETSc

import numpy as np
import pytest
from mode_block import Block

pytestmark = pytest.mark.mpi


def compressed_ring(comm) -> Block:
    """A thin ring compressed in the hoop direction past its wrinkling stretch, so that a
    band of high n is unstable and the low n are not."""
    inner, radius, height = 19.0, 20.0, 0.25
    block = Block(inner, radius, height, (8, 1),
                  [(0, lambda x: np.isclose(x[0], inner)),
                   (1, lambda x: np.isclose(x[1], 0) | np.isclose(x[1], height))], kappa=1e4, comm=comm)
    stretch = 0.4  # the surface's hoop stretch 0.49, past Biot's 0.544 for n ~ 30 and above
    block.solve(lambda x: np.vstack([np.sqrt(stretch**2 * inner**2 + x[0]**2 - inner**2) - x[0], 0 * x[0]]),
                [(stretch - 1) * inner, 0.0])
    return block


@pytest.fixture(scope="module")
def ring():
    block = compressed_ring(MPI.COMM_WORLD)
    yield block
    block.modes.close()


def test_interpolated_blocks_equal_assembled_ones(ring):
    modes = ring.modes
    waves = list(range(2, 41))
    interpolated = [A.copy() for A in modes.interpolated(waves)]
    compiled = modes._compiled(2)
    bcs = modes._bcs(compiled, 2, None)
    direct = compiled["matrix"].duplicate()
    try:
        for n, A in zip(waves, interpolated):
            modes._assemble(compiled, n, bcs, direct)
            scale = direct.norm(PETSc.NormType.FROBENIUS)
            A.axpy(-1.0, direct, PETSc.Mat.Structure.SAME_NONZERO_PATTERN)
            assert A.norm(PETSc.NormType.FROBENIUS) <= 1e-12 * scale, n
    finally:
        direct.destroy()
        for A in interpolated:
            A.destroy()


def test_scan_counts_as_each_wave_number_alone(ring):
    modes = ring.modes
    waves = range(1, 41)
    scanned = modes.scan(waves)
    alone = {n: modes.unstable(n) for n in waves}
    assert scanned == alone
    unstable = [n for n, count in alone.items() if count > 0]
    # a band of wrinkles, not every n and not none: the comparison sees both kinds
    assert unstable and 1 not in unstable and len(unstable) < len(alone)


def test_ranks_agree_on_the_scan(ring):
    if MPI.COMM_WORLD.size == 1:
        pytest.skip("needs 2 ranks")
    serial = compressed_ring(MPI.COMM_SELF)
    try:
        assert serial.modes.scan(range(1, 41)) == ring.modes.scan(range(1, 41))
    finally:
        serial.modes.close()
