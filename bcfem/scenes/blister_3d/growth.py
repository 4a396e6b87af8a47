r"""The debond front after the onset: a sharp front that moves in the plane where the release
rate reaches the cost of debonding (Griffith, no healing), at prescribed volumes.

The film is elastic and its reference state unstressed, so the state at a volume depends only
on the debonded region Ω: the path is a sequence of regions, each with its equilibrium, the film
clamped (unstretched) on ∂Ω. At each volume the front is moved until the release rate
(:class:`bcfem.scenes.blister_3d.release.ReleaseRate`) is at most the cost everywhere on it and
equal to it where it moved: the outline's nodes where G exceeds the cost w + α advance along
their normal by (G − w − α)/k, k the front's stiffness -∂G/∂d, a secant estimate updated at each
move (a quasi-Newton step on the front), at most ``cap`` per move. The mesh follows by the
harmonic extension of the outline's motion, so its cells keep their shape; the displacement's
nodal values are the next solve's guess.

The constraint of :class:`bcfem.physics.energies.PressureVolume` spreads its target over the
reference area of the first mesh; on a grown mesh the target is rescaled by that area over the
current one, so that the volume held is the one asked for.
"""

from __future__ import annotations

from mpi4py import MPI

import numpy as np
import ufl
from dolfinx import fem
from dolfinx.fem.petsc import LinearProblem

from bcfem.mpi import global_sum
from bcfem.path.branch import ContinuationError

_SOLVER = {"ksp_type": "preonly", "pc_type": "lu", "pc_factor_mat_solver_type": "mumps"}


class MeshMotion:
    """Moves the mesh's outline nodes by given vectors and its interior by their harmonic
    extension (P1; interpolated into the geometry's own space, curved cells included)."""

    def __init__(self, release, edge_facets):
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
        self.moved.interpolate(extension)
        self.msh.geometry.x[:, :2] += self.moved.x.array.reshape(-1, 2)[self.node_of]


class FrontGrowth:
    """Grow the front from the onset to each of ``volumes`` (see the module's docstring).

    Args:
        ctx: the context; its ``volume_target`` constant is the volume constraint's.
        problem: a problem whose pressure row is the volume constraint (no arc-length row).
        release: the release rate along the outline.
        motion: the mesh's motion.
        size: the element size at the front: a move is at most ``cap`` times it.
        tolerance: the front is in equilibrium when G <= (1 + tolerance)(w + α) on it.
    """

    def __init__(self, ctx, problem, release, motion, size: float, tolerance: float = 2e-3,
                 cap: float = 0.5, max_moves: int = 40):
        kin = ctx.kin
        self.ctx, self.problem, self.release, self.motion = ctx, problem, release, motion
        self.target = ctx.constant("volume_target")
        self.volume = fem.form(kin.integral(kin.volume_density))
        self.area = fem.form(kin.integral(1.0))
        self.reference_area = kin.reference_area
        self.step = cap * size
        self.tolerance = tolerance
        self.max_moves = max_moves
        self.stiffness = 1.0  # -dG/dd in mu_f t0 / R0, first guess: the circle's order
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
        G = cost where it moved (an overshoot is taken back, never behind where it was)."""
        comm = self.release.comm
        cost, tol = self.release.cost, self.tolerance * self.release.cost
        self.solve_to(volume)
        excess = self.release.rates() - cost
        advanced = np.zeros_like(excess)
        for _ in range(self.max_moves):
            moving = advanced > 0
            # too high anywhere, or too low where the front moved in this volume's settling
            error = np.where(moving, np.abs(excess), np.clip(excess, 0.0, None))
            if comm.allreduce(float(error.max(initial=0.0)), op=MPI.MAX) <= tol:
                return
            wanted = np.where(moving | (excess > 0), excess, 0.0) / self.stiffness
            advance = np.clip(wanted, -advanced, self.step)
            share = self.release.share
            normal = share / np.linalg.norm(share, axis=1)[:, None]
            self.motion.move(self.release.nodes, advance[:, None] * normal)
            advanced += advance
            self.moves += 1
            self.solve_to(volume)
            after = self.release.rates() - cost
            # secant: the rate's drop per advance where the front moved
            drop, norm = comm.allreduce(np.array([float(np.dot(excess - after, advance)),
                                                  float(np.dot(advance, advance))]), op=MPI.SUM)
            if norm > 0 and drop > 0:
                self.stiffness = min(max(drop / norm, 0.05), 1e3)
            excess = after
        raise ContinuationError(f"front growth: the front did not settle at V = {volume:.6g} in "
                                f"{self.max_moves} moves (max G - cost = {excess.max(initial=0):.3g})")
