"""What a scene is: the type the runner takes (:class:`Scene`), and the arc-length scene
(:class:`BranchScene`): a geometry and states (the context), energy terms, boundary
conditions, a load path and its observables. Nothing here knows which physics a scene holds.

Every scene has a ``name``, declared ``stages`` (its PETSc prefixes are
``bcfem_<name>_<stage>_``), ``params``, ``columns``, ``solve(run)``, ``figures(rows,
summary)`` and ``tables(rows, summary)`` (:mod:`bcfem.run.runner` drives it). A
:class:`BranchScene` has the one stage ``branch``; a staged scene declares its own, as data
(:class:`bcfem.run.stages.StagedScene`) or in its ``solve``.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

from bcfem.columns import Column
from bcfem.params import ContinuationParams
from bcfem.path.terminations import Termination
from bcfem.physics.context import Context


class Scene:
    """What the runner solves: a scene's contract, with no figures and no extra tables by
    default.

    Attributes:
        name: the registry name (the PETSc prefixes ``bcfem_<name>_<stage>_``).
        stages: the names of the stages it declares.
        params: its parameters (a dataclass, recorded in ``summary.json``), or None.
        columns: the columns of ``branch.csv`` with their units (:func:`bcfem.columns.declare`;
            None: every key of the rows).
    """

    name: str
    stages: tuple[str, ...]
    params: Any = None
    columns: Sequence[Column] | None = None

    def solve(self, run) -> None:
        """Solve into ``run`` (:class:`bcfem.run.runner.Run`): its rows, results and stages'
        problems. Raises on a path that cannot go on, with the converged part in ``run``."""
        raise NotImplementedError

    def figures(self, rows, summary) -> dict:
        """PNG file name -> matplotlib figure, drawn after the solve (rank 0)."""
        return {}

    def tables(self, rows, summary) -> dict[str, list[dict]]:
        """CSV file name -> rows, besides ``branch.csv``."""
        return {}


@dataclass
class BranchScene(Scene):
    """A composed model traced by arc-length, ready to solve.

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

    def solve(self, run) -> None:
        """Trace the branch into ``run``: its rows, limit points, events and counts."""
        from bcfem.path.continuation import ContinuationError
        from bcfem.run.trace import trace

        run.watch(self.fields)
        try:
            branch, problem = trace(self, run.on_accept, run)
        except ContinuationError as err:
            self._report(run, err.branch)
            raise
        self._report(run, branch)
        self.ended(run, branch)

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

        return {name: branch_figure(self._branch, x, y, xl, yl, title=self.name)
                for name, (x, y, xl, yl) in self.plots.items()}


def describe(end: Callable[[dict], float]) -> str:
    """An end condition in words: a termination's own, else its function's summary line."""
    if isinstance(end, Termination):
        return str(end)
    doc = (end.__doc__ or "").strip().splitlines()
    return doc[0] if doc else "the scene's end function turns non-negative"
