"""Self-contact (bcfem.contact.self_contact): exact derivatives, and two blocks pressed together."""

import math

from mpi4py import MPI

import numpy as np
import pytest
import ufl
from dolfinx import fem
from helpers import exact_nominal_stress

from bcfem.contact.self_contact import WallSelfContact, gap, gap_derivatives
from bcfem.kinematics.solid import AxisymmetricSolid
from bcfem.mpi import global_sum
from bcfem.physics.context import Context
from bcfem.physics.energies import SolidStrain
from bcfem.physics.materials import NearlyIncompressibleNeoHookean
from bcfem.physics.protocols import DiscreteTerm, Term, find_term
from bcfem.solver.problem import Problem

RADIUS, LOWER, SLOT, UPPER = 1.0, 1.0, 0.05, 1.5
SIZES = (0.25, 0.18)  # the two blocks' meshes do not match at the contact
KAPPA, PENALTY = 1e4, 3e2
CONTACT, AXIS, BOTTOM, TOP, OTHER = 10, 11, 12, 13, 14
UPPER_FACE = 15  # the slot's upper face, when tagged apart from the lower one


def test_self_contact_is_a_discrete_term():
    term = WallSelfContact.__new__(WallSelfContact)
    assert isinstance(term, DiscreteTerm) and not isinstance(term, Term)
    assert term.is_discrete and term.name == "self_contact"


def test_gap_derivatives_match_finite_differences():
    rng = np.random.default_rng(1)
    z = rng.normal(size=6)
    grad, hess = gap_derivatives(z[:2], z[2:4], z[4:])

    def g(z):
        return gap(z[None, :2], z[None, 2:4], z[None, 4:])[0][0]

    h = 1e-6
    eye = np.eye(6)
    fd_grad = np.array([(g(z + h * e) - g(z - h * e)) / (2 * h) for e in eye])
    fd_hess = np.array([(gap_derivatives(z[:2] + h * e[:2], z[2:4] + h * e[2:4], z[4:] + h * e[4:])[0]
                         - gap_derivatives(z[:2] - h * e[:2], z[2:4] - h * e[2:4], z[4:] - h * e[4:])[0]) / (2 * h)
                        for e in eye])
    assert np.allclose(grad, fd_grad, atol=1e-8)
    assert np.allclose(hess, fd_hess, atol=1e-7)
    assert np.allclose(hess, hess.T)


def stacked_blocks(comm, split: bool = False):
    """Two cylinders, one above the other with a slot between them; the slot's two faces
    are one self-contact boundary (tagged CONTACT, or CONTACT and UPPER_FACE if ``split``)."""
    import gmsh
    from dolfinx.io import gmsh as gmshio

    if comm.rank == 0:
        gmsh.initialize(interruptible=False)
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.option.setNumber("General.NumThreads", 1)
        occ = gmsh.model.occ
        lower = occ.addRectangle(0, 0, 0, RADIUS, LOWER)
        upper = occ.addRectangle(0, LOWER + SLOT, 0, RADIUS, UPPER)
        occ.synchronize()
        for tag, size in zip((lower, upper), SIZES):
            points = gmsh.model.getBoundary([(2, tag)], recursive=True)
            gmsh.model.mesh.setSize(points, size)
        gmsh.model.addPhysicalGroup(2, [lower, upper], 1)
        groups = {CONTACT: [], AXIS: [], BOTTOM: [], TOP: [], OTHER: [], UPPER_FACE: []}
        for _, curve in gmsh.model.getEntities(1):
            x = gmsh.model.occ.getCenterOfMass(1, curve)
            if abs(x[0]) < 1e-9:
                groups[AXIS].append(curve)
            elif abs(x[1]) < 1e-9:
                groups[BOTTOM].append(curve)
            elif abs(x[1] - (LOWER + SLOT + UPPER)) < 1e-9:
                groups[TOP].append(curve)
            elif abs(x[1] - LOWER - SLOT) < 1e-9:
                groups[UPPER_FACE if split else CONTACT].append(curve)
            elif abs(x[1] - LOWER) < 1e-9:
                groups[CONTACT].append(curve)
            else:
                groups[OTHER].append(curve)
        for tag, curves in groups.items():
            if curves:
                gmsh.model.addPhysicalGroup(1, curves, tag)
        gmsh.model.mesh.generate(2)
    data = gmshio.model_to_mesh(gmsh.model if comm.rank == 0 else None, comm, 0, gdim=2)
    if comm.rank == 0:
        gmsh.finalize()
    return data


