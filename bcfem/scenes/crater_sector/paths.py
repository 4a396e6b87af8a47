"""The wedge's paths as functions: the suction cycle, and its stability under loading, a dead
suction or the volume drawn off (with the branch past the first onset), and the axisymmetric
crater's n-wave reference (collective; the scene :mod:`.scene` runs them from the CLI)."""

from __future__ import annotations

import math

from mpi4py import MPI

import numpy as np
from dolfinx import fem

from bcfem.geometry.crater_sector import WALL, CraterSector
from bcfem.mpi import global_sum, real_value
from bcfem.path.stepping import SteppingError
from bcfem.physics.cavity import Cavity
from bcfem.physics.fluids import IdealGas, IncompressibleLiquid, Vacuum
from bcfem.scenes.crater_sector.branch import wave_branch
from bcfem.scenes.crater_sector.model import Sector
from bcfem.scenes.crater_sector.onset import first_onset, standalone
from bcfem.solver.problem import Problem
from bcfem.stability.inertia import unstable_modes

__all__ = ["axisymmetric_suction_waves", "cycle", "drawn_stability", "first_onset", "loading_stability",
           "suction_stability"]


def cycle(preload: float, beta: float = 47.3 / 101.325, kappa_ratio: float = 1e4, steps: int = 4,
          sector: CraterSector = CraterSector(), comm=MPI.COMM_WORLD, extra_terms=(), open_problem=None) -> list[dict]:
    """Rows (stage, eps, p_over_pa, V_over_V0, A_over_A0, F_tilde) of the cycle; its problems are
    ``open_problem``'s stages ``load`` and ``unload`` (default: :func:`.onset.standalone`) (collective)."""
    model = Sector(sector, beta, kappa_ratio, comm, extra_terms=extra_terms)
    ctx, kin, bcs, solids = model.ctx, model.ctx.kin, model.bcs, model.terms
    cavity = Cavity(WALL)
    volume = fem.form(cavity.volume(kin))
    opening = fem.form(-kin.surface_integral(kin.vertical_area(), WALL))  # the rim's disc, projected
    a = sector.crater_radius
    V0, A0 = model.crater_volume, math.pi * a**2 / sector.share
    rows = []

    def record(stage, eps, p):
        V2, A2 = global_sum(volume), global_sum(opening)
        if model.lowest_wall_point() < -1e-9 * a:
            raise SteppingError(f"the crater wall passed through the plate at eps = {eps:g} (no contact here)", eps)
        rows.append({"stage": stage, "eps": eps, "p_over_pa": p, "V_over_V0": V2 / V0, "A_over_A0": A2 / A0,
                     "F_tilde": (1 - p) * A2 / A0})

    def path(problem, stage, strains, pressure):
        for eps in strains:
            model.set_platen(eps)
            if not problem.solve():
                raise SteppingError(f"{stage}: Newton failed at eps = {eps:g} ({problem.failure})", eps)
            record(stage, eps, pressure())

    opener = open_problem or standalone(comm)
    with opener("load", ctx, solids, bcs, energy_scale=model.energy_scale) as loading:
        path(loading, "load", np.linspace(preload / steps, preload, steps), lambda: 1.0)
    gas = IdealGas(cavity, sealed_volume=global_sum(volume))
    ctx.real_state(gas.pressure_name).x.array[:] = 1.0
    with opener("unload", ctx, [*solids, gas], bcs, energy_scale=model.energy_scale) as unloading:
        p = ctx.states[gas.pressure_name]
        path(unloading, "unload", np.linspace(preload, 0, steps + 1)[1:], lambda: real_value(p))
    return rows


def loading_stability(strains, beta: float = 47.3 / 101.325, kappa_ratio: float = 1e4,
                      sector: CraterSector = CraterSector(), bisections: int = 6, comm=MPI.COMM_WORLD,
                      extra_terms=()) -> dict:
    """Vented loading of the wedge through the increasing ``strains``, its stability followed
    (:func:`first_onset`; collective)."""
    model = Sector(sector, beta, kappa_ratio, comm, extra_terms=extra_terms)
    return first_onset(model, model.terms, model.set_platen, strains, bisections, "eps")


def suction_stability(suctions, beta: float = 47.3 / 101.325, kappa_ratio: float = 1e4,
                      layer_stiffness: float = 1.0, sector: CraterSector = CraterSector(), bisections: int = 6,
                      comm=MPI.COMM_WORLD, extra_terms=()) -> dict:
    """The wedge at eps = 0 with the crater pulled by a dead suction s (over p_a; the crater
    scene's vacuum term, :class:`bcfem.physics.fluids.Vacuum`) through the increasing ``suctions``,
    its stability followed (:func:`first_onset`; collective). A stiff lining (``sector``'s
    ``layer_thickness``, ``layer_stiffness`` beta'), pulled in, is compressed in hoop and wrinkles."""
    model = Sector(sector, beta, kappa_ratio, comm, layer_stiffness, extra_terms)
    suction = model.ctx.constant("vacuum_load")

    def set_suction(s: float) -> None:
        suction.value = np.asarray(s)

    return first_onset(model, [*model.terms, Vacuum(Cavity(WALL))], set_suction, suctions, bisections, "s")


