r"""The splits of PETSc's ``fieldsplit`` preconditioner, from the states' function spaces.

PETSc options select a field split (``-<prefix>pc_type fieldsplit``) but cannot name its
fields in dolfinx's monolithic matrix, and algebraic multigrid on an elastic block needs the
rigid-body motions as its near-nullspace. Both follow from the states' spaces, with no
physics named:

- ``u``: the vector fields on the mesh (value size = its dimension; the displacement), in
  blocks of that size, with the rigid-body motions of their nodes as the near-nullspace;
- ``p``: every other state: the scalar fields on the mesh (a mixed pressure, whose block is
  -M/κ, not zero, so that PETSc's ``pc_fieldsplit_detect_saddle_point`` finds no split) and
  the global unknowns on the real element (a lateral strain, a cavity pressure).

The globals go with ``p``: in ``u`` their one or two dense rows would break the block size
that GAMG aggregates nodes by, and a third split would rule out the Schur factorisation,
which PETSc allows for two splits only. In ``p`` they enter the Schur complement, whose
preconditioner (``selfp``: C - B diag(A)^-1 Bᵀ) keeps their dense rows, and whose solve
(a Krylov method by options) handles them exactly.

Under ``vinewtonrsls`` the Newton step solves the system reduced to the inactive set. PETSc
(3.25) would restrict the splits to it, but resets the PC first when the set changes, and the
index sets given in code are gone by then ("must have at least two fields, not 0"). Here the
user's Krylov method solves the reduced system, and its preconditioner applies the split to the
full-size system with the held rows and columns set to the identity
(:class:`bcfem.solver.reduced_lu.ReducedLU`), on which the index sets and the near-nullspace
stay valid for every active set.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from petsc4py import PETSc

import numpy as np

if TYPE_CHECKING:
    from bcfem.solver.algebra import ConvergedAlgebra

#: the option value that selects the split
TYPE = "fieldsplit"

#: the split of a nearly incompressible Taylor–Hood solid that bcfem chooses for the user
#: (docs/three-dimensional.md): FGMRES on the Schur factorisation, GAMG on u (its set-up kept
#: across Newton steps while it serves: :class:`bcfem.solver.reduced_lu.Refresh`), Jacobi
#: on selfp
SCHUR_GAMG = {
    "ksp_type": "fgmres", "ksp_rtol": 1e-8, "pc_type": TYPE, "pc_fieldsplit_type": "schur",
    "pc_fieldsplit_schur_fact_type": "lower", "pc_fieldsplit_schur_precondition": "selfp",
    "fieldsplit_u_ksp_type": "preonly", "fieldsplit_u_pc_type": "gamg", "fieldsplit_u_pc_gamg_threshold": 0.05,
    "fieldsplit_p_ksp_type": "preonly", "fieldsplit_p_pc_type": "jacobi"}

#: displacement dofs above which :data:`SCHUR_GAMG` is faster than MUMPS's LDLᵀ for a
#: crater cell's cycle (both about 80 s at 4.2e4 unknowns on one core: docs/three-dimensional.md)
SPLIT_ABOVE = 40_000


def split_names(problem: ConvergedAlgebra) -> dict[str, list[str]]:
    """The states of each split (``u``, ``p``), by their function spaces (see the module)."""
    gdim = problem.ctx.mesh.geometry.dim
    vector = [n for n, s in zip(problem.names, problem.states)
              if s.function_space.mesh is problem.ctx.mesh and not s.function_space.ufl_element().is_real
              and s.function_space.dofmap.index_map_bs == gdim]
    return {"u": vector, "p": [n for n in problem.names if n not in vector]}


def owned_rows(problem: ConvergedAlgebra, name: str) -> np.ndarray:
    """The global rows of the dofs of state ``name`` this rank owns, in dof order."""
    space = problem.state(name).function_space
    owned = space.dofmap.index_map.size_local * space.dofmap.index_map_bs
    return problem.global_indices(name)[:owned]


def rigid_body_modes(problem: ConvergedAlgebra, names: list[str], rows: np.ndarray) -> PETSc.NullSpace:
    """The translations and rotations of the vector states ``names`` (zero on any other row of
    the split ``rows``), orthonormalised: GAMG's near-nullspace of an elastic block."""
    gdim = problem.ctx.mesh.geometry.dim
    count = 3 if gdim == 2 else 6
    modes = np.zeros((count, rows.size))
    for name in names:
        space = problem.state(name).function_space
        nodes = space.dofmap.index_map.size_local
        x = space.tabulate_dof_coordinates()[:nodes, :gdim]
        at = np.searchsorted(rows, owned_rows(problem, name)).reshape(nodes, gdim)  # rows is sorted
        for i in range(gdim):
            modes[i, at[:, i]] = 1.0
        # rotations in the planes (x, y), (y, z), (z, x): (-y, x, 0), (0, -z, y), (z, 0, -x)
        planes = [(0, 1)] if gdim == 2 else [(0, 1), (1, 2), (2, 0)]
        for k, (i, j) in enumerate(planes):
            modes[gdim + k, at[:, i]] = -x[:, j]
            modes[gdim + k, at[:, j]] = x[:, i]
    comm = problem.snes.comm
    vectors: list[PETSc.Vec] = []
    for mode in modes:
        v = PETSc.Vec().createMPI((rows.size, PETSc.DETERMINE), comm=comm)
        v.array[:] = mode
        for w in vectors:  # modified Gram-Schmidt (collective dots)
            v.axpy(-v.dot(w), w)
        v.normalize()
        vectors.append(v)
    space = PETSc.NullSpace().create(vectors=vectors, comm=comm)
    for v in vectors:
        v.destroy()
    return space