def slot_model(comm, material, top_shift: float, split: bool = False):
    """The stacked blocks: (context, self-contact term, terms, Dirichlet conditions: the axis,
    the bottom, and the top moved by ``top_shift`` in z); ``split``: the contact boundary
    given as two tagged parts."""
    data = stacked_blocks(comm, split)
    msh, facets = data.mesh, data.facet_tags
    V = fem.functionspace(msh, ("Lagrange", 2, (2,)))
    u = fem.Function(V, name="displacement")
    ctx = Context(u, AxisymmetricSolid(u, quadrature_degree=4, facet_tags=facets))
    contact = WallSelfContact(facets, (CONTACT, UPPER_FACE) if split else CONTACT, modulus=1.0, penalty=PENALTY)

    def on(sub, tag, value=0.0):
        space, _ = V.sub(sub).collapse()
        g = fem.Function(space)
        g.x.array[:] = value
        return fem.dirichletbc(g, fem.locate_dofs_topological((V.sub(sub), space), 1, facets.find(tag)), V.sub(sub))

    bcs = [on(0, AXIS), on(1, BOTTOM), on(1, TOP, top_shift)]
    return ctx, contact, [SolidStrain(material), contact], bcs


def press(shortening: float, comm=MPI.COMM_WORLD, split: bool = False):
    """The top moves down by SLOT + shortening: the slot closes and both blocks are compressed
    through the contact alone. Returns (nominal stress at the top, stretch of each block,
    the slot's gap, pairs in contact, Newton iterations)."""
    ctx, contact, terms, bcs = slot_model(comm, NearlyIncompressibleNeoHookean(mu=1.0, kappa=KAPPA),
                                          -(SLOT + shortening), split)
    u = ctx.u
    V = u.function_space
    top = LOWER + SLOT + UPPER
    # start from a homogeneous guess with the slot just closed (1e-3 overlap), so that
    # Newton starts in contact
    stretch0 = 1 - (shortening - 1e-3) / (LOWER + UPPER)
    u.interpolate(lambda x: np.vstack([(stretch0**-0.5 - 1) * x[0],
                                       np.where(x[1] < LOWER + SLOT / 2, (stretch0 - 1) * x[1],
                                                top - SLOT - shortening - (top - x[1]) * stretch0 - x[1])]))
    # a stiff penalty needs a line search that minimises along Newton's direction
    with Problem(ctx, terms, bcs, "bcfem_test_self_contact_", {"snes_linesearch_type": "cp"}) as problem:
        assert problem.solve(), problem.reason
        iterations = problem.iterations
        energy = find_term(terms, SolidStrain).energy(ctx)
        w = fem.Function(V)  # 1 on the top, 0 on the contact faces and the lower block
        w.interpolate(lambda x: np.vstack([0 * x[0], np.clip((x[1] - LOWER - SLOT) / UPPER, 0, None)]))
        force = global_sum(fem.form(ufl.derivative(energy, u, w)))
        active = contact.active
        x = contact._positions()
        _, segments, gaps = contact.pairs(x)
        depth = comm.allreduce(float(np.max(-gaps / contact.segment_length[segments], initial=0.0)), op=MPI.MAX)

    def uz_at(z):
        dofs = np.flatnonzero(np.isclose(V.tabulate_dof_coordinates()[:, 1], z))
        local = u.x.array.reshape(-1, 2)[dofs, 1]
        values = comm.allgather(local)
        return float(np.mean(np.concatenate(values)))

    lower_top, upper_bottom = uz_at(LOWER), uz_at(LOWER + SLOT)
    stretch_lower = 1 + lower_top / LOWER
    stretch_upper = (UPPER - (SLOT + shortening) - upper_bottom) / UPPER
    gap_ = SLOT + upper_bottom - lower_top
    return force / (math.pi * RADIUS**2), stretch_lower, stretch_upper, gap_, active, iterations, depth


