r"""Mixed-dimensional assembly: a membrane on part of a substrate's top, coupled to it.

The prototype of chapter 4's blister on a soft substrate. The substrate
:math:`\Omega = [0, 1] \times [-1, 0]` (axisymmetric, R = x, Z = y) carries a P2
displacement :math:`u_s`. A membrane covers the top. On the bonded top (R > R0) it
moves with the substrate; on the wetted top :math:`\Gamma` (R < R0, a codim-1
submesh) it is :math:`u_f = u_s|_\Gamma + w`, with the lift :math:`w` a P2 field on
:math:`\Gamma` held at 0 at the contact vertex R = R0: membrane and substrate share
that node exactly, with no multiplier. The energy

.. math:: \int_\Omega W(F(u_s))\,dV + \int_{top} [\tfrac{C}{2}(\lambda_r^2 + \lambda_\theta^2
          + (\lambda_r\lambda_\theta)^{-2} - 3) + \gamma\lambda_r\lambda_\theta]\,dA
          - p\,(V(u_s, w) - \hat V)

with V the liquid volume between membrane and substrate and p (a real-space state)
its pressure. Checks: the patch's surface gradient (dolfinx 0.11's grad of a submesh
function in a parent facet integral is wrong), closed-form energies, Taylor rates of
residual and tangent, the same solution from a single-mesh formulation (w as a parent
field pinned off Γ), and the same numbers on 1 and 2 ranks for partitions that split
Γ (with and without ghosts) or keep it off a rank. Marked ``mpi``: make test runs it
on 2 ranks too, where each rank also solves alone (COMM_SELF) for the comparison.
"""

import functools
import math
from dataclasses import dataclass, field

from mpi4py import MPI
from petsc4py import PETSc

import basix.ufl
import numpy as np
import pytest
import ufl
from dolfinx import default_scalar_type, fem, graph, mesh

import bcfem  # noqa: F401  (first: MPI before dolfinx, when run as a script)
from bcfem import Context, Term, global_sum, real_value
from bcfem.kinematics.solid import AxisymmetricSolid
from bcfem.kinematics.submesh import BoundaryPatch
from bcfem.solver.problem import Problem

pytestmark = pytest.mark.mpi

R0 = 0.5
WETTED, BONDED, AXIS, BOTTOM = 1, 2, 3, 4
LIFT = ("Lagrange", 2, (2,))


