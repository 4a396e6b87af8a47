r"""The crater model: mesh, states, energy terms, boundary conditions and observables.

A neo-Hookean specimen (nearly incompressible, Taylor-Hood u-p) with a crater in its
bottom face stands on a rigid plate. The bottom face is held on the plate (u_z = 0,
free to slide: ambient pressure holds the sealed interface down), or, with
``bottom = contact``, in frictionless unilateral contact with it (the dissertation's
model), free to lift off. The crater wall is
in frictionless contact with the plate (z >= 0, bounds of a variational inequality)
and may not pass through itself (penalty self-contact, :mod:`bcfem.contact.self_contact`).
A surface energy γ on the wall gives its creases a length scale. The crater fluid is
a term of the unloading stage (:mod:`bcfem.physics.fluids`); units: pressures in p_a (so
μ/p_a = β), lengths in mm.

The Lagrangian, over the axisymmetric specimen Ω with the crater wall Γ_w:

.. math:: L(u, p_s, p) = \int_\Omega W(F, p_s)\,dV + \gamma\int_{\Gamma_w} da
          + \Pi_f(V(u), p) + \Pi_c(u),

W the nearly incompressible neo-Hookean density with μ = β and its mixed pressure p_s
(:class:`bcfem.physics.energies.SolidStrain`), da the wall's current area
(:class:`bcfem.physics.energies.SolidSurfaceEnergy`), V(u) the crater's volume. While loading
the crater is vented (Π_f = 0); sealed, Π_f is the fluid's: air :math:`-(p-1)V + V_1\ln p`,
a liquid :math:`-(p-1)(V-V_1)`, a closed crater :math:`sV` (:mod:`bcfem.physics.fluids`).
Π_c is the wall's penalty self-contact; the platen u_z = -εH on the top face and the plate
z >= 0 are conditions, not energies.
"""

from __future__ import annotations

import math
from contextlib import contextmanager

from mpi4py import MPI

import numpy as np
import ufl
from dolfinx import fem, mesh

from bcfem.contact import plate_edge
from bcfem.contact.self_contact import WallSelfContact
from bcfem.geometry.crater import AXIS, BOTTOM, CRATER, LAYER, SPECIMEN, TOP, create_mesh
from bcfem.kinematics.solid import AxisymmetricSolid
from bcfem.mpi import PointEvaluator, global_sum, real_value
from bcfem.physics.bcs import component
from bcfem.physics.cavity import Cavity
from bcfem.physics.context import Context
from bcfem.physics.energies import SolidStrain, SolidSurfaceEnergy
from bcfem.physics.materials import NearlyIncompressibleNeoHookean
from bcfem.physics.viscosity import Viscosity
from bcfem.scenes.crater.params import ELEMENTS, Specimen
from bcfem.stability.modes import ModeAnalysis

#: the facet tag of the bottom face inside the seal's reach (``bottom = contact``)
SEALED_BOTTOM = 16
#: with the bottom face in contact, the cavity's gap scale over a (:class:`bcfem.physics.cavity.Cavity`):
#: its nodes on the plate feel no fluid, and a lift h counts as h (1 - O(g^2/h^2))
CONTACT_GAP = 1e-4
#: how far out the seal may move before the crater counts as pulled off: this fraction of the
#: way from the rim to the specimen's edge
SEAL_REACH = 0.5