@pytest.mark.mpi
def test_blocks_pressed_through_the_contact_match_uniaxial_compression():
    """Node-to-segment contact of two non-matching P2 faces is over-constrained: the faces
    take a slight waviness (about 1e-3 of the element size here), so the closed form holds
    to 1e-3 rather than to round-off."""
    stress, lam_lower, lam_upper, gap_, active, iterations, depth = press(0.25)
    stretch = 1 - 0.25 / (LOWER + UPPER)  # no slot left, no penetration
    # both blocks carry the same stress, so they have the same stretch
    assert lam_lower == pytest.approx(lam_upper, abs=3e-4)
    assert lam_upper == pytest.approx(stretch, abs=3e-4)
    # and the top carries the closed-form uniaxial stress (eq. 7.4, nearly incompressible)
    assert stress == pytest.approx(exact_nominal_stress(stretch, KAPPA), rel=2e-3)
    assert active > 0
    # the penalty keeps the faces apart: no node deeper than 1e-2 of a segment
    assert 0 < depth < 1e-2
    assert iterations <= 12


@pytest.mark.mpi
def test_open_slot_has_no_contact():
    # the top moves down 0.03: 0.02 of the slot stays open
    stress, lam_lower, lam_upper, gap_, active, _, depth = press(-0.02)
    assert active == 0 and depth == 0
    assert lam_lower == pytest.approx(1.0, abs=1e-12)
    assert gap_ == pytest.approx(0.02, abs=1e-12)
    assert stress == pytest.approx(0.0, abs=1e-12)


@pytest.mark.mpi
def test_contact_is_rank_count_invariant():
    """On 2 ranks the contact pairs span ranks; the result is the serial one."""
    here = press(0.25)
    alone = press(0.25, MPI.COMM_SELF)
    assert here[4] == alone[4]  # the same pairs in contact
    for a, b in zip(here[:4], alone[:4]):
        assert a == pytest.approx(b, rel=1e-8, abs=1e-11)


@pytest.mark.mpi
def test_a_boundary_of_two_tagged_parts_is_one_boundary():
    """The slot's faces tagged apart and given as a tuple (as a crater's sidewall and
    protuberance are): the same contact, the same answer."""
    one, two = press(0.25), press(0.25, split=True)
    assert two[4] == one[4] > 0
    for a, b in zip(two[:4], one[:4]):
        assert a == pytest.approx(b, rel=1e-12, abs=1e-14)


def boundary(points, depth=0.25):
    """A self-contact term on the polyline ``points`` (one segment between consecutive
    points, the solid on the right), without a mesh: for the geometric checks alone."""
    term = WallSelfContact.__new__(WallSelfContact)
    x = np.asarray(points, dtype=float)
    term.segments = np.column_stack([np.arange(len(x) - 1), np.arange(1, len(x))])
    term.depth = depth
    term._last_search = None
    term._positions = lambda: x
    return term


def test_a_wall_that_does_not_cross_itself_is_admissible():
    # a hairpin whose two legs touch, the tip's node 1e-2 of a segment behind the other leg
    # (the penetration a penalty contact leaves)
    legs = [(0, 0), (1, 0), (2, 0), (2, 0.5), (1, -0.01), (0, 0.5)]
    assert boundary(legs).inadmissible() is None
    assert boundary([(0, 0), (1, 0), (2, 1), (3, 0)]).inadmissible() is None


def test_a_wall_through_itself_is_inadmissible():
    # a hairpin whose tip has passed through the other leg: each crossing's endpoints lie
    # 0.41 and 1 segment lengths behind the other segment, out of the penalty's reach (a
    # quarter of a segment), so nothing pushes them back
    legs = [(0, 0), (1, 0), (2, 0), (2, 0.2), (1, -1), (0, 0.2)]
    message = boundary(legs).inadmissible()
    assert message is not None and "passes through itself" in message
    assert "0.41 segment lengths deep" in message
    # within a deeper window the same state is a contact the penalty holds
    assert boundary(legs, depth=0.75).inadmissible() is None
    # a loop: the wall comes back across itself (Fig. 7.10, alpha = 1, beta = 0.5 before the check)
    loop = [(0, 0), (0, 1), (0, 2), (1, 2), (1, 1.5), (-0.5, 1.5)]
    assert "passes through itself" in boundary(loop).inadmissible()


