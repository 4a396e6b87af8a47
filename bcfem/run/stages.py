"""A scene's stages as data, and the loop that runs them.

A :class:`Stage` says what a stage changes and what drives it: what happens on entering it
(``enter``: seal a cavity, switch a fluid; it may skip the stage, saying why), the terms its
problem holds, what is set on the problem once built (``prepare``: contact bounds, a force to
measure), the path that drives it (``drive``) and what ends it (``until``, a
:class:`~bcfem.path.terminations.Termination`). ``drive`` records the accepted rows into the
run as it goes (they are the run's as soon as they are accepted) and returns :class:`Ended`:
why it ended, what it found for the summary, and whether the stage is entered again with its
terms built anew. A :class:`StagedScene` builds its model, declares its stages, and
:meth:`StagedScene.solve` runs them in order, each as one problem under the prefix
``bcfem_<scene>_<stage>_``, as PyBaMM's ``Simulation`` runs the steps of an ``Experiment``.
The summary's ``stages`` lists each problem's stage, its end condition and why it ended.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from bcfem.columns import Column
from bcfem.path.terminations import Termination

if TYPE_CHECKING:
    from bcfem.solver.problem import Problem


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


@dataclass(frozen=True)
class Ended:
    """What a stage's drive found.

    Attributes:
        why: why it ended, in words (e.g. ``zero platen force at eps = 0.0412``).
        results: its entries of the summary.
        again: enter the stage again, its terms built anew (a liquid that changed phase,
            chambers that split): the drive then starts from the state it ended in.
    """

    why: str
    results: dict = field(default_factory=dict)
    again: bool = False


@dataclass(frozen=True)
class Stage:
    """One stage of a scene (``run``: the :class:`bcfem.run.runner.Run` it records into; not
    imported here, which the runner imports).

    Attributes:
        name: the stage's name (its PETSc prefix ``bcfem_<scene>_<name>_``).
        terms: the stage's energy terms, built when it is entered (after ``enter``).
        drive: follows the stage's path on its problem, recording the accepted rows into the
            run, until ``until`` holds (or the stage must be entered again): :class:`Ended`.
        until: what ends the stage (recorded in the summary's ``stages``).
        enter: what happens on entering the stage, before its terms are built; it returns
            why the stage is skipped (e.g. a crater that stays closed), or None.
        prepare: what is set on the stage's problem before it is driven.
        petsc_options: the stage's PETSc defaults (the user's options still win).
        options: the keyword arguments of the stage's problem, instead of the scene's
            :attr:`StagedScene.problem_options` (a stage with rows or a scale of its own).
    """

    name: str
    terms: Callable[[], list]
    drive: Callable[[Problem, Any], Ended]
    until: Termination
    enter: Callable[[Any], str | None] | None = None
    prepare: Callable[[Problem], None] | None = None
    petsc_options: dict = field(default_factory=dict)
    options: Callable[[], dict] | None = None


class StagedScene(Scene):
    """A scene whose solve is its stages in order. A subclass sets ``name``, ``columns``,
    ``stages`` (the names it plans) and ``params``, builds its model in :meth:`setup` and returns its stages
    from :meth:`plan`; ``model.ctx``, ``model.bcs`` and :attr:`problem_options` are shared by
    every stage. :attr:`extra_terms` (a research script's) join the terms of every stage they
    belong to (:meth:`bcfem.physics.protocols.Term.belongs_to`)."""

    model: Any = None
    extra_terms: tuple = ()

    @property
    def problem_options(self) -> dict:
        """Keyword arguments of every stage's :class:`~bcfem.solver.problem.Problem`."""
        return {}

    def setup(self, run) -> None:
        """Build the model (mesh, states) and record what the run reports before any stage."""
        raise NotImplementedError

    def plan(self) -> list[Stage]:
        """The stages, in order (called once the model is built)."""
        raise NotImplementedError

    def finish(self, run) -> None:
        """Summary entries once every stage has ended."""

    def context(self) -> tuple[Any, list]:
        """The context and the Dirichlet conditions every stage's problem is built on."""
        return self.model.ctx, self.model.bcs

    def solve(self, run) -> None:
        self.setup(run)
        stages = self.plan()
        undeclared = [s.name for s in stages if s.name not in self.stages]
        if undeclared:
            raise ValueError(f"scene {self.name!r} plans the undeclared stages {undeclared}")
        for stage in stages:
            skipped = stage.enter(run) if stage.enter is not None else None
            if skipped is not None:
                run.stages.append({"stage": stage.name, "until": str(stage.until), "skipped": skipped})
                continue
            again = True
            while again:
                options = {**(stage.options() if stage.options is not None else self.problem_options)}
                petsc = {**options.pop("petsc_options", {}), **stage.petsc_options}
                terms = [*stage.terms(), *(t for t in self.extra_terms if t.belongs_to(stage.name))]
                ctx, bcs = self.context()
                with run.stage(stage.name, ctx, terms, bcs, petsc, **options) as problem:
                    if stage.prepare is not None:
                        stage.prepare(problem)
                    ended = stage.drive(problem, run)
                run.results.update(ended.results)
                run.stages.append({"stage": stage.name, "until": str(stage.until), "ended": ended.why})
                again = ended.again
        self.finish(run)
