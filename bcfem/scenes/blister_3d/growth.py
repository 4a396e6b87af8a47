r"""The debond front after the onset: a sharp front that moves in the plane where the release
rate reaches the cost of debonding (Griffith, no healing), at prescribed volumes.

The film is elastic and its reference state unstressed, so the state at a volume depends only
on the debonded region Ω: the path is a sequence of regions, each with its equilibrium, the film
clamped (unstretched) on ∂Ω. At each volume the front is moved until the release rate
(:class:`bcfem.scenes.blister_3d.release.ReleaseRate`) is at most the cost everywhere on it and
equal to it where it moved: the outline's nodes where G exceeds the cost w + α advance along
their normal by a quasi-Newton step on the front (:meth:`FrontGrowth.settle`), at most ``cap``
element sizes per move. The mesh follows by the
harmonic extension of the outline's motion, so its cells keep their shape; the displacement's
nodal values are the next solve's guess.

The constraint of :class:`bcfem.physics.energies.PressureVolume` spreads its target over the
reference area of the first mesh; on a grown mesh the target is rescaled by that area over the
current one, so that the volume held is the one asked for.
"""

from __future__ import annotations

import numpy as np
import ufl
from dolfinx import fem
from dolfinx.fem.petsc import LinearProblem

from bcfem.mpi import global_sum
from bcfem.path.branch import ContinuationError

_SOLVER = {"ksp_type": "preonly", "pc_type": "lu", "pc_factor_mat_solver_type": "mumps"}


class MeshMotion:
    """Moves the mesh's outline nodes by given vectors and its interior by their harmonic
    extension (P1; interpolated into the geometry's own space, curved cells included), then
    calls ``moved`` (a term's fields tied to the substrate; a ValueError stops the growth)."""

    def __init__(self, release, edge_facets, moved=None):
        self.moved_hook = moved  # called after each move: fields tied to the substrate, not the mesh
        space = release.space
        msh = space.mesh
        self.msh = msh
        self.boundary = fem.Function(space)
        dofs = fem.locate_dofs_topological(space, msh.topology.dim - 1, edge_facets)
        bc = fem.dirichletbc(self.boundary, dofs)
        trial, test = ufl.TrialFunction(space), ufl.TestFunction(space)
        zero = fem.Constant(msh, np.zeros(2))
        laplace = ufl.inner(ufl.grad(trial), ufl.grad(test)) * ufl.dx
        self.problem = LinearProblem(laplace, ufl.inner(zero, test) * ufl.dx, bcs=[bc],
                                     petsc_options_prefix="bcfem_blister_3d_mesh_motion_",
                                     petsc_options=_SOLVER)
        self.geometry_space = fem.functionspace(msh, msh.ufl_domain().ufl_coordinate_element())
        self.moved = fem.Function(self.geometry_space)
        node_of = np.empty(msh.geometry.x.shape[0], dtype=np.int64)
        node_of[msh.geometry.dofmaps[0].ravel()] = self.geometry_space.dofmap.list.ravel()
        self.node_of = node_of

    def move(self, nodes, vectors) -> None:
        """Move this rank's owned outline ``nodes`` (of the release's P1 space) by ``vectors``."""
        values = self.boundary.x.array.reshape(-1, 2)
        values[:] = 0.0
        values[nodes] = vectors
        self.boundary.x.scatter_forward()
        extension = self.problem.solve()
        assert isinstance(extension, fem.Function), "one unknown"
        self.moved.interpolate(extension)
        shift = self.moved.x.array.reshape(-1, 2)[self.node_of]
        self.msh.geometry.x[:, :2] += shift
        if self.moved_hook is not None:
            try:
                self.moved_hook()
            except ValueError as err:  # back to where the hook held
                self.msh.geometry.x[:, :2] -= shift
                self.moved_hook()
                raise ContinuationError(f"front growth: {err}") from None


def _chain(points: np.ndarray):
    """The outline's nodes as a closed chain ordered by polar angle about the origin (the front
    is star-shaped about the initial centroid): (order, W the lumped lengths, H the stiffness
    of the chain's half Laplacian, W^1/2 (W^-1/2 A W^-1/2)^1/2 W^1/2 with A the chain's
    Laplacian, so that a front wave of wavenumber q costs ~ q, as a membrane's edge does)."""
    order = np.argsort(np.arctan2(points[:, 1], points[:, 0]))
    p = points[order]
    gaps = np.linalg.norm(np.roll(p, -1, axis=0) - p, axis=1)  # node i to i + 1
    n = len(p)
    lumped = 0.5 * (gaps + np.roll(gaps, 1))
    A = np.zeros((n, n))
    for i in range(n):
        j = (i + 1) % n
        A[i, i] += 1 / gaps[i]
        A[j, j] += 1 / gaps[i]
        A[i, j] -= 1 / gaps[i]
        A[j, i] -= 1 / gaps[i]
    root = 1 / np.sqrt(lumped)
    values, vectors = np.linalg.eigh(root[:, None] * A * root[None, :])
    half = (vectors * np.sqrt(np.clip(values, 0.0, None))) @ vectors.T
    return order, lumped, np.sqrt(lumped)[:, None] * half * np.sqrt(lumped)[None, :]


