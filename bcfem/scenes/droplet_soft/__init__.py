"""Scene ``droplet-soft``: a liquid drop on a soft substrate, the wetting ridge (ch. 5).

``params`` (no dolfinx), ``model`` (mesh, terms, boundary conditions, observables and the
solve), ``report`` (profile and figures). The model loads the finite-element stack on
first use, so the command line checks the parameters before any of it.
"""

from __future__ import annotations

from bcfem.scenes.droplet_soft.params import COLUMNS, DESCRIPTION, MODELS, SUMMARY, Params


def build(params: Params, comm):
    """The droplet scene (meshed here), for :mod:`bcfem.run.runner`."""
    from bcfem.scenes.droplet_soft.model import DropletSoft

    return DropletSoft(params, comm)


def solve(params: Params, comm):
    """One solve in memory: (scene, rows, summary); the scene holds the surface ``profile``."""
    from bcfem.run import runner
    scene = build(params, comm)
    solved, summary = runner.solve(scene, comm)
    return scene, solved.rows, summary


__all__ = ["COLUMNS", "DESCRIPTION", "MODELS", "SUMMARY", "Params", "build", "solve"]
