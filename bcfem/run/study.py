"""A study: many solves (the branches of a demo, a research script's grid) recorded as one run.

Each branch or scene is solved through the runner's :class:`~bcfem.run.runner.Run` (its
problems under the scene's own PETSc prefixes, the user's options winning), and the study
counts them all: Newton solves and iterations, failed solves, null pivots, the largest
problem, the time split, the JIT and the effective options. A solve on the study's
communicator is counted once; one on a rank's own (a pooled sweep's point,
:func:`bcfem.run.sweep.run_pool`) is summed over the ranks. :meth:`Study.write` writes a
``summary.json`` with the runner's schema (:func:`~bcfem.run.summary.summary_of`) and the
study's own entries; a study that raises writes ``status: failed`` with the error.
"""

from __future__ import annotations

import time
import traceback
from pathlib import Path

from mpi4py import MPI

from bcfem import io, jit, log
from bcfem.path.continuation import Branch, ContinuationError
from bcfem.run.runner import Run, SolveError, solve
from bcfem.run.scene import BranchScene
from bcfem.run.stages import Scene
from bcfem.run.summary import summary_of
from bcfem.run.trace import trace


class _StudyScene(Scene):
    """What the study's own record is named by (no stages of its own, no columns)."""

    def __init__(self, name: str):
        self.name = name
        self.stages = ()


class Study:
    """Solves recorded as one run (use as a context: a failure is written as ``failed``).

    Args:
        name: the study's name (``scene`` in its summary).
        comm: the communicator of its solves.
        out: where :meth:`write` writes ``summary.json``.
        parameters: the study's parameters (``parameters`` in its summary).
    """

    def __init__(self, name: str, comm, out: Path, parameters: dict | None = None):
        jit.install()
        log.ensure(comm)
        self.name, self.comm, self.out = name, comm, Path(out)
        self.parameters = parameters or {}
        self.total = Run(_StudyScene(name), comm)
        #: solves on a communicator of their own (each rank's), summed over the ranks at the end
        self.apart = Run(_StudyScene(name), comm)
        self._started = (time.perf_counter(), jit.tally())
        self.written = False

    def branch(self, scene: BranchScene) -> Branch:
        """Trace an arc-length scene's branch (collective); its problem is closed after."""
        run = Run(scene, self.comm)
        try:
            branch, _ = trace(scene, run.on_accept, run)
        except ContinuationError:
            run.close()
            self.total.absorb(run, scene.name)
            raise
        run.close()
        run.rows[:] = branch.rows
        scene.ended(run, branch)
        self.total.absorb(run, scene.name)
        return branch

    def solve(self, scene: Scene, comm=None) -> tuple[list[dict], dict]:
        """Solve any scene through the runner (collective on ``comm``, default the study's):
        (its rows, its own summary)."""
        comm = comm or self.comm
        record = self.total if comm is self.comm else self.apart
        try:
            run, summary = solve(scene, comm)
        except SolveError as err:
            record.absorb(err.run, scene.name)
            raise
        record.absorb(run, scene.name)
        return run.rows, summary

    def _counted(self) -> Run:
        """The solves together and apart as one record (collective)."""
        comm, apart = self.comm, self.apart
        total = Run(_StudyScene(self.name), comm)
        total.absorb(self.total, self.name)
        total.stages = list(self.total.stages)
        for key in ("newton_solves", "newton_iterations", "failed_solves"):
            setattr(total, key, getattr(total, key) + comm.allreduce(getattr(apart, key)))
        total.null_pivots = max(total.null_pivots, comm.allreduce(apart.null_pivots, op=MPI.MAX))
        total.dofs = max(total.dofs, comm.allreduce(apart.dofs, op=MPI.MAX))
        for key, seconds in apart.timings.items():  # this rank's own share of its wall time
            total.timings[key] = total.timings.get(key, 0.0) + seconds
        for options in comm.allgather(apart.petsc_options):
            total.petsc_options.update(options)
        total.rows.extend({} for _ in range(comm.allreduce(len(apart.rows))))
        return total

    def summary(self, entries: dict, status: str = "ok", error: str | None = None,
                trace_text: str | None = None) -> dict:
        """The study's summary: the runner's schema, then ``entries`` (collective)."""
        return {**summary_of(self._counted(), self.name, self.parameters, status, error, self._started, trace_text),
                **entries}

    def write(self, entries: dict) -> dict:
        """Write ``summary.json`` into ``out`` (rank 0; collective) and return it."""
        summary = self.summary(entries)
        io.write_json(self.out / "summary.json", summary, self.comm)
        self.written = True
        return summary

    def __enter__(self) -> Study:
        return self

    def __exit__(self, kind, error, tb) -> None:
        # collective: a study fails on every rank (a path that cannot go on, a check of global values)
        if error is not None and not self.written and isinstance(error, Exception):
            text = "".join(traceback.format_exception(error))
            summary = self.summary({}, "failed", f"{type(error).__name__}: {error}", text)
            io.write_json(self.out / "summary.json", summary, self.comm)
