"""The residual of a blocked problem without dolfinx's lifting, where the lifting is nought."""

from __future__ import annotations

from petsc4py import PETSc

from dolfinx import fem
from dolfinx.fem.petsc import assemble_vector, assign, set_bc


class UnliftedResidual:
    """dolfinx's blocked residual (:func:`dolfinx.fem.petsc.assemble_residual`) without the
    lifting, for an iterate that meets its Dirichlet values.

    The lifting adds J (g - x) to the free rows: the Newton step's move of the Dirichlet
    dofs, coupled into the rest. It runs the Jacobian's kernels on every cell at a Dirichlet
    dof, at every residual, although g - x is round-off once a solve's first step has moved
    the dofs onto g. The residual is then assembled without it."""

    def __init__(self, b: PETSc.Vec, u, residual, jacobian, bcs, _blocks):
        self.u, self.forms, self.blocks = u, residual, _blocks
        spaces = fem.extract_function_spaces(residual)
        assert isinstance(spaces, list), "a blocked residual has a space per block"
        self.bcs = fem.bcs_by_block(spaces, bcs)
        self.misfit = b.duplicate()
        self.misfit.setAttr("_blocks", _blocks)

    def lifting_needed(self, x: PETSc.Vec) -> bool:
        """Whether x misses g by more than round-off anywhere (the same answer on every rank:
        the norm is global)."""
        self.misfit.zeroEntries()
        x.setAttr("_blocks", self.blocks)
        set_bc(self.misfit, self.bcs, x0=x, alpha=-1.0)  # x - g at the Dirichlet dofs
        scale = max(1.0, x.norm(PETSc.NormType.INFINITY))
        return self.misfit.norm(PETSc.NormType.INFINITY) > 1e-14 * scale

    def __call__(self, x: PETSc.Vec, b: PETSc.Vec) -> None:
        x.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
        assign(x, self.u)
        b.setAttr("_blocks", self.blocks)
        with b.localForm() as local:
            local.set(0.0)
        assemble_vector(b, self.forms)
        b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        set_bc(b, self.bcs, x0=x, alpha=-1.0)
        b.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)

    def destroy(self) -> None:
        self.misfit.destroy()
