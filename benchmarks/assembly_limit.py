"""The crater cell's assembly against its limit: docs/benchmarks/assembly-limit.{csv,md}.

The limit is a bare dolfinx assembly of what every Newton iteration needs at least, on the same
mesh: the residual and the tangent of a nearly incompressible neo-Hookean solid in Taylor-Hood
cells (P2 displacement, P1 pressure), quadrature degree 4, as blocked PETSc objects. The
scene's cost is its own: the assembly time of `bcfem run crater-cell --preload 0.0125` (its
`time_split_s.assembly`: every stage and form of its Newton solves, each solve's first residual
lifted by the platen's move; the stability counts' tangents are timed as stability) over its
Newton iterations. Their ratio says
how far the scene's assembly is from the limit (issue #53 asks for 2 at most).

Run from the repository root, on an idle machine: `.venv/bin/python benchmarks/assembly_limit.py`
(about 3 min on one core); `--render-only` writes the page again from the CSV.
"""

from __future__ import annotations

import sys
import time

from mpi4py import MPI

import ufl
from common import ROOT, atomic_text, csv_text, table, write_report
from dolfinx import fem
from dolfinx.fem.petsc import assemble_matrix, assemble_vector

import bcfem  # noqa: F401  (before dolfinx / petsc4py)
from bcfem.geometry.crater_cell import create_mesh
from bcfem.io import read_csv
from bcfem.log import configure
from bcfem.scenes import crater_cell

OUT = ROOT / "docs" / "benchmarks"
#: issue #53's two cells (the default mesh and the finer one) and one of about 1e5 dofs, at its filling
FILLING = 0.0490873852
MESHES = {"default": {}, "fine": {"size_wall": 0.15, "size_rim": 0.05, "size_far": 0.4},
          "1e5": {"size_wall": 0.13, "size_rim": 0.043, "size_far": 0.33}}
REPEATS = 5
COLUMNS = ["mesh", "dofs", "newton_iterations", "scene_assembly_s", "scene_per_iteration_s", "bare_per_iteration_s",
           "ratio"]


def bare_assembly(msh, kappa: float, repeats: int) -> float:
    """Seconds of one residual and one tangent of the Taylor-Hood neo-Hookean solid on ``msh``."""
    V = fem.functionspace(msh, ("Lagrange", 2, (3,)))
    Q = fem.functionspace(msh, ("Lagrange", 1))
    u, p = fem.Function(V), fem.Function(Q)
    u.interpolate(lambda x: 0.01 * x)  # a deformed state: every quadrature point does real work
    F = ufl.Identity(3) + ufl.grad(u)
    J = ufl.det(F)
    dx = ufl.Measure("dx", domain=msh, metadata={"quadrature_degree": 4})
    energy = (0.5 * (ufl.tr(F.T * F) - 3) - ufl.ln(J) + p * (J - 1) - p**2 / (2 * kappa)) * dx
    states = [u, p]
    residual = [ufl.derivative(energy, s, ufl.TestFunction(s.function_space)) for s in states]
    tangent = [[ufl.derivative(r, s, ufl.TrialFunction(s.function_space)) for s in states] for r in residual]
    residual_form, tangent_form = fem.form(residual), fem.form(tangent)
    A = assemble_matrix(tangent_form, kind="mpi")
    A.assemble()
    b = assemble_vector(residual_form, kind="mpi")
    best = float("inf")
    for _ in range(repeats):
        t0 = time.perf_counter()
        A.zeroEntries()
        assemble_matrix(A, tangent_form)
        A.assemble()
        with b.localForm() as local:
            local.set(0.0)
        assemble_vector(b, residual_form)
        best = min(best, time.perf_counter() - t0)
    A.destroy()
    b.destroy()
    return best


def measure(name: str) -> dict:
    params = crater_cell.Params(preload=0.0125, filling=FILLING, **MESHES[name])
    _, summary = crater_cell.solve(params, MPI.COMM_SELF)
    iterations = summary["newton_iterations"]
    scene = summary["time_split_s"]["assembly"]
    msh = create_mesh(params.geometry(), MPI.COMM_SELF).mesh
    bare = bare_assembly(msh, params.kappa_ratio, REPEATS)
    per_iteration = scene / iterations
    return {"mesh": name, "dofs": summary["dofs"], "newton_iterations": iterations, "scene_assembly_s": scene,
            "scene_per_iteration_s": per_iteration, "bare_per_iteration_s": bare, "ratio": per_iteration / bare}


def main(render_only: bool) -> None:
    configure(MPI.COMM_SELF, quiet=True)
    if render_only:  # the page again from the CSV, nothing solved
        rows = read_csv(OUT / "assembly-limit.csv")
    else:
        rows = [measure(name) for name in MESHES]
        atomic_text(OUT / "assembly-limit.csv", csv_text(rows, COLUMNS))
    shown = [("mesh", "{mesh}"), ("dofs", lambda r: f"{int(r['dofs'])}"),
             ("Newton iterations", lambda r: f"{int(r['newton_iterations'])}"),
             ("scene: assembly per iteration [s]", lambda r: f"{r['scene_per_iteration_s']:.3f}"),
             ("bare residual + tangent [s]", lambda r: f"{r['bare_per_iteration_s']:.3f}"),
             ("ratio", lambda r: f"{r['ratio']:.2f}")]
    text = ("# The crater cell's assembly against a bare dolfinx assembly\n\n"
            "`.venv/bin/python benchmarks/assembly_limit.py` (one core). The scene: `bcfem run crater-cell "
            f"--filling {FILLING} --preload 0.0125` (and `--size-wall 0.15 --size-rim 0.05 --size-far 0.4`, "
            "`--size-wall 0.13 --size-rim 0.043 --size-far 0.33`; the default solver), its "
            "assembly time in its Newton solves, every form and stage, over its "
            "Newton iterations. The limit: one residual and one tangent of a Taylor-Hood neo-Hookean solid, "
            "quadrature degree 4, blocked PETSc objects, on the same mesh (the best of "
            f"{REPEATS}).\n\n" + table(rows, shown) + "\n")
    write_report(OUT / "assembly-limit.md", text)
    for r in rows:
        print(r, flush=True)


if __name__ == "__main__":
    main("--render-only" in sys.argv[1:])