def spiked(comm):
    """(contact term, problem's state vector x = 0, step y) on the stacked blocks: the step
    x - y pushes one node of the slot's upper face 0.2 down, through the lower face."""
    data = stacked_blocks(comm)
    V = fem.functionspace(data.mesh, ("Lagrange", 2, (2,)))
    u = fem.Function(V, name="displacement")
    ctx = Context(u, AxisymmetricSolid(u, quadrature_degree=4, facet_tags=data.facet_tags))
    contact = WallSelfContact(data.facet_tags, CONTACT, modulus=1.0, penalty=PENALTY)
    problem = Problem(ctx, [SolidStrain(NearlyIncompressibleNeoHookean(mu=1.0, kappa=KAPPA)), contact], [],
                      "bcfem_test_step_bound_")
    X = V.tabulate_dof_coordinates()
    face = np.flatnonzero(np.isclose(X[:, 1], LOWER + SLOT))
    nearest = min(comm.allgather(min(((abs(X[k, 0] - 0.5), tuple(X[k, :2])) for k in face), default=(9.0, ()))))
    spike = fem.Function(V)
    node = np.flatnonzero(np.all(np.isclose(X[:, :2], nearest[1]), axis=1))
    spike.x.array.reshape(-1, 2)[node, 1] = 0.2  # y = -(the displacement of x - y)
    return problem, contact, problem.vector_from([u]), problem.vector_from([spike])


def bounded_step(comm):
    problem, contact, x, y = spiked(comm)
    with problem:
        t = contact.step_bound(x, y)
        start, _ = x.getOwnershipRange()
        local = contact.rows[contact.owned] - start
        here, step = contact._positions(x.array[local]), contact._positions(y.array[local]) - contact.X
        admissible = [contact.inadmissible(here - s * step) is None for s in (t, 2 * t)]
        x.destroy()
        y.destroy()
    return t, admissible


@pytest.mark.mpi
def test_the_step_is_bounded_to_keep_the_wall_admissible():
    t, (at_t, at_twice) = bounded_step(MPI.COMM_WORLD)
    # the full step goes through the wall; the bound is the longest halving that does not
    assert t < 1 and at_t and not at_twice
    # the same on every rank count: every rank sees the whole boundary and the whole step
    assert t == bounded_step(MPI.COMM_SELF)[0]


# -- the assembled penalty: a Taylor test through the problem --------------------------------
OVERLAP, ENERGY_SCALE = 5e-3, 2.5


def overlapping(comm):
    """The stacked blocks with the upper one moved down through the slot by OVERLAP, and
    stretched radially unlike the lower one (0.99 and 1.013), so that no node of one face lies
    at a segment end of the other and a small perturbation keeps every pair. The solid is
    so soft (mu = 1e-6) that the remainders are the contact's. Returns the problem (Dirichlet
    conditions as in :func:`press`, energy_scale 2.5), the contact, the energy (scaled like
    the residual), and a perturbation of the displacement held at zero on Dirichlet dofs."""
    shift = -(SLOT + OVERLAP)
    ctx, contact, terms, bcs = slot_model(comm, NearlyIncompressibleNeoHookean(mu=1e-6, kappa=1e-3), shift)
    u = ctx.u
    V = u.function_space
    problem = Problem(ctx, terms, bcs, "bcfem_test_self_contact_taylor_", energy_scale=ENERGY_SCALE)
    upper = lambda x: x[1] > LOWER + SLOT / 2  # noqa: E731
    u.interpolate(lambda x: np.vstack([np.where(upper(x), 0.013, -0.01) * x[0], np.where(upper(x), shift, 0.0)]))
    contact.begin_solve()  # who faces whom, frozen as in a Newton solve
    du = fem.Function(V)
    du.interpolate(lambda x: np.vstack([0.5 * x[0] * np.cos(3 * x[1]), 0.4 * np.sin(2 * x[0] + x[1])]))
    du.x.array[problem.constrained("displacement")] = 0.0
    pressure = fem.Function(ctx.states["solid_pressure"].function_space)
    dx = problem.vector_from([du, pressure])
    strain_energy = fem.form(problem.lagrangian)

    def energy():
        return (global_sum(strain_energy) + contact.penalty_energy()) / ENERGY_SCALE

    return problem, contact, energy, dx


