"""The crater's suction cycle on a 3-D quarter of its specimen (:mod:`bcfem.geometry.crater_sector`):
the axisymmetric crater's terms on :class:`bcfem.kinematics.solid_3d.Solid3D`, the first brick of the 3-D
crater cells.

Vented loading to the preload, the crater sealed there with air at p_a, unloading to eps = 0
(the dissertation's Steps 1–2), with the bottom face held on the plate (free to slide) and the
top face on the platen (frictionless). The platen is the lift w z/H of the kinematics. The mirror
faces keep the quarter's share of a response with the quarter's symmetry (n = 0, 2, 4, ...
circumferential waves); the wall is checked to stay above the plate (no contact is modelled
here). Pressures in p_a, lengths in mm as the crater scene.
"""

from __future__ import annotations

import math

from mpi4py import MPI

import numpy as np
import ufl
from dolfinx import fem

from bcfem.contact.plate_bounds import plate_bounds
from bcfem.geometry.crater_sector import (
    BOTTOM,
    LAYER,
    MIRROR_X,
    MIRROR_Y,
    SPECIMEN,
    TOP,
    WALL,
    CraterSector,
    create_mesh,
)
from bcfem.kinematics.solid_3d import Solid3D
from bcfem.log import progress
from bcfem.mpi import global_sum, real_value
from bcfem.physics.bcs import component
from bcfem.physics.cavity import Cavity
from bcfem.physics.context import Context
from bcfem.physics.energies import SolidStrain
from bcfem.physics.fluids import IdealGas, IncompressibleLiquid, Vacuum
from bcfem.physics.materials import NearlyIncompressibleNeoHookean
from bcfem.solver.problem import Problem

#: the quarter's share of the specimen
SHARE = 4
#: halvings of a load step that Newton fails, towards the last stable state
CUTBACKS = 3


class _Sector:
    """The quarter's states, kinematics (the platen the lift w z/H), mirror and plate conditions
    and solid term."""

    def __init__(self, sector: CraterSector, beta: float, kappa_ratio: float, comm, layer_stiffness: float = 1.0):
        data = create_mesh(sector, comm)
        self.mesh, self.facets = msh, facets = data.mesh, data.facet_tags
        V = fem.functionspace(msh, ("Lagrange", 2, (3,)))
        self.u = u = fem.Function(V, name="displacement")
        self.ctx = ctx = Context(u)
        self.platen = fem.Constant(msh, 0.0)
        x = ufl.SpatialCoordinate(msh)
        ctx.kin = Solid3D(u, quadrature_degree=4, cell_tags=data.cell_tags, facet_tags=facets,
                          lift=ufl.as_vector([0, 0, self.platen * x[2] / sector.height]))
        self.bcs = [component(V, 0, facets.find(MIRROR_X)), component(V, 1, facets.find(MIRROR_Y)),
                    component(V, 2, facets.find(BOTTOM)), component(V, 2, facets.find(TOP))]
        def solid(mu, region=None):
            return SolidStrain(NearlyIncompressibleNeoHookean(mu=mu, kappa=kappa_ratio * mu), region)

        #: the solid's terms: one, or the specimen's and the lining's
        self.solids = ([solid(beta, SPECIMEN), solid(layer_stiffness * beta, LAYER)] if sector.layer_thickness > 0
                       else [solid(beta)])
        self.energy_scale = beta * max(1.0, layer_stiffness if sector.layer_thickness > 0 else 1.0)
        self.nodes = V.tabulate_dof_coordinates()
        self.wall_nodes = fem.locate_dofs_topological(V, 2, facets.find(WALL))
        self.sector = sector

    def set_platen(self, eps: float) -> None:
        self.platen.value = -eps * self.sector.height

    def lowest_wall_point(self) -> float:
        z = self.nodes[self.wall_nodes, 2] + self.u.x.array.reshape(-1, 3)[self.wall_nodes, 2]
        return self.mesh.comm.allreduce(float(z.min(initial=np.inf)), op=MPI.MIN)

    def contact_bounds(self, problem) -> None:
        """z = Z + u_z >= 0 on the wall: its frictionless contact with the plate."""
        plate_bounds(problem, 3 * self.wall_nodes + 2, self.nodes[self.wall_nodes, 2])