def rectangle(comm, n: int, partition: str | None = None):
    """Triangles on [0, 1] x [-1, 0], built on rank 0. ``partition``: None (dolfinx's
    graph partitioner), ``"ghosted"`` (the same, with shared-facet ghosts), ``"split"``
    (rank 0 holds R < 1/4: Γ is cut), ``"split-ghosted"`` (the same, each rank ghosting
    the cells next to the cut) or ``"off-top"`` (rank 0 holds Z < -1/2: it has none of Γ)."""
    if comm.rank == 0:
        i, j = np.meshgrid(np.arange(n + 1), np.arange(n + 1))
        x = np.c_[i.ravel() / n, j.ravel() / n - 1.0]
        v = np.arange((n + 1) ** 2).reshape(n + 1, n + 1)
        a, b, c, d = v[:-1, :-1].ravel(), v[:-1, 1:].ravel(), v[1:, 1:].ravel(), v[1:, :-1].ravel()
        cells = np.r_[np.c_[a, b, c], np.c_[a, c, d]].astype(np.int64)
    else:
        x, cells = np.zeros((0, 2)), np.zeros((0, 3), dtype=np.int64)

    def by_centroid(comm_, nparts, cell_types, local_cells):
        centroid = x[np.asarray(local_cells[0]).reshape(-1, 3)].mean(axis=1)
        first = centroid[:, 0] < 0.25 if partition.startswith("split") else centroid[:, 1] < -0.5
        owner = np.where(first, 0, nparts - 1).astype(np.int32)
        if partition != "split-ghosted":
            return graph.adjacencylist(owner)._cpp_object
        # each rank also ghosts the cells within one cell width of the cut
        near = np.abs(centroid[:, 0] - 0.25) < 1.0 / n
        links = [[o, nparts - 1 - o] if g and nparts > 1 else [o] for o, g in zip(owner, near)]
        offsets = np.cumsum([0] + [len(k) for k in links]).astype(np.int32)
        data = np.array([r for k in links for r in k], dtype=np.int32)
        return graph.adjacencylist(data, offsets)._cpp_object

    element = basix.ufl.element("Lagrange", "triangle", 1, shape=(2,))
    partitioner = None
    if comm.size > 1 and partition == "ghosted":
        partitioner = mesh.create_cell_partitioner(mesh.GhostMode.shared_facet, 2)
    elif comm.size > 1 and partition is not None:
        partitioner = by_centroid
    msh = mesh.create_mesh(comm, cells, ufl.Mesh(element), x, partitioner=partitioner)
    tdim = msh.topology.dim
    msh.topology.create_connectivity(tdim - 1, tdim)
    # located by geometry, so that ghost facets are tagged too (exterior_facet_indices
    # returns owned facets only, and a submesh of those has no ghost cells)
    facets = mesh.locate_entities(msh, tdim - 1, lambda x: np.isclose(x[1], 0) | np.isclose(x[1], -1)
                                  | np.isclose(x[0], 0))
    mid = mesh.compute_midpoints(msh, tdim - 1, facets)
    tags = np.select([np.isclose(mid[:, 1], 0) & (mid[:, 0] < R0), np.isclose(mid[:, 1], 0),
                      np.isclose(mid[:, 0], 0), np.isclose(mid[:, 1], -1)], [WETTED, BONDED, AXIS, BOTTOM], 0)
    keep = tags > 0
    return msh, mesh.meshtags(msh, tdim - 1, facets[keep], tags[keep].astype(np.int32))


# -- the lift w: on the wetted patch (the design), or a parent field pinned off it (reference)
class PatchLift:
    """w on the submesh Γ; its R-derivative via the patch's (corrected) surface gradient."""

    def __init__(self, patch: BoundaryPatch):
        self.patch = patch

    def __call__(self, ctx):
        w = self.patch.state(ctx, "lift", LIFT)
        return w, self.patch.grad(w)[:, 0]

    def bcs(self, ctx):
        W = ctx.states["lift"].function_space
        contact = fem.dirichletbc(np.zeros(2, dtype=default_scalar_type), self.patch.vertex_dofs(W, (R0, 0)), W)
        axis = fem.dirichletbc(default_scalar_type(0), self.patch.vertex_dofs(W.sub(0), (0, 0)), W.sub(0))
        return [contact, axis]


class ParentLift(Term):
    """w as a P2 field on the whole substrate, every dof off the closure of Γ held at 0:
    the same discrete space on Γ, assembled without a submesh."""

    def __init__(self, tags):
        self.tags = tags

    def __call__(self, ctx):
        if "lift" not in ctx.states:
            ctx.state_in("lift", fem.functionspace(ctx.mesh, LIFT))
        w = ctx.states["lift"]
        return w, ufl.grad(w)[:, 0]

    def energy(self, ctx):
        """0 * |w|^2 over the body. Without a cell integral the lift's sparsity pattern has
        no entries off Γ, so the unit diagonal of its Dirichlet rows there is lost (zero pivot)."""
        w, _ = self(ctx)
        return ctx.kin.integral(fem.Constant(ctx.mesh, default_scalar_type(0)) * ufl.inner(w, w))

    def bcs(self, ctx):
        W = ctx.states["lift"].function_space
        tdim = ctx.mesh.topology.dim
        on_gamma = fem.locate_dofs_topological(W, tdim - 1, self.tags.find(WETTED))
        imap = W.dofmap.index_map
        off = np.setdiff1d(np.arange(imap.size_local + imap.num_ghosts, dtype=np.int32), on_gamma)
        contact = fem.locate_dofs_geometrical(W, lambda x: np.isclose(x[0], R0) & np.isclose(x[1], 0))
        axis = fem.locate_dofs_topological(W.sub(0), 0, mesh.locate_entities_boundary(
            ctx.mesh, 0, lambda x: np.isclose(x[0], 0) & np.isclose(x[1], 0)))
        zero = np.zeros(2, dtype=default_scalar_type)
        return [fem.dirichletbc(zero, np.union1d(off, contact), W),
                fem.dirichletbc(default_scalar_type(0), axis, W.sub(0))]


