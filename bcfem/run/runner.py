"""Solve any scene and write its results directory: one contract for every scene.

A scene declares its stages and solves itself into a :class:`Run`, which builds each
stage's :class:`~bcfem.solver.problem.Problem` under the prefix ``bcfem_<scene>_<stage>_`` and
records the accepted rows, the effective PETSc options and the cost. Arc-length scenes
(:class:`~bcfem.run.scene.Scene`) and staged scenes (a crater cycle) differ only in their
``solve``. Outputs (rank 0 writes CSV, JSON and PNG; all ranks write VTX):

* ``summary.json``: ``status`` (``ok``, ``failed`` or ``interrupted``) and ``error`` (with a
  ``traceback`` for an internal error), the parameters, the scene's results, ``steps``,
  ``newton_iterations``, ``dofs``, ``ranks``, ``wall_time_s`` and its split, ``jit`` (the forms
  compiled and loaded, :mod:`bcfem.jit`), ``versions``,
  ``petsc_options`` (the effective options, by full name) and ``files`` (what the run wrote);
* ``branch.csv``: the accepted rows; on failure or interruption the converged part is kept;
* the scene's PNGs, and ``fields.bp`` for scenes with fields (``fields_<name>.bp`` for
  fields on a boundary submesh).

Files an earlier run listed and this one did not write are removed (:mod:`bcfem.run.outdir`).
"""

from __future__ import annotations

import time
import traceback
from contextlib import contextmanager
from dataclasses import asdict, is_dataclass
from pathlib import Path

from bcfem import columns, interrupt, io, jit, log
from bcfem.log import logger
from bcfem.path.checkpoint import Checkpoints, ResumeError, StageCheckpoints
from bcfem.path.continuation import ContinuationError
from bcfem.path.stepping import SteppingError
from bcfem.run import outdir, resume
from bcfem.run.stages import Scene
from bcfem.run.summary import summary_of
from bcfem.solver.memory import OutOfMemory
from bcfem.solver.problem import TIMED, Problem

#: what a scene raises when its path cannot go on (the converged part is kept)
SolveErrors = (ContinuationError, SteppingError, io.DiskFull, OutOfMemory, ResumeError)
#: more unknowns than this make a run warn that it will take minutes (on a few cores)
LARGE_PROBLEM_DOFS = 200_000


class SolveError(RuntimeError):
    """A scene's solve failed; ``run`` holds what converged."""

    def __init__(self, message: str, run: Run):
        super().__init__(message)
        self.run = run


def _parameters(params) -> dict:
    """A scene's parameters as a dict, for ``summary.json``."""
    return asdict(params) if is_dataclass(params) and not isinstance(params, type) else {}


