r"""Delamination onset of the adhesive edge, the second way: by energies at fixed volume.

The scene locates the onset where the configurational force :math:`-\partial\Pi/\partial R_1`
(a domain integral, :mod:`~bcfem.scenes.blister_soft.front`) turns positive. Independently,
hold the front at :math:`R_1 = 1 \pm \delta`, trace each model to the same liquid volume V
and compare the free energies there. At fixed V the free energy is
:math:`F = \Pi + \Delta p\,V` (the load's potential removed), and by the envelope theorem
:math:`dF/dR_1|_V = \partial\Pi/\partial R_1`; the onset is the V at which the central
difference :math:`(F_+ - F_-)/2\delta` vanishes (error :math:`O(\delta^2)`).

The dissertation's way (Fig. 4.8) is :func:`critical_point`: a model with the front held at
:math:`R_1 > R_0` traced until its release rate reaches zero; that point lies on the
propagating branch.
"""

from __future__ import annotations

import math

from bcfem.path.roots import bracketed_root
from bcfem.run.trace import branch_of
from bcfem.scenes.blister_soft.model import V0


def hold(scene, radius: float, end=None) -> None:
    """Hold the front of an adhesive ``scene`` at ``radius`` (no release), with the branch's
    ``end`` replaced if given."""
    ctx = scene.ctx
    if "debond_radius" not in ctx.states:
        raise ValueError("the scene has no moving front (edge 'adhesive')")
    ctx.constant("debond_radius_held").value = radius
    ctx.states["debond_radius"].x.array[:] = radius
    scene.model.front.value = 0.0
    scene.switches = []
    if end is not None:
        scene.end = end


def free_energy(row: dict) -> float:
    """F = Pi + dp V over pi mu_f t0 R0^2, of a branch row."""
    return row["energy"] + row["P"] * row["V_over_V0"] * V0 / math.pi


def energy_at_volume(scene, radius: float, volume: float) -> float:
    """F at V/V0 = ``volume`` of the model with the front held at ``radius`` (collective)."""
    hold(scene, radius, end=lambda values: values["V_over_V0"] - volume)
    row = branch_of(scene).rows[-1]
    if abs(row["V_over_V0"] - volume) > 1e-8 * volume:
        raise RuntimeError(f"the held trace ended at V/V0 = {row['V_over_V0']}, not {volume}")
    return free_energy(row)


def release_rate_by_energy(scene, volume: float, delta: float = 1e-3) -> float:
    """dF/dR1 at fixed V by central difference of two held models (per pi mu_f t0 R0^2)."""
    return (energy_at_volume(scene, 1 + delta, volume) - energy_at_volume(scene, 1 - delta, volume)) / (2 * delta)


def onset_by_energy(scene, bracket: tuple[float, float], delta: float = 1e-3, xtol: float = 1e-7) -> dict:
    """The V/V0 in ``bracket`` where dF/dR1|_V changes sign, and the evaluations it took."""
    calls = []

    def rate(volume):
        calls.append(volume)
        return release_rate_by_energy(scene, volume, delta)

    volume = bracketed_root(rate, *bracket, xtol=xtol)
    return {"V_over_V0": volume, "evaluations": len(calls), "delta": delta}


def critical_point(scene, radius: float) -> dict:
    """The row of the model held at R1 = ``radius`` where its release rate -dPi/dR1 reaches
    zero from below (the dissertation's fixed-R1 models)."""
    hold(scene, radius, end=lambda values: -values["dPi_dR1"])
    return branch_of(scene).rows[-1]
