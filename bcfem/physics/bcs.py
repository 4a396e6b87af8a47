"""Dirichlet conditions on a component of a vector displacement, on located facets."""

from __future__ import annotations

import numpy as np
from dolfinx import fem, mesh


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
