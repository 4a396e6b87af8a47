r"""The lattice cell's model: mesh, states, terms, boundary conditions and observables.

The displacement is u = ũ + (e_x x, e_y y, 0) (the lift of :class:`bcfem.kinematics.solid_3d.Solid3D`),
with ũ held normal to every side face: each side face stays on its plane, the faces x = Lx
and y = Ly move with the lateral macroscopic strains e_x, e_y (real-space states; in the
eighth cell one strain e_x = e_y, the diagonal face y = x held by
:class:`bcfem.physics.bcs.MirrorPlane`, a multiplier field). Their
residuals are the derivatives of the energy, the mean lateral tractions on the side faces: zero,
so the array spreads freely under the platen (uniaxial stress on average). The platen is
ũ_z = -eps H on the top face, the plate ũ_z = 0 on the bottom face (both frictionless); the
walls are in frictionless contact with the plate, z = Z + ũ_z >= 0 as bounds of the
variational-inequality solver. Each quarter crater is a cavity of its own
(:class:`bcfem.physics.cavity.Cavity`, with the crater scene's contact gap, so that a wall on the plate
is not wetted), sealed with its own fluid. Pressures in p_a (μ/p_a = β), lengths in mm.

The Lagrangian of the cell Ω, with the lateral strains e = (e_x, e_y) unknowns:

.. math:: L(\tilde u, e, p_s, \lambda, p_k) = \int_\Omega W(F, p_s)\,dV
          + \gamma\int_{\Gamma_w} da + \int_{\Gamma_m} \lambda\,u\cdot n\,dA
          + \sum_k \Pi_f(V_k(u), p_k),

W the nearly incompressible neo-Hookean density with μ = β and its mixed pressure p_s, the
walls' surface energy γ (optional), the diagonal mirror Γ_m of the eighth cell (λ its
traction), and each crater's fluid as in ``crater`` (vented while loading, sealed after).
"""

from __future__ import annotations

import math

from mpi4py import MPI

import numpy as np
import ufl
from dolfinx import fem

from bcfem.contact.plate_bounds import plate_bounds
from bcfem.geometry.crater_cell import BOTTOM, DIAGONAL, MIRROR_X, MIRROR_Y, SIDE_X, SIDE_Y, TOP, WALL, create_mesh
from bcfem.kinematics.solid_3d import Solid3D
from bcfem.kinematics.submesh import BoundaryPatch
from bcfem.mpi import global_sum, real_value
from bcfem.physics.bcs import MirrorPlane, component
from bcfem.physics.cavity import Cavity
from bcfem.physics.context import Context
from bcfem.physics.energies import SolidStrain, SolidSurfaceEnergy
from bcfem.physics.fluids import FLUIDS
from bcfem.physics.materials import NearlyIncompressibleNeoHookean
from bcfem.physics.viscosity import Viscosity
from bcfem.scenes.crater.model import CONTACT_GAP
from bcfem.scenes.crater_cell.params import Params

#: the lateral strains' states, along x and y
LATERAL = ("lateral_strain_x", "lateral_strain_y")


