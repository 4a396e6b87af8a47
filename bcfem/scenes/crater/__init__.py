"""Scene ``crater``: the suction cycle of an air- or liquid-filled crater (ch. 7-8).

``params`` (no dolfinx), ``model`` (mesh, terms, boundary conditions, observables),
``stages`` (the declared stages ``load`` and ``unload``), ``report`` (summary and plot)
and ``frames`` (deformed shapes). The model and stages load the finite-element stack on
first use, so the command line checks the parameters before any of it.
"""

from __future__ import annotations

import importlib
import math

from bcfem.scenes.crater.params import (
    CLOSURE_CRITERIA,
    COLUMNS,
    DESCRIPTION,
    MAX_CLOSURE_PRELOAD,
    PRELOAD_TO_CLOSURE,
    STABILITY,
    SUMMARY,
    ClosureCriteria,
    Params,
)

_HEAVY = {"Crater": "model", "CraterCycle": "stages", "LINE_SEARCH_FALLBACKS": "stages", "CAREFUL": "stages",
          "classify": "report", "symmetry_breaking": "report", "plot": "report"}


def __getattr__(name: str):
    if name in _HEAVY:
        return getattr(importlib.import_module(f"bcfem.scenes.crater.{_HEAVY[name]}"), name)
    raise AttributeError(f"module 'bcfem.scenes.crater' has no attribute {name!r}")


def build(params: Params, comm, *, extra_terms=(), model_class=None):
    """The crater scene (meshed when solved), for :mod:`bcfem.run.runner`. ``extra_terms``: a
    research script's terms, added to every stage they belong to; ``model_class``: a subclass of
    :class:`~bcfem.scenes.crater.model.Crater` (another geometry)."""
    from bcfem.scenes.crater.fundamental import FundamentalCycle
    from bcfem.scenes.crater.stages import CraterCycle

    cycle = FundamentalCycle if params.path == "fundamental" else CraterCycle
    scene = cycle(params, comm, *(model_class,) if model_class else ())
    scene.extra_terms = tuple(extra_terms)
    return scene


def solve(params: Params, comm, model_class=None, *, extra_terms=()) -> tuple[list[dict], dict]:
    """One cycle in memory: (rows, summary). Raises :class:`bcfem.run.runner.SolveError` if it
    cannot be completed (the error's ``run`` holds the converged part)."""
    from bcfem.run.runner import solve_rows

    return solve_rows(build(params, comm, extra_terms=extra_terms, model_class=model_class), comm)


def sweep_point(params: Params, comm) -> dict:
    """One point of ``bcfem sweep crater``: the cycle's end values."""
    _, summary = solve(params, comm)
    return point_of(params, summary)


def point_of(params: Params, summary: dict) -> dict:
    """A solved cycle's point of a map (``summary``: the cycle's)."""
    point = {k: summary[k] for k in ("F_tilde", "F_hat", "V1_over_V0", "V2_over_V0", "p2_over_pa", "A2_over_A0",
                                     "eps_at_zero_force", "preload", "eps_m", "stability", "final_unstable_modes")}
    point["stability_code"] = STABILITY.index(summary["stability"])  # a number for contour maps
    point["retraced"] = summary["retraced"] is not None
    if params.cavitation != -math.inf:  # where the liquid cavitates on unloading (None: it does not)
        point["eps_cavitation"] = summary["cavitation"]["eps"] if summary["cavitation"] else None
    if params.waves:
        point["stability_waves"] = summary["stability_waves"]
        point["symmetry_code"] = STABILITY.index(summary["stability_waves"])
    return point


#: What ``bcfem sweep crater`` computes and plots (one axis: a curve per column).
#: ``bcfem fit`` has no inverse problem of this scene
FIT_TARGETS: dict = {}
SWEEP = {"solve": sweep_point,
         "maps": [("F_tilde", "F~"), ("F_hat", "F^ = F/(mu A0)"), ("V1_over_V0", "V1/V0"),
                  ("V2_over_V0", "V2/V0"), ("p2_over_pa", "p2/p_a"), ("A2_over_A0", "A2/A0"),
                  ("preload", "eps (eps_m for --preload closure)"),
                  ("stability_code", "0 stable, 1 unstable on unloading, 2 on loading too"),
                  ("symmetry_code", "symmetry breaking (--waves): 0 none, 1 on unloading, 2 on loading too")],
         "title": "suction cycle"}

__all__ = ["CLOSURE_CRITERIA", "COLUMNS", "DESCRIPTION", "FIT_TARGETS", "MAX_CLOSURE_PRELOAD", "PRELOAD_TO_CLOSURE",
           "STABILITY", "SUMMARY", "SWEEP", "ClosureCriteria", "Params", "build", "point_of", "solve", "sweep_point"]