def meridian(ctx, lift, tag):
    """(r, z, dr/dR, dz/dR) of the membrane on the top facets ``tag`` (Z = 0, tangent e_R),
    or of the substrate's surface when ``lift`` is None."""
    u, du = ctx.u, ufl.grad(ctx.u)[:, 0]
    if lift is not None:
        w, dw = lift(ctx)
        u, du = u + w, du + dw
    return ctx.kin.x[0] + u[0], u[1], 1 + du[0], du[1]


@dataclass(frozen=True)
class Substrate(Term):
    r"""Compressible neo-Hookean bulk, :math:`W = \tfrac{\mu}{2}(I_1-3) - \mu\ln J + \tfrac{\lambda}{2}(\ln J)^2`."""

    mu: float = 1.0
    lam: float = 2.0

    def energy(self, ctx):
        kin = ctx.kin
        lnJ = ufl.ln(kin.J)
        return kin.integral(0.5 * self.mu * (kin.I1 - 3) - self.mu * lnJ + 0.5 * self.lam * lnJ**2)


@dataclass(frozen=True)
class Membrane(Term):
    """Neo-Hookean membrane (stiffness C = mu_f t0) with surface tension gamma on the
    whole top: lifted on Γ, bonded beyond."""

    lift: object = field(compare=False)
    stiffness: float = 0.3
    tension: float = 0.1

    def density(self, ctx, lift, tag):
        r, _, dr, dz = meridian(ctx, lift, tag)
        lam_r, lam_t = ufl.sqrt(dr**2 + dz**2), r / ctx.kin.x[0]
        I1 = lam_r**2 + lam_t**2 + 1 / (lam_r * lam_t) ** 2
        return 0.5 * self.stiffness * (I1 - 3) + self.tension * lam_r * lam_t

    def energy(self, ctx):
        kin = ctx.kin
        return (kin.surface_integral(self.density(ctx, self.lift, WETTED), WETTED)
                + kin.surface_integral(self.density(ctx, None, BONDED), BONDED))


def volume_density(ctx, lift):
    r"""Liquid volume between membrane and substrate per reference area 2πR dR:
    :math:`-(r_f^2 z_f' - r_s^2 z_s')/(2R)`; exact, since both meridians meet at R0."""
    rf, _, _, dzf = meridian(ctx, lift, WETTED)
    rs, _, _, dzs = meridian(ctx, None, WETTED)
    return -(rf**2 * dzf - rs**2 * dzs) / (2 * ctx.kin.x[0])


@dataclass(frozen=True)
class LiquidVolume(Term):
    r""":math:`-p\,(V - \hat V)`, p the real-space state ``liquid_pressure``."""

    lift: object = field(compare=False)

    def energy(self, ctx):
        p = ctx.real_state("liquid_pressure")
        target = ctx.constant("liquid_volume", 0.0)
        return ctx.kin.surface_integral(-p * (volume_density(ctx, self.lift) - target / (math.pi * R0**2)), WETTED)


