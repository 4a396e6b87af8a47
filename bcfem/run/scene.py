"""The arc-length scene (:class:`BranchScene`): a geometry and states (the context), energy
terms, boundary conditions, a load path and its observables, solved as a staged scene of the
one stage ``branch`` (:class:`bcfem.run.stages.StagedScene`), an arc-length stage. Nothing
here knows which physics a scene holds.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

from bcfem.columns import Column
from bcfem.params import ContinuationParams
from bcfem.path.branch import Branch
from bcfem.path.terminations import Described, Termination
from bcfem.physics.context import Context
from bcfem.run.stages import Ended, Stage, StagedScene


@dataclass
class BranchScene(StagedScene):
    """A composed model traced by arc-length, ready to solve: a staged scene whose one stage,
    ``branch``, follows the branch from its start to ``end``.

    Attributes:
        name: the registry name (also the PETSc prefix ``bcfem_<name>_``).
        ctx: context with the mesh, displacement and kinematics.
        terms: energy terms; only these are compiled.
        bcs: Dirichlet conditions.
        load: name of the real-space state that is the load parameter.
        start: ``start(fraction)`` sets an initial guess at ``fraction`` of the
            scene's starting level and returns the starting load.
        observe: collective; observables of the current state (normalised).
        end: the path ends where this turns non-negative (a
            :class:`~bcfem.path.terminations.Termination`, or a function of the observables).
        begin: if given, the path is first traced backwards from the start until
            this turns positive (for branches whose small-load end cannot be
            reached from a simple guess).
        grows: the observable that increases along the forward path (orients the
            first tangent).
        progress_keys: observables shown in the progress line.
        petsc_options: scene defaults for PETSc.
        fields: functions written to the VTX file.
        continuation: step control of the load path.
        plots: PNG file name -> (x column, y column, x label, y label).
        load_scale: typical magnitude of the load, for the arc-length norm.
        guard: message for a converged state that is physically out of range, else None.
        rows: replacement residual rows of states (e.g. a held or free debond radius).
        switches: model changes along the path (``bcfem.path.continuation.Switch``).
        summarize: extra entries of ``summary.json`` from the finished branch.
        params: the scene's parameters (recorded in ``summary.json``).
        columns: the columns of ``branch.csv`` (:func:`bcfem.columns.declare`).
    """

    name: str
    ctx: Context
    terms: list
    bcs: list
    load: str
    start: Callable[[float], float]
    observe: Callable[[], dict]
    end: Callable[[dict], float]
    progress_keys: tuple[str, ...] = ()
    begin: Callable[[dict], float] | None = None
    grows: str | None = None
    petsc_options: dict = field(default_factory=dict)
    fields: list = field(default_factory=list)
    continuation: ContinuationParams = field(default_factory=ContinuationParams)
    plots: dict = field(default_factory=dict)
    load_scale: float = 1.0
    guard: Callable[[dict], str | None] | None = None
    rows: dict = field(default_factory=dict)
    switches: list = field(default_factory=list)
    summarize: Callable[[object], dict] | None = None
    params: Any = None
    columns: Sequence[Column] | None = None
    #: observers of the trace whose state a checkpoint keeps (:class:`bcfem.path.checkpoint.Kept`)
    kept: tuple = ()
    #: the traced branch (None until the trace ends)
    _branch: Branch | None = field(default=None, init=False, repr=False)

    stages = ("branch",)

    @property
    def prefix(self) -> str:
        return f"bcfem_{self.name}_branch_".replace("-", "_")

    # -- the hooks of the runner's trace (:func:`bcfem.run.runner.trace`) --------------------
    def arc_length(self):
        """The arc-length continuation of the branch (a scene may measure it otherwise)."""
        from bcfem.path.continuation import ArcLength

        return ArcLength(self.ctx, self.load, self.continuation, self.load_scale)

    @property
    def energy_scale(self) -> float:
        """The residual's unit: the load's."""
        return self.load_scale

    def first_point(self, arc, problem) -> None:
        """Converge the first point (a scene may reach it another way, e.g. by a homotopy)."""
        from bcfem.run.trace import start

        start(arc, problem, self)

    def trace_back(self, arc, problem, forward: int):
        """(the branch traced backwards from the start to where ``begin`` turns positive, or
        None; the forward direction). The states are restored to the start."""
        if self.begin is None:
            return None, forward
        origin = problem.save()
        back = arc.trace(problem, self.observe, self.begin, self.progress_keys, guard=self.guard,
                         direction=-forward)
        problem.restore(origin)
        arc.restart_row(problem)
        return back, forward

    # -- the one stage -----------------------------------------------------------------------
    def context(self) -> tuple[Context, list]:
        return self.ctx, self.bcs

    def setup(self, run) -> None:
        run.watch(self.fields)
        self._arc = self.arc_length()

    @property
    def problem_options(self) -> dict:
        return dict(petsc_options=self.petsc_options, rows={**self.rows, **self._arc.rows()},
                    energy_scale=self.energy_scale)

    def plan(self) -> list[Stage]:
        until = self.end if isinstance(self.end, Termination) else Described(describe(self.end))
        return [Stage("branch", terms=lambda: self.terms, drive=self._trace, until=until)]

    def _trace(self, problem, run) -> Ended:
        """Trace the branch into ``run``: its rows, limit points, events and counts."""
        from bcfem.path.continuation import ContinuationError
        from bcfem.run.trace import trace

        try:
            branch, _ = trace(self, run.record, run, arc=self._arc, problem=problem)
        except ContinuationError as err:
            self._report(run, err.branch)
            raise
        self._report(run, branch)
        return Ended(f"the end condition holds at point {len(branch.rows)}")

    def ended(self, run, branch) -> None:
        """Record the branch's stage as ended by its end condition (the summary's ``stages``)."""
        run.stages.append({"stage": "branch", "until": describe(self.end),
                           "ended": f"the end condition holds at point {len(branch.rows)}"})

    def _report(self, run, branch) -> None:
        run.rows[:] = branch.rows
        run.results.update({
            "limit_points": [{**lp.values, "kind": lp.kind} for lp in branch.limit_points],
            "events": branch.events,
            **(self.summarize(branch) if self.summarize and branch.rows else {}),
            "failed_steps": branch.failed_steps})
        self._branch = branch

    def figures(self, rows, summary) -> dict:
        """The scene's ``plots`` of the branch, limit points marked."""
        from bcfem.plots import branch_figure

        branch = self._branch or Branch(rows=list(rows))  # a trace that stopped: the rows it kept
        return {name: branch_figure(branch, x, y, xl, yl, title=self.name)
                for name, (x, y, xl, yl) in self.plots.items()}


def describe(end: Callable[[dict], float]) -> str:
    """An end condition in words: a termination's own, else its function's summary line."""
    if isinstance(end, Termination):
        return str(end)
    doc = (end.__doc__ or "").strip().splitlines()
    return doc[0] if doc else "the scene's end function turns non-negative"
