"""The field split selected by PETSc options alone: its splits come from the states' spaces, its
near-nullspace is the elastic block's kernel, and Newton with it (a Krylov method on the reduced
system of the contact inequality, the split on the full-size one, its set-up kept while it
serves) reaches the direct solver's state, on 1 and 2 ranks."""

from contextlib import contextmanager

from mpi4py import MPI
from petsc4py import PETSc

import numpy as np
import pytest
import ufl
from dolfinx import fem, mesh

from bcfem import Context
from bcfem.contact.plate_bounds import plate_bounds
from bcfem.kinematics.solid_3d import Solid3D
from bcfem.physics.bcs import component, where
from bcfem.physics.energies import SolidStrain
from bcfem.physics.materials import NearlyIncompressibleNeoHookean
from bcfem.solver.problem import Problem

PREFIX = "bcfem_test_fieldsplit_"
#: the options a user gives (the Schur complement of a u-p split, multigrid on u)
SPLIT = {"ksp_type": "fgmres", "ksp_rtol": 1e-12, "pc_type": "fieldsplit", "pc_fieldsplit_type": "schur",
         "pc_fieldsplit_schur_fact_type": "lower", "pc_fieldsplit_schur_precondition": "selfp",
         "fieldsplit_u_ksp_type": "preonly", "fieldsplit_u_pc_type": "gamg",
         "fieldsplit_p_ksp_type": "preonly", "fieldsplit_p_pc_type": "jacobi"}


@contextmanager
def user_options(values: dict):
    """``values`` in PETSc's database under :data:`PREFIX`, as the command line puts them."""
    opts = PETSc.Options()
    for key, value in values.items():
        opts.setValue(PREFIX + key, value)
    try:
        yield
    finally:
        for key in values:
            opts.delValue(PREFIX + key)


def block(comm, tilt: float = 0.0):
    """A nearly incompressible Taylor-Hood cube (mu = 1, kappa = 1e3) with a global lateral strain
    e (u = ũ + (e x, 0, 0), ũ_x = 0 on x = 0 and 1, as the crater cell's sides), ũ_y = 0 on y = 0,
    the top pressed down by 0.1 and tilted by ``tilt`` along x; the bottom on the plate z = 0 as
    bounds. Returns (context, terms, bcs, bottom dofs)."""
    msh = mesh.create_box(comm, [[0, 0, 0], [1, 1, 1]], [2, 2, 2], mesh.CellType.tetrahedron)
    V = fem.functionspace(msh, ("Lagrange", 2, (3,)))
    ctx = Context(fem.Function(V, name="displacement"))
    strain = ctx.real_state("lateral_strain")
    x = ufl.SpatialCoordinate(msh)
    ctx.kin = Solid3D(ctx.u, quadrature_degree=4, lift=ufl.as_vector([strain * x[0], 0, 0]))
    top = fem.Function(V.sub(2).collapse()[0])
    top.interpolate(lambda x: -0.1 + tilt * x[0])
    bcs = [component(V, 0, where(V, lambda x: np.isclose(x[0], 0) | np.isclose(x[0], 1))),
           component(V, 1, where(V, lambda x: np.isclose(x[1], 0))),
           component(V, 2, where(V, lambda x: np.isclose(x[2], 1)), top)]
    bottom = fem.locate_dofs_topological(V, 2, where(V, lambda x: np.isclose(x[2], 0)))
    return ctx, [SolidStrain(NearlyIncompressibleNeoHookean(mu=1.0, kappa=1e3))], bcs, 3 * bottom + 2


def pressed(comm, split: bool, scene_default: bool = False) -> dict:
    """The block pressed and tilted so that part of its bottom lifts off the plate: its states'
    global measures. The split's options are the user's, or the scene's defaults."""
    ctx, terms, bcs, bottom = block(comm, tilt=0.15)
    scene = {"snes_type": "vinewtonrsls", **(SPLIT if split and scene_default else {})}
    with user_options(SPLIT if split and not scene_default else {}), \
            Problem(ctx, terms, bcs, PREFIX, scene) as problem:
        plate_bounds(problem, bottom, np.zeros(bottom.size))
        assert problem.solve(), problem.failure
        pc = problem.snes.getKSP().getPC()
        inner = pc.getPythonContext().ksp.getPC()
        u_pc = inner.getFieldSplitSubKSP()[0].getPC().getType() if inner.getType() == "fieldsplit" else None
        held = comm.allreduce(problem.held_rows().size)
        refresh = pc.getPythonContext().refresh
        set_ups = refresh.done if refresh is not None else problem.snes.getIterationNumber()
        u, p = ctx.u, ctx.states["solid_pressure"]

        def total(form):
            return comm.allreduce(fem.assemble_scalar(fem.form(form)), op=MPI.SUM)

        dx = ufl.dx(domain=ctx.mesh)
        return {"inner": inner.getType(), "u_pc": u_pc, "held": held, "set_ups": set_ups,
                "newton_iterations": problem.snes.getIterationNumber(),
                "lateral_strain": float(ctx.states["lateral_strain"].x.array[0]),
                "pressure": total(p * dx), "u_z": total(u[2] * dx), "u_x": total(u[0] ** 2 * dx)}