class Run:
    """The record of one solve of a scene.

    Attributes:
        rows: accepted states' observables, in path order.
        stages: each stage's problem in order: its end condition and why it ended.
        results: the scene's own summary entries (filled as the solve goes on, so that
            a failed solve still reports what it found).
        petsc_options: effective options of every stage's problem, by full name.
        dofs: the largest global size of the stages' problems.
        newton_solves, newton_iterations: Newton solves and their iterations (fallbacks
            included), over every stage.
        summary: the run's ``summary.json``, set when the solve ends (:func:`solve`).
    """

    def __init__(self, scene: Scene, comm, fields_path: Path | None = None, rows_path: Path | None = None,
                 checkpoints: Checkpoints | None = None):
        self.scene = scene
        #: the run's checkpoints (None: none written)
        self.checkpoints = checkpoints
        self.comm = comm
        self.fields_path = fields_path
        self._writers: list = []
        #: the rows on disk as they are accepted (``rows_path``), else None
        self.journal = io.RowJournal(rows_path, columns.names(scene.columns), comm) if rows_path else None
        self.rows: list[dict] = []
        self.results: dict = {}
        self.petsc_options: dict[str, str] = {}
        self.dofs = 0
        self.newton_solves = 0
        self.newton_iterations = 0
        self.failed_solves = 0
        #: the most null pivots of a converged tangent, over every stage (0: all regular)
        self.null_pivots = 0
        self.timings = dict.fromkeys(TIMED, 0.0)
        #: each stage's problem: its end condition and why it ended (or why it was skipped)
        self.stages: list[dict] = []
        self.summary: dict = {}
        self._problems: list[Problem] = []

    def prefix(self, stage: str) -> str:
        """``bcfem_<scene>_<stage>_``, for a stage the scene declares."""
        if stage not in self.scene.stages:
            raise ValueError(f"scene {self.scene.name!r} declares the stages {self.scene.stages}, not {stage!r}")
        return f"bcfem_{self.scene.name}_{stage}_".replace("-", "_")

    def problem(self, stage: str, ctx, terms, bcs, petsc_options=None, **kwargs) -> Problem:
        """The problem of ``stage`` (closed by :meth:`close` or :meth:`stage`)."""
        problem = Problem(ctx, terms, bcs, self.prefix(stage), petsc_options, **kwargs)
        if self.checkpoints is not None:
            problem.checkpoints = StageCheckpoints(self.checkpoints, stage, self.rows, self._resumed)
        self.petsc_options.update({problem.prefix + k: str(v) for k, v in problem.options.items()})
        dofs = problem.global_size(problem.names)
        if dofs > LARGE_PROBLEM_DOFS >= self.dofs:
            logger.warning(f"warning: {dofs} dofs: a large problem (more than {LARGE_PROBLEM_DOFS}); "
                           "expect minutes")
        self.dofs = max(self.dofs, dofs)
        self._problems.append(problem)
        return problem

    @contextmanager
    def stage(self, stage: str, ctx, terms, bcs, petsc_options=None, **kwargs):
        """:meth:`problem` as a context: the problem is closed on leaving, also on failure."""
        problem = self.problem(stage, ctx, terms, bcs, petsc_options, **kwargs)
        try:
            yield problem
        finally:
            self.release(problem)

    def release(self, problem: Problem) -> None:
        """Count the problem's Newton iterations and destroy its PETSc objects."""
        if problem in self._problems:
            self._problems.remove(problem)
            self.newton_solves += problem.newton_solves
            self.newton_iterations += problem.newton_iterations
            self.failed_solves += problem.failed_solves
            self.null_pivots = max(self.null_pivots, problem.null_pivots or 0)
            for key, seconds in problem.timings.items():
                self.timings[key] = self.timings.get(key, 0.0) + seconds
            problem.close()

    def watch(self, functions) -> None:
        """Write ``functions`` at every recorded row (collective; VTX, when the run has a
        fields path): those on the first one's mesh into ``fields.bp``, those on another mesh
        (a boundary submesh) into ``fields_<name of its first function>.bp``. A second call,
        e.g. for the model of a retraced path, starts the files again."""
        if self.fields_path is None or not functions:
            return
        self._close_writers()
        groups: dict[int, list] = {}
        for f in functions:
            groups.setdefault(id(f.function_space.mesh), []).append(f)
        for k, group in enumerate(groups.values()):
            path = self.fields_path if k == 0 else self.fields_path.with_name(f"fields_{group[0].name}.bp")
            self._writers.append(io.FieldWriter(self.comm, path, group))

    @property
    def resuming(self) -> bool:
        """Whether the run is resumed and not yet past its last checkpoint: its rows up to there
        are on disk, and its fields are written from there."""
        return self.checkpoints is not None and self.checkpoints.resuming

    def _resumed(self, rows: list[dict]) -> None:
        """Past the last checkpoint: ``rows`` are on disk, and the run writes from there."""
        if self.journal is not None:
            self.journal.rewrite(rows)

    def on_accept(self, row: dict) -> None:
        """Write an accepted state's row (with a rows path) and its watched fields (their time:
        the arc length, or the row's index); a traced branch calls it with each row it keeps.
        Nothing is written before a resumed run passes its last checkpoint."""
        if self.resuming:
            return
        for writer in self._writers:  # the fields first: a row on disk has its fields on disk
            writer.write(row.get("s", len(self.rows)))
        if self.journal is not None:
            self.journal.append(row)

    def _close_writers(self) -> None:
        for writer in self._writers:
            writer.close()
        self._writers = []

    def record(self, row: dict) -> None:
        """Keep an accepted state's observables (on disk too, with a rows path), and write its
        fields."""
        self.on_accept(row)
        self.rows.append(row)

    def replace_last(self, row: dict) -> None:
        """The last accepted row replaced by ``row`` (a state found past it, e.g. by bisection)."""
        self.rows[-1] = row
        if self.journal is not None and not self.resuming:
            self.journal.rewrite(self.rows)

    def drop_last(self) -> dict:
        """The last accepted row, taken out of the rows (a state the scene reports otherwise)."""
        row = self.rows.pop()
        if self.journal is not None and not self.resuming:
            self.journal.rewrite(self.rows)
        return row

    def restart(self) -> None:
        """Forget the rows and results (a scene that traces its path again from the start)."""
        self.rows.clear()
        self.results.clear()
        self.stages.clear()
        if self.journal is not None and not self.resuming:
            self.journal.rewrite([])

    def absorb(self, other: Run, label: str) -> None:
        """Count ``other``'s finished problems as this run's (a study of many runs): its Newton
        counts, timings, options and rows; its stages under ``label``."""
        self.newton_solves += other.newton_solves
        self.newton_iterations += other.newton_iterations
        self.failed_solves += other.failed_solves
        self.null_pivots = max(self.null_pivots, other.null_pivots)
        self.dofs = max(self.dofs, other.dofs)
        for key, seconds in other.timings.items():
            self.timings[key] = self.timings.get(key, 0.0) + seconds
        self.petsc_options.update(other.petsc_options)
        self.rows.extend(other.rows)
        self.stages.extend({**stage, "stage": f"{label}: {stage['stage']}"} for stage in other.stages)

    def close(self) -> None:
        for problem in list(self._problems):
            self.release(problem)
        self._close_writers()
        if self.journal is not None:
            self.journal.close()