def cycle(preload: float, beta: float = 47.3 / 101.325, kappa_ratio: float = 1e4, steps: int = 4,
          sector: CraterSector = CraterSector(), comm=MPI.COMM_WORLD) -> list[dict]:
    """Rows (stage, eps, p_over_pa, V_over_V0, A_over_A0, F_tilde) of the cycle (collective)."""
    model = _Sector(sector, beta, kappa_ratio, comm)
    ctx, kin, bcs, solids = model.ctx, model.ctx.kin, model.bcs, model.solids
    cavity = Cavity(WALL)
    volume = fem.form(cavity.volume(kin))
    opening = fem.form(-kin.surface_integral(kin.vertical_area(), WALL))  # the rim's disc, projected
    a = sector.crater_radius
    V0, A0 = 2 * math.pi * a**3 / 3 / SHARE, math.pi * a**2 / SHARE
    rows = []

    def record(stage, eps, p):
        V2, A2 = global_sum(volume), global_sum(opening)
        if model.lowest_wall_point() < -1e-9 * a:
            raise RuntimeError(f"the crater wall passed through the plate at eps = {eps:g} (no contact here)")
        rows.append({"stage": stage, "eps": eps, "p_over_pa": p, "V_over_V0": V2 / V0, "A_over_A0": A2 / A0,
                     "F_tilde": (1 - p) * A2 / A0})

    def path(problem, stage, strains, pressure):
        for eps in strains:
            model.set_platen(eps)
            if not problem.solve():
                raise RuntimeError(f"{stage}: Newton failed at eps = {eps:g} ({problem.failure})")
            record(stage, eps, pressure())

    loading = Problem(ctx, solids, bcs, "bcfem_crater_sector_load_", energy_scale=model.energy_scale)
    path(loading, "load", np.linspace(preload / steps, preload, steps), lambda: 1.0)
    loading.close()
    gas = IdealGas(cavity, sealed_volume=global_sum(volume))
    ctx.real_state(gas.pressure_name).x.array[:] = 1.0
    unloading = Problem(ctx, [*solids, gas], bcs, "bcfem_crater_sector_unload_", energy_scale=model.energy_scale)
    p = ctx.states[gas.pressure_name]
    path(unloading, "unload", np.linspace(preload, 0, steps + 1)[1:], lambda: real_value(p))
    unloading.close()
    return rows


def loading_stability(strains, beta: float = 47.3 / 101.325, kappa_ratio: float = 1e4,
                      sector: CraterSector = CraterSector(), bisections: int = 6, comm=MPI.COMM_WORLD) -> dict:
    """Vented loading of the quarter through the increasing ``strains``, its stability followed
    (:func:`first_onset`; collective)."""
    model = _Sector(sector, beta, kappa_ratio, comm)
    return first_onset(model, model.solids, model.set_platen, strains, bisections, "eps")


def suction_stability(suctions, beta: float = 47.3 / 101.325, kappa_ratio: float = 1e4,
                      layer_stiffness: float = 1.0, sector: CraterSector = CraterSector(), bisections: int = 6,
                      comm=MPI.COMM_WORLD) -> dict:
    """The quarter at eps = 0 with the crater pulled by a dead suction s (over p_a; the crater
    scene's vacuum term, :class:`bcfem.physics.fluids.Vacuum`) through the increasing ``suctions``,
    its stability followed (:func:`first_onset`; collective). A stiff lining (``sector``'s
    ``layer_thickness``, ``layer_stiffness`` beta'), pulled in, is compressed in hoop and wrinkles."""
    model = _Sector(sector, beta, kappa_ratio, comm, layer_stiffness)
    suction = model.ctx.constant("vacuum_load")

    def set_suction(s: float) -> None:
        suction.value = s

    return first_onset(model, [*model.solids, Vacuum(Cavity(WALL))], set_suction, suctions, bisections, "s")


