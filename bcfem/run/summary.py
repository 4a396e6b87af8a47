"""The ``summary.json`` every run writes (one schema for every scene and study): its status, what
it found, its counts and where its wall time went."""

from __future__ import annotations

import time

from bcfem import columns, jit


def versions() -> dict:
    from petsc4py import PETSc

    import dolfinx

    import bcfem

    return {"bcfem": bcfem.__version__, "dolfinx": dolfinx.__version__,
            "petsc": "{}.{}.{}".format(*PETSc.Sys.getVersion())}




def summary_of(run, name: str, parameters: dict, status: str, error: str | None,
               started: tuple[float, jit.Tally], trace_text: str | None = None) -> dict:
    """The ``summary.json`` of ``run`` (a :class:`bcfem.run.runner.Run`; one schema for every scene
    and study): its status, the parameters, what it found (``run.results``), its stages and
    columns, the counts of its problems, the wall time from ``started`` (a clock and the JIT's
    tally) and its split, each rank's peak memory, the versions and the effective PETSc options
    (collective: the JIT's counts are summed)."""
    t0, jit0 = started
    wall = time.perf_counter() - t0
    compiled = jit.tally() - jit0
    return {
        "scene": name,
        "status": status,
        "error": error,
        **({"traceback": trace_text} if trace_text else {}),
        "parameters": parameters,
        **run.results,
        "stages": run.stages,
        "columns": columns.record(run.scene.columns),
        "steps": len(run.rows),
        "newton_solves": run.newton_solves,
        "newton_iterations": run.newton_iterations,
        "failed_solves": run.failed_solves,
        "null_pivots": run.null_pivots,
        "dofs": run.dofs,
        "ranks": run.comm.size,
        "wall_time_s": wall,
        "time_split_s": time_split(run.timings, wall, compiled.seconds),
        "peak_rss_mb": peak_rss_mb(run.comm),
        "jit": compiled.over(run.comm),
        "versions": versions(),
        "petsc_options": run.petsc_options,
    }



def peak_rss_mb(comm) -> list[float]:
    """Each rank's peak resident memory so far, in MB (collective; the process's high-water mark,
    so a run in a process that ran others before reports theirs if larger)."""
    import resource

    return comm.allgather(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0)


def time_split(timings: dict, wall: float, jit_s: float = 0.0) -> dict:
    """Where a run's wall time went. Within Newton: form assembly, discrete terms
    (self-contact), the direct solver's factorisations (analysis included) and its triangular
    solves, and the rest of Newton (line search, active sets, reduced matrices, convergence
    tests); then stability checks, the form compiler (compiling and loading forms, wherever
    it ran), and everything else (meshing, observables, relaxation set-up, output)."""
    split = {"assembly": timings["assembly"], "discrete_terms": timings["discrete_terms"],
             "factorisation": timings["factorisation"], "linear_solve": timings["linear_solve"],
             "newton_other": timings["newton"], "stability": timings["stability"], "jit": jit_s}
    split["other"] = wall - sum(split.values())
    return split
