"""PETSc's SNESNEWTONAL against bcfem's bordered pseudo-arc-length, on the clamped Gent blister.

Both solve the same discrete equations (Gent Jm = 100, alpha = 0, P2, 200 cells):
the displacement residual of the membrane strain energy minus the pressure
times the (follower) volume derivative, dPi/du - P dV/du = 0.

* bcfem: ``runner.trace`` - the arc-length equation is one more real-space
  row of the blocked Newton system; adaptive step, retries, folds located by
  Brent on dP/ds = 0.
* NEWTONAL: the unknown is u alone; PETSc owns the load parameter lambda,
  and the residual is F(u) - (P0 + lambda) q(u), with q = dV/du re-assembled
  at every iterate (the tangent-load callback) and P0 the pressure of the
  converged start. Fixed step (raw 2-norm of (u, lambda)), no fold location:
  the best it can do for a fold is the nearest converged increment.

Run from the repository root, on one core::

    OMP_NUM_THREADS=1 taskset -c 0 .venv/bin/python benchmarks/newtonal_vs_bordered.py

Prints a markdown table (docs/continuation.md holds a copy).
"""

from __future__ import annotations

import argparse
import time

import dolfinx_solver  # noqa: F401  (before dolfinx / petsc4py)
from mpi4py import MPI
from petsc4py import PETSc

import numpy as np
import ufl
from dolfinx import fem
from dolfinx.fem.petsc import NonlinearProblem, assemble_jacobian, assemble_residual, assemble_vector, set_bc

from bcfem.mpi import global_sum
from bcfem.params import ContinuationParams
from bcfem.physics.energies import MembraneStrain
from bcfem.run.trace import trace
from bcfem.scenes import blister_rigid
from bcfem.solver import options

V0 = blister_rigid.V0
NEWTON = {"snes_rtol": 1e-10, "snes_atol": 1e-10, "snes_stol": 1e-12, "ksp_type": "preonly",
          "pc_type": "lu", "pc_factor_mat_solver_type": "mumps"}  # bcfem's defaults


def scene_of(args, **continuation):
    params = blister_rigid.Params(material="gent", Jm=100.0, alpha=0.0, cells=args.cells, degree=args.degree,
                                  v_max=args.v_max, continuation=ContinuationParams(**continuation))
    return blister_rigid.build(params, MPI.COMM_WORLD)


def folds(P):
    """Interior extrema of P along the recorded points: (kind, index)."""
    return [("max" if P[i] > P[i - 1] else "min", i) for i in range(1, len(P) - 1)
            if (P[i] - P[i - 1]) * (P[i + 1] - P[i]) < 0]


# -- bcfem: bordered pseudo-arc-length ------------------------------------------------------
def run_bcfem(args, ds_max):
    scene = scene_of(args, ds_max=ds_max, ds=min(0.05, ds_max))
    t0, c0 = time.perf_counter(), time.process_time()
    branch, problem = trace(scene)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    its = problem.newton_iterations  # every Newton solve, also those of the event location
    problem.close()
    return {"method": "bcfem bordered", "setting": f"ds_max={ds_max:g}", "steps": len(branch.rows) - 1,
            "its": its, "wall": wall, "cpu": cpu, "V_end": branch.rows[-1]["V_over_V0"], "stop": "reached v_max",
            "folds": {lp.kind: (lp.values["P"], lp.values["V_over_V0"]) for lp in branch.limit_points}}


