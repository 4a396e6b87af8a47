"""Scene ``crater-sector``: the crater on a 3-D wedge pi/m of its specimen
(:mod:`bcfem.geometry.crater_sector`; m = 2: the quarter), the axisymmetric crater's terms on
:class:`bcfem.kinematics.solid_3d.Solid3D`: its suction cycle, and its first non-axisymmetric
bifurcation and the branch past it.

Vented loading to the preload, the crater sealed there with air at p_a, unloading to eps = 0
(the dissertation's Steps 1–2), with the bottom face held on the plate (free to slide) and the
top face on the platen (frictionless). The platen is the lift w z/H of the kinematics. The mirror
faces keep the wedge's share of a response with the wedge's symmetry (n = 0, m, 2m, ...
circumferential waves; :mod:`.model`); the wall is checked to stay above the plate (no contact is modelled
here). Pressures in p_a, lengths in mm as the crater scene.

``params`` (no dolfinx) and ``scene`` (the CLI's ``bcfem run crater-sector``); ``model`` (the wedge,
its mirror multiplier), ``onset`` (the first bifurcation), ``branch`` (the critical mode, the
branch past it) and ``paths`` (the drivers as functions, loaded on first use, so that the command
line checks the parameters before the finite-element stack is imported).
"""

from __future__ import annotations

from bcfem.columns import union
from bcfem.scenes.crater_sector.params import DESCRIPTION, SUMMARY, Params, columns

_PATHS = ("axisymmetric_suction_waves", "cycle", "drawn_stability", "first_onset", "loading_stability",
          "suction_stability")


def build(params: Params, comm, *, extra_terms=()):
    """The scene (meshed when solved), for :mod:`bcfem.run.runner`. ``extra_terms``: a research
    script's terms, in every problem on the wedge."""
    from bcfem.scenes.crater_sector.scene import SectorScene

    return SectorScene(params, comm, extra_terms)


def solve(params: Params, comm, *, extra_terms=()) -> tuple[list[dict], dict]:
    """One run in memory: (rows, summary)."""
    from bcfem.run.runner import solve_rows

    return solve_rows(build(params, comm, extra_terms=extra_terms), comm)


def __getattr__(name: str):
    if name in _PATHS:
        from bcfem.scenes.crater_sector import paths

        return getattr(paths, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


COLUMNS = union(columns("cycle"), columns("drawn"))
__all__ = ["COLUMNS", "DESCRIPTION", "SUMMARY", "Params", "build", "solve", *_PATHS]