class CellModel:
    """The composed cell: mesh, states (ũ, the solid pressure, e_x, e_y and, once sealed, each
    crater's fluid pressure), terms, boundary conditions and observables."""

    def __init__(self, params: Params, comm):
        self.params = params
        self.cell = cell = params.geometry()
        data = create_mesh(cell, comm)
        msh, facets = data.mesh, data.facet_tags
        self.mesh = msh
        V = fem.functionspace(msh, ("Lagrange", 2, (3,)))
        self.u = fem.Function(V, name="displacement")
        self.ctx = ctx = Context(self.u)
        eighth = cell.cell == "eighth"
        #: the lateral strains' states: (e_x, e_y), or e twice in the eighth cell
        self.strains = [ctx.real_state(LATERAL[0 if eighth else k]) for k in range(2)]
        strains = self.strains
        x = ufl.SpatialCoordinate(msh)
        ctx.kin = kin = Solid3D(self.u, quadrature_degree=4, facet_tags=facets,
                                lift=ufl.as_vector([strains[0] * x[0], strains[1] * x[1], 0]))
        self.platen = fem.Function(V.sub(2).collapse()[0], name="platen")
        sides = {axis: np.concatenate([facets.find(tag) for tag in tags])
                 for axis, tags in ((0, (MIRROR_X, SIDE_X)), (1, (MIRROR_Y, SIDE_Y)))}
        self.bcs = [component(V, 0, sides[0]), component(V, 1, sides[1]), component(V, 2, facets.find(BOTTOM)),
                    component(V, 2, facets.find(TOP), self.platen)]
        self.mirror = MirrorPlane(BoundaryPatch(msh, facets, DIAGONAL), math.pi / 4) if eighth else None
        beta, a = params.beta, cell.crater_radius
        self.walls = tuple(WALL + k for k in range(len(cell.centres)))
        self.solid = SolidStrain(NearlyIncompressibleNeoHookean(mu=beta, kappa=params.kappa_ratio * beta))
        gamma = params.surface_energy * beta * a
        self.surface = SolidSurfaceEnergy(gamma, self.walls, "crater_surface_energy") if gamma > 0 else None
        self.viscosity = Viscosity(self.u)
        self.energy_scale = max(1.0, beta)
        self.cavities = [Cavity(wall, CONTACT_GAP * a) for wall in self.walls]
        self._volumes = [fem.form(c.volume(kin)) for c in self.cavities]
        # the wetted opening: dV/d(a lift of the whole cell), -∫ (cof F N)_z over the wall off the
        # plate, the area its contact line encloses
        lift = fem.Function(V)
        lift.interpolate(lambda x: np.vstack([0 * x[0], 0 * x[0], 1 + 0 * x[0]]))
        self._openings = [fem.form(ufl.derivative(c.volume(kin), self.u, lift)) for c in self.cavities]
        self.pressure_names = tuple("fluid_pressure" if k == 0 else f"fluid_pressure_{k}"
                                    for k in range(len(self.walls)))
        self.sealed = False
        wall_facets = np.concatenate([facets.find(wall) for wall in self.walls])
        self._wall_nodes = fem.locate_dofs_topological(V, 2, wall_facets)
        self._nodes = V.tabulate_dof_coordinates()
        self.strain = 0.0
        self._force: fem.Form | None = None
        #: a whole crater's volume and opening at rest; the cell holds ``craters`` of them
        self.V0, self.A0, self.craters = cell.crater_volume, math.pi * a**2, cell.craters

    def terms(self, *fluids) -> list:
        """The solid, the diagonal mirror and the walls' surface energy (if any), the fluids and the
        relaxation's viscosity."""
        return [self.solid, *(t for t in (self.mirror, self.surface) if t), *fluids, self.viscosity]

    def set_platen(self, strain: float) -> None:
        """The platen at eps = -dL/L."""
        self.strain = strain
        self.platen.x.array[:] = -strain * self.params.specimen_height

    def measure_force(self, problem) -> None:
        """The platen force of ``problem``'s states from now on: its Lagrangian differentiated in
        w = (0, 0, Z/H), which moves the top face alone by 1 (< 0 pressing)."""
        w = fem.Function(self.u.function_space)
        H = self.params.specimen_height
        w.interpolate(lambda x: np.vstack([0 * x[0], 0 * x[0], x[2] / H]))
        self._force = fem.form(ufl.derivative(problem.lagrangian, self.u, w), entity_maps=self.ctx.entity_maps or None)

    def platen_force(self) -> float:
        """The platen's force on the cell, in p_a mm² (collective; :meth:`measure_force` first)."""
        if self._force is None:
            raise RuntimeError("measure_force(problem) first")
        return global_sum(self._force)

    def volumes(self) -> list[float]:
        """Each crater's current volume in the cell (a quarter's or an eighth's; collective)."""
        return [global_sum(form) for form in self._volumes]

    def seal(self) -> list:
        """Each crater sealed at p_a with its current volume: the fluid terms."""
        self.sealed = True
        fluid = FLUIDS[self.params.fluid]
        terms = [fluid(cavity, sealed_volume=V, pressure_name=name)
                 for cavity, V, name in zip(self.cavities, self.volumes(), self.pressure_names)]
        for name in self.pressure_names:
            self.ctx.real_state(name).x.array[:] = 1.0
        return terms

    def pressures(self) -> list[float]:
        if not self.sealed:
            return [1.0] * len(self.walls)
        return [real_value(self.ctx.states[name]) for name in self.pressure_names]

    def contact_bounds(self, problem) -> None:
        """z = Z + ũ_z >= 0 on the walls: their frictionless contact with the plate."""
        plate_bounds(problem, 3 * self._wall_nodes + 2, self._nodes[self._wall_nodes, 2])

    def lowest_wall_point(self) -> float:
        """The least current height of the walls' nodes (collective)."""
        z = self._nodes[self._wall_nodes, 2] + self.u.x.array.reshape(-1, 3)[self._wall_nodes, 2]
        return self.mesh.comm.allreduce(float(z.min(initial=np.inf)), op=MPI.MIN)

    def wall_on_plate(self) -> int:
        """How many of the walls' nodes above the rim lie on the plate (collective)."""
        tolerance = 1e-6 * self.cell.crater_radius
        owned = self._wall_nodes[self._wall_nodes < self.u.function_space.dofmap.index_map.size_local]
        Z = self._nodes[owned, 2]
        z = Z + self.u.x.array.reshape(-1, 3)[owned, 2]
        touching = int(np.sum((Z > tolerance) & (z <= tolerance)))
        return self.mesh.comm.allreduce(touching, op=MPI.SUM)

    def observe(self, stage: str, eps: float) -> dict:
        """The row of the current state (collective)."""
        V, A, p = self.volumes(), [global_sum(f) for f in self._openings], self.pressures()
        suction = sum((1 - pk) * Ak for pk, Ak in zip(p, A))
        return {"stage": stage, "eps": eps, "p_over_pa": p[0], "V_over_V0": sum(V) / (self.craters * self.V0),
                "A_over_A0": sum(A) / (self.craters * self.A0), "F_tilde": suction / (self.craters * self.A0),
                "F_tilde_area": suction / self.cell.area,
                **{name: real_value(state) for name, state in zip(LATERAL, self.strains)},
                "platen_force": self.platen_force() / (self.craters * self.A0),
                "pressure_spread": max(p) - min(p), "wall_on_plate": self.wall_on_plate()}
