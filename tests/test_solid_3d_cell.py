"""A lattice cell that spreads: the 3-D solid kinematics with two global strains.

A quarter of a square prism (mirror faces x = 0, y = 0; the cell's side faces x = y = L/2
stay planes) is pressed by a platen. The platen's strain w and the lateral macroscopic strain e
enter as the lift u = ũ + e (x, y, 0) + w (0, 0, z) of :class:`bcfem.kinematics.solid_3d.Solid3D`, with
ũ held normal to every face: w is prescribed, e is a global unknown whose residual is the mean
lateral traction, zero. An uncratered cell is then in uniform uniaxial stress: e = (1 − ε)^(−1/2)
− 1 for an incompressible solid and the platen's nominal stress μ(λ − λ⁻²), λ = 1 − ε.
"""

from mpi4py import MPI

import numpy as np
import pytest
import ufl
from dolfinx import fem, mesh

from bcfem.kinematics.solid_3d import Solid3D
from bcfem.mpi import global_sum, real_value
from bcfem.physics.bcs import component, where
from bcfem.physics.context import Context
from bcfem.physics.energies import SolidStrain
from bcfem.physics.materials import NearlyIncompressibleNeoHookean
from bcfem.solver.problem import Problem
from tests.helpers import exact_uniaxial

pytestmark = pytest.mark.mpi
HALF = 0.5  # the cell's half-width; height 1
KAPPA = 1e6


def spread_cell(eps: float):
    msh = mesh.create_box(MPI.COMM_WORLD, [[0, 0, 0], [HALF, HALF, 1]], [3, 3, 4], mesh.CellType.tetrahedron)
    V = fem.functionspace(msh, ("Lagrange", 2, (3,)))
    u = fem.Function(V, name="displacement")
    ctx = Context(u)
    e = ctx.real_state("lateral_strain")
    w = fem.Constant(msh, -eps)
    x = ufl.SpatialCoordinate(msh)
    ctx.kin = Solid3D(u, quadrature_degree=4, lift=ufl.as_vector([e * x[0], e * x[1], w * x[2]]))
    bcs = [component(V, axis, where(V, lambda p, a=axis, v=v: np.isclose(p[a], v)))
           for axis, ends in ((0, (0, HALF)), (1, (0, HALF)), (2, (0, 1))) for v in ends]
    terms = [SolidStrain(NearlyIncompressibleNeoHookean(mu=1.0, kappa=KAPPA))]
    problem = Problem(ctx, terms, bcs, "test_cell_")
    assert problem.solve(), problem.failure
    force = ufl.derivative(sum(t.energy(ctx) for t in terms), u, ufl.as_vector([0, 0, x[2]]))
    # dPi/dw over the cell's volume (height 1): the platen's nominal stress
    stress = global_sum(fem.form(force)) / (HALF * HALF)
    lateral = real_value(e)
    problem.close()
    return lateral, stress


@pytest.mark.parametrize("eps", [0.1, 0.3])
def test_an_uncratered_cell_spreads_in_uniaxial_stress(eps):
    """The homogeneous state is in the discrete space: the cell is the exact uniaxial state of its
    nearly incompressible energy to solver tolerance, and that state is the incompressible one
    to O(mu/kappa)."""
    lateral, stress = spread_cell(eps)
    stretch = 1 - eps
    l, exact = exact_uniaxial(stretch, KAPPA)
    assert lateral == pytest.approx(l - 1, rel=1e-9)
    assert stress == pytest.approx(exact, rel=1e-9)
    assert lateral == pytest.approx(stretch**-0.5 - 1, rel=10 / KAPPA)
    assert stress == pytest.approx(stretch - stretch**-2, rel=10 / KAPPA)