class FrontGrowth:
    """Grow the front from the onset to each of ``volumes`` (see the module's docstring).

    Args:
        ctx: the context; its ``volume_target`` constant is the volume constraint's.
        problem: a problem whose pressure row is the volume constraint (no arc-length row).
        release: the release rate along the outline.
        motion: the mesh's motion.
        size: the element size at the front: a move is at most ``cap`` times it.
        tolerance: the front is in equilibrium when G <= (1 + tolerance)(w + α) on it (and
            G >= (1 - tolerance)(w + α) where it moved).
        accepted: after ``max_moves``, a front within this (relative) is kept, its residual
            reported in the rows (``front_residual``): on a coarse mesh the rate's response to a
            move is noisy at the 1e-4 level.
    """

    def __init__(self, ctx, problem, release, motion, size: float, tolerance: float = 1e-4,
                 cap: float = 0.5, max_moves: int = 40, accepted: float = 1e-3):
        kin = ctx.kin
        self.ctx, self.problem, self.release, self.motion = ctx, problem, release, motion
        self.target = ctx.constant("volume_target")
        self.volume = fem.form(kin.integral(kin.volume_density))
        self.area = fem.form(kin.integral(1.0))
        self.reference_area = kin.reference_area
        self.step = cap * size
        self.tolerance = tolerance
        self.max_moves = max_moves
        self.accepted = accepted
        self.residual = 0.0
        self.stiffness = 1.0  # k0 = -dG/dd of a uniform advance, in mu_f t0 / R0: the circle's order
        self.wave = 1.0  # b: a front wave of wavenumber q costs k0 + b q
        self.moves = 0

    def _hold(self, volume: float) -> None:
        self.target.value = volume * self.reference_area / global_sum(self.area)

    def solve_to(self, volume: float) -> None:
        """Equilibrium at ``volume`` on the current front, by sub-steps from the current volume."""
        current = global_sum(self.volume)
        step = volume - current
        while True:
            trial = volume if abs(step) >= abs(volume - current) else current + step
            saved = self.problem.save()
            self._hold(trial)
            if self.problem.solve():
                current = trial
                if trial == volume:
                    return
                step *= 1.5
            else:
                self.problem.restore(saved)
                step *= 0.5
                if abs(step) < 1e-8 * max(1.0, abs(volume)):
                    raise ContinuationError(f"front growth: no equilibrium beyond V = {current:.6g} towards "
                                            f"{volume:.6g} ({self.problem.failure})")

    def settle(self, volume: float) -> None:
        """Move the front until it is in equilibrium at ``volume``: G <= cost where it stayed,
        G = cost where it moved (an overshoot is taken back, never behind where it was).

        The move solves (k0 W + b H) d = W (G - cost) on the nodes that may move (a
        quasi-Newton step: a uniform advance costs k0 per length, a wave of wavenumber q about
        k0 + b q, H of :func:`_chain`), k0 and b fitted to the last move's response."""
        comm = self.release.comm
        cost = self.release.cost
        self.solve_to(volume)
        local = self.release.excess()
        counts = comm.allgather(len(local))
        offset = sum(counts[: comm.rank])
        mine = slice(offset, offset + len(local))
        order, lumped, half = _chain(np.vstack(comm.allgather(self.release.points)))
        excess = np.concatenate(comm.allgather(local))[order]
        advanced = np.zeros_like(excess)
        for _ in range(self.max_moves):
            moving = advanced > 0
            # too high anywhere, or too low where the front moved in this volume's settling
            self.residual = np.where(moving, np.abs(excess), np.clip(excess, 0.0, None)).max(initial=0.0) / cost
            if self.residual <= self.tolerance:
                return
            free = moving | (excess > 0)
            K = self.stiffness * np.diag(lumped) + self.wave * half
            advance = np.zeros_like(excess)
            advance[free] = np.linalg.solve(K[np.ix_(free, free)], lumped[free] * excess[free])
            advance = np.clip(advance, -advanced, self.step)
            moved = np.empty_like(advance)
            moved[order] = advance  # back to the gathered (rank) order
            share = self.release.share
            normal = share / np.linalg.norm(share, axis=1)[:, None]
            self.motion.move(self.release.nodes, moved[mine][:, None] * normal)
            advanced += advance
            self.moves += 1
            self.solve_to(volume)
            after = np.concatenate(comm.allgather(self.release.excess()))[order]
            self._fit(lumped * (excess - after), lumped * advance, half @ advance)
            excess = after
        self.residual = np.where(advanced > 0, np.abs(excess), np.clip(excess, 0.0, None)).max(initial=0.0) / cost
        if self.residual > self.accepted:
            raise ContinuationError(f"front growth: the front did not settle at V = {volume:.6g} in "
                                    f"{self.max_moves} moves (max |G - cost| / cost = {self.residual:.3g})")

    def _fit(self, response, uniform, wave) -> None:
        """k0, b by least squares of response = k0 uniform + b wave (each kept within bounds;
        b alone is not seen by a uniform move, k0 alone not by a pure wave)."""
        M = np.array([[uniform @ uniform, uniform @ wave], [uniform @ wave, wave @ wave]])
        rhs = np.array([uniform @ response, wave @ response])
        if np.linalg.cond(M) < 1e8:
            k0, b = np.linalg.solve(M, rhs)
        elif uniform @ uniform >= wave @ wave:
            k0, b = (rhs[0] - self.wave * M[0, 1]) / M[0, 0], self.wave
        else:
            k0, b = self.stiffness, (rhs[1] - self.stiffness * M[0, 1]) / M[1, 1]
        # a move's response is noisy where the mesh is coarse: each fit changes k0 and b by at
        # most a factor 2 (and keeps them within physical bounds)
        self.stiffness = min(max(k0, 0.5 * self.stiffness, 0.05), 2 * self.stiffness, 1e3)
        self.wave = min(max(b, 0.5 * self.wave, 0.1), 2 * self.wave, 1e3)
