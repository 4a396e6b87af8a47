"""The residual of a blocked problem lifted only by the Dirichlet conditions the iterate misses."""

from __future__ import annotations

from petsc4py import PETSc

from dolfinx import fem
from dolfinx.fem.petsc import apply_lifting, assemble_vector, assign, set_bc


class UnliftedResidual:
    """dolfinx's blocked residual (:func:`dolfinx.fem.petsc.assemble_residual`), lifted by the
    Dirichlet conditions whose values the iterate misses and by no other.

    The lifting adds J (g - x) to the free rows: the Newton step's move of the Dirichlet dofs,
    coupled into the rest. It runs the Jacobian's kernels on every cell at a Dirichlet dof,
    although g - x is round-off wherever the dofs are on g already: everywhere once a solve's
    first step has moved them, and on every held face but a moving platen before it. A
    condition met to round-off contributes nothing, so it is left out of the lifting (all of
    them, when the iterate meets every one), and the residual is the same."""

    def __init__(self, b: PETSc.Vec, u, residual, jacobian, bcs, _blocks):
        self.u, self.forms, self.jacobian, self.blocks = u, residual, jacobian, _blocks
        spaces, trial_spaces = fem.extract_function_spaces(residual), fem.extract_function_spaces(jacobian, 1)
        assert isinstance(spaces, list) and isinstance(trial_spaces, list), "a blocked problem has a space per block"
        self.spaces, self.trial_spaces = spaces, trial_spaces
        self.bcs = fem.bcs_by_block(self.spaces, bcs)
        self._each = [(bc, fem.bcs_by_block(self.spaces, [bc])) for bc in bcs]  # one condition by block
        self.misfit = b.duplicate()
        self.misfit.setAttr("_blocks", _blocks)

    def missed(self, x: PETSc.Vec) -> list[fem.DirichletBC]:
        """The conditions whose dofs x misses by more than round-off (the same on every rank:
        the norms are global)."""
        x.setAttr("_blocks", self.blocks)
        scale = max(1.0, x.norm(PETSc.NormType.INFINITY))
        missed = []
        for bc, by_block in self._each:
            self.misfit.zeroEntries()
            set_bc(self.misfit, by_block, x0=x, alpha=-1.0)  # x - g on its dofs
            if self.misfit.norm(PETSc.NormType.INFINITY) > 1e-14 * scale:
                missed.append(bc)
        return missed

    def __call__(self, x: PETSc.Vec, b: PETSc.Vec) -> bool:
        """b = the residual at x; whether it was lifted (by some condition)."""
        missed = self.missed(x)
        x.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
        assign(x, self.u)
        b.setAttr("_blocks", self.blocks)
        with b.localForm() as local:
            local.set(0.0)
        assemble_vector(b, self.forms)
        if missed:
            apply_lifting(b, self.jacobian, bcs=fem.bcs_by_block(self.trial_spaces, missed), x0=x, alpha=-1.0)
        b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        set_bc(b, self.bcs, x0=x, alpha=-1.0)
        b.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
        return bool(missed)

    def destroy(self) -> None:
        self.misfit.destroy()
