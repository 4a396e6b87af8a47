r"""The wedge's states, kinematics, mirror and plate conditions and solid terms, and the Fourier
content of its wall: what every path of :mod:`bcfem.scenes.crater_sector` starts from.

The face theta = 0 is the plane y = 0, held by u_y = 0. The face theta = pi/m is a coordinate
plane only for m = 1 (y = 0) and m = 2 (x = 0), held by a Dirichlet condition on one component
as before. For m >= 3 its normal n = (-sin pi/m, cos pi/m, 0) mixes two components, and u.n = 0
is a Lagrange multiplier field on the face (:class:`MirrorPlane`), which keeps the energy's exact
tangent and the symmetric saddle-point form MUMPS's LDL^T already factorises for the fluids'
pressures; it needs no penalty or Nitsche parameter, and no change of basis inside the solver.

The Lagrangian of the wedge Ω (the specimen, and a lining of k times its modulus):

.. math:: L = \int_{\Omega_s} W_\beta(F, p_s)\,dV + \int_{\Omega_l} W_{k\beta}(F, p_s)\,dV
          + \int_{\Gamma_m} \lambda\,u\cdot n\,dA + \Pi_f(V(u), p),

Γ_m the oblique mirror (m >= 3; λ its traction), and the fluid's term as in ``crater`` on the
cycle, or on the drawn path a liquid of which the fraction r is drawn off,
:math:`-(p-1)(V - (1-r)V_0)`.
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
    MIRROR_END,
    MIRROR_START,
    SPECIMEN,
    TOP,
    WALL,
    CraterSector,
    create_mesh,
)
from bcfem.kinematics.solid_3d import Solid3D
from bcfem.kinematics.submesh import BoundaryPatch
from bcfem.mpi import global_sum
from bcfem.physics.bcs import MirrorPlane, component
from bcfem.physics.context import Context
from bcfem.physics.energies import SolidStrain
from bcfem.physics.materials import NearlyIncompressibleNeoHookean


class Sector:
    """The wedge's states, kinematics (the platen the lift w z/H), mirror and plate conditions
    and solid terms (:attr:`solids`, with :attr:`mirror`, the oblique face's multiplier term, if
    any: every problem on the wedge includes :attr:`terms`)."""

    def __init__(self, sector: CraterSector, beta: float, kappa_ratio: float, comm, layer_stiffness: float = 1.0,
                 extra_terms=()):
        data = create_mesh(sector, comm)
        self.mesh, self.facets = msh, facets = data.mesh, data.facet_tags
        V = fem.functionspace(msh, ("Lagrange", 2, (3,)))
        self.u = u = fem.Function(V, name="displacement")
        self.ctx = ctx = Context(u)
        self.platen = fem.Constant(msh, 0.0)
        x = ufl.SpatialCoordinate(msh)
        ctx.kin = Solid3D(u, quadrature_degree=4, cell_tags=data.cell_tags, facet_tags=facets,
                          lift=ufl.as_vector([0, 0, self.platen * x[2] / sector.height]))
        self.bcs = [component(V, 1, facets.find(MIRROR_START)),
                    component(V, 2, facets.find(BOTTOM)), component(V, 2, facets.find(TOP))]
        m = sector.wedge_waves
        self.mirror = None
        if m == 2:
            self.bcs.insert(0, component(V, 0, facets.find(MIRROR_END)))
        elif m > 2:  # m = 1: both faces lie on y = 0, tagged MIRROR_START
            self.mirror = MirrorPlane(BoundaryPatch(msh, facets, MIRROR_END), sector.angle)

        def solid(mu, region=None):
            return SolidStrain(NearlyIncompressibleNeoHookean(mu=mu, kappa=kappa_ratio * mu), region)

        #: the solid's terms: one, or the specimen's and the lining's
        self.solids = ([solid(beta, SPECIMEN), solid(layer_stiffness * beta, LAYER)] if sector.layer_thickness > 0
                       else [solid(beta)])
        self.energy_scale = beta * max(1.0, layer_stiffness if sector.layer_thickness > 0 else 1.0)
        self.nodes = V.tabulate_dof_coordinates()
        self.wall_nodes = fem.locate_dofs_topological(V, 2, facets.find(WALL))
        self.sector = sector
        #: a research script's terms, in every problem on the wedge
        self.extra_terms = tuple(extra_terms)
        self._fourier: dict[tuple, tuple] = {}
        self._forms: dict[str, fem.Form] = {}

    @property
    def terms(self) -> list:
        """The solids, the oblique mirror's multiplier term (if the wedge has one) and the extra terms."""
        return [*self.solids, *([self.mirror] if self.mirror else []), *self.extra_terms]

    @property
    def crater_volume(self) -> float:
        """The wedge's share of the hemisphere's volume."""
        return 2 * math.pi * self.sector.crater_radius**3 / 3 / self.sector.share

    def set_platen(self, eps: float) -> None:
        self.platen.value = np.asarray(-eps * self.sector.height)

    def lowest_wall_point(self) -> float:
        z = self.nodes[self.wall_nodes, 2] + self.u.x.array.reshape(-1, 3)[self.wall_nodes, 2]
        return self.mesh.comm.allreduce(float(z.min(initial=np.inf)), op=MPI.MIN)

    def contact_bounds(self, problem) -> None:
        """z = Z + u_z >= 0 on the wall: its frictionless contact with the plate."""
        plate_bounds(problem, 3 * self.wall_nodes + 2, self.nodes[self.wall_nodes, 2])

    def opening(self) -> float:
        """A2/A0: the area the rim encloses, projected on the plate, over the wedge's share of
        pi a^2 (the wall's -int (cof F N)_z dA; collective)."""
        if "opening" not in self._forms:
            kin = self.ctx.kin
            self._forms["opening"] = fem.form(-kin.surface_integral(kin.vertical_area(), WALL))
        return global_sum(self._forms["opening"]) / (math.pi * self.sector.crater_radius**2 / self.sector.share)

    def wall_fourier(self, u: fem.Function, waves) -> dict[int, float]:
        r"""The wall's radial displacement u.X/|X| (the sphere's normal) in the modes the wedge
        admits: :math:`c_n = \int u_\rho \cos n\theta\, dA / \int \cos^2 n\theta\, dA` over the
        reference wall, for each n in ``waves`` (multiples of m), over the crater radius
        (collective)."""
        kin, out = self.ctx.kin, {}
        for n in waves:
            if (id(u), n) not in self._fourier:
                theta = ufl.atan2(kin.x[1], kin.x[0])
                self._fourier[id(u), n] = (fem.form(kin.surface_integral(wall_content(self.ctx, u, n), WALL)),
                                           global_sum(fem.form(kin.surface_integral(ufl.cos(n * theta) ** 2, WALL))))
            projection, norm = self._fourier[id(u), n]
            out[n] = global_sum(projection) / norm / self.sector.crater_radius
        return out


def wall_content(ctx, u, waves: int):
    """The integrand of the wall's cos n theta content: u.X/|X| cos n theta."""
    X = ufl.SpatialCoordinate(ctx.mesh)
    return ufl.dot(u, X) / ufl.sqrt(ufl.dot(X, X)) * ufl.cos(waves * ufl.atan2(X[1], X[0]))