def build(msh, tags, single_mesh=False, prefix="bcfem_test_mixeddim_"):
    V = fem.functionspace(msh, ("Lagrange", 2, (2,)))
    u = fem.Function(V, name="displacement")
    ctx = Context(u, AxisymmetricSolid(u, quadrature_degree=4, facet_tags=tags))
    patch = None if single_mesh else BoundaryPatch(msh, tags, WETTED)
    lift = ParentLift(tags) if single_mesh else PatchLift(patch)
    terms = [Substrate(), Membrane(lift), LiquidVolume(lift)] + ([lift] if single_mesh else [])
    lift(ctx)  # the lift's state now, for its Dirichlet conditions
    bottom = fem.locate_dofs_topological(V, 1, tags.find(BOTTOM))
    axis = fem.locate_dofs_topological(V.sub(0), 1, tags.find(AXIS))
    bcs = [fem.dirichletbc(np.zeros(2, dtype=default_scalar_type), bottom, V),
           fem.dirichletbc(default_scalar_type(0), axis, V.sub(0)), *lift.bcs(ctx)]
    problem = Problem(ctx, terms, bcs, prefix)
    return problem, lift, patch


def solve(problem, volumes=(0.04, 0.08)):
    for v in volumes:
        problem.ctx.constant("liquid_volume").value = v
        assert problem.solve(), problem.failure


def observables(problem, lift) -> dict:
    ctx = problem.ctx
    w, _ = lift(ctx)
    maps = ctx.entity_maps or None
    kin = ctx.kin
    forms = {"volume": kin.surface_integral(volume_density(ctx, lift), WETTED),
             "substrate": kin.integral(ufl.inner(ctx.u, ctx.u)),
             "lift": kin.surface_integral(ufl.inner(w, w), WETTED),
             "height": kin.surface_integral(ctx.u[1] + w[1], WETTED)}
    out = {k: global_sum(fem.form(f, entity_maps=maps)) for k, f in forms.items()}
    out["pressure"] = real_value(ctx.real_state("liquid_pressure"))
    return out


# -- the trap, and its fix -------------------------------------------------------------------
def distorted_square(comm, degree: int, n: int = 4):
    """The unit square in 2n^2 triangles of geometry degree 1 or 2, bent so that its
    boundary facets point every way (and, for degree 2, are curved)."""
    m = degree * n
    if comm.rank == 0:
        i, j = np.meshgrid(np.arange(m + 1), np.arange(m + 1))
        x = np.c_[i.ravel() / m, j.ravel() / m]
        x = np.c_[x[:, 0] + 0.15 * np.sin(3 * x[:, 1]), x[:, 1] + 0.12 * np.cos(2 * x[:, 0]) + 0.1 * x[:, 0] ** 2]
        v = np.arange((m + 1) ** 2).reshape(m + 1, m + 1)
        k = degree
        a, b, c, d = v[:-1:k, :-1:k], v[:-1:k, k::k], v[k::k, k::k], v[k::k, :-1:k]
        cells = [np.c_[a.ravel(), b.ravel(), c.ravel()], np.c_[a.ravel(), c.ravel(), d.ravel()]]
        if degree == 2:  # then the midpoints of the edges (1, 2), (0, 2), (0, 1)
            h = 1
            ab, bc, cd, da, ac = (v[:-1:k, h::k], v[h::k, k::k], v[k::k, h::k], v[h::k, :-1:k], v[h::k, h::k])
            cells = [np.c_[cells[0], bc.ravel(), ac.ravel(), ab.ravel()],
                     np.c_[cells[1], cd.ravel(), da.ravel(), ac.ravel()]]
        cells = np.r_[cells[0], cells[1]].astype(np.int64)
    else:
        x, cells = np.zeros((0, 2)), np.zeros((0, 3 * degree), dtype=np.int64)
    element = basix.ufl.element("Lagrange", "triangle", degree, shape=(2,))
    return mesh.create_mesh(comm, cells, ufl.Mesh(element), x)


