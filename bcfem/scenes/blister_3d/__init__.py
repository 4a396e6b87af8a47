"""Scene ``blister-3d``: a membrane blister of any outline on a rigid substrate, on a flat
reference mesh with a three-component displacement.

``params`` (no dolfinx) and ``model`` (the mesh, terms, start and observables); the model
loads the finite-element stack on first use, so the command line checks the parameters first.
"""

from __future__ import annotations

from bcfem.scenes.blister_3d.params import COLUMNS, DESCRIPTION, SUMMARY, Params


def build(params: Params, comm, *, extra_terms=()):
    """The blister of ``params``, for :mod:`bcfem.run.runner`. ``extra_terms``: a research
    script's terms, added to its energy."""
    from bcfem.scenes.blister_3d.model import build as compose

    return compose(params, comm, extra_terms)


__all__ = ["COLUMNS", "DESCRIPTION", "SUMMARY", "Params", "build"]
