"""Loss of stability from the tangent's inertia, on a case whose answer is known exactly:
an inflated neo-Hookean membrane is stable under volume control everywhere, and under
pressure control up to the pressure maximum only (a dead load past a limit point)."""

import math

from mpi4py import MPI

import pytest

from bcfem import Term
from bcfem.path.volume_control import VolumeControl
from bcfem.physics.energies import MembraneStrain
from bcfem.physics.protocols import find_term
from bcfem.scenes import blister_rigid
from bcfem.solver.problem import Problem
from bcfem.stability.inertia import unstable_modes

pytestmark = pytest.mark.mpi
FOLD = 0.667656  # V/V0 of the neo-Hookean pressure maximum (tests/test_blister_rigid.py, P2/200)


class DeadPressure(Term):
    """-P V with P a fixed number: pressure control."""

    def __init__(self, pressure):
        self.pressure = pressure

    def energy(self, ctx):
        kin = ctx.kin
        return kin.integral(-ctx.constant("dead_pressure", self.pressure) * kin.volume_density)


@pytest.mark.parametrize("v_over_v0, unstable_under_pressure", [(0.55, 0), (0.66, 0), (0.675, 1), (0.9, 1)])
def test_inertia_finds_the_pressure_maximum(v_over_v0, unstable_under_pressure):
    params = blister_rigid.Params(material="neo-hookean", cells=60)
    scene = blister_rigid.build(params, MPI.COMM_WORLD)
    scene.start()
    volume = Problem(scene.ctx, scene.terms, scene.bcs, scene.prefix, scene.petsc_options)
    VolumeControl.membrane(scene.ctx).solve_to(volume, v_over_v0 * 4 * math.pi / 3)
    # the pressure is the multiplier of the volume constraint: PressureVolume says so
    assert volume.multipliers == ("pressure",)
    assert unstable_modes(volume) == unstable_modes(volume, ["pressure"]) == 0  # volume control: always stable
    pressure = scene.ctx.states["pressure"].x.array[0]
    strain = find_term(scene.terms, MembraneStrain)
    dead = Problem(scene.ctx, [strain, DeadPressure(pressure)], scene.bcs, "dead_", scene.petsc_options)
    # the same state is an equilibrium of the pressure-controlled problem (same u-residual);
    # its unused "pressure" unknown only adds a null pivot, not a negative one, and no term
    # declares it a multiplier
    assert dead.multipliers == ()
    assert unstable_modes(dead) == unstable_under_pressure
    dead.close()
    volume.close()


def _tridiagonal(diagonal, coupling, extra=None):
    """A symmetric tridiagonal matrix on COMM_WORLD; ``extra`` (i, j, value) adds one
    symmetric pair of entries outside that pattern."""
    from petsc4py import PETSc

    n = len(diagonal)
    A = PETSc.Mat().createAIJ((n, n), nnz=(4, 4), comm=MPI.COMM_WORLD)
    A.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, False)
    start, end = A.getOwnershipRange()
    for i in range(start, end):
        A.setValue(i, i, diagonal[i])
        for j in (i - 1, i + 1):
            if 0 <= j < n:
                A.setValue(i, j, coupling)
        if extra is not None and i in extra[:2]:
            A.setValue(i, extra[1] if i == extra[0] else extra[0], extra[2])
    A.assemble()
    return A


def test_kept_inertia_matches_a_fresh_count_and_analyses_a_new_pattern_again():
    """Counts with the kept copy and analysis equal those of a fresh factorisation as the
    values change; a held row drops out of the count; an entry outside the pattern (a new
    contact) makes the copy and the analysis afresh."""
    import numpy as np

    from bcfem.stability.inertia import TangentInertia, negative_eigenvalues

    signs = np.array([1.0, -2.0, 3.0, -4.0, 5.0, 6.0, -7.0, 8.0])
    kept = TangentInertia("test_kept_inertia_")
    try:
        for k, diagonal in enumerate([signs, -signs, np.abs(signs), signs]):
            A = _tridiagonal(diagonal, 0.01)
            fresh = A.copy()
            rows = np.arange(*A.getOwnershipRange(), dtype=np.int32)
            held = rows[np.isin(rows, [1])]  # unknown 1 (negative in signs) held
            fresh.zeroRowsColumns(held, diag=1.0)
            expected = int(np.sum(np.delete(diagonal, 1) < 0))
            assert kept.negative(A, held) == negative_eigenvalues(fresh, "test_fresh_") == expected
            assert kept.analyses == 1, f"values {k}: one analysis for one pattern"
            A.destroy()
            fresh.destroy()
        A = _tridiagonal(signs, 0.01, extra=(0, 5, 0.02))
        assert kept.negative(A, np.zeros(0, dtype=np.int32)) == int(np.sum(signs < 0))
        assert kept.analyses == 2
        A.destroy()
    finally:
        kept.close()


def test_the_users_unprefixed_mumps_options_reach_the_inertia_count():
    """``-mat_mumps_icntl_14 77`` (more workspace) applies to every MUMPS factorisation, the
    stability count's under its own prefix too; bcfem's ICNTL(13) = 1 (a global inertia) stays."""
    from petsc4py import PETSc

    import numpy as np

    from bcfem.stability.inertia import Inertia

    opts = PETSc.Options()
    opts["mat_mumps_icntl_14"] = 77
    inertia = Inertia("test_users_mumps_")
    A = _tridiagonal(np.array([1.0, -2.0, 3.0, -4.0]), 0.01)
    try:
        assert inertia.negative(A) == 2
        factor = inertia._ksp.getPC().getFactorMatrix()
        assert factor.getMumpsIcntl(14) == 77 and factor.getMumpsIcntl(13) == 1
        assert not opts.hasName("test_users_mumps_mat_mumps_icntl_14")  # nothing left behind
    finally:
        opts.delValue("mat_mumps_icntl_14")
        inertia.close()
        A.destroy()