@pytest.mark.parametrize("degree", [1, 2])
def test_patch_gradient_equals_the_gradient_on_the_submesh(degree):
    """BoundaryPatch.grad in a parent facet integral equals grad on the submesh itself, on
    straight and curved boundary facets pointing every way; dolfinx 0.11's raw grad does not."""
    msh = distorted_square(MPI.COMM_WORLD, degree)
    msh.topology.create_connectivity(1, 2)
    facets = mesh.exterior_facet_indices(msh.topology)
    patch = BoundaryPatch(msh, mesh.meshtags(msh, 1, facets, np.full(facets.size, 7, dtype=np.int32)), 7)
    w = fem.Function(patch.space(("Lagrange", 2, (2,))))
    w.interpolate(lambda x: np.vstack([np.sin(x[0]) * x[1], x[0] ** 2 + 3 * x[1]]))
    f = fem.Function(patch.space(("Lagrange", 1)))
    f.interpolate(lambda x: 1 + x[0] + 2 * x[1] ** 2)
    exact_degree = {"quadrature_degree": 8}
    ds = ufl.Measure("ds", domain=msh, metadata=exact_degree)  # the patch is every exterior facet

    def total(expr, measure, maps):
        return global_sum(fem.form(expr * measure, entity_maps=maps))

    worst_raw = 0.0
    for i in range(2):
        for j in range(2):
            exact = total(f * ufl.grad(w)[i, j], ufl.dx(domain=patch.mesh, metadata=exact_degree), None)
            assert total(f * patch.grad(w)[i, j], ds, [patch.entity_map]) == pytest.approx(exact, rel=1e-13, abs=1e-13)
            worst_raw = max(worst_raw, abs(total(f * ufl.grad(w)[i, j], ds, [patch.entity_map]) - exact))
    # if this fails, dolfinx fixed the trap (FFCx #816); BoundaryPatch.grad stays right either way
    assert worst_raw > 1.0


def test_energies_in_closed_form():
    """The volume between membrane and substrate, and the membrane energy at uniform
    stretch, assembled from parent and submesh fields together."""
    problem, lift, patch = build(*rectangle(MPI.COMM_WORLD, 4))
    ctx = problem.ctx
    a, b, c, d = 0.1, -0.2, 0.05, 0.3
    ctx.u.interpolate(lambda x: np.vstack([a * x[0], b * x[0] ** 2 + 0.4 * x[1]]))
    w = ctx.states["lift"]
    w.interpolate(lambda x: np.vstack([c * x[0], d * (R0**2 - x[0] ** 2)]))
    volume = global_sum(fem.form(ctx.kin.surface_integral(volume_density(ctx, lift), WETTED),
                                 entity_maps=ctx.entity_maps))
    exact = -math.pi / 2 * R0**4 * ((1 + a + c) ** 2 * (b - d) - (1 + a) ** 2 * b)
    assert volume == pytest.approx(exact, rel=1e-13)
    ctx.u.interpolate(lambda x: np.vstack([a * x[0], 0 * x[0]]))
    w.interpolate(lambda x: np.vstack([c * x[0], 0 * x[0]]))
    membrane = Membrane(lift)
    energy = global_sum(fem.form(membrane.energy(ctx), entity_maps=ctx.entity_maps))

    def W(lam):
        return 0.5 * membrane.stiffness * (2 * lam**2 + lam**-4 - 3) + membrane.tension * lam**2

    assert energy == pytest.approx(math.pi * (R0**2 * W(1 + a + c) + (1 - R0**2) * W(1 + a)), rel=1e-13)
    problem.close()


# -- Taylor: the residual is the energy's derivative, the tangent the residual's ------------
def direction(problem) -> PETSc.Vec:
    """A smooth direction, 0 on every Dirichlet dof (the same on any partition)."""
    fields = {n: fem.Function(s.function_space) for n, s in zip(problem.names, problem.states)}
    fields["displacement"].interpolate(lambda x: np.vstack([x[0] * np.sin(3 * x[1]), np.cos(2 * x[0]) * (x[1] + 1)]))
    fields["lift"].interpolate(lambda x: np.vstack([x[0] * (R0 - x[0]), R0**2 - x[0] ** 2]))
    fields["liquid_pressure"].x.array[:] = 1.0
    for name, f in fields.items():
        f.x.array[problem.constrained(name)] = 0.0
    return problem.vector_from(fields.values())


