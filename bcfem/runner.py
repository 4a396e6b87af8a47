"""Solve a scene along its load path and write its results directory.

Outputs (rank 0 writes CSV, JSON and PNG; all ranks write VTX):
``branch.csv``, ``summary.json``, ``fields.bp`` and the scene's PNGs.
"""

from __future__ import annotations

import time
from dataclasses import asdict
from pathlib import Path

from bcfem import io
from bcfem.continuation import ArcLength, Branch, ContinuationError
from bcfem.log import logger
from bcfem.problem import Problem


def versions() -> dict:
    import dolfinx
    from petsc4py import PETSc

    import bcfem

    return {"bcfem": bcfem.__version__, "dolfinx": dolfinx.__version__,
            "petsc": "{}.{}.{}".format(*PETSc.Sys.getVersion())}


def trace(scene, on_accept=None) -> tuple[Branch, Problem]:
    """Build the arc-length problem of ``scene``, start it and follow the branch.

    If the scene has a ``begin`` condition, the branch is first traced backwards
    from the start to where ``begin`` turns positive (without switches, and
    without field output), then forwards; the rows are joined in path order,
    with negative arc lengths before the start.
    """
    arc = ArcLength(scene.ctx, scene.load, scene.continuation, scene.load_scale)
    problem = Problem(scene.ctx, scene.terms, scene.bcs, scene.prefix,
                      scene.petsc_options, rows={**scene.rows, **arc.rows()},
                      energy_scale=scene.load_scale)
    back = None
    try:
        start(arc, problem, scene)
        forward = arc.forward_sign(problem, scene.observe, scene.grows) if scene.grows else 1
        if scene.begin is not None:
            origin = problem.save()
            back = arc.trace(problem, scene.observe, scene.begin, scene.progress_keys,
                             guard=scene.guard, direction=-forward)
            problem.restore(origin)
            arc.restart_row(problem)
        branch = arc.trace(problem, scene.observe, scene.end, scene.progress_keys, on_accept=on_accept,
                           guard=scene.guard, switches=scene.switches, direction=forward)
    except ContinuationError as err:
        err.problem = problem
        if not hasattr(err, "branch"):
            err.branch = Branch()
        raise
    if back is not None:
        branch = _join(back, branch)
    return branch, problem


def _join(back: Branch, forward: Branch) -> Branch:
    """A backward and a forward branch from the same start, as one branch in path order."""
    def flip(values):
        return {**values, "s": -values["s"]}

    for lp in back.limit_points:
        lp.s, lp.values = -lp.s, flip(lp.values)
    return Branch(rows=[flip(r) for r in reversed(back.rows[1:])] + forward.rows,
                  limit_points=list(reversed(back.limit_points)) + forward.limit_points,
                  events=forward.events,
                  newton_iterations=back.newton_iterations + forward.newton_iterations,
                  failed_steps=back.failed_steps + forward.failed_steps,
                  wall_time_s=back.wall_time_s + forward.wall_time_s)


def branch_of(scene) -> Branch:
    """Trace ``scene`` and destroy its PETSc objects at once, also when the trace fails.

    For scripts that need only the branch; left to the garbage collector, the
    objects can deadlock at exit under MPI.
    """
    try:
        branch, problem = trace(scene)
    except ContinuationError as error:
        if getattr(error, "problem", None) is not None:
            error.problem.close()
        raise
    problem.close()
    return branch


def start(arc, problem, scene, attempts: int = 6) -> None:
    """Converge the first point; if the guess is too far, start closer to the unloaded state.

    Each retry halves the starting load level of the scene's guess (a flatter
    cap is closer to its equilibrium); the last failure is raised.
    """
    for attempt in range(attempts):
        try:
            arc.start(problem, scene.start(0.5**attempt))
            return
        except ContinuationError:
            if attempt == attempts - 1:
                raise


def run(scene, params, out: Path, comm, columns: list[str] | None = None) -> dict:
    """Trace ``scene`` and write ``out``; returns the summary dict."""
    t0 = time.perf_counter()
    out = Path(out)
    if comm.rank == 0:
        out.mkdir(parents=True, exist_ok=True)
    comm.barrier()
    fields = io.FieldWriter(comm, out / "fields.bp", scene.fields) if scene.fields else None
    on_accept = (lambda values: fields.write(values["s"])) if fields else None
    status, error = "complete", None
    try:
        branch, problem = trace(scene, on_accept)
    except ContinuationError as err:
        # keep what converged, and say plainly that the branch is incomplete
        status, error = "failed", str(err)
        branch, problem = err.branch, err.problem
    if fields:
        fields.close()
    dofs = sum(s.function_space.dofmap.index_map.size_global * s.function_space.dofmap.bs
               for s in problem.states)
    petsc_options = {k: str(v) for k, v in problem.options.items()}
    problem.close()
    wall = time.perf_counter() - t0

    io.write_csv(out / "branch.csv", branch.rows, comm, columns)
    summary = {
        "scene": scene.name,
        "status": status,
        "error": error,
        "parameters": asdict(params),
        "limit_points": [{**lp.values, "kind": lp.kind} for lp in branch.limit_points],
        "events": branch.events,
        **(scene.summarize(branch) if scene.summarize else {}),
        "steps": len(branch.rows),
        "newton_iterations": branch.newton_iterations,
        "failed_steps": branch.failed_steps,
        "dofs": dofs,
        "ranks": comm.size,
        "wall_time_s": wall,
        "versions": versions(),
        "petsc_options": petsc_options,
    }
    io.write_json(out / "summary.json", summary, comm)
    if comm.rank == 0:
        from bcfem.plots import branch_figure

        for name, (x, y, xl, yl) in scene.plots.items():
            fig = branch_figure(branch, x, y, xl, yl, title=scene.name)
            io.save_figure(fig, out / name, comm)
    if error:
        raise ContinuationError(f"{error} (the converged part is in {out})")
    logger.info(f"{scene.name}: {len(branch.rows)} points, {len(branch.limit_points)} limit points, "
                f"{wall:.2f} s -> {out}")
    return summary


def run_staged(module, params, out: Path, comm) -> dict:
    """Run a scene that drives its own stages (``module.solve``) and write its results."""
    out = Path(out)
    if comm.rank == 0:
        out.mkdir(parents=True, exist_ok=True)
    rows, summary = module.solve(params, comm)
    summary = {**summary, "versions": versions()}
    io.write_csv(out / "branch.csv", rows, comm, module.COLUMNS)
    io.write_json(out / "summary.json", summary, comm)
    if comm.rank == 0 and hasattr(module, "plot"):
        io.save_figure(module.plot(rows, summary), out / "cycle.png", comm)
    logger.info(f"{module.__name__.rsplit('.', 1)[-1]}: {len(rows)} points, {summary['wall_time_s']:.2f} s -> {out}")
    return summary
