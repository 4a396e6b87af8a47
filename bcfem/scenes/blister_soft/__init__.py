"""Scene ``blister-soft``: a liquid-filled membrane blister bonded to a soft substrate (ch. 4).

``params`` (no dolfinx: the command line checks the parameters before any meshing) and
``model`` (mesh, states, energy terms, boundary conditions, observables, the scene).
"""

from __future__ import annotations

from bcfem.scenes.blister_soft.params import COLUMNS, DESCRIPTION, EDGES, HELP, SUMMARY, Params

__all__ = ["COLUMNS", "DESCRIPTION", "EDGES", "HELP", "SUMMARY", "Params", "build"]


def build(params: Params, comm, *, extra_terms=(), data=None):
    """The scene (meshed here), for :mod:`bcfem.run.runner`. ``extra_terms``: a research script's
    terms, added to its energy; ``data``: a distributed substrate mesh to reuse."""
    from bcfem.scenes.blister_soft.model import build as build_model

    return build_model(params, comm, data, extra_terms)