def taylor_remainders(problem, scale=0.02, halvings=4):
    """|E(x+h d) - E(x) - h F.d| and ||F(x+h d) - F(x) - h J d|| for h = scale / 2^k."""
    energy = fem.form(problem.lagrangian, entity_maps=problem.ctx.entity_maps)
    d = direction(problem)
    J, x_ = problem.jacobian()
    x = x_.copy()
    Jd, F0, F, y = x.duplicate(), x.duplicate(), x.duplicate(), x.duplicate()
    J.mult(d, Jd)
    problem.snes.computeFunction(x, F0)
    problem.functions_from(x, problem.states)
    E0, F0d = global_sum(energy), F0.dot(d)
    first, second = [], []
    for k in range(halvings + 1):
        h = scale / 2**k
        x.copy(y)
        y.axpy(h, d)
        problem.snes.computeFunction(y, F)
        problem.functions_from(y, problem.states)
        first.append(abs(global_sum(energy) - E0 - h * F0d))
        F.axpy(-1.0, F0)
        F.axpy(-h, Jd)
        second.append(F.norm())
    problem.functions_from(x, problem.states)
    for v in (d, x, Jd, F0, F, y):
        v.destroy()
    return np.array(first), np.array(second)


def taylor_off_equilibrium(comm):
    """Taylor remainders at the solution for V = 0.04 with u_s scaled by 1.1 (off the
    equilibrium, so that F(x).d is not 0)."""
    problem, _, _ = build(*rectangle(comm, 8))
    solve(problem, (0.04,))
    problem.states[0].x.array[:] *= 1.1
    remainders = taylor_remainders(problem)
    problem.close()
    return remainders


def test_taylor_rates_of_residual_and_tangent():
    for remainders in taylor_off_equilibrium(MPI.COMM_WORLD):
        rates = np.log2(remainders[:-1] / remainders[1:])
        assert rates == pytest.approx(2.0, abs=0.05), (remainders, rates)


# -- the coupling: the same solution without a submesh ---------------------------------------
def test_single_mesh_formulation_gives_the_same_solution():
    """With w a parent field pinned off Γ the discrete problem is the same: every number agrees."""
    msh, tags = rectangle(MPI.COMM_WORLD, 8)
    problem, lift, _ = build(msh, tags)
    reference, parent_lift, _ = build(msh, tags, single_mesh=True)
    ctx = problem.ctx
    solve(problem)
    solve(reference)
    got, want = observables(problem, lift), observables(reference, parent_lift)
    assert got == pytest.approx(want, rel=1e-12)
    assert got["volume"] == pytest.approx(0.08, rel=1e-12) and got["pressure"] > 0.1
    # the fields themselves: the lifts compared on Γ, in one form over both meshes
    w, wp = problem.states[1], reference.states[1]
    diff = wp - w
    gap = global_sum(fem.form(ctx.kin.surface_integral(ufl.inner(diff, diff), WETTED), entity_maps=ctx.entity_maps))
    assert math.sqrt(gap / got["lift"]) < 1e-12
    assert np.abs(problem.states[0].x.array - reference.states[0].x.array).max() < 1e-12
    problem.close()
    reference.close()


# -- ranks ------------------------------------------------------------------------------------
@functools.cache
def serial_solution() -> dict:
    problem, lift, _ = build(*rectangle(MPI.COMM_SELF, 8), prefix="bcfem_test_mixeddim_self_")
    solve(problem)
    out = observables(problem, lift)
    problem.close()
    return out


