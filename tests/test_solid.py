"""The axisymmetric nearly incompressible solid: homogeneous compression against closed forms."""

import math

import numpy as np
import pytest
import ufl
from dolfinx import fem, mesh
from mpi4py import MPI

from bcfem.context import Context
from bcfem.energies import SolidStrain
from bcfem.materials import NearlyIncompressibleNeoHookean
from bcfem.mpi import global_sum
from bcfem.problem import Problem
from bcfem.solid import AxisymmetricSolid
from helpers import exact_nominal_stress

pytestmark = pytest.mark.mpi
RADIUS, HEIGHT = 1.0, 2.0


def compress(stretch: float, kappa_over_mu: float, cells: int = 4):
    """A frictionless cylinder between plates, top displaced to stretch * H; returns the
    nominal stress (force / reference area) from the virtual work of w = (0, z/H)."""
    msh = mesh.create_rectangle(MPI.COMM_WORLD, [[0.0, 0.0], [RADIUS, HEIGHT]], [cells, 2 * cells],
                                mesh.CellType.triangle)
    V = fem.functionspace(msh, ("Lagrange", 2, (2,)))
    u = fem.Function(V, name="displacement")
    ctx = Context(u, AxisymmetricSolid(u, quadrature_degree=4))
    material = NearlyIncompressibleNeoHookean(mu=1.0, kappa=kappa_over_mu)
    terms = [SolidStrain(material)]
    Vr, _ = V.sub(0).collapse()
    Vz, _ = V.sub(1).collapse()
    fdim = 1

    def dofs(sub, collapsed, where):
        facets = mesh.locate_entities_boundary(msh, fdim, where)
        return fem.locate_dofs_topological((V.sub(sub), collapsed), fdim, facets)

    top_z = fem.Function(Vz)
    top_z.x.array[:] = (stretch - 1) * HEIGHT
    bcs = [fem.dirichletbc(fem.Function(Vr), dofs(0, Vr, lambda x: np.isclose(x[0], 0)), V.sub(0)),
           fem.dirichletbc(fem.Function(Vz), dofs(1, Vz, lambda x: np.isclose(x[1], 0)), V.sub(1)),
           fem.dirichletbc(top_z, dofs(1, Vz, lambda x: np.isclose(x[1], HEIGHT)), V.sub(1))]
    u.interpolate(lambda x: np.vstack([(stretch**-0.5 - 1) * x[0], (stretch - 1) * x[1]]))
    with Problem(ctx, terms, bcs, "bcfem_test_solid_") as problem:
        assert problem.solve(), problem.reason
        energy = sum(t.energy(ctx) for t in terms)
        w = fem.Function(V)
        w.interpolate(lambda x: np.vstack([0 * x[0], x[1] / HEIGHT]))
        force = global_sum(fem.form(ufl.derivative(energy, u, w)))
    return force / (math.pi * RADIUS**2)


@pytest.mark.parametrize("stretch", [0.6, 0.85, 1.2])
def test_homogeneous_compression_matches_the_closed_form(stretch):
    nominal = compress(stretch, kappa_over_mu=1e6)
    assert nominal == pytest.approx(exact_nominal_stress(stretch, 1e6), rel=1e-9)
    # and the incompressible limit, eq. 7.4: mu (lambda - lambda^-2), to O(mu/kappa)
    assert nominal == pytest.approx(stretch - stretch**-2, rel=1e-5)


def test_near_incompressibility_does_not_lock():
    """Taylor-Hood: kappa/mu = 1e6 gives the 1e3 result up to the O(mu/kappa) physics."""
    stiff, soft = compress(0.7, 1e6), compress(0.7, 1e3)
    limit = 0.7 - 0.7**-2
    assert abs(stiff - limit) < abs(soft - limit)
    assert stiff == pytest.approx(limit, rel=1e-5)