def contact_taylor(comm):
    from helpers import taylor

    problem, contact, energy, dx = overlapping(comm)
    with problem:
        pairs = lambda: sorted(map(tuple, comm.allgather(  # noqa: E731
            [(p, s) for p, s in zip(*contact.pairs(contact._positions())[:2])])))
        before = pairs()
        result = taylor(problem, energy, dx, eps0=1e-3, observe=pairs)
        # the residual's Dirichlet rows hold x - g = 0: the contact adds nothing there
        start, _ = dx.getOwnershipRange()
        held = problem.global_indices("displacement")[problem.constrained("displacement")]
        owned = held[(held >= start) & (held < start + dx.getLocalSize())] - start
        result["dirichlet_rows"] = comm.allreduce(float(np.max(np.abs(result["residual"][owned]), initial=0.0)),
                                                  op=MPI.MAX)
        result["pairs"], result["active"] = before, contact.active
        dx.destroy()
    return result


@pytest.mark.mpi
def test_assembled_contact_residual_and_tangent_are_derivatives():
    """With pairs in contact, the residual the problem assembles (forms plus the contact's
    free rows, scaled by 1/energy_scale) is the derivative of the scaled energy, and its
    tangent that of the residual: remainders O(e^2). Under mpirun the pairs span ranks,
    and the numbers are those of one rank."""
    from helpers import assert_second_order

    result = contact_taylor(MPI.COMM_WORLD)
    assert result["active"] > 10
    assert all(seen == result["pairs"] for seen in result["seen"])  # no pair switched on or off
    # the contact dominates: its energy is most of the total
    assert result["energy"] > 1e-4
    assert_second_order(result)
    assert result["dirichlet_rows"] < 1e-12
    if MPI.COMM_WORLD.size > 1:
        alone = contact_taylor(MPI.COMM_SELF)
        assert alone["active"] == result["active"]
        for key in ("energy", "dE", "F", "Jdx"):
            assert result[key] == pytest.approx(alone[key], rel=1e-9), key


# -- the bucketed search finds what a test of every combination finds ------------------------
def every_pair(term, x):
    """Reference for ``pairs``: the gap of every (owned node, segment) combination."""
    seg = term.segments
    a, b = x[seg[:, 0]], x[seg[:, 1]]
    length = np.linalg.norm(b - a, axis=1)
    nodes = term.owned
    facing = (term._facing(x) if term.facing is None else term.facing).reshape(-1)
    P = np.repeat(nodes, len(seg))
    S = np.tile(np.arange(len(seg)), nodes.size)
    g, xi = gap(x[P], a[S], b[S])
    hit = ((g <= 0) & (g > -term.depth * length[S]) & (xi >= term.xi_min[S]) & (xi < term.xi_max[S]) & facing
           & ~term.excluded[P, S] & (term.weight[P] > 0))
    return P[hit], S[hit], g[hit]


def every_crossing(term, x):
    """Reference for ``inadmissible``: every pair of segments that share no node; returns
    (the message's depth and place, or None) and the number of crossings."""
    seg = term.segments
    i, j = np.triu_indices(len(seg), k=1)
    apart = np.all(seg[i][:, :, None] != seg[j][:, None, :], axis=(1, 2))
    i, j = i[apart], j[apart]
    p, q, a, b = x[seg[i, 0]], x[seg[i, 1]], x[seg[j, 0]], x[seg[j, 1]]
    g_p, g_q, g_a, g_b = gap(p, a, b)[0], gap(q, a, b)[0], gap(a, p, q)[0], gap(b, p, q)[0]
    cross = (g_p * g_q < 0) & (g_a * g_b < 0)
    depth = np.where(cross, np.minimum(-np.minimum(g_a, g_b) / np.linalg.norm(q - p, axis=1),
                                       -np.minimum(g_p, g_q) / np.linalg.norm(b - a, axis=1)), 0.0)
    worst = int(np.argmax(depth)) if depth.size else 0
    if not cross.any() or depth[worst] <= term.depth:
        return None, int(cross.sum())
    r, z = 0.5 * (p[worst] + q[worst])
    return f"near (r, z) = ({r:.4g}, {z:.4g}), {depth[worst]:.2f} segment lengths deep", int(cross.sum())