def solve_partitioned(comm, partition):
    """(owned, ghost) patch cells of every rank, and the observables at V = 0.08."""
    problem, lift, patch = build(*rectangle(comm, 8, partition))
    imap = patch.mesh.topology.index_map(1)
    cells = comm.allgather((imap.size_local, imap.num_ghosts))
    solve(problem)
    got = observables(problem, lift)
    problem.close()
    return cells, got


PARTITIONS = [None, "ghosted", "split", "split-ghosted", "off-top"]


@pytest.mark.parametrize("partition", PARTITIONS)
def test_ranks_give_the_serial_solution(partition):
    """On 2 ranks: Γ cut between the ranks ("split", with ghost cells of Γ on both sides
    of the cut in "split-ghosted"), or wholly on one ("off-top")."""
    comm = MPI.COMM_WORLD
    patch_cells, got = solve_partitioned(comm, partition)
    cells, ghosts = np.array(patch_cells).T
    assert cells.sum() == 4
    if comm.size > 1 and partition in ("split", "split-ghosted"):
        assert cells.min() > 0
    if comm.size > 1 and partition == "split-ghosted":
        assert ghosts.min() > 0
    if comm.size > 1 and partition == "off-top":
        assert cells.min() == 0
    assert got == pytest.approx(serial_solution(), rel=1e-12)


def test_problem_handles_a_state_on_the_submesh():
    """Problem's linear algebra (global rows, Dirichlet masks, save/restore, vectors) with
    the lift on Γ, and the context's entity maps."""
    comm = MPI.COMM_WORLD
    problem, lift, patch = build(*rectangle(comm, 4))
    ctx = problem.ctx
    assert problem.names == ["displacement", "lift", "liquid_pressure"]
    assert len(ctx.entity_maps) == 1 and ctx.entity_maps[0] is patch.entity_map
    W = ctx.states["lift"].function_space
    owned = W.dofmap.index_map.size_local * W.dofmap.index_map_bs
    # w = 0 at the contact vertex (2 dofs) and w_r = 0 on the axis (1 dof)
    assert comm.allreduce(int(problem.constrained("lift")[:owned].sum())) == 3
    rows = []
    for name, state in zip(problem.names, problem.states):
        imap = state.function_space.dofmap.index_map
        rows.append(problem.global_indices(name)[: imap.size_local * state.function_space.dofmap.index_map_bs])
    rows = np.concatenate(comm.allgather(np.concatenate(rows)))
    assert np.array_equal(np.sort(rows), np.arange(problem.new_vector().getSize()))
    ctx.states["lift"].interpolate(lambda x: np.vstack([x[0], x[0] ** 2]))
    saved = problem.save()
    v = problem.vector_from(problem.states)
    ctx.states["lift"].x.array[:] = 0.0
    problem.functions_from(v, problem.states)
    assert np.array_equal(ctx.states["lift"].x.array, saved[1])
    ctx.states["lift"].x.array[:] = 0.0
    problem.restore(saved)
    assert np.array_equal(ctx.states["lift"].x.array, saved[1])
    with pytest.raises(ValueError, match="entity map"):
        ctx.state_in("stray", patch.space(("Lagrange", 1)))
    problem.close()


if __name__ == "__main__":
    # the numbers of docs/mixed-dimensional.md (also under mpirun -n 2)
    comm = MPI.COMM_WORLD
    for name, r in zip(("energy -> residual", "residual -> tangent"), taylor_off_equilibrium(comm)):
        if comm.rank == 0:
            print(f"{name}: remainders {np.array2string(r, precision=3)}, rates {np.round(np.log2(r[:-1] / r[1:]), 3)}")
    serial = serial_solution()
    for partition in PARTITIONS:
        cells, got = solve_partitioned(comm, partition)
        deviation = max(abs(got[k] / serial[k] - 1) for k in serial)
        if comm.rank == 0:
            print(f"{partition}: patch cells (owned, ghost) per rank {cells}, largest relative deviation "
                  f"from serial {deviation:.1e}, pressure {got['pressure']:.16g} (serial {serial['pressure']:.16g})")