class FieldSplit:
    """The index sets ``u`` and ``p`` of a :class:`bcfem.solver.problem.Problem`'s blocked system,
    and the rigid-body near-nullspace of ``u``, for PETSc's ``fieldsplit`` PC. Destroy with
    :meth:`destroy` (collective)."""

    def __init__(self, problem: ConvergedAlgebra):
        comm = problem.snes.comm
        self.names = split_names(problem)
        if not self.names["u"] or not self.names["p"]:
            raise ValueError(f"a field split needs a vector field and another state; the states are "
                             f"{', '.join(problem.names)}")
        self.index_sets: dict[str, PETSc.IS] = {}
        rows = {}
        for split, names in self.names.items():
            rows[split] = np.sort(np.concatenate([owned_rows(problem, n) for n in names])).astype(PETSc.IntType)
            self.index_sets[split] = PETSc.IS().createGeneral(rows[split], comm=comm)
        gdim = problem.ctx.mesh.geometry.dim
        self.index_sets["u"].setBlockSize(gdim)
        self.near_nullspace = rigid_body_modes(problem, self.names["u"], rows["u"])
        # PCFieldSplit gives the split's matrix what is composed on its index set
        self.index_sets["u"].compose("nearnullspace", self.near_nullspace)
        # the splits read their options at set-up, from the database: put the scene's and bcfem's
        # there (the user's are there already, and won in the merge)
        opts = PETSc.Options()
        self._written = [problem.prefix + key for key in problem.options
                         if "fieldsplit_" in key and not opts.hasName(problem.prefix + key)]
        for name in self._written:
            opts.setValue(name, problem.options[name[len(problem.prefix):]])

    def configure(self, pc: PETSc.PC) -> None:
        """Give ``pc`` (of type fieldsplit) the splits, before its set-up."""
        pc.setFieldSplitIS(*self.index_sets.items())

    def destroy(self) -> None:
        opts = PETSc.Options()
        for name in self._written:
            opts.delValue(name)
        self._written = []
        for index_set in self.index_sets.values():
            index_set.destroy()
        self.near_nullspace.destroy()
        self.index_sets = {}


def reduced_inner_ksp(problem: ConvergedAlgebra, split: FieldSplit) -> PETSc.KSP:
    """One application of the user's field split (their ``-<prefix>pc_*`` options) to a full-size
    matrix: the preconditioner of the Krylov method that solves the reduced system."""
    ksp = PETSc.KSP().create(problem.snes.comm)
    ksp.setType("preonly")
    pc = ksp.getPC()
    pc.setOptionsPrefix(problem.prefix)
    pc.setType(TYPE)
    split.configure(pc)
    pc.setFromOptions()
    return ksp
