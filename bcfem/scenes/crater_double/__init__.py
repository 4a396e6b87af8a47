"""Scene ``crater-double``: the double-chamber crater of chapter 9, whose protuberance splits
the cavity into two chambers by contact.

``params`` (no dolfinx), ``model`` (the crater model on the double geometry: the split, the
chambers' volumes, the wetted area), ``stages`` (the cycle: ``load`` and ``unload``, each
followed with the chambers as they are) and ``report`` (the figures). The model and stages
load the finite-element stack on first use, so the command line checks the parameters first.
"""

from __future__ import annotations

from bcfem.scenes.crater_double.params import COLUMNS, DESCRIPTION, SUMMARY, Params


def build(params: Params, comm, model_class=None):
    """The double-crater scene (meshed when solved), for :mod:`bcfem.runner`."""
    from bcfem.scenes.crater_double.stages import DoubleCraterCycle

    return DoubleCraterCycle(params, comm, *(model_class,) if model_class else ())


def solve(params: Params, comm, model_class=None) -> tuple[list[dict], dict]:
    """One cycle in memory: (rows, summary); raises :class:`bcfem.runner.SolveError` if it
    cannot be completed (the error's ``run`` holds the converged part)."""
    from bcfem.runner import solve_rows

    return solve_rows(build(params, comm, model_class), comm)


__all__ = ["COLUMNS", "DESCRIPTION", "SUMMARY", "Params", "build", "solve"]
