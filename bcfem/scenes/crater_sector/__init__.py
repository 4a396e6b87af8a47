"""The crater's suction cycle on a 3-D wedge pi/m of its specimen (:mod:`bcfem.geometry.crater_sector`;
m = 2: the quarter), the axisymmetric crater's terms on :class:`bcfem.kinematics.solid_3d.Solid3D`,
the first brick of the 3-D crater cells; its first non-axisymmetric bifurcation and the branch
past it.

``model`` (the wedge, its mirror multiplier), ``onset`` (the first bifurcation), ``branch`` (the
critical mode, the branch past it) and ``paths`` (the drivers as functions, loaded on first use).
"""

from __future__ import annotations

_PATHS = ("axisymmetric_suction_waves", "cycle", "drawn_stability", "first_onset", "loading_stability",
          "suction_stability")


def __getattr__(name: str):
    if name in _PATHS:
        from bcfem.scenes.crater_sector import paths

        return getattr(paths, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = list(_PATHS)
