r"""Edge conditions of an axisymmetric membrane blister, each derived from one energy.

An edge is what it adds to the model: Dirichlet conditions, energy terms and,
for a moving edge, a global unknown with its own residual row. The Young-type
and Griffith-type edge conditions of eqs. 3.59-3.64 are then the natural
(transversality) conditions of the total free energy; nothing is hand-coded.

* clamped: u = 0 at R0.
* sliding: z = 0 at the material edge R0 = 1, r0 = r(R0) free; the liquid wets
  π r0² of substrate at (γ_ls - γ_s) = -γ_l cos φY per area (Young's angle φY).
* adhesive: the debond radius R1 >= 1 is a real-space unknown (R = R1 ξ);
  u = 0 at R1 (the bonded film is unstretched, r1 = R1); debonding costs
  (γ_ls - Δγ) per area, or a profile of the rigid substrate's radius. Its row holds R1 until the configurational force
  ∂Π/∂R1 turns negative (onset, a Switch), then is ∂Π/∂R1 = 0.
* slippery: the film beyond the front R1 stays on a wet substrate (z = 0)
  but slides, out to the material radius n R0, and is strained too. The mesh
  has two zones (ξ < 1: blister, ξ > 1: the bonded annulus, R from R1 to n).
  Interface energies: (γ_ls - Δγ) π r1² under the liquid and
  (Δγ - γ_s) π rn² under the film, whose variation gives N_r(nR0) = γ_s - Δγ
  (eq. 3.68). The front moves as for the adhesive edge.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
import ufl
from dolfinx import fem, mesh

from bcfem.kinematics.membrane import scaled, two_zone
from bcfem.physics.bcs import component, where
from bcfem.physics.energies import WettedSubstrate
from bcfem.radial_profile import scale_of, shape_of


@dataclass
class Edge:
    """What an edge condition contributes to a blister model."""

    name: str
    bcs: list
    terms: list = field(default_factory=list)
    reference: object = None  # reference map of the kinematics (None: R = ξ)
    liquid_region: int | None = None  # cell tag of the liquid-wetted membrane (None: all)
    rows: dict = field(default_factory=dict)  # state -> callable(lagrangian) -> residual form
    free: fem.Constant | None = None  # 1 once a moving edge is released
    #: params -> {name: value} of the run-time constants of the edge's terms
    constants: Callable[[object], dict[str, float]] = lambda params: {}
    #: puts the edge's own states and switches back as built (a moving front: held at R0)
    restart: Callable[[], None] = lambda: None

    def reset(self, ctx, params) -> None:
        """The edge as :data:`EDGES` builds it for ``params``, without compiling anything:
        its constants set from ``params`` and its states restarted."""
        for name, value in self.constants(params).items():
            ctx.set(name, value)
        self.restart()


def _edge(x0):
    return lambda x: np.isclose(x[0], x0)


def _axis_bc(V):
    return component(V, 0, where(V, _edge(0.0)))


def _fixed_edge_bc(V):
    zero = np.zeros(2, dtype=fem.Function(V).x.array.dtype)
    fdim = V.mesh.topology.dim - 1
    return fem.dirichletbc(zero, fem.locate_dofs_topological(V, fdim, where(V, _edge(1.0))), V)


def _lifted_edge_bc(V):
    """z = 0 at the edge; r free."""
    return component(V, 1, where(V, _edge(1.0)))


def clamped(ctx, params) -> Edge:
    V = ctx.u.function_space
    return Edge("clamped", [_fixed_edge_bc(V), _axis_bc(V)])


def sliding(ctx, params) -> Edge:
    V = ctx.u.function_space

    def constants(p):
        return {"gamma_wet": -p.alpha * math.cos(math.radians(p.phi_Y_deg))}  # (γ_ls - γ_s)/(μ t0)

    return Edge("sliding", [_lifted_edge_bc(V), _axis_bc(V)],
                terms=[WettedSubstrate(constants(params)["gamma_wet"])], constants=constants)


BLISTER, BONDED = 1, 2  # cell tags of the two zones of the slippery edge


def domain(params, comm):
    """The reference mesh in ξ: [0, 1], or [0, 2] with tagged zones for the slippery edge."""
    if params.edge != "slippery":
        return mesh.create_interval(comm, params.cells, [0.0, 1.0]), None
    msh = mesh.create_interval(comm, 2 * params.cells, [0.0, 2.0])
    tdim = msh.topology.dim
    n = msh.topology.index_map(tdim).size_local
    cells = np.arange(n, dtype=np.int32)
    midpoints = mesh.compute_midpoints(msh, tdim, cells)[:, 0]
    tags = np.where(midpoints < 1.0, BLISTER, BONDED).astype(np.int32)
    return msh, mesh.meshtags(msh, tdim, cells, tags)


def moving_front(ctx):
    """The debond radius R1 with its held/free row (held at R0 = 1 until released), and
    the callable that holds it at R0 again."""
    R1 = ctx.real_state("debond_radius")
    free = fem.Constant(ctx.mesh, 0.0)
    held_at = ctx.constant("debond_radius_held", 1.0)
    q = ufl.TestFunction(R1.function_space)
    hold = (R1 - held_at) * q * ufl.dx(domain=ctx.mesh)

    def row(lagrangian):
        # held before onset; the transversality condition dPi/dR1 = 0 after
        return free * ufl.derivative(lagrangian, R1, q) + (1 - free) * hold

    def restart():
        R1.x.array[:] = 1.0
        free.value = np.asarray(0.0)
        held_at.value = 1.0

    restart()
    return R1, free, {"debond_radius": row}, restart


def slippery(ctx, params) -> Edge:
    V = ctx.u.function_space
    R1, free, rows, restart = moving_front(ctx)
    Vz, _ = V.sub(1).collapse()
    flat = fem.locate_dofs_geometrical((V.sub(1), Vz), lambda x: x[0] >= 1.0 - 1e-12)
    bcs = [fem.dirichletbc(fem.Function(Vz), flat, V.sub(1)), _axis_bc(V)]

    def constants(p):
        return {"gamma_wet": p.adhesion, "gamma_film": -p.far_field}

    values = constants(params)
    terms = [WettedSubstrate(values["gamma_wet"], region=BLISTER),
             WettedSubstrate(values["gamma_film"], name="gamma_film")]
    return Edge("slippery", bcs, terms=terms, reference=two_zone(R1, params.outer_radius),
                rows=rows, free=free, liquid_region=BLISTER, constants=constants, restart=restart)


def adhesive(ctx, params) -> Edge:
    V = ctx.u.function_space
    R1, free, rows, restart = moving_front(ctx)

    def constants(p):  # a profile's shape is compiled in, its scale a constant
        return {"gamma_wet": scale_of(p.adhesion)}

    wetted = WettedSubstrate(constants(params)["gamma_wet"], profile=shape_of(params.adhesion))
    return Edge("adhesive", [_fixed_edge_bc(V), _axis_bc(V)],
                terms=[wetted], reference=scaled(R1), rows=rows,
                free=free, constants=constants, restart=restart)


EDGES = {"clamped": clamped, "sliding": sliding, "adhesive": adhesive, "slippery": slippery}