def test_the_splits_follow_the_spaces():
    """u holds the displacement in blocks of 3; p the mixed pressure and the global strain."""
    ctx, terms, bcs, _ = block(MPI.COMM_WORLD)
    with user_options(SPLIT), Problem(ctx, terms, bcs, PREFIX) as problem:
        split = problem.field_split
        assert split.names == {"u": ["displacement"], "p": ["lateral_strain", "solid_pressure"]}
        sizes = {name: index_set.getSize() for name, index_set in split.index_sets.items()}
        assert sizes["u"] == problem.global_size(["displacement"])
        assert sizes["p"] == problem.global_size(["solid_pressure", "lateral_strain"])
        assert split.index_sets["u"].getBlockSize() == 3


def test_rigid_body_modes_are_the_kernel_of_the_elastic_block():
    """At rest (no stress, so no geometric stiffness) the displacement block annihilates the six
    rigid-body motions, and resists a stretch with its closed-form energy."""
    ctx, terms, _, _ = block(MPI.COMM_WORLD)
    with user_options(SPLIT), Problem(ctx, terms, [], PREFIX) as problem:
        A, _ = problem.jacobian()
        u_rows = problem.field_split.index_sets["u"]
        Auu = A.createSubMatrix(u_rows, u_rows)
        modes = problem.field_split.near_nullspace.getVecs()
        assert len(modes) == 6
        scale = Auu.norm(PETSc.NormType.FROBENIUS)
        y = modes[0].duplicate()
        for v in modes:
            assert v.norm() == pytest.approx(1.0)
            Auu.mult(v, y)
            assert y.norm() < 1e-12 * scale
        # a stretch w = (x, 0, 0) is resisted: wᵀAw = μ ∫ |∇w|² + tr(∇w ∇w) dV = 2 μ V = 2
        stretch = fem.Function(ctx.u.function_space)
        stretch.interpolate(lambda x: np.vstack([x[0], 0 * x[0], 0 * x[0]]))
        owned = ctx.u.function_space.dofmap.index_map.size_local * 3
        w = y.duplicate()
        w.array[:] = stretch.x.array[:owned]
        Auu.mult(w, y)
        assert w.dot(y) == pytest.approx(2.0, rel=1e-12)
        w.destroy()
        y.destroy()
        Auu.destroy()


@pytest.mark.mpi
def test_the_split_gives_the_direct_answer():
    """Newton with the split reaches MUMPS's state on a partly held contact set, and 2 ranks the
    serial one, to the Krylov tolerance."""
    direct = pressed(MPI.COMM_SELF, split=False)
    assert direct["inner"] == "cholesky" and direct["held"] > 0
    for comm in (MPI.COMM_SELF,) if MPI.COMM_WORLD.size == 1 else (MPI.COMM_SELF, MPI.COMM_WORLD):
        result = pressed(comm, split=True)
        assert result["inner"] == "fieldsplit" and result["u_pc"] == "gamg" and result["held"] == direct["held"]
        # the split's set-up is kept across Newton iterations: the answer is the same
        assert 1 <= result["set_ups"] < result["newton_iterations"]
        for key in ("lateral_strain", "pressure", "u_z", "u_x"):
            assert result[key] == pytest.approx(direct[key], rel=1e-8), key


@pytest.mark.mpi
def test_a_scenes_default_split_works_and_leaves_no_options():
    """The split's options given as a scene's defaults reach the splits, which read them at set-up,
    and leave PETSc's database as it was."""
    before = PETSc.Options().getAll()
    direct = pressed(MPI.COMM_WORLD, split=False)
    result = pressed(MPI.COMM_WORLD, split=True, scene_default=True)
    assert result["inner"] == "fieldsplit" and result["u_pc"] == "gamg"
    assert result["lateral_strain"] == pytest.approx(direct["lateral_strain"], rel=1e-8)
    assert PETSc.Options().getAll() == before