def assert_same_search(term, x):
    """``pairs`` and ``inadmissible`` at x are those of the references, to the bit and in
    the same order; returns (contacts, crossings) for the caller to check it tested some."""
    found, reference = term.pairs(x), every_pair(term, x)
    for mine, theirs in zip(found, reference):
        assert mine.dtype == theirs.dtype and np.array_equal(mine, theirs)
    message, crossings = every_crossing(term, x)
    verdict = term.inadmissible(x)
    assert (verdict is None) == (message is None), (verdict, message)
    assert message is None or message in verdict
    return len(reference[0]), crossings


def chain(points, depth=0.25, owned=None, zero_weight=()):
    """A self-contact term on one polyline (solid on the right), with every attribute
    ``pairs`` reads set as :meth:`WallSelfContact.bind` sets them for a chain."""
    term = boundary(points, depth)
    n, m = len(term._positions()), len(term.segments)
    term.X = term._positions()
    term.owned = np.arange(n) if owned is None else np.asarray(owned)
    term.weight = np.ones(n)
    term.weight[list(zero_weight)] = 0.0
    term.xi_min = np.where(np.arange(m) == 0, -0.5, 0.0)  # the free ends reach half a segment
    term.xi_max = np.where(np.arange(m) == m - 1, 1.5, 1.0)
    term.excluded = np.zeros((n, m), dtype=bool)
    for s in range(m):
        term.excluded[max(s - 1, 0):s + 3, s] = True  # the segment's nodes and their neighbours
    term.facing = None
    return term