class Crater:
    """The composed crater model: mesh, states, terms, the two stages' problems.

    A subclass may change the geometry: :attr:`walls` (the cavity's wall, one curve from the
    rim on the plate to the axis, given as facet tags) and :meth:`create_mesh`; its geometry
    has ``crater_radius`` (the rim's), ``crater_volume`` and the mesh's tags of
    :mod:`bcfem.geometry.crater` for the axis, bottom and top.
    """

    #: facet tags of the cavity's wall
    walls: tuple[int, ...] = (CRATER,)

    @staticmethod
    def create_mesh(geometry, comm):
        return create_mesh(geometry, comm)

    def __init__(self, params: Specimen, comm):
        self.params = params
        geometry = params.geometry
        self.geometry = geometry
        data = self.create_mesh(geometry, comm)
        msh, facets = data.mesh, data.facet_tags
        element = ELEMENTS[params.element]
        V = fem.functionspace(msh, ("Lagrange", element.displacement, (2,)))
        self.u = fem.Function(V, name="displacement")
        self.ctx = Context(self.u)
        Vz, zmap = V.sub(1).collapse()
        _, rmap = V.sub(0).collapse()
        wall = fem.locate_dofs_topological(Vz, 1, np.concatenate([facets.find(tag) for tag in self.walls]))
        self._wall_dofs = wall
        # reference points and displacement dofs of the crater wall, found once
        self._wall = (Vz.tabulate_dof_coordinates()[wall], np.asarray(zmap).reshape(-1)[wall],
                      np.asarray(rmap).reshape(-1)[wall])
        #: the bottom face in unilateral contact with the plate (else held on it)
        self.bottom_contact = params.bottom == "contact"
        bottom = fem.locate_dofs_topological(Vz, 1, facets.find(BOTTOM)) if self.bottom_contact else wall[:0]
        self._bottom = (Vz.tabulate_dof_coordinates()[bottom], np.asarray(zmap).reshape(-1)[bottom],
                        np.asarray(rmap).reshape(-1)[bottom])
        #: the platen displacement as an unknown (``path = fundamental``), else None
        self.platen_state: fem.Function | None = None
        lift = self._lift(V, msh.comm)
        if self.bottom_contact:
            facets = self._tag_sealed_bottom(msh, facets)
        self.ctx.kin = AxisymmetricSolid(self.u, quadrature_degree=element.quadrature, cell_tags=data.cell_tags,
                                         facet_tags=facets, lift=lift)

        def solid(mu, region=None):
            return SolidStrain(NearlyIncompressibleNeoHookean(mu=mu, kappa=params.kappa_ratio * mu), region,
                               element.pressure)

        if params.layer_thickness > 0:  # the layer is its own material region
            self.solids = [solid(params.beta, SPECIMEN), solid(params.layer_stiffness * params.beta, LAYER)]
        else:
            self.solids = [solid(params.beta)]
        self.platen = fem.Function(V.sub(1).collapse()[0])
        gamma = params.surface_energy * params.beta * geometry.crater_radius  # gamma~ mu a
        self.surface = SolidSurfaceEnergy(gamma, self.walls, "crater_surface_energy") if gamma > 0 else None
        self.viscosity = Viscosity(self.u)
        # the wall (or its lining) must not fold through itself; the stiffest material sets k
        stiffest = params.beta * (max(1.0, params.layer_stiffness) if params.layer_thickness > 0 else 1.0)
        # residuals in units of the stiffest modulus (>= p_a): Newton's round-off floor grows
        # with the stiffness and stalled above the absolute tolerance for beta' = 300 linings
        self.energy_scale = max(1.0, stiffest)
        self.self_contact = (WallSelfContact(facets, self.walls, stiffest, penalty=params.self_contact)
                             if params.self_contact > 0 else None)
        self.strain = 0.0
        #: the platen's force of the stage being solved (:meth:`measuring`), else None
        self.platen_force = None
        self.bcs = self._bcs(V, facets)
        # a bottom face that lifts off the plate inside the seal bounds the cavity too: where it
        # lies on the plate (z = 0) it adds no volume and no load
        self.cavity = (Cavity((*self.walls, SEALED_BOTTOM), CONTACT_GAP * geometry.crater_radius)
                       if self.bottom_contact else Cavity(self.walls))
        if self.bottom_contact:  # the area the fluid pulls on: d V / d (a lift of the whole specimen)
            lift = fem.Function(V)
            lift.interpolate(lambda x: np.vstack([0 * x[0], 1 + 0 * x[0]]))
            self.wetted_area = fem.form(ufl.derivative(self.cavity.volume(self.ctx.kin), self.u, lift))
        self.volume = fem.form(self.cavity.volume(self.ctx.kin))
        self.rim = PointEvaluator(msh, [geometry.crater_radius, 0.0]).expression(self.u[0])
        self.mesh = msh
        self.cell_tags, self.facet_tags = data.cell_tags, facets

    def _tag_sealed_bottom(self, msh, facets):
        """``facets`` with the bottom face inside :data:`SEAL_REACH` of the rim retagged
        ``SEALED_BOTTOM``: the part of the bottom face that bounds the cavity where it lifts."""
        a, Rs = self.geometry.crater_radius, self.geometry.radius
        self.seal_reach = a + SEAL_REACH * (Rs - a)
        values = facets.values.copy()
        bottom = facets.find(BOTTOM)
        midpoints = mesh.compute_midpoints(msh, 1, bottom)
        values[np.isin(facets.indices, bottom[midpoints[:, 0] < self.seal_reach])] = SEALED_BOTTOM
        return mesh.meshtags(msh, 1, facets.indices, values)

    def terms(self, *fluid) -> list:
        """The solid, the wall's surface energy and self-contact (if any), the fluid, and the
        viscosity used only while relaxing past an instability."""
        optional = [t for t in (self.surface, self.self_contact) if t is not None]
        return [*self.solids, *optional, *fluid, self.viscosity]

    def _lift(self, V, comm):
        """None, or the UFL vector added to u in the kinematics: the platen's with ``path =
        fundamental`` (a subclass may add its own)."""
        if self.params.path != "fundamental":
            return None
        self.platen_state = self.ctx.real_state("platen_displacement")
        return ufl.as_vector([0, self.platen_state * self._platen_shape(V.sub(1).collapse()[0], comm)])

    def _platen_shape(self, Vz, comm) -> fem.Function:
        """phi(Z), 0 up to the wall's top and rising linearly to 1 on the top face: the lift
        u + w phi e_z moves the top face by w and leaves the wall's unknowns, their contact
        bounds and the self-contact as they are."""
        top = comm.allreduce(float(self._wall[0][:, 1].max(initial=0.0)), op=MPI.MAX)
        H = self.params.specimen_height
        shape = fem.Function(Vz, name="platen_shape")
        shape.interpolate(lambda x: np.clip((x[1] - top) / (H - top), 0.0, 1.0))
        return shape

    def set_platen(self, strain: float) -> None:
        """Platen displacement for the specimen strain eps = -dL/L."""
        self.strain = strain
        target = self.platen if self.platen_state is None else self.platen_state
        target.x.array[:] = -strain * self.params.specimen_height

    def platen_strain(self) -> float:
        """eps = -dL/L of the current state."""
        if self.platen_state is None:
            return self.strain
        return 0.0 - real_value(self.platen_state) / self.params.specimen_height  # no -0.0 at rest

    def _bcs(self, V, facets):
        held = [] if self.bottom_contact else [component(V, 1, facets.find(BOTTOM))]
        return [component(V, 0, facets.find(AXIS)), *held, component(V, 1, facets.find(TOP), self.platen)]

    def observe(self, stage: str, eps: float, V1: float | None = None) -> dict:
        V0, A0 = self.geometry.crater_volume, math.pi * self.geometry.crater_radius**2
        V = global_sum(self.volume)
        A = global_sum(self.wetted_area) if self.bottom_contact else math.pi * self.open_radius() ** 2
        p = real_value(self.ctx.states["fluid_pressure"]) if "fluid_pressure" in self.ctx.states and V1 else 1.0
        if V1 == 0.0:  # closed crater: the vacuum's suction s = 1 - p (p = p_v for a cavitated liquid)
            p = 1.0 - float(self.ctx.constant("vacuum_load").value)
        force = global_sum(self.platen_force) / A0 if self.platen_force is not None else None
        return {"stage": stage, "eps": eps, "V_over_V0": V / V0, "p_over_pa": p, "A_over_A0": A / A0,
                "F_tilde": (1 - p) * A / A0, "F_hat": (1 - p) * A / A0 / self.params.beta, "platen_force": force,
                "V": V}

    @contextmanager
    def measuring(self, problem):
        """Within: the rows report the platen's force, ``platen_force`` (the Lagrangian of
        ``problem`` differentiated in w = Z/H e_z, which moves the top face alone by 1; < 0
        pressing, > 0 pulling). Self-contact is left out: its forces pair up on the wall, so
        their work in w is the contact force times gap / H, negligible."""
        w = fem.Function(self.u.function_space)
        H = self.params.specimen_height
        w.interpolate(lambda x: np.vstack([0 * x[0], x[1] / H]))
        self.platen_force = fem.form(ufl.derivative(problem.lagrangian, self.u, w))
        try:
            yield self.platen_force
        finally:
            self.platen_force = None

    def contact_bounds(self, problem):
        """z = Z + u_z >= 0 on the crater wall (frictionless contact with the plate), and on
        the bottom face where it is in contact rather than held, as bounds of the
        variational-inequality solver; every other unknown is free."""
        lower = [fem.Function(s.function_space) for s in problem.states]
        upper = [fem.Function(s.function_space) for s in problem.states]
        for f in lower:
            f.x.array[:] = -1e20
        for f in upper:
            f.x.array[:] = 1e20
        V = self.u.function_space
        Vz, zmap = V.sub(1).collapse()
        Z = Vz.tabulate_dof_coordinates()[self._wall_dofs, 1]
        lower[problem.names.index("displacement")].x.array[np.asarray(zmap).reshape(-1)[self._wall_dofs]] = -Z
        X, bottom, _ = self._bottom
        lower[problem.names.index("displacement")].x.array[bottom] = -X[:, 1]
        problem.set_bounds(lower, upper)

    def wave_check(self, problem, terms):
        """None, or {n: unstable modes with n waves} at the current state, n = 1..``waves``;
        the wall nodes on the plate hold their normal displacement. Its matrices are closed
        with ``problem``."""
        if not self.params.waves:
            return None
        analysis = problem.own(ModeAnalysis(self.ctx, [t for t in terms if t is not self.viscosity], self.bcs,
                                            problem.prefix + "modes_"))
        X, zdofs, _ = self._wall
        tolerance = 1e-9 * self.geometry.crater_radius

        Xb, zb, _ = self._bottom

        def check():
            on_plate = np.concatenate([zdofs[X[:, 1] + self.u.x.array[zdofs] <= tolerance],
                                       zb[Xb[:, 1] + self.u.x.array[zb] <= tolerance]])
            return analysis.scan(range(1, self.params.waves + 1), held=on_plate)

        return check

    def on_plate(self) -> bool:
        """Whether a node of the wall or of the bottom face lies on the plate (collective): with
        the bottom face in contact, none once the specimen has pulled off."""
        tolerance = 1e-6 * self.geometry.crater_radius
        touching = False
        for X, zdofs, _ in (self._wall, self._bottom):
            touching |= bool(np.any(X[:, 1] + self.u.x.array[zdofs] <= tolerance))
        return self.mesh.comm.allreduce(touching, op=MPI.LOR)

    def open_radius(self) -> float:
        """Current radius of the edge of the suction area, where the crater wall leaves
        the plate (located inside its element, :mod:`bcfem.contact.plate_edge`). The pressure on
        the wall has the vertical resultant Δp π r_edge² whatever the wall's shape above
        (an overhang cancels), so A = π r_edge². With the bottom face in contact the edge is
        the sealed contact line: where the surface leaves the plate on the way from the far
        bottom face over the rim into the crater (a rim lifted off the plate moves it out)."""
        if not self.bottom_contact:
            return self.plate_edge(np.ones(len(self._wall[0]), dtype=bool))
        (Xw, zw, rw), (Xb, zb, rb) = self._wall, self._bottom
        # the rim's node is on both: once
        zdofs, once = np.unique(np.concatenate([zw, zb]), return_index=True)
        X, rdofs = np.vstack([Xw, Xb])[once], np.concatenate([rw, rb])[once]
        # along the surface: the bottom face from outside in (below 0), then the wall up (its Z)
        order = np.concatenate([Xw[:, 1], self.geometry.crater_radius - Xb[:, 0]])[once]
        x = np.column_stack([X[:, 0] + self.u.x.array[rdofs], X[:, 1] + self.u.x.array[zdofs]])
        return plate_edge.plate_edge(self.mesh.comm, X[:, :2], x, 1e-6 * self.geometry.crater_radius,
                                       order=order)

    def plate_edge(self, part: np.ndarray) -> float:
        """The current radius where the wall nodes ``part`` (a mask of the wall's dofs) leave
        the plate. They lie on it from their lowest reference height up to the highest node
        on the plate; the edge lies between that node and the next one off it, where
        :func:`bcfem.contact.plate_edge.plate_edge` extrapolates the gap of the nodes off the
        plate, g^(2/3), to zero (a smooth edge: g ~ (s - s0)^(3/2)); an edge at a corner
        stays at the corner's node. 0 if none of them is on the plate (collective)."""
        X, zdofs, rdofs = (a[part] for a in self._wall)
        x = np.column_stack([X[:, 0] + self.u.x.array[rdofs], X[:, 1] + self.u.x.array[zdofs]])
        return plate_edge.plate_edge(self.mesh.comm, X[:, :2], x, 1e-6 * self.geometry.crater_radius)
