"""What the crater holds when its vent closes at the end of loading: one decision for the
stable path (:mod:`.stages`) and the fundamental branch (:mod:`.fundamental`)."""

from __future__ import annotations

from dataclasses import dataclass

from bcfem.scenes.crater.params import CLOSURE_CRITERIA


@dataclass(frozen=True)
class Sealing:
    """The crater sealed at the preload.

    Attributes:
        V1: the crater's volume at the preload.
        closed: nothing is left inside (the closure criteria, or a located closure): a
            vacuum holds the wall from then on.
        stays_closed: a closed liquid crater that cannot cavitate stays closed: V2 = V1 = 0
            and F = 0 (eq. 8.8), with no unloading to trace.
    """

    V1: float
    closed: bool
    stays_closed: bool

    @property
    def sealed_volume(self) -> float:
        """What the sealed fluid holds (a closed crater neglects its remnant)."""
        return 0.0 if self.closed else self.V1

    def final_closed(self, model, preload: float) -> dict:
        """The cycle's last row for a crater that stays closed: no suction."""
        return {**model.observe("unload", preload, 0.0), "p_over_pa": 1.0, "F_tilde": 0.0, "F_hat": 0.0,
                "A_over_A0": 0.0}


def seal(model, V1: float, closes: bool, fluid: str, cavitates: bool) -> Sealing:
    """Seal the crater at the end of loading (its volume V1; ``closes``: the load stage ended
    at a located closure; ``fluid``: ``air`` or ``liquid``; ``cavitates``: a liquid that can
    cavitate). An open crater's fluid starts at p_a."""
    closed = V1 <= CLOSURE_CRITERIA.closed * model.geometry.crater_volume or closes
    if not closed:
        model.ctx.real_state("fluid_pressure").x.array[:] = 1.0
    return Sealing(V1, closed, closed and fluid == "liquid" and not cavitates)
