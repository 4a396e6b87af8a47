"""What a crater cycle reports: the summary entries, the stability class and the plot."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from bcfem.scenes.crater.params import CLOSURE_CRITERIA, PRELOAD_TO_CLOSURE, Params
from bcfem.scenes.crater.seal import Sealing
from bcfem.theory.crater import permeation_estimate


@dataclass
class Cycle:
    """What a crater cycle's stages find, in the order they find it: one record per trace, kept
    by the scene and read by :func:`finish`.

    Attributes:
        events: instabilities (inertia changes, snaps, folds), in path order.
        phase_changes: the sealed liquid's cavitation and collapse events.
        preload: the strain at the seal.
        closes: the load stage ended at a located closure.
        V1: the crater's volume at the seal.
        sealing: what the seal holds (None before it).
        vapour: the sealed liquid holds its vapour pressure now.
        start: where the unloading (re)starts: the preload, or the last phase change.
        zero_force: the strain at zero platen force (the preload for a crater that stays closed).
        final: the cycle's row at zero platen force.
        final_unstable: the unstable axisymmetric modes there (> 0: F is that of an unstable
            equilibrium, a saddle).
    """

    events: list[dict] = field(default_factory=list)
    phase_changes: list[dict] = field(default_factory=list)
    preload: float = 0.0
    closes: bool = False
    V1: float = 0.0
    sealing: Sealing | None = None
    vapour: bool = False
    start: float = 0.0
    zero_force: float = 0.0
    final: dict = field(default_factory=dict)
    final_unstable: int = 0

    @property
    def sealed(self) -> Sealing:
        if self.sealing is None:
            raise RuntimeError("the crater is not sealed yet")
        return self.sealing

    @property
    def cavitation(self) -> dict | None:
        """The first cavitation, or None."""
        return next((e for e in self.phase_changes if e["kind"] == "cavitation"), None)

    def partial(self) -> dict:
        """The summary entries a failed cycle reports too."""
        return {"instabilities": self.events, "phase_changes": self.phase_changes, "cavitation": self.cavitation}


def finish(run, params: Params, model, cycle: Cycle, recorded: bool = False) -> None:
    """Record the cycle's zero-force row (unless ``recorded``: a retraction went on from it) and
    its results in ``run`` (``params``: the crater scene's)."""
    geometry = model.geometry
    final, V1, closed, preload = cycle.final, cycle.V1, cycle.sealed.closed, cycle.preload
    events, vapour = cycle.events, cycle.vapour
    if not recorded:
        run.record(final)
    run.results.update({
        "F_tilde": final["F_tilde"], "F_hat": final["F_tilde"] / params.beta,
        "V1_over_V0": V1 / geometry.crater_volume,
        "V2_over_V0": final["V_over_V0"], "p2_over_pa": final["p_over_pa"], "A2_over_A0": final["A_over_A0"],
        "preload": preload, "eps_at_zero_force": cycle.zero_force,
        # the fluid's equation of state at the end of stage 2: p V = V1 (air), V = V1 (liquid);
        # a cavitated liquid's p = p_v holds exactly (its pressure is not an unknown)
        "fluid_law_residual": 0.0 if closed or vapour else
        (final["p_over_pa"] if params.fluid == "air" else 1.0) * final["V"] / V1 - 1,
        "eps_closure": first_closure(run.rows, geometry.crater_volume),
        "eps_m": preload if params.preload == PRELOAD_TO_CLOSURE and closed else None,
        "closure_note": closure_note(params, closed, preload, V1 / geometry.crater_volume, final["V_over_V0"]),
        "stability": classify(events),
        "final_unstable_modes": cycle.final_unstable,
        "symmetry_breaking": symmetry_breaking(events) if params.waves else None,
        "stability_waves": classify([e for e in events if e.get("breaks_symmetry")]) if params.waves else None,
        **cycle.partial(),
        "surface_energy": params.surface_energy,
        "gas_permeation": permeation_estimate(1 - final["p_over_pa"], geometry.crater_radius)
        if params.fluid == "air" else None,
    })
    for row in run.rows:
        row.pop("V")


def closure_note(params, closed: bool, preload: float, V1_over_V0: float, V2_over_V0: float) -> str | None:
    """What closure means for this cycle's force (None: an open crater at a given preload)."""
    if not closed:
        return f"does not close up to eps = {preload:g}: the cycle runs from there" \
            if params.preload == PRELOAD_TO_CLOSURE else None
    held = params.fluid == "liquid" and params.cavitation == -math.inf  # V2 = V1 = 0: nothing opens it
    if params.fluid == "air":
        note = "closed on loading: vacuum inside, F = p_a A2 (eq. 7.17)"
    elif held:
        note = "closed on loading: an incompressible liquid crater stays closed, F = 0 (eq. 8.8)"
    else:
        note = "closed on loading: the liquid cavitates, vapour at p_v inside, F = (p_a - p_v) A2"
    if V1_over_V0 > CLOSURE_CRITERIA.closed:
        note += f"; a trapped remnant V1 = {V1_over_V0:.2g} V0 is neglected"
    if not held and V2_over_V0 <= CLOSURE_CRITERIA.volume:
        # the vacuum holds the flattened wall on the plate (a soft or shallow crater)
        note += (f"; it stays closed after unloading (V2 = {V2_over_V0:.2g} V0): no cavity, so A2 and "
                 f"F are ~0 (the force to peel a closed crater off the plate is not this measure)")
    return note


def classify(events) -> str:
    """``stable``, ``unstable-unloading`` (only on unloading) or ``unstable-both`` (already on
    loading), from the inertia events and snaps of a cycle (or from the symmetry-breaking
    events alone: ``stability_waves``)."""
    def unstable(event):
        return event["kind"] == "snap" or (event["unstable"] or 0) > 0 or event.get("breaks_symmetry", False)

    if any(unstable(e) for e in events if e["stage"] == "load"):
        return "unstable-both"
    if any(unstable(e) for e in events):
        return "unstable-unloading"
    return "stable"


def symmetry_breaking(events) -> dict:
    """{stage: the first eps where more modes with n waves than axisymmetric ones are unstable,
    and those n}, for the stages where it happens (needs ``waves``)."""
    first = {}
    for e in events:
        if e["kind"] == "waves" and e["breaks_symmetry"] and e["stage"] not in first:
            first[e["stage"]] = {"eps": e["eps"], "waves": e["waves"]}
    return first


def first_closure(rows, V0: float) -> float | None:
    """The first accepted loading strain with V = 0 (to 1e-8 V0), or None."""
    closed = [r["eps"] for r in rows if r["stage"] == "load" and r["V"] <= CLOSURE_CRITERIA.closed * V0]
    return min(closed) if closed else None


def plot(rows, summary):
    """The cycle: crater volume, pressure and suction against the platen strain."""
    from bcfem.plots import pyplot

    plt = pyplot()
    fig, axes = plt.subplots(1, 3, figsize=(11, 3.4))
    for stage, style in (("load", "-o"), ("unload", "-s")):
        part = [r for r in rows if r["stage"] == stage]
        if not part:  # not reached (a failed run): no curve, no legend entry
            continue
        eps = [r["eps"] for r in part]
        for ax, key, label in zip(axes, ("V_over_V0", "p_over_pa", "F_tilde"), ("V/V0", "p/p_a", "F~")):
            ax.plot(eps, [r[key] for r in part], style, ms=3, label=stage)
            ax.set_xlabel("platen strain ε")
            ax.set_ylabel(label)
    if summary["status"] == "ok":
        axes[2].set_title(f"F~ = {summary['F_tilde']:.4g} (preload {summary['parameters']['preload']:g})",
                          fontsize=9)
    else:
        axes[2].set_title("failed: the converged part", fontsize=9)
    axes[0].legend(fontsize=8)
    fig.tight_layout()
    return fig