def solve(scene: Scene, comm, fields_path: Path | None = None,
          started: tuple[float, jit.Tally] | None = None, rows_path: Path | None = None,
          checkpoints: Checkpoints | None = None) -> tuple[Run, dict]:
    """Solve ``scene``; returns (the run, its summary). When the path cannot go on, raises
    :class:`SolveError` (with the run, whose ``summary`` says ``failed``); on a signal
    :class:`~bcfem.interrupt.Interrupted` (``status`` ``interrupted``, the run as its ``run``);
    on any other exception a :class:`SolveError` from it (``failed``, with the traceback).
    With ``fields_path`` the fields the scene watches are written there (VTX), with ``rows_path``
    the rows as they are accepted (:class:`bcfem.io.RowJournal`). ``started``: the
    clock and the JIT's tally when the scene began to be built (its wall time and compiles
    count from there; default: from here). With ``checkpoints`` its paths write checkpoints (and a
    resumed run goes on from them); a run that ends ok removes them."""
    jit.install()
    log.ensure(comm)
    t0, jit0 = started if started is not None else (time.perf_counter(), jit.tally())
    owned = checkpoints is not None  # else a sweep point's, which the sweep removes (:func:`checkpointed`)
    checkpoints = checkpoints if owned else resume.point_checkpoints()
    run = Run(scene, comm, fields_path, rows_path, checkpoints)
    status, error, raised = "ok", None, None
    try:
        scene.solve(run)
        if checkpoints is not None and checkpoints.resuming:
            logger.warning(f"warning: the resumed run never reached its last checkpoint "
                           f"({checkpoints.latest_key}); its rows are from the start")
    except SolveErrors as err:
        status, error = "failed", str(err)
    except (Exception, interrupt.Interrupted) as err:
        raised = err
    finally:
        with interrupt.deferred():
            run.close()
    signum = interrupt.received(comm)  # every rank says the same
    if signum and (raised is not None or status == "failed"):
        status, error = "interrupted", f"interrupted by {interrupt.Interrupted(signum)}"
        raised = interrupt.Interrupted(signum)
    elif raised is not None:
        status, error = "failed", f"internal error: {type(raised).__name__}: {raised}"
    run.summary = summary_of(run, scene.name, _parameters(scene.params), status, error, (t0, jit0),
                             trace_text="".join(traceback.format_exception(raised))
                             if status == "failed" and raised else None)
    if checkpoints is not None:
        run.summary["resumed_from"] = checkpoints.latest_key
        if status == "ok" and owned:
            checkpoints.remove()
    if isinstance(raised, interrupt.Interrupted):
        raised.run = run
        raise raised
    if error:
        raise SolveError(error, run) from raised
    return run, run.summary


