"""Dirichlet conditions on a component of a vector displacement, on located facets, and a
mirror plane that is not a coordinate plane, held by a multiplier field (:class:`MirrorPlane`)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import ufl
from dolfinx import fem, mesh

from bcfem.physics.context import Context
from bcfem.physics.protocols import Term

if TYPE_CHECKING:
    from bcfem.kinematics.submesh import BoundaryPatch


def component(V: fem.FunctionSpace, sub: int, facets: np.ndarray, value: fem.Function | None = None
              ) -> fem.DirichletBC:
    """``u[sub] = value`` (0 if None; a Function of the collapsed component space, so it can
    change during a run, e.g. a platen) on the dofs of ``facets``."""
    collapsed, _ = V.sub(sub).collapse()
    fdim = V.mesh.topology.dim - 1
    dofs = fem.locate_dofs_topological((V.sub(sub), collapsed), fdim, facets)
    return fem.dirichletbc(value if value is not None else fem.Function(collapsed), dofs, V.sub(sub))


def where(V: fem.FunctionSpace, marker) -> np.ndarray:
    """The boundary facets of V's mesh whose points satisfy ``marker(x)``."""
    msh = V.mesh
    return mesh.locate_entities_boundary(msh, msh.topology.dim - 1, marker)


@dataclass(frozen=True)
class MirrorPlane(Term):
    r"""The displacement held in a mirror plane through the z axis at the angle ``angle``:
    :math:`\int_\Gamma \lambda\, u\cdot n\, dA`, n = (-sin, cos, 0), with the multiplier field
    :math:`\lambda` (P2 on the face's submesh, the trace space of u.n, so that the constraint is
    u.n = 0 at every node of the face: its mass matrix is invertible). :math:`\lambda` is the
    face's normal traction (per reference area, over the energy scale). One multiplier per face
    node, each one negative eigenvalue of the tangent (:mod:`bcfem.stability.inertia`).

    Attributes:
        patch: the face's submesh.
        angle: its polar angle theta [rad].
    """

    patch: BoundaryPatch
    angle: float
    name = "mirror_plane"
    multipliers = ("mirror_traction",)

    def energy(self, ctx: Context) -> ufl.Form:
        traction = self.patch.state(ctx, "mirror_traction", ("Lagrange", 2))
        normal = ufl.as_vector([-math.sin(self.angle), math.cos(self.angle), 0.0])
        # a zero lambda-lambda block that is assembled, so that the multiplier's rows have their
        # diagonal in the matrix's pattern: PETSc's zeroRowsColumns (the unknowns held on the
        # plate, in the solver's reduced step and the inertia count) refuses a matrix without
        return ctx.kin.surface_integral(traction * ufl.dot(ctx.u, normal)
                                        + ctx.constant("mirror_pattern", 0.0) * traction**2, self.patch.tag)