# -- SNESNEWTONAL ---------------------------------------------------------------------------
def run_newtonal(args, step, correction="exact"):
    scene = scene_of(args)
    ctx, bcs = scene.ctx, scene.bcs
    u, kin = ctx.u, ctx.kin
    V = u.function_space
    t0, c0 = time.perf_counter(), time.process_time()
    p0 = scene.start()  # cap guess; its simple-membrane pressure
    pressure = fem.Constant(ctx.mesh, p0)
    strain = sum(t.energy(ctx) for t in scene.terms if isinstance(t, MembraneStrain))
    v = ufl.TestFunction(V)
    volume = kin.integral(kin.volume_density)
    F = ufl.derivative(strain - kin.integral(pressure * kin.volume_density), u, v)
    J = ufl.derivative(F, u, ufl.TrialFunction(V))

    def problem(prefix, opts):  # unique prefix; the options database is left as it was
        with options.untouched():
            return NonlinearProblem(F, u, bcs=bcs, J=J, petsc_options_prefix=prefix, petsc_options=opts)

    # converge at P0 with plain Newton (NEWTONAL always starts at lambda = 0 from the given u)
    start = problem("nal_start_", {**NEWTON, "snes_type": "newtonls", "snes_linesearch_type": "basic"})
    start.solve()
    its = start.solver.getIterationNumber()
    assert start.solver.getConvergedReason() > 0, "no converged start"

    nal = problem("nal_", {**NEWTON, "snes_type": "newtonal", "snes_max_it": 25,
                           "snes_newtonal_step_size": step, "snes_newtonal_max_continuation_steps": 5000,
                           "snes_newtonal_lambda_min": -1e10, "snes_newtonal_lambda_max": 1e10,
                           "snes_newtonal_correction_type": correction})
    snes = nal.solver
    q_form, v_form = fem.form(ufl.derivative(volume, u, v)), fem.form(volume)

    def to_u(x):
        x.copy(u.x.petsc_vec)
        u.x.scatter_forward()

    def load(snes, x, q):  # Q = -dF/dlambda = dV/du at the current iterate (follower load)
        to_u(x)
        with q.localForm() as q_local:
            q_local.set(0.0)
        assemble_vector(q, q_form)
        q.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        set_bc(q, bcs)  # zero on Dirichlet rows (the conditions are homogeneous)

    def residual(snes, x, b):  # F(u) - (P0 + lambda) q(u), lambda owned by PETSc
        pressure.value = p0 + snes.getNewtonALLoadParameter()
        assemble_residual(snes, x, b, u, nal.F, nal.J, bcs)

    def jacobian(snes, x, A, P):  # includes -P d2V/du2 (load stiffness of the follower pressure)
        pressure.value = p0 + snes.getNewtonALLoadParameter()
        assemble_jacobian(snes, x, A, P, u, nal.J, None, bcs)

    path = []

    def monitor(snes, it, fnorm):  # record converged increments; stop past v_max
        if snes.getConvergedReason() > 0:
            to_u(snes.getSolution())
            path.append((global_sum(v_form) / V0, p0 + snes.getNewtonALLoadParameter()))
            if path[-1][0] >= args.v_max:
                snes.setConvergedReason(PETSc.SNES.ConvergedReason.DIVERGED_MAX_IT)

    snes.setFunction(residual, nal.b)
    snes.setJacobian(jacobian, nal.A)
    snes.setNewtonALFunction(load)  # after the type is newtonal and setFromOptions (else dropped)
    snes.setMonitor(monitor)
    nal.solve()
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    its += snes.getIterationNumber()
    reason = snes.getConvergedReason()
    Vs, Ps = np.array([pv[0] for pv in path]), np.array([pv[1] for pv in path])
    stop = "reached v_max" if len(Vs) and Vs[-1] >= args.v_max else f"stopped: {reason_name(reason)}"
    found = {}
    for kind, i in folds(Ps):
        found.setdefault(kind, (Ps[i], Vs[i], parabola(Vs[i - 1:i + 2], Ps[i - 1:i + 2])))
    return {"method": "PETSc NEWTONAL", "setting": f"step={step:.3g} ({correction})", "steps": len(path),
            "its": its, "wall": wall, "cpu": cpu, "V_end": Vs[-1] if len(Vs) else float("nan"), "stop": stop,
            "folds": found, "path": path}


def parabola(x, y):
    """Extremum of the parabola through three points (post-processing, not NEWTONAL's)."""
    c = np.polyfit(x, y, 2)
    return np.polyval(c, -c[1] / (2 * c[0]))


def reason_name(code):
    return next((k for k, v in vars(PETSc.SNES.ConvergedReason).items() if v == code and k.isupper()), str(code))


def table(rows, ref):
    L = ["| method | setting | steps | Newton its | wall [s] | CPU [s] | end | P max: rel. error (nearest step / 3-pt parabola) "
         "| P min: rel. error (nearest step / 3-pt parabola) |", "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        cells = []
        for kind in ("max", "min"):
            if kind not in r["folds"]:
                cells.append("not passed")
            elif r["method"].startswith("bcfem"):
                p = r["folds"][kind][0]
                cells.append(f"located (Brent): {abs(p - ref[kind]) / ref[kind]:.1e}")
            else:
                p, _, fit = r["folds"][kind]
                cells.append(f"passed; {abs(p - ref[kind]) / ref[kind]:.1e} / {abs(fit - ref[kind]) / ref[kind]:.1e}")
        L.append(f"| {r['method']} | {r['setting']} | {r['steps']} | {r['its']} | {r['wall']:.2f} | {r['cpu']:.2f} "
                 f"| V/V0 = {r['V_end']:.3f}, {r['stop']} | {cells[0]} | {cells[1]} |")
    return "\n".join(L)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cells", type=int, default=200)
    ap.add_argument("--degree", type=int, default=2)
    ap.add_argument("--v-max", type=float, default=6.0)
    ap.add_argument("--repeats", type=int, default=3, help="runs per setting; the best time is kept")
    ap.add_argument("--steps", type=float, nargs="+", default=[0.01, 0.02, 0.04, 0.08, 0.16, 0.64],
                    help="NEWTONAL step sizes, in units of sqrt(number of dofs)")
    args = ap.parse_args()
    V = scene_of(args).ctx.u.function_space
    n = V.dofmap.index_map.size_global * V.dofmap.index_map_bs  # displacement dofs

    def best(run, *a):  # best of --repeats runs (the least disturbed by other load)
        runs = [run(args, *a) for _ in range(args.repeats)]
        return {**runs[0], "wall": min(r["wall"] for r in runs), "cpu": min(r["cpu"] for r in runs)}

    run_bcfem(args, 0.1), run_newtonal(args, 0.04 * np.sqrt(n))  # warm the JIT cache and imports
    rows = [best(run_bcfem, 0.1), best(run_bcfem, 0.5)]
    ref = {k: v[0] for k, v in rows[0]["folds"].items()}  # located folds of the same discrete problem
    rows += [best(run_newtonal, c * np.sqrt(n)) for c in args.steps]
    rows += [best(run_newtonal, 0.04 * np.sqrt(n), "normal")]
    print(f"Gent Jm=100, alpha=0, P{args.degree}, {args.cells} cells ({n} displacement dofs), to V/V0 = {args.v_max}; "
          f"reference folds (bcfem, Brent): P_max = {ref['max']:.12f}, P_min = {ref['min']:.12f}\n")
    print(table(rows, ref))


if __name__ == "__main__":
    main()
