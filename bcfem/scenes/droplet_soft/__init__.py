"""Scene ``droplet-soft``: a liquid drop on a soft substrate, the wetting ridge (ch. 5).

``params`` (no dolfinx), ``model`` (mesh, terms, boundary conditions, observables and the
solve), ``report`` (profile and figures). The model loads the finite-element stack on
first use, so the command line checks the parameters before any of it.
"""

from __future__ import annotations

from bcfem.scenes.droplet_soft.params import COLUMNS, DESCRIPTION, MODELS, SUMMARY, Params


def build(params: Params, comm, *, extra_terms=()):
    """The droplet scene (meshed here), for :mod:`bcfem.run.runner`. ``extra_terms``: a research
    script's terms, added to every stage they belong to."""
    from bcfem.scenes.droplet_soft.model import DropletSoft

    scene = DropletSoft(params, comm)
    scene.extra_terms = tuple(extra_terms)
    return scene


def solve(params: Params, comm, *, extra_terms=()):
    """One solve in memory: (scene, rows, summary); the scene holds the surface ``profile``."""
    from bcfem.run import runner
    scene = build(params, comm, extra_terms=extra_terms)
    solved, summary = runner.solve(scene, comm)
    return scene, solved.rows, summary


__all__ = ["COLUMNS", "DESCRIPTION", "MODELS", "SUMMARY", "Params", "build", "solve"]