def folded(spacing, layers=5, per_layer=12, tilt=0.5):
    """An accordion: ``layers`` straight runs of unit segments ``spacing`` apart, joined by
    hairpins. The third and fourth runs are shifted by half a segment, so that nodes fall at
    the ends (xi = 0, 1) and at the middle of the segments of the next run; the fourth is
    tilted by ``tilt``, so that it passes through its neighbours (a fold pressed through
    itself). Binary fractions: gaps of exactly 0 and exactly -``spacing`` occur."""
    points = []
    for k in range(layers):
        r = np.arange(per_layer + 1) + 0.5 * (k // 2 % 2)
        z = -spacing * k + (tilt * (r - per_layer / 2) if k == 3 else 0.0 * r)
        run = np.column_stack([r, z]) if k % 2 == 0 else np.column_stack([r, z])[::-1]
        points += list(run)
        direction = 1.0 if k % 2 == 0 else -1.0
        points.append((run[-1, 0] + 0.5 * direction, run[-1, 1] - spacing / 2))  # the hairpin
    return np.array(points[:-1])


def test_search_finds_every_pair_on_random_polylines():
    rng = np.random.default_rng(26)
    contacts = crossings = vetoed = 0
    for trial in range(40):
        # a random walk crosses and overlaps itself at every scale of segment length
        n = int(rng.integers(2, 150))
        x = np.cumsum(rng.normal(size=(n, 2)) * rng.uniform(0.05, 1.0, size=(n, 1)), axis=0)
        owned = np.sort(rng.choice(n, size=max(1, n // 2), replace=False)) if trial % 2 else None
        term = chain(x, depth=float(rng.uniform(0.05, 0.95)), owned=owned,
                     zero_weight=rng.choice(n, size=n // 5, replace=False))
        if trial % 3 == 0:  # facing frozen at another state, as within a Newton solve
            term.facing = rng.random((len(term.owned), len(term.segments))) < 0.5
        found = assert_same_search(term, x)
        contacts, crossings = contacts + found[0], crossings + found[1]
        vetoed += term.inadmissible(x) is not None
    assert contacts > 100 and crossings > 100 and 0 < vetoed < 40


@pytest.mark.parametrize("depth", [0.25, 0.5])
@pytest.mark.parametrize("spacing", [0.0, 0.1, 0.25, 0.5])
def test_search_finds_every_pair_on_folds(depth, spacing):
    # spacing 0 puts nodes on other segments (g = 0), spacing = depth exactly at the far
    # edge of their windows (g = -depth L)
    x = folded(spacing)
    axis = np.flatnonzero(x[:, 0] == 0.5)  # weightless nodes, as those on the axis
    term = chain(x, depth=depth, zero_weight=axis)
    contacts, crossings = assert_same_search(term, x)
    # at spacing 0.25 the tilted run's nodes land exactly on its neighbours: no crossing
    assert contacts > 0 and (crossings > 0) == (spacing != 0.25)
    # the tilted run passes deeper than the window through its neighbours
    assert (term.inadmissible(x) is None) == (spacing != 0.1 or depth != 0.25)
    # rotated and translated off the grid, and in a large coordinate offset
    c, s = math.cos(0.3), math.sin(0.3)
    for y in (x @ np.array([[c, s], [-s, c]]) + (3.0, -7.0), x + 1e4):
        assert_same_search(chain(y, depth=depth, zero_weight=axis), y)


def test_search_skips_what_is_not_finite():
    # a diverged Newton iterate: no pair involves a node that is not finite
    x = folded(0.1)
    term = chain(x)
    with np.errstate(invalid="ignore"):
        for bad in (np.nan, np.inf):
            y = x.copy()
            y[[3, 40]] = bad
            assert_same_search(term, y)
        assert all(len(a) == 0 for a in term.pairs(np.full_like(x, np.nan)))


def search_on_the_slot(comm):
    """``pairs`` and ``inadmissible`` of the slot's faces, bound on the mesh (pairs across
    ranks under mpirun), against the references: in contact, in random perturbations of
    it, and with the upper face pushed through the lower one in a wave (a fold)."""
    problem, contact, _, dx = overlapping(comm)
    rng = np.random.default_rng(7 + comm.rank)
    with problem:
        x0 = contact._positions()
        L = float(np.median(contact.segment_length))
        contacts = assert_same_search(contact, x0)[0]
        upper = contact.X[:, 1] > LOWER + SLOT / 2
        for scale in (0.01, 0.1, 0.5):
            noise = comm.bcast(rng.normal(size=x0.shape) * scale * L, root=0)
            contacts += assert_same_search(contact, x0 + noise)[0]
        for amplitude in (0.1, 0.5, 2.0):
            x = x0.copy()
            x[upper, 1] -= amplitude * L * (1 + np.sin(9 * contact.X[upper, 0]))
            contacts += assert_same_search(contact, x)[0]  # who faces whom frozen at x0
            contact.facing = None  # and as at x
            contacts += assert_same_search(contact, x)[0]
            contact.begin_solve()
        dx.destroy()
    return comm.allreduce(contacts, op=MPI.SUM)


@pytest.mark.mpi
def test_search_finds_every_pair_on_the_slot():
    assert search_on_the_slot(MPI.COMM_WORLD) > 100


def test_a_bonded_pair_acts_whatever_its_gap_and_is_never_counted_twice():
    """WallSelfContact.bond (non-separable contact): a bonded pair is in the pairs with its
    signed gap wherever it is, and a bonded pair the search finds anyway appears once."""
    from bcfem.contact.gap import gap

    apart = folded(0.5, tilt=0.0)  # runs 0.5 apart: nothing within a quarter segment
    term = chain(apart)
    assert term.pairs(apart)[0].size == 0
    first = term.segments[:12]  # the first run's segments
    node = 20  # a node of the second run, above the first
    g, xi = gap(np.repeat(apart[None, node], len(first), axis=0), apart[first[:, 0]], apart[first[:, 1]])
    segment = int(np.flatnonzero((xi >= 0) & (xi < 1))[0])
    term.bond([node], [segment])
    P, S, gaps = term.pairs(apart)
    assert list(P) == [node] and list(S) == [segment]
    # beyond the one-sided search's window (a quarter segment), it still acts
    assert gaps[0] == pytest.approx(g[segment]) and abs(gaps[0]) > term.depth

    touching = folded(0.1)
    term = chain(touching)
    P, S, gaps = term.pairs(touching)
    assert P.size > 0
    term.bond(P[:1], S[:1])
    again = term.pairs(touching)
    assert all(np.array_equal(a, b) for a, b in zip(again, (P, S, gaps)))
