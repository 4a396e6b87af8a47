"""A neo-Hookean block on a rectangle with its Fourier modes, shared by the modes tests."""

from mpi4py import MPI

from dolfinx import fem, mesh

from bcfem.kinematics.solid import AxisymmetricSolid
from bcfem.physics.context import Context
from bcfem.physics.energies import SolidStrain
from bcfem.physics.materials import NearlyIncompressibleNeoHookean
from bcfem.solver.problem import Problem
from bcfem.stability.modes import ModeAnalysis


class Block:
    """A neo-Hookean body on the rectangle [r0, r1] x [0, h], held by ``held`` =
    [(component, where, value(x) or None)]: its axisymmetric state and Fourier modes."""

    def __init__(self, r0, r1, h, cells, held, kappa=1e4, comm=MPI.COMM_WORLD):
        self.mesh = mesh.create_rectangle(comm, [[r0, 0.0], [r1, h]], list(cells),
                                          mesh.CellType.triangle)
        V = fem.functionspace(self.mesh, ("Lagrange", 2, (2,)))
        self.u = fem.Function(V, name="displacement")
        ctx = Context(self.u, AxisymmetricSolid(self.u, quadrature_degree=4))
        terms = [SolidStrain(NearlyIncompressibleNeoHookean(mu=1.0, kappa=kappa))]
        self.values, bcs = [], []
        for component, where in held:
            space, _ = V.sub(component).collapse()
            facets = mesh.locate_entities_boundary(self.mesh, 1, where)
            dofs = fem.locate_dofs_topological((V.sub(component), space), 1, facets)
            value = fem.Function(space)
            self.values.append(value)
            bcs.append(fem.dirichletbc(value, dofs, V.sub(component)))
        self.problem = Problem(ctx, terms, bcs, "bcfem_test_modes_")
        self.modes = ModeAnalysis(ctx, terms, bcs)

    def solve(self, guess, values):
        self.u.interpolate(guess)
        for function, value in zip(self.values, values):
            function.x.array[:] = value
        assert self.problem.solve(), self.problem.reason
