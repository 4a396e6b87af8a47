"""A kept copy of a matrix whose sparsity only grows: a direct solver's symbolic analysis of
the copy stays valid from one factorisation to the next along a path."""

from __future__ import annotations

from petsc4py import PETSc


class KeptCopy:
    """The values of a source matrix copied into one kept matrix. A source with more entries
    than the copy (a discrete term added some, e.g. a new contact) is copied afresh. Destroy
    with :meth:`destroy` (collective)."""

    def __init__(self) -> None:
        self.matrix: PETSc.Mat | None = None
        self._entries = -1

    def update(self, source: PETSc.Mat) -> bool:
        """Copy ``source``'s values into the kept matrix; True when that matrix is new (its
        pattern needs a new analysis). Collective."""
        entries = source.getInfo()["nz_used"]  # summed over the ranks: one answer on all
        if self.matrix is not None and entries == self._entries:
            source.copy(self.matrix, structure=PETSc.Mat.Structure.SAME_NONZERO_PATTERN)
            return False
        self.destroy()
        self.matrix = source.duplicate(copy=True)
        self.matrix.setOption(PETSc.Mat.Option.KEEP_NONZERO_PATTERN, True)
        self._entries = entries
        return True

    def holds(self, source: PETSc.Mat) -> bool:
        """Whether the kept matrix has ``source``'s pattern (collective)."""
        return self.matrix is not None and source.getInfo()["nz_used"] == self._entries

    def destroy(self) -> None:
        if self.matrix is not None:
            self.matrix.destroy()
        self.matrix, self._entries = None, -1
