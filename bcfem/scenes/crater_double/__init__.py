"""Scene ``crater-double``: the double-chamber crater of chapter 9, whose protuberance splits
the cavity into two chambers by contact.

``params`` (no dolfinx), ``model`` (the crater model on the double geometry: the split, the
chambers' volumes, the wetted area), ``stages`` (the cycle: ``load`` and ``unload``, each
followed with the chambers as they are) and ``report`` (the figures). The model and stages
load the finite-element stack on first use, so the command line checks the parameters first.
"""

from __future__ import annotations

from bcfem.scenes.crater_double.params import COLUMNS, DESCRIPTION, SUMMARY, Params


def build(params: Params, comm, *, extra_terms=(), model_class=None):
    """The double-crater scene (meshed when solved), for :mod:`bcfem.run.runner`. ``extra_terms``:
    a research script's terms, added to every stage they belong to."""
    from bcfem.scenes.crater_double.membrane import MembraneCycle
    from bcfem.scenes.crater_double.stages import DoubleCraterCycle

    cycle = MembraneCycle if params.chambers == "membrane" else DoubleCraterCycle
    scene = cycle(params, comm, *(model_class,) if model_class else ())
    scene.extra_terms = tuple(extra_terms)
    return scene


def solve(params: Params, comm, model_class=None, *, extra_terms=()) -> tuple[list[dict], dict]:
    """One cycle in memory: (rows, summary); raises :class:`bcfem.run.runner.SolveError` if it
    cannot be completed (the error's ``run`` holds the converged part)."""
    from bcfem.run.runner import solve_rows

    return solve_rows(build(params, comm, extra_terms=extra_terms, model_class=model_class), comm)


def sweep_point(params: Params, comm) -> dict:
    """One point of ``bcfem sweep crater-double``: the cycle's end values and its split."""
    _, summary = solve(params, comm)
    split = summary["split"]
    return {"F_tilde": summary["F_tilde"], "p_c1_over_pa": summary["p_c1_over_pa"],
            "p_c2_over_pa": summary["p_c2_over_pa"], "eps_contact": summary["eps_contact"],
            "splits": split is not None, "merged": summary["merge"] is not None,
            "p_at_split": split["p_over_pa"] if split else None, "stability": summary["stability"],
            "least_sidewall_gap": summary["least_sidewall_gap"]}


#: What ``bcfem sweep crater-double`` computes and plots (two axes: contour maps)
#: ``bcfem fit`` has no inverse problem of this scene
FIT_TARGETS: dict = {}
SWEEP = {"solve": sweep_point,
         "maps": [("F_tilde", "F~ at eps = 0 after the cycle"), ("p_c1_over_pa", "p_c1/p_a"),
                  ("p_c2_over_pa", "p_c2/p_a"), ("eps_contact", "eps_a (empty: no split)"),
                  ("least_sidewall_gap", "least sidewall-protuberance gap / H")],
         "title": "double-chamber crater cycle"}

__all__ = ["COLUMNS", "DESCRIPTION", "FIT_TARGETS", "SUMMARY", "SWEEP", "Params", "build", "solve", "sweep_point"]
