"""The crater model on the double-chamber geometry: the same terms, contact with the plate
and self-contact, on a wall of three tagged parts (sidewall, roof, protuberance), so that
the sidewall's contact with the protuberance is the wall's self-contact."""

from __future__ import annotations

from bcfem.geometry.double_crater import WALLS, create_mesh
from bcfem.scenes.crater.model import Crater


class DoubleCrater(Crater):
    """:class:`~bcfem.scenes.crater.model.Crater` on :mod:`bcfem.geometry.double_crater`
    (parameters: :class:`bcfem.scenes.crater_double.params.Params`)."""

    walls = WALLS
    create_mesh = staticmethod(create_mesh)
