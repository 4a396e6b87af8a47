"""Scene ``crater-cell``: the suction cycle of a lattice of craters, on its smallest mirror cell
in 3-D (:mod:`bcfem.geometry.crater_cell`).

``params`` (no dolfinx), ``model`` (mesh, lateral strains, terms, observables) and ``stages``
(the cycle: ``load`` vented, ``unload`` sealed). The model loads the finite-element stack on
first use, so the command line checks the parameters first.
"""

from __future__ import annotations

from bcfem.scenes.crater_cell.params import COLUMNS, DESCRIPTION, SUMMARY, Params


def build(params: Params, comm, *, extra_terms=()):
    """The cell's cycle (meshed when solved), for :mod:`bcfem.run.runner`. ``extra_terms``: a
    research script's terms, added to every stage they belong to."""
    from bcfem.scenes.crater_cell.stages import CellCycle

    scene = CellCycle(params, comm)
    scene.extra_terms = tuple(extra_terms)
    return scene


def solve(params: Params, comm, *, extra_terms=()) -> tuple[list[dict], dict]:
    """One cycle in memory: (rows, summary); raises :class:`bcfem.run.runner.SolveError` if it cannot
    be completed (the error's ``run`` holds the converged part)."""
    from bcfem.run.runner import solve_rows

    return solve_rows(build(params, comm, extra_terms=extra_terms), comm)


__all__ = ["COLUMNS", "DESCRIPTION", "SUMMARY", "Params", "build", "solve"]
