r"""The start of a blister of any outline: the Föppl (small-deflection) membrane.

At small volume a membrane inflated from flat has out-of-plane stiffness only through the
tension its own deflection makes, so Newton needs a guess that is already stretched the right
way. For the deflection h ŵ (ŵ: the solution of -Δŵ = 1, ŵ = 0 on the edge, over its maximum)
the in-plane displacement h² a minimises the small-strain stretching energy of the
incompressible membrane (plane stress, E = 3μ, ν = 1/2),

.. math:: U = \mu t_0 \int \varepsilon:\varepsilon + (\operatorname{tr}\varepsilon)^2\, dA,
   \qquad \varepsilon = \operatorname{sym}\nabla a + \tfrac12 \nabla\hat w\otimes\nabla\hat w,

with a = 0 on the edge: two linear solves, whatever the outline. Then U = h⁴ U₁ and
V = h ∫ŵ dA, so the pressure guess is dU/dV = 4 h³ U₁ / ∫ŵ dA.
"""

from __future__ import annotations

from mpi4py import MPI

import numpy as np
import ufl
from dolfinx import fem
from dolfinx.fem.petsc import LinearProblem

from bcfem.mpi import global_sum

_SOLVER = {"ksp_type": "preonly", "pc_type": "lu"}


class FopplStart:
    """The shape (a, ŵ) and its constants on the mesh of ``V`` (the displacement's space).

    Args:
        V: the three-component displacement space.
        edge_facets: the clamped edge's facets.
    """

    def __init__(self, V, edge_facets):
        msh = V.mesh
        degree = V.element.basix_element.degree
        fdim = msh.topology.dim - 1
        S = fem.functionspace(msh, ("Lagrange", degree))
        P = fem.functionspace(msh, ("Lagrange", degree, (2,)))
        w, q = ufl.TrialFunction(S), ufl.TestFunction(S)
        bc = fem.dirichletbc(0.0, fem.locate_dofs_topological(S, fdim, edge_facets), S)
        shape = LinearProblem(ufl.inner(ufl.grad(w), ufl.grad(q)) * ufl.dx, q * ufl.dx, bcs=[bc],
                              petsc_options_prefix="bcfem_blister_3d_shape_", petsc_options=_SOLVER).solve()
        assert isinstance(shape, fem.Function), "one unknown"
        self.w = shape
        peak = msh.comm.allreduce(float(self.w.x.array.max(initial=0.0)), op=MPI.MAX)
        self.w.x.array[:] /= peak

        def strain(a):
            return ufl.sym(ufl.grad(a))

        def stress(e):
            return 2 * (e + ufl.tr(e) * ufl.Identity(2))

        lift = 0.5 * ufl.outer(ufl.grad(self.w), ufl.grad(self.w))
        a, b = ufl.TrialFunction(P), ufl.TestFunction(P)
        bc = fem.dirichletbc(fem.Function(P), fem.locate_dofs_topological(P, fdim, edge_facets))
        self.a = LinearProblem(ufl.inner(stress(strain(a)), strain(b)) * ufl.dx,
                               -ufl.inner(stress(lift), strain(b)) * ufl.dx, bcs=[bc],
                               petsc_options_prefix="bcfem_blister_3d_stretch_", petsc_options=_SOLVER).solve()
        e = strain(self.a) + lift
        self.stretching = global_sum(fem.form((ufl.inner(e, e) + ufl.tr(e) ** 2) * ufl.dx))
        self.shape_volume = global_sum(fem.form(self.w * ufl.dx))
        self.slope_area = global_sum(fem.form(0.5 * ufl.inner(ufl.grad(self.w), ufl.grad(self.w)) * ufl.dx))
        self._h = fem.Constant(msh, 0.0)
        self._shape = fem.Expression(ufl.as_vector([self._h**2 * self.a[0], self._h**2 * self.a[1],
                                                    self._h * self.w]), V.element.interpolation_points)

    def apply(self, u: fem.Function, volume: float, stiffness: float = 1.0, tension: float = 0.0) -> float:
        """Set ``u`` to the shape of enclosed ``volume`` (to first order); returns the pressure
        of the Föppl membrane of modulus ``stiffness`` plus that of an isotropic ``tension``."""
        h = volume / self.shape_volume
        self._h.value = np.asarray(h)
        u.interpolate(self._shape)
        # dU/dV of U = h^4 U1 stiffness + tension h^2 slope_area, V = h shape_volume
        return (4 * h**3 * self.stretching * stiffness + 2 * h * self.slope_area * tension) / self.shape_volume