def drawn_stability(removed, beta: float = 47.3 / 101.325, kappa_ratio: float = 1e4, layer_stiffness: float = 1.0,
                    sector: CraterSector = CraterSector(), bisections: int = 6, comm=MPI.COMM_WORLD) -> dict:
    """As :func:`suction_stability`, with the crater's volume drawn off instead: V = (1 - r) V0
    through the increasing fractions ``removed`` (a liquid's constraint, its pressure p the
    multiplier; the suction is s = 1 - p). A fold of the suction is passed; the n >= 1 modes do
    not couple to the pressure, so their onsets in s are those under the dead suction. Rows
    (r, unstable, s) (collective)."""
    model = _Sector(sector, beta, kappa_ratio, comm, layer_stiffness)
    V0 = 2 * math.pi * sector.crater_radius**3 / 3 / SHARE
    liquid = IncompressibleLiquid(Cavity(WALL), sealed_volume=V0)
    model.ctx.real_state(liquid.pressure_name).x.array[:] = 1.0
    pressure = model.ctx.states[liquid.pressure_name]
    amount = model.ctx.constant(f"{liquid.pressure_name}_sealed")

    def set_removed(r: float) -> None:
        amount.value = (1 - r) * V0

    return first_onset(model, [*model.solids, liquid], set_removed, removed, bisections, "r",
                       observe=lambda: 1 - real_value(pressure))


def first_onset(model: _Sector, terms, set_load, loads, bisections: int, name: str, observe=None) -> dict:
    """The load raised through the increasing ``loads`` with the wall in frictionless contact with the
    plate (bounds of the variational-inequality solver), the unstable modes counted after every
    step by the inertia of the 3-D tangent (:func:`bcfem.stability.inertia.unstable_modes`: unknowns
    on the plate held). The quarter's modes are those of the axisymmetric scene's n-blocks with
    n = 0, 2, 4, ... (cos n theta, symmetric about both mirror planes), one per unstable block. The
    first change of the count is bisected. Returns {"rows": [(load, unstable)], "onset": (load
    below, load above) or None, "failure": None or why the last step failed after its cut-backs
    (the path ends there; a failed bisection step ends the bisection)}; the states are left at the
    last stable solution below the onset or the failure."""
    from bcfem.stability.inertia import unstable_modes

    comm = model.mesh.comm
    rows, onset = [], None
    with Problem(model.ctx, terms, model.bcs, f"bcfem_crater_sector_onset_{comm.size}_",
                 {"snes_type": "vinewtonrsls"}, energy_scale=model.energy_scale,
                 line_search_fallbacks=("bt", "cp")) as problem:
        model.contact_bounds(problem)

        def solve_at(load):
            set_load(load)
            if not problem.solve():
                raise _Failed(f"Newton failed at {name} = {load:g} ({problem.failure})")
            count = unstable_modes(problem)
            rows.append((load, count, *((observe(),) if observe else ())))
            progress(f"crater sector: {name} = {load:.6g}, unstable modes {count}")
            return count

        def state():
            return [st.x.array.copy() for st in problem.states]

        def restore(saved):
            for st, values in zip(problem.states, saved):
                st.x.array[:] = values

        before, saved, failure = 0.0, state(), None

        def count_at(load):
            """The count at ``load`` solved from the saved state, or None if Newton fails."""
            restore(saved)
            try:
                return solve_at(load)
            except _Failed as error:
                nonlocal failure
                failure = str(error)
                return None

        pending = list(loads)
        while pending:
            target = load = pending[0]
            for _ in range(CUTBACKS + 1):  # near a singular tangent Newton may fail: halve the step
                count = count_at(load)
                if count is not None:
                    break
                load = 0.5 * (before + load)
            if count is None:
                break
            if count > 0:
                below, above = before, load
                for _ in range(bisections):
                    mid = 0.5 * (below + above)
                    count = count_at(mid)
                    if count is None:
                        break
                    if count > 0:
                        above = mid
                    else:
                        below, saved = mid, state()
                onset = (below, above)
                break
            before, saved, failure = load, state(), None
            if load == target:  # else cut back: on to the target from here
                pending.pop(0)
        restore(saved)
    return {"rows": rows, "onset": onset, "failure": failure}


class _Failed(RuntimeError):
    """A load step that Newton could not solve."""


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
    model = Crater(params, comm)
    if drawn:  # the volume drawn off, V = (1 - r) V0, the suction s = 1 - p
        V0 = model.geometry.crater_volume
        liquid = IncompressibleLiquid(model.cavity, sealed_volume=V0)
        terms = [*model.solids, liquid]
        model.ctx.real_state(liquid.pressure_name).x.array[:] = 1.0
        pressure = model.ctx.states[liquid.pressure_name]
        amount = model.ctx.constant(f"{liquid.pressure_name}_sealed")
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