def drawn_stability(removed, beta: float = 47.3 / 101.325, kappa_ratio: float = 1e4, layer_stiffness: float = 1.0,
                    sector: CraterSector = CraterSector(), bisections: int = 6, amplitudes=(),
                    comm=MPI.COMM_WORLD, extra_terms=(), open_problem=None) -> dict:
    """As :func:`suction_stability`, with the crater's volume drawn off instead: V = (1 - r) V0
    through the increasing fractions ``removed`` (a liquid's constraint, its pressure p the
    multiplier; the suction is s = 1 - p). A fold of the suction is passed; the n >= 1 modes do
    not couple to the pressure, so their onsets in s are those under the dead suction. Rows
    (r, unstable, s); with ``amplitudes`` (increasing from 0, in crater radii), the bifurcated
    branch from the onset, followed by its wave's amplitude (:func:`.branch.wave_branch`: "mode",
    "waves", "branch" rows {amplitude, r, s, unstable, fourier}) (collective)."""
    model = Sector(sector, beta, kappa_ratio, comm, layer_stiffness, extra_terms)
    V0 = model.crater_volume
    liquid = IncompressibleLiquid(Cavity(WALL), sealed_volume=V0)
    model.ctx.real_state(liquid.pressure_name).x.array[:] = 1.0
    pressure = model.ctx.states[liquid.pressure_name]
    amount = model.ctx.parameter(liquid, "sealed_volume")

    def set_removed(r: float) -> None:
        amount.value = np.asarray((1 - r) * V0)

    def beyond(problem, below: float) -> dict:
        def count(r: float) -> int:  # at fixed volume: the physical stability of a branch's state
            set_removed(r)
            return unstable_modes(problem)

        found = wave_branch(model, problem, model.terms, below, amplitudes, count, open_problem=open_problem)
        return {"mode": found["mode"], "waves": found["waves"], "branch": found["rows"],
                "branch_failure": found["failure"]}

    return first_onset(model, [*model.terms, liquid], set_removed, removed, bisections, "r",
                       observe=lambda: 1 - real_value(pressure), beyond=beyond if len(amplitudes) else None,
                       open_problem=open_problem, stage="drawn")


def axisymmetric_suction_waves(suctions, waves: int, layer_thickness: float, layer_stiffness: float,
                               size_crater: float, beta: float = 47.3 / 101.325, kappa_ratio: float = 1e4,
                               sector: CraterSector = CraterSector(), drawn: bool = False,
                               comm=MPI.COMM_WORLD) -> list[dict]:
    """The axisymmetric crater (:class:`bcfem.scenes.crater.model.Crater`, the sector's specimen,
    no surface energy or self-contact) at eps = 0 pulled by the suctions ``suctions``: at each,
    the unstable axisymmetric modes and {n: unstable modes} of its n-wave blocks, n = 1..``waves``
    (:mod:`bcfem.stability.modes`); with ``drawn``, the loads are the fractions r of the volume
    drawn off (:func:`drawn_stability`). Rows {"load", "s", "n0", "waves"} until Newton fails
    (collective)."""
    from bcfem.scenes.crater.model import Crater
    from bcfem.scenes.crater.params import Params
    from bcfem.stability.inertia import unstable_modes

    params = Params(beta=beta, kappa_ratio=kappa_ratio, layer_thickness=layer_thickness,
                    layer_stiffness=layer_stiffness, size_crater=size_crater, surface_energy=0.0, self_contact=0.0,
                    waves=waves, specimen_radius=sector.radius, specimen_height=sector.height,
                    crater_radius=sector.crater_radius)
    model = Crater(params.model_inputs(), comm)
    if drawn:  # the volume drawn off, V = (1 - r) V0, the suction s = 1 - p
        V0 = model.geometry.crater_volume
        liquid = IncompressibleLiquid(model.cavity, sealed_volume=V0)
        terms = [*model.solids, liquid]
        model.ctx.real_state(liquid.pressure_name).x.array[:] = 1.0
        pressure = model.ctx.states[liquid.pressure_name]
        amount = model.ctx.parameter(liquid, "sealed_volume")
    else:
        terms = [*model.solids, Vacuum(model.cavity)]
        amount = model.ctx.constant("vacuum_load")
    rows = []
    with Problem(model.ctx, terms, model.bcs, f"bcfem_crater_axi_suction_{comm.size}_",
                 {"snes_type": "vinewtonrsls"}, energy_scale=model.energy_scale,
                 line_search_fallbacks=("bt", "cp")) as problem:
        model.contact_bounds(problem)
        check = model.wave_check(problem, terms)
        for load in suctions:
            amount.value = (1 - load) * V0 if drawn else load
            if not problem.solve():
                break
            s = 1 - real_value(pressure) if drawn else load
            rows.append({"load": load, "s": s, "n0": unstable_modes(problem), "waves": check()})
    return rows
