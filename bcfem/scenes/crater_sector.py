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

from bcfem.geometry.crater_sector import BOTTOM, MIRROR_X, MIRROR_Y, TOP, WALL, CraterSector, create_mesh
from bcfem.kinematics.solid_3d import Solid3D
from bcfem.mpi import global_sum, real_value
from bcfem.physics.bcs import component
from bcfem.physics.cavity import Cavity
from bcfem.physics.context import Context
from bcfem.physics.energies import SolidStrain
from bcfem.physics.fluids import IdealGas
from bcfem.physics.materials import NearlyIncompressibleNeoHookean
from bcfem.solver.problem import Problem

#: the quarter's share of the specimen
SHARE = 4


def cycle(preload: float, beta: float = 47.3 / 101.325, kappa_ratio: float = 1e4, steps: int = 4,
          sector: CraterSector = CraterSector(), comm=MPI.COMM_WORLD) -> list[dict]:
    """Rows (stage, eps, p_over_pa, V_over_V0, A_over_A0, F_tilde) of the cycle (collective)."""
    data = create_mesh(sector, comm)
    msh, facets = data.mesh, data.facet_tags
    V = fem.functionspace(msh, ("Lagrange", 2, (3,)))
    u = fem.Function(V, name="displacement")
    ctx = Context(u)
    platen = fem.Constant(msh, 0.0)
    x = ufl.SpatialCoordinate(msh)
    ctx.kin = kin = Solid3D(u, quadrature_degree=4, facet_tags=facets,
                            lift=ufl.as_vector([0, 0, platen * x[2] / sector.height]))
    bcs = [component(V, 0, facets.find(MIRROR_X)), component(V, 1, facets.find(MIRROR_Y)),
           component(V, 2, facets.find(BOTTOM)), component(V, 2, facets.find(TOP))]
    strain = SolidStrain(NearlyIncompressibleNeoHookean(mu=beta, kappa=kappa_ratio * beta))
    cavity = Cavity(WALL)
    volume = fem.form(cavity.volume(kin))
    opening = fem.form(-kin.surface_integral(kin.vertical_area(), WALL))  # the rim's disc, projected
    a = sector.crater_radius
    V0, A0 = 2 * math.pi * a**3 / 3 / SHARE, math.pi * a**2 / SHARE
    def lowest_wall_point() -> float:
        z = x_nodes[:, 2] + u.x.array.reshape(-1, 3)[:, 2]
        local = z[wall_nodes].min(initial=np.inf)
        return msh.comm.allreduce(float(local), op=MPI.MIN)

    x_nodes = V.tabulate_dof_coordinates()
    wall_nodes = fem.locate_dofs_topological(V, 2, facets.find(WALL))

    rows = []

    def record(stage, eps, p):
        V2, A2 = global_sum(volume), global_sum(opening)
        if lowest_wall_point() < -1e-9 * a:
            raise RuntimeError(f"the crater wall passed through the plate at eps = {eps:g} (no contact here)")
        rows.append({"stage": stage, "eps": eps, "p_over_pa": p, "V_over_V0": V2 / V0, "A_over_A0": A2 / A0,
                     "F_tilde": (1 - p) * A2 / A0})

    def path(problem, stage, strains, pressure):
        for eps in strains:
            platen.value = -eps * sector.height
            if not problem.solve():
                raise RuntimeError(f"{stage}: Newton failed at eps = {eps:g} ({problem.failure})")
            record(stage, eps, pressure())

    loading = Problem(ctx, [strain], bcs, "bcfem_crater_sector_load_", energy_scale=beta)
    path(loading, "load", np.linspace(preload / steps, preload, steps), lambda: 1.0)
    loading.close()
    gas = IdealGas(cavity, sealed_volume=global_sum(volume))
    ctx.real_state(gas.pressure_name).x.array[:] = 1.0
    unloading = Problem(ctx, [strain, gas], bcs, "bcfem_crater_sector_unload_", energy_scale=beta)
    p = ctx.states[gas.pressure_name]
    path(unloading, "unload", np.linspace(preload, 0, steps + 1)[1:], lambda: real_value(p))
    unloading.close()
    return rows