def solve_rows(scene: Scene, comm) -> tuple[list[dict], dict]:
    """:func:`solve` in memory: (the accepted rows, the summary)."""
    solved, summary = solve(scene, comm)
    return solved.rows, summary


def solve_into(scene: Scene, out: Path, comm, plots: bool = True,
               started: tuple[float, jit.Tally] | None = None, checkpoints: Checkpoints | None = None) -> dict:
    """Solve ``scene`` and write ``out`` (also on failure or a signal, then raising
    :class:`SolveError` or :class:`~bcfem.interrupt.Interrupted` after writing), with the
    scene's PNGs unless ``plots`` is False; returns the summary. The summary's ``files``
    lists what the run wrote; an earlier run's files not among them are removed. ``started`` and
    ``checkpoints``: as :func:`solve`'s."""
    out = Path(out)
    if comm.rank == 0:
        out.mkdir(parents=True, exist_ok=True)
    previous = outdir.files_of_last_run(out) if comm.rank == 0 else []
    comm.barrier()
    failure = None
    with io.recording() as written:
        if checkpoints is not None and checkpoints.resuming and comm.rank == 0:
            outdir.keep_fields_part(out)
        try:
            solved, summary = solve(scene, comm, out / "fields.bp", started, out / "branch.csv", checkpoints)
        except (SolveError, interrupt.Interrupted) as err:
            if err.run is None:
                raise
            failure, solved, summary = err, err.run, err.run.summary
        with interrupt.deferred():  # the results of a signalled run are written all the same
            def results() -> None:
                io.write_csv(out / "branch.csv", solved.rows, comm, columns.names(scene.columns))
                for name, table in scene.tables(solved.rows, summary).items():  # the scene's declared tables
                    io.write_csv(out / name, table, comm)
                if plots and comm.rank == 0 and solved.rows:
                    for name, fig in scene.figures(solved.rows, summary).items():
                        io.save_figure(fig, out / name, comm)
                _write_summary(out, summary, written, previous, comm)

            try:
                io.collectively(comm, results)
            except io.DiskFull as err:  # the rows accepted so far stay in branch.csv
                summary.update(status="failed", error=str(err))
                try:  # a short summary may still fit
                    io.collectively(comm, lambda: _write_summary(out, summary, written, previous, comm))
                except io.DiskFull:
                    pass
                failure = SolveError(str(err), solved)
    if isinstance(failure, interrupt.Interrupted):
        raise failure
    if failure is not None:
        raise SolveError(f"{summary['error']} (the converged part is in {out})", solved)
    logger.info(f"{scene.name}: {len(solved.rows)} points, {summary['wall_time_s']:.2f} s -> {out}")
    return summary


def write_unsolved(out: Path, name: str, params, error: BaseException, comm) -> dict:
    """The summary of a run stopped before its solve (while its scene was built): ``failed``
    with the traceback, or ``interrupted``."""
    out = Path(out)
    previous = outdir.files_of_last_run(out) if comm.rank == 0 else []
    summary: dict
    if isinstance(error, interrupt.Interrupted):
        summary = {"scene": name, "status": "interrupted", "error": f"interrupted by {error}"}
    else:
        summary = {"scene": name, "status": "failed", "error": f"internal error: {type(error).__name__}: {error}",
                   "traceback": "".join(traceback.format_exception(error))}
    summary["parameters"] = _parameters(params)
    with interrupt.deferred():
        _write_summary(out, summary, [], previous, comm)
    return summary


def _write_summary(out: Path, summary: dict, written: list[Path], previous: list[str], comm) -> None:
    """Write ``summary.json`` with the list of the run's files, and remove the files of the
    run before that are not among them (rank 0)."""
    names = {str(p.relative_to(out)) for p in written if p.is_relative_to(out)
             and not p.is_relative_to(out / resume.FOLDER)}
    kept = {resume.FOLDER} if comm.rank == 0 and (out / resume.FOLDER).is_dir() else set()
    summary["files"] = sorted(names | kept | {"summary.json"})
    io.write_json(out / "summary.json", summary, comm)
    if comm.rank == 0:
        outdir.remove_stale(out, previous, summary["files"])
